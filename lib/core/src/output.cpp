#include "navimpact/core/output.hpp"

#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdint>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <mutex>
#include <random>
#include <set>

#include "navimpact/core/error.hpp"

namespace fs = std::filesystem;

namespace navimpact {
namespace {

std::string hex16(std::uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

/// FNV-1a of the host name: identifies "this machine" in staging names
/// (separator-free, unlike host names).
std::string hostTag() {
  char name[256] = {0};
  if (gethostname(name, sizeof name - 1) != 0) std::strcpy(name, "unknown");
  std::uint64_t h = 1469598103934665603ULL;
  for (const char* p = name; *p; ++p) h = (h ^ static_cast<unsigned char>(*p)) * 1099511628211ULL;
  return hex16(h);
}

/// True when @p folder, or one of the folders in it, contains a folder: a
/// navimpact output is files plus at most one level of folders of files.
bool deeperThanOneLevel(const fs::path& folder) {
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(folder, ec)) {
    if (!e.is_directory(ec) || e.is_symlink(ec)) continue;
    for (const auto& f : fs::directory_iterator(e.path(), ec))
      if (f.is_directory(ec) && !f.is_symlink(ec)) return true;
  }
  return static_cast<bool>(ec);
}

/// The first folder of @p folder (itself or a folder in it) whose entries this
/// process cannot remove (no write and search permission for its effective
/// ids, e.g. a sub-folder a container left owned by root), or "" when none.
/// Replacing the output whole deletes them all: checked before any work, as a
/// delete that stops half-way would leave part of the old output hidden in a
/// staging folder.
std::string unremovableIn(const fs::path& folder) {
  auto blocked = [](const fs::path& p) { return ::faccessat(AT_FDCWD, p.c_str(), W_OK | X_OK, AT_EACCESS) != 0; };
  if (blocked(folder)) return folder.string();
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(folder, ec))
    if (e.is_directory(ec) && !e.is_symlink(ec) && blocked(e.path())) return e.path().string();
  return {};
}

// The staging folders of this process's live jobs, for removeLiveStaging()
// (a signal handler): fixed slots of plain bytes. A slot is free (0), being
// written or cleared (1), or published (2); the handler reads only published
// slots, so it never sees a path half copied (a prefix such as "/tmp" would
// have been emptied).
constexpr int kLiveSlots = 32;
constexpr std::size_t kLivePathMax = 4096;
enum : int { kSlotFree = 0, kSlotBusy = 1, kSlotPublished = 2 };
char g_livePath[kLiveSlots][kLivePathMax];
std::atomic<int> g_liveState[kLiveSlots];

int registerLive(const fs::path& p) noexcept {
  const std::string& s = p.native();
  if (s.empty() || s.size() >= kLivePathMax) return -1;
  for (int i = 0; i < kLiveSlots; ++i) {
    int expected = kSlotFree;
    if (g_liveState[i].compare_exchange_strong(expected, kSlotBusy)) {
      std::memcpy(g_livePath[i], s.c_str(), s.size() + 1);
      g_liveState[i].store(kSlotPublished, std::memory_order_release);
      return i;
    }
  }
  return -1;  // more than 32 at once: the next run in the folder removes it
}

void unregisterLive(int slot) noexcept {
  if (slot < 0) return;
  g_liveState[slot].store(kSlotBusy, std::memory_order_release);
  g_livePath[slot][0] = '\0';
  g_liveState[slot].store(kSlotFree, std::memory_order_release);
}

/// Remove the entries of the folder open at @p fd, then close it; a folder
/// inside is emptied the same way (staging folders are at most two levels
/// deep). Only async-signal-safe calls (getdents64, unlinkat, openat, lseek).
void emptyFolderFd(int fd, int depth) noexcept {
  struct Dirent64 {
    std::uint64_t d_ino;
    std::int64_t d_off;
    unsigned short d_reclen;
    unsigned char d_type;
    char d_name[1];
  };
  alignas(8) char buf[4096];
  for (int pass = 0; pass < 1000; ++pass) {  // entries removed while listing: list again from the start
    if (::lseek(fd, 0, SEEK_SET) != 0) break;
    bool removed = false;
    for (;;) {
      const long n = ::syscall(SYS_getdents64, fd, buf, sizeof buf);
      if (n <= 0) break;
      for (long off = 0; off < n;) {
        const auto* d = reinterpret_cast<const Dirent64*>(buf + off);
        off += d->d_reclen;
        const char* name = d->d_name;
        if (name[0] == '.' && (name[1] == '\0' || (name[1] == '.' && name[2] == '\0'))) continue;
        if (::unlinkat(fd, name, 0) == 0) {
          removed = true;
        } else if (errno == EISDIR && depth > 0) {
          const int sub = ::openat(fd, name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
          if (sub >= 0) emptyFolderFd(sub, depth - 1);
          if (::unlinkat(fd, name, AT_REMOVEDIR) == 0) removed = true;
        }
      }
    }
    if (!removed) break;
  }
  ::close(fd);
}

std::mutex g_inputsMutex;
std::set<fs::path>& inputs() {
  static std::set<fs::path> s;
  return s;
}

/// An input of this run that is @p p or lies inside it (canonical paths), or "".
std::string inputAt(const fs::path& p) {
  std::lock_guard<std::mutex> lock(g_inputsMutex);
  for (const auto& in : inputs()) {
    const auto rel = in.lexically_relative(p);
    if (!rel.empty() && *rel.begin() != "..") return in.string();
  }
  return {};
}

bool isEmptyDir(const fs::path& p) {
  std::error_code ec;
  return fs::is_empty(p, ec) && !ec;
}

/// Why @p dest must not be replaced whole, or "" when it may be.
std::string refuseReplace(const fs::path& dest) {
  std::error_code ec;
  const fs::path d = fs::weakly_canonical(dest, ec);
  if (d == d.root_path()) return "refusing to replace the file-system root";
  if (const char* home = std::getenv("HOME"); home && *home && fs::equivalent(d, fs::path(home), ec))
    return "refusing to replace the home folder";
  const fs::path cwd = fs::weakly_canonical(fs::current_path(ec), ec);
  const auto rel = cwd.lexically_relative(d);
  if (!rel.empty() && *rel.begin() != "..") return "refusing to replace the current folder or a folder containing it";
  if (deeperThanOneLevel(d))
    return "it holds folders of folders, which no navimpact output does; remove it yourself if it is meant";
  if (const std::string in = inputAt(d); !in.empty())
    return "it holds " + in + ", an input of this run (write the output elsewhere)";
  if (const std::string f = unremovableIn(d); !f.empty())
    return "this user may not delete the files in " + f + " (no write permission there), so the old output could not be removed whole";
  return {};
}

/// True when a process holds the lock of staging folder @p p (a live job).
bool lockedByLiveJob(const fs::path& p) {
  const int fd = ::open(p.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return false;
  const bool held = ::flock(fd, LOCK_EX | LOCK_NB) != 0 && errno == EWOULDBLOCK;
  ::close(fd);  // releases the lock if this call took it
  return held;
}

}  // namespace

void removeLiveStaging() noexcept {
  for (int i = 0; i < kLiveSlots; ++i) {
    if (g_liveState[i].load(std::memory_order_acquire) != kSlotPublished) continue;
    const int fd = ::open(g_livePath[i], O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    if (fd >= 0) emptyFolderFd(fd, 2);
    ::rmdir(g_livePath[i]);
  }
}

void noteInput(const fs::path& path) {
  std::error_code ec;
  const fs::path c = fs::weakly_canonical(fs::absolute(path, ec), ec);
  if (ec || c.empty()) return;
  std::lock_guard<std::mutex> lock(g_inputsMutex);
  inputs().insert(c);
}

int OutputSet::removeStaleStaging(const fs::path& folder) {
  static const std::string self = hostTag();
  const std::string prefix = kStagingPrefix;
  int removed = 0;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(folder, ec)) {
    const std::string name = e.path().filename().string();
    if (name.compare(0, prefix.size(), prefix) != 0 || !e.is_directory(ec)) continue;
    // <prefix><pid>_<16 hex random>_<16 hex host>_<destination name>
    const std::string rest = name.substr(prefix.size());
    const auto u1 = rest.find('_');
    if (u1 == std::string::npos || u1 == 0 || rest.size() < u1 + 35 || rest[u1 + 17] != '_' ||
        rest[u1 + 34] != '_')
      continue;
    if (rest.find_first_not_of("0123456789") < u1) continue;
    const std::string host = rest.substr(u1 + 18, 16);
    if (host.find_first_not_of("0123456789abcdef") != std::string::npos) continue;
    bool dead = false;
    if (host == self) {
      // its lock free (no job holds it, whatever its PID namespace) and its pid gone
      // (a job of an older build that took no lock)
      const long pid = std::strtol(rest.substr(0, u1).c_str(), nullptr, 10);
      dead = pid > 0 && kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH && !lockedByLiveJob(e.path());
    } else {  // another machine sharing this folder: only when clearly abandoned
      const auto age = fs::file_time_type::clock::now() - fs::last_write_time(e.path(), ec);
      dead = !ec && age > std::chrono::hours(24 * 7);
    }
    if (!dead) continue;
    std::error_code rec;
    fs::remove_all(e.path(), rec);
    if (!rec) ++removed;
  }
  return removed;
}

OutputSet::OutputSet(fs::path dir, Overwrite ow) : OutputSet(std::move(dir), ow, Kind::Directory) {}

OutputSet OutputSet::singleFile(fs::path file, Overwrite ow) { return OutputSet(std::move(file), ow, Kind::File); }

OutputSet::OutputSet(fs::path dest, Overwrite ow, Kind kind) : dest_(std::move(dest)), ow_(ow), kind_(kind) {
  const std::string shown = dest_.string();
  if (shown.empty()) throw Error("output path is empty");
  std::error_code ec;
  fs::path abs = fs::absolute(dest_, ec).lexically_normal();
  if (!abs.has_filename()) abs = abs.parent_path();
  if (abs == abs.root_path()) throw Error(shown + ": refusing to write an output onto the file-system root");
  const fs::path parent = abs.parent_path();

  // Missing parent folders are created now and removed again if the job fails.
  std::vector<fs::path> missing;
  for (fs::path p = parent; !p.empty() && !fs::exists(p, ec); p = p.parent_path()) {
    missing.push_back(p);
    if (p == p.root_path()) break;
  }
  for (auto it = missing.rbegin(); it != missing.rend(); ++it) {
    const bool created = fs::create_directory(*it, ec);
    if (!created && !ec && fs::is_directory(*it, ec)) continue;  // another job created it meanwhile
    if (!created || ec) {
      removeCreatedParents();
      throw Error(it->string() + ": cannot create folder for " + shown + " (" +
                  (ec ? ec.message() : std::string("exists and is not a folder")) + ")");
    }
    createdParents_.push_back(*it);
  }
  if (!fs::is_directory(parent, ec)) throw Error(parent.string() + ": not a folder (output " + shown + ")");

  removeStaleStaging(parent);

  try {
    const auto st = fs::symlink_status(abs, ec);
    if (fs::exists(st)) {
      if (kind_ == Kind::Directory) {
        if (!fs::is_directory(st)) throw Error(shown + ": exists and is not a folder (an output folder is expected)");
        if (!isEmptyDir(abs)) {
          if (ow_ == Overwrite::Refuse)
            throw Error(shown + ": output folder exists and is not empty (pass --overwrite to replace it whole)");
          if (const auto why = refuseReplace(abs); !why.empty()) throw Error(shown + ": --overwrite: " + why);
        }
      } else {
        if (fs::is_directory(st)) throw Error(shown + ": is a folder (an output file is expected)");
        if (!fs::is_regular_file(st) && !fs::is_symlink(st))
          throw Error(shown + ": exists and is not a regular file (a device, pipe or socket is never replaced, "
                              "--overwrite or not)");
        if (ow_ == Overwrite::Refuse) throw Error(shown + ": output file exists (pass --overwrite to replace it)");
      }
      // in a folder with the sticky bit (/tmp) only the owner of an entry or
      // of the folder may rename over it: fail before the work, not at commit
      struct stat sd {}, sp {};
      const uid_t me = ::geteuid();
      if (me != 0 && ::lstat(abs.c_str(), &sd) == 0 && ::stat(parent.c_str(), &sp) == 0 && (sp.st_mode & S_ISVTX) &&
          sd.st_uid != me && sp.st_uid != me)
        throw Error(shown + ": belongs to another user (uid " + std::to_string(sd.st_uid) + ") in " + parent.string() +
                    ", a folder with the sticky bit, so it cannot be replaced (write the output elsewhere)");
    }
    // a name the folder cannot hold fails here, before the work, not at commit
    if (const long most = ::pathconf(parent.c_str(), _PC_NAME_MAX);
        most > 0 && abs.filename().string().size() > static_cast<std::size_t>(most))
      throw Error(shown + ": the output name is " + std::to_string(abs.filename().string().size()) +
                  " bytes long, more than the " + std::to_string(most) + " a name in " + parent.string() + " may have");
    if (abs.filename().string().compare(0, std::strlen(kStagingPrefix), kStagingPrefix) == 0)
      throw Error(shown + ": an output name starting with " + kStagingPrefix +
                  " is a staging folder's, which later runs remove (choose another name)");
    std::random_device rd;
    const std::uint64_t r = (static_cast<std::uint64_t>(rd()) << 32) ^ rd();
    static const std::string host = hostTag();
    // at most 250 bytes (a file name holds 255; ".old" is added while replacing):
    // the destination's name is only a hint in it
    std::string name = std::string(kStagingPrefix) + std::to_string(getpid()) + "_" + hex16(r) + "_" + host + "_" +
                       abs.filename().string();
    if (name.size() > 250) name.resize(250);
    staging_ = parent / name;
    if (!fs::create_directory(staging_, ec) || ec)
      throw Error(parent.string() + ": cannot create the staging folder for " + shown + " (" +
                  (ec ? ec.message() : std::string("exists")) + ")");
    stagingFd_ = ::open(staging_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (stagingFd_ < 0 || ::flock(stagingFd_, LOCK_EX | LOCK_NB) != 0)
      throw Error(staging_.string() + ": cannot lock the staging folder (" + std::strerror(errno) + ")");
    liveSlot_ = registerLive(staging_);
  } catch (...) {
    if (!staging_.empty()) {
      fs::remove_all(staging_, ec);
      releaseStaging();
    }
    staging_.clear();
    removeCreatedParents();
    throw;
  }
  target_ = abs;
}

OutputSet::OutputSet(OutputSet&& o) noexcept
    : dest_(std::move(o.dest_)),
      target_(std::move(o.target_)),
      staging_(std::move(o.staging_)),
      stagingFd_(o.stagingFd_),
      liveSlot_(o.liveSlot_),
      createdParents_(std::move(o.createdParents_)),
      names_(std::move(o.names_)),
      ow_(o.ow_),
      kind_(o.kind_),
      committed_(o.committed_),
      mayReplaceInput_(o.mayReplaceInput_) {
  o.staging_.clear();
  o.stagingFd_ = -1;
  o.liveSlot_ = -1;
  o.createdParents_.clear();
  o.committed_ = true;
}

OutputSet::~OutputSet() {
  if (!committed_ && !staging_.empty()) {
    std::error_code ec;
    fs::remove_all(staging_, ec);
    removeCreatedParents();
  }
  releaseStaging();
}

void OutputSet::releaseStaging() noexcept {
  unregisterLive(liveSlot_);
  liveSlot_ = -1;
  if (stagingFd_ >= 0) ::close(stagingFd_);  // and its lock
  stagingFd_ = -1;
}

void OutputSet::checkStaging() const {
  // still the folder this job made (not removed, not replaced by another)
  struct stat a {}, b {};
  if (stagingFd_ < 0 || ::fstat(stagingFd_, &a) != 0 || ::stat(staging_.c_str(), &b) != 0 || a.st_dev != b.st_dev ||
      a.st_ino != b.st_ino)
    throw Error(dest_.string() + ": the staging folder " + staging_.filename().string() +
                " was removed while the job ran: nothing was written");
  std::error_code ec;
  for (const auto& n : names_)
    if (!fs::is_regular_file(staging_ / n, ec))
      throw Error(dest_.string() + ": " + n + " vanished from the staging folder while the job ran: nothing was written");
}

void OutputSet::removeCreatedParents() noexcept {
  std::error_code ec;
  for (auto it = createdParents_.rbegin(); it != createdParents_.rend(); ++it) fs::remove(*it, ec);  // only if empty
  createdParents_.clear();
}

fs::path OutputSet::stage(const std::string& name) {
  if (kind_ != Kind::Directory) throw Error(dest_.string() + ": stage() on a single-file output");
  const fs::path rel = fs::path(name).lexically_normal();
  if (rel.empty() || rel.is_absolute() || *rel.begin() == "..")
    throw Error(dest_.string() + ": output name '" + name + "' is not inside the output folder");
  for (const auto& n : names_)
    if (n == rel.string()) throw Error(dest_.string() + ": output '" + n + "' written twice by one job");
  names_.push_back(rel.string());
  const fs::path p = staging_ / rel;
  std::error_code ec;
  // the sub-folder only: a staging folder removed under the job is not made again
  if (!fs::is_directory(staging_, ec))
    throw Error(dest_.string() + ": the staging folder " + staging_.filename().string() + " was removed while the job ran");
  if (p.parent_path() != staging_) {
    fs::create_directory(p.parent_path(), ec);
    if (ec) throw Error(p.parent_path().string() + ": cannot create (" + ec.message() + ")");
  }
  return p;
}

fs::path OutputSet::stagedFile() const {
  if (kind_ != Kind::File) throw Error(dest_.string() + ": stagedFile() on a folder output");
  return staging_ / target_.filename();
}

void OutputSet::writeText(const std::string& name, const std::string& content) {
  const fs::path p = stage(name);
  std::ofstream f(p, std::ios::binary);
  f << content;
  f.close();
  if (!f) throw Error(p.string() + ": cannot write");
}

void OutputSet::commit() {
  if (committed_) throw Error(dest_.string() + ": output committed twice");
  const std::string shown = dest_.string();
  checkStaging();
  if (kind_ == Kind::File) {
    const fs::path src = stagedFile();
    std::error_code ec;
    if (!fs::exists(src, ec)) throw Error(shown + ": nothing was written");
    if (ow_ == Overwrite::Refuse && fs::exists(fs::symlink_status(target_, ec)))
      throw Error(shown + ": output file appeared while the job ran (pass --overwrite to replace it)");
    if (!mayReplaceInput_ && fs::exists(target_, ec) && !inputAt(fs::weakly_canonical(target_, ec)).empty())
      throw Error(shown + ": --overwrite: it is an input of this run (write the output elsewhere)");
    if (std::rename(src.c_str(), target_.c_str()) != 0)
      throw Error(shown + ": cannot move the output into place (" + std::strerror(errno) + ")");
    fs::remove_all(staging_, ec);
  } else {
    if (::rename(staging_.c_str(), target_.c_str()) != 0) {
      const int err = errno;
      if ((err != ENOTEMPTY && err != EEXIST) || ow_ == Overwrite::Refuse)
        throw Error(shown + ": cannot move the output into place (" +
                    (err == ENOTEMPTY || err == EEXIST ? std::string("the folder was filled while the job ran")
                                                       : std::string(std::strerror(err))) +
                    ")");
      if (const auto why = refuseReplace(target_); !why.empty()) throw Error(shown + ": --overwrite: " + why);
      // Replace whole: swap the two folders atomically, then delete the old one
      // (now at the staging name, so a crash here leaves only a stale staging folder).
      if (::renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, target_.c_str(), RENAME_EXCHANGE) != 0) {
        const fs::path old = staging_.string() + ".old";
        if (::rename(target_.c_str(), old.c_str()) != 0)
          throw Error(shown + ": cannot replace the output folder (" + std::strerror(errno) + ")");
        if (::rename(staging_.c_str(), target_.c_str()) != 0) {
          const int e2 = errno;
          ::rename(old.c_str(), target_.c_str());
          throw Error(shown + ": cannot replace the output folder (" + std::strerror(e2) + ")");
        }
        staging_ = old;
      }
      std::error_code ec;
      fs::remove_all(staging_, ec);
    }
  }
  committed_ = true;
  createdParents_.clear();
  releaseStaging();
}

std::vector<fs::path> OutputSet::finalPaths() const {
  std::vector<fs::path> out;
  if (kind_ == Kind::File) return {dest_};
  for (const auto& n : names_) out.push_back(dest_ / n);
  return out;
}

}  // namespace navimpact
