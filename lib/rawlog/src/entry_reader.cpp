#include "entry_reader.hpp"

#include <mrpt/obs/CObservationIMU.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/obs/registerAllClasses.h>
#include <mrpt/rtti/CObject.h>

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <new>
#include <stdexcept>
#include <string_view>

#include "frames.hpp"
#include "mrpt_errors.hpp"
#include "navimpact/core/alloc_limit.hpp"

namespace navimpact::rawlog::detail {

StderrSilence::StderrSilence() {
  std::fflush(stderr);
  const int null = ::open("/dev/null", O_WRONLY | O_CLOEXEC);
  if (null < 0) return;
  saved_ = ::dup(2);
  if (saved_ >= 0 && ::dup2(null, 2) < 0) {
    ::close(saved_);
    saved_ = -1;
  }
  ::close(null);
}

StderrSilence::~StderrSilence() {
  if (saved_ < 0) return;
  std::fflush(stderr);
  ::dup2(saved_, 2);
  ::close(saved_);
}

namespace {
/// The classes whose entries navimpact reads (and what they hold): MRPT
/// prints nothing while it decodes them. Any other class is decoded with
/// stderr silenced (StderrSilence), then skipped by the readers.
bool readByNavimpact(const std::string& name) {
  const auto at = name.rfind("::");
  const std::string base = at == std::string::npos ? name : name.substr(at + 2);
  static const char* const kRead[] = {"CObservationIMU", "CObservationGPS", "CObservationComment", "CSensoryFrame",
                                      "CObservationRobotPose", "CPose3D", "CPose3DPDFGaussian", "CPoint3D"};
  for (const char* k : kRead)
    if (base == k) return true;
  return false;
}
}  // namespace

size_t GzCStream::Read(void* out, size_t n) {
  if (error) return 0;
  try {
    const std::size_t got = in_.read(out, n);
    // An object header naming a class MRPT registers without a constructor
    // (an abstract one: CObservation, CSerializable, ...): MRPT would print a
    // line to stderr and then fail. Refused here, before MRPT sees the name.
    if (name_len_ > 0 && got == n && n == name_len_) {
      // (up to a NUL byte, as MRPT makes a C string of it)
      const std::string_view name(static_cast<const char*>(out), strnlen(static_cast<const char*>(out), n));
      if (name != last_name_) {
        last_name_ = name;
        const auto* id = mrpt::rtti::findRegisteredClass(last_name_);
        last_registered_ = id != nullptr;
        last_abstract_ = id && !id->ptrCreateObject;
        last_read_ = readByNavimpact(last_name_);
      }
      if (last_abstract_) {
        error = Error(in_.path() + ": an object of class '" + printable(last_name_, 60) +
                      "', which MRPT cannot create (an abstract class): malformed entry");
        return 0;
      }
      if (last_registered_ && !last_read_ && !quiet) quiet.emplace();
    }
    const auto* c = static_cast<const unsigned char*>(out);
    const std::size_t old = old_len_;
    name_len_ = old_len_ = 0;
    if (n == 1 && got == 1 && c[0] != 255) {
      if (c[0] & 0x80) name_len_ = c[0] & 0x7F;
      else old_len_ = c[0];
    } else if (old > 0 && n == 3 && got == 3 && c[0] == 0 && c[1] == 0 && c[2] == 0) {
      name_len_ = old;
    }
    return got;
  } catch (const Error& e) {
    error = e;
    return 0;
  }
}

size_t GzCStream::Write(const void*, size_t) { throw std::runtime_error("read-only stream"); }

uint64_t GzCStream::Seek(int64_t, mrpt::io::CStream::TSeekOrigin) { throw std::runtime_error("not seekable"); }

EntryReader::EntryReader(const std::string& path) : in_(path), stream_(in_), arch_(stream_) {
  mrpt::obs::registerAllClasses_mrpt_obs();
  GzInput head(path);  // a bzip2, xz, zstd ... file (or one inside gzip) is named, not parsed as entries
  char b[16] = {};
  const std::size_t n = head.read(b, sizeof b);
  if (const std::string packed = packedFormat({b, n}); !packed.empty()) throw Error(path + ": " + packedError(packed));
}

std::size_t EntryReader::allocationCap() const {
  constexpr std::uint64_t kFloor = std::uint64_t(64) << 20;
  return static_cast<std::size_t>(std::max<std::uint64_t>(kFloor, in_.statedSize()));
}

namespace {
/// MRPT reads each presence flag of a CObservationIMU as one raw byte into a
/// bool; a byte other than 0 or 1 is no bool (using it is undefined
/// behaviour; found by fuzzing): "" or what is wrong.
std::string badImuFlags(const mrpt::serialization::CSerializable* obj) {
  const auto* m = dynamic_cast<const mrpt::obs::CObservationIMU*>(obj);
  if (!m) return {};
  for (std::size_t i = 0; i < m->dataIsPresent.size(); ++i) {
    const unsigned char b = storedByte(m->dataIsPresent[i]);
    if (b > 1)
      return "CObservationIMU presence flag " + std::to_string(i) + " is byte " + std::to_string(b) +
             ", not 0 or 1 (malformed entry)";
  }
  return {};
}
}  // namespace

void EntryReader::fail(const std::string& what) const {
  throw Error(in_.path() + ": entry " + std::to_string(entry_) + ": " + what);
}

mrpt::serialization::CSerializable::Ptr EntryReader::next() {
  try {
    if (in_.atEnd()) return nullptr;  // clean end, between two entries
  } catch (const Error& e) {
    ++entry_;
    throw;
  }
  ++entry_;
  struct EndQuiet {  // stderr back when the entry is read or refused
    GzCStream& s;
    ~EndQuiet() { s.quiet.reset(); }
  } end_quiet{stream_};
  auto streamError = [this]() -> std::string {
    std::string m = stream_.error->what();
    const std::string pre = in_.path() + ": ";
    return m.rfind(pre, 0) == 0 ? m.substr(pre.size()) : m;
  };
  auto refused = [this]() -> std::string {
    const std::size_t n = AllocationLimit::takeRefused();
    if (n == 0) return {};
    return "a length field asks for " + std::to_string(n) + " bytes, more than the file can hold (" +
           std::to_string(in_.statedSize()) + " bytes decompressed): malformed entry";
  };
  AllocationLimit::takeRefused();
  try {
    AllocationLimit limit(allocationCap());
    auto obj = arch_.ReadObject();
    if (!obj) fail("empty object (malformed entry)");
    if (const auto m = badImuFlags(obj.get()); !m.empty()) fail(m);
    if (const auto* sf = dynamic_cast<const mrpt::obs::CSensoryFrame*>(obj.get()))
      for (const auto& o : *sf)
        if (const auto m = badImuFlags(o.get()); !m.empty()) fail(m);
    return obj;
  } catch (const mrpt::serialization::CExceptionEOF&) {
    if (stream_.error) fail(streamError());
    if (const auto r = refused(); !r.empty()) fail(r);
    fail("truncated or malformed entry (the file ends inside it)");
  } catch (const std::bad_alloc&) {
    if (const auto r = refused(); !r.empty()) fail(r);
    fail("out of memory while decoding the entry");
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    if (stream_.error) fail(streamError());
    if (const auto r = refused(); !r.empty()) fail(r);
    fail("truncated or malformed entry (" + mrptCause(e) + ")");
  }
}

}  // namespace navimpact::rawlog::detail
