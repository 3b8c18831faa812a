#include <gtest/gtest.h>
#include <sys/stat.h>
#include <grp.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <optional>
#include <fstream>

#include "navimpact/core/error.hpp"
#include "navimpact/core/output.hpp"
#include "test_support.hpp"

using namespace navimpact;
namespace fs = std::filesystem;

namespace {

std::vector<std::string> entries(const fs::path& dir) {
  std::vector<std::string> v;
  for (const auto& e : fs::directory_iterator(dir)) v.push_back(e.path().filename().string());
  std::sort(v.begin(), v.end());
  return v;
}

int stagingCount(const fs::path& dir) {
  int n = 0;
  for (const auto& e : fs::directory_iterator(dir))
    n += e.path().filename().string().rfind(OutputSet::kStagingPrefix, 0) == 0 ? 1 : 0;
  return n;
}

void touch(const fs::path& p, const std::string& text = "x\n") {
  fs::create_directories(p.parent_path());
  std::ofstream(p) << text;
}

}  // namespace

TEST(OutputSet, NothingAppearsUntilCommit) {
  const fs::path dir = test::tempDir() / "out";
  {
    OutputSet out(dir);
    out.writeText("a.json", "{}");
    EXPECT_FALSE(fs::exists(dir / "a.json"));
    // destroyed without commit: a failed job leaves nothing behind
  }
  EXPECT_FALSE(fs::exists(dir));
  EXPECT_EQ(stagingCount(dir.parent_path()), 0);
  {
    OutputSet out(dir);
    out.writeText("a.json", "{}");
    out.writeText("sub/b.csv", "x\n");
    out.commit();
  }
  EXPECT_TRUE(fs::exists(dir / "a.json"));
  EXPECT_TRUE(fs::exists(dir / "sub/b.csv"));
  EXPECT_EQ(stagingCount(dir.parent_path()), 0);
}

TEST(OutputSet, StagesInOneFolderNextToTheDestination) {
  const fs::path base = test::tempDir();
  OutputSet out(base / "out");
  EXPECT_EQ(out.stagingDir().parent_path(), fs::absolute(base).lexically_normal());
  EXPECT_EQ(out.stage("x.csv").parent_path(), out.stagingDir());
  auto file = OutputSet::singleFile(base / "f" / "x.rawlog");
  EXPECT_EQ(file.stagedFile().parent_path().parent_path(), fs::absolute(base / "f").lexically_normal());
}

TEST(OutputSet, RefusesANonEmptyDestinationBeforeAnyWork) {
  const fs::path dir = test::tempDir() / "out";
  touch(dir / "old.txt");
  EXPECT_THROW(OutputSet out(dir), Error);
  EXPECT_EQ(entries(dir), std::vector<std::string>{"old.txt"});
  EXPECT_EQ(stagingCount(dir.parent_path()), 0);
  fs::remove(dir / "old.txt");
  OutputSet ok(dir);  // an empty folder is fine
  ok.writeText("a", "1");
  ok.commit();
  EXPECT_EQ(entries(dir), std::vector<std::string>{"a"});
  touch(dir.parent_path() / "file.txt");
  EXPECT_THROW(OutputSet(dir.parent_path() / "file.txt"), Error);  // not a folder
}

TEST(OutputSet, OverwriteReplacesTheFolderWhole) {
  const fs::path dir = test::tempDir() / "out";
  touch(dir / "errors_outage_2.png");
  touch(dir / "sub" / "old.csv");
  {
    OutputSet out(dir, Overwrite::Replace);
    out.writeText("summary.json", "{}");
    // failing job: the old output stays as it was
  }
  EXPECT_EQ(entries(dir), (std::vector<std::string>{"errors_outage_2.png", "sub"}));
  OutputSet out(dir, Overwrite::Replace);
  out.writeText("summary.json", "{}");
  out.commit();
  EXPECT_EQ(entries(dir), std::vector<std::string>{"summary.json"});
  EXPECT_EQ(stagingCount(dir.parent_path()), 0);
}

namespace {

/// Replace @p dir whole with one new file as the user @p uid (a forked child
/// that drops root to it; this process when @p uid is ours). Returns the
/// error's message, or "(no error)" when the replacement was committed.
std::string replaceAs(uid_t uid, const fs::path& dir) {
  auto job = [&dir] {
    return test::errorOf([&dir] {
      OutputSet out(dir, Overwrite::Replace);
      out.writeText("summary.json", "{\"new\": true}");
      out.commit();
    });
  };
  if (uid == ::geteuid()) return job();
  int pipeFd[2];
  if (::pipe(pipeFd) != 0) return "pipe failed";
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(pipeFd[0]);
    std::string msg = "cannot drop to the user";
    if (::setgroups(0, nullptr) == 0 && ::setgid(uid) == 0 && ::setuid(uid) == 0) msg = job();
    const ssize_t w = ::write(pipeFd[1], msg.data(), msg.size());
    ::_exit(w == static_cast<ssize_t>(msg.size()) ? 0 : 1);
  }
  ::close(pipeFd[1]);
  std::string msg;
  char buf[512];
  for (ssize_t r; (r = ::read(pipeFd[0], buf, sizeof buf)) > 0;) msg.append(buf, static_cast<std::size_t>(r));
  ::close(pipeFd[0]);
  int status = 0;
  ::waitpid(pid, &status, 0);
  return msg;
}

}  // namespace

// --overwrite over an output holding a folder whose files the user may not
// delete (e.g. one a container wrote as root) is refused before any work: the
// old output stays whole. Once the folder is the user's, it is replaced.
TEST(OutputSet, OverwriteRefusesAnOutputItCouldNotDeleteWhole) {
  const fs::path base = test::tempDir() / "shared";
  const fs::path dir = base / "out";
  touch(dir / "summary.json");
  touch(dir / "plots" / "old.png");
  // as root: the output is another user's and its sub-folder stays root's;
  // as a user: the sub-folder is read-only to its owner
  const bool root = ::geteuid() == 0;
  const uid_t user = root ? 65534 : ::geteuid();  // nobody
  if (root) {
    fs::permissions(base, fs::perms::all);
    for (const fs::path& p : {dir, dir / "summary.json"}) ASSERT_EQ(::chown(p.c_str(), user, user), 0);
  } else {
    fs::permissions(dir / "plots", fs::perms::owner_read | fs::perms::owner_exec);
  }
  const std::string refused = replaceAs(user, dir);
  EXPECT_NE(refused.find("may not delete the files in " + (dir / "plots").string()), std::string::npos) << refused;
  EXPECT_EQ(entries(dir), (std::vector<std::string>{"plots", "summary.json"}));
  EXPECT_TRUE(fs::exists(dir / "plots" / "old.png"));
  EXPECT_EQ(stagingCount(base), 0);

  if (root)
    for (const fs::path& p : {dir / "plots", dir / "plots" / "old.png"}) ASSERT_EQ(::chown(p.c_str(), user, user), 0);
  else
    fs::permissions(dir / "plots", fs::perms::owner_all);
  EXPECT_EQ(replaceAs(user, dir), "(no error)");
  EXPECT_EQ(entries(dir), std::vector<std::string>{"summary.json"});
  EXPECT_EQ(stagingCount(base), 0);
}

// In a folder with the sticky bit (/tmp) another user's output cannot be
// renamed over: refused when the OutputSet is made, not after the work.
TEST(OutputSet, AnOutputOfAnotherUserInAStickyFolderIsRefusedBeforeAnyWork) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root to make an output of another user";
  const fs::path base = test::tempDir() / "sticky";
  const fs::path dir = base / "out";
  touch(dir / "summary.json");
  fs::permissions(base, fs::perms::all | fs::perms::sticky_bit);
  fs::permissions(dir, fs::perms::all);  // root's, but open to all: only the sticky bit stands in the way
  const std::string m = replaceAs(65534, dir);
  EXPECT_NE(m.find(dir.string() + ": belongs to another user (uid 0) in " + base.string() +
                   ", a folder with the sticky bit"),
            std::string::npos) << m;
  EXPECT_EQ(entries(dir), std::vector<std::string>{"summary.json"});
  EXPECT_EQ(stagingCount(base), 0);
}

TEST(OutputSet, OverwriteRefusesFoldersNoOutputLooksLike) {
  const fs::path base = test::tempDir();
  touch(base / "project" / "src" / "lib" / "a.cpp");
  EXPECT_THROW(OutputSet(base / "project", Overwrite::Replace), Error);
  EXPECT_TRUE(fs::exists(base / "project" / "src" / "lib" / "a.cpp"));
  const fs::path cwd = fs::current_path();
  fs::current_path(base / "project" / "src");
  EXPECT_THROW(OutputSet(".", Overwrite::Replace), Error);
  EXPECT_THROW(OutputSet("..", Overwrite::Replace), Error);
  fs::current_path(cwd);
  EXPECT_THROW(OutputSet("/", Overwrite::Replace), Error);
}

TEST(OutputSet, SingleFile) {
  const fs::path base = test::tempDir();
  const fs::path f = base / "x.rawlog";
  {
    auto out = OutputSet::singleFile(f);
    std::ofstream(out.stagedFile()) << "new";
  }
  EXPECT_FALSE(fs::exists(f));
  touch(f, "old");
  EXPECT_THROW(OutputSet::singleFile(f), Error);
  auto out = OutputSet::singleFile(f, Overwrite::Replace);
  std::ofstream(out.stagedFile()) << "new";
  out.commit();
  std::ifstream in(f);
  std::string s;
  in >> s;
  EXPECT_EQ(s, "new");
  EXPECT_EQ(entries(base), std::vector<std::string>{"x.rawlog"});
}

// A device, pipe or socket at the output's path is never replaced by a file,
// --overwrite or not (import --out /dev/full --overwrite replaced the device).
TEST(OutputSet, NeverReplacesANodeThatIsNotAFile) {
  const fs::path base = test::tempDir();
  const fs::path fifo = base / "pipe.rawlog";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  for (const Overwrite ow : {Overwrite::Refuse, Overwrite::Replace}) {
    try {
      OutputSet::singleFile(fifo, ow);
      ADD_FAILURE() << "a FIFO accepted as the output";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("exists and is not a regular file"), std::string::npos) << e.what();
    }
  }
  EXPECT_TRUE(fs::is_fifo(fifo));
  EXPECT_EQ(entries(base), std::vector<std::string>{"pipe.rawlog"});
}

TEST(OutputSet, FailureRemovesTheParentsItCreated) {
  const fs::path base = test::tempDir();
  {
    OutputSet out(base / "a" / "b" / "out");
    out.writeText("x", "1");
  }
  EXPECT_TRUE(entries(base).empty());
}

TEST(OutputSet, OneNameTwiceIsAnError) {
  OutputSet out(test::tempDir() / "out");
  out.writeText("fig.png", "1");
  EXPECT_THROW(out.writeText("fig.png", "2"), Error);
  EXPECT_THROW(out.stage("../escape.txt"), Error);
}

// A run killed without unwinding (here: a child that _exit()s with its OutputSet alive)
// leaves its staging folder; the next OutputSet in that folder removes it,
// but not the staging folder of a process that is still alive.
TEST(OutputSet, StaleStagingOfDeadRunsIsRemoved) {
  const fs::path base = test::tempDir();
  int status = 0;
  const pid_t child = fork();
  if (child == 0) {
    auto* leak = new OutputSet(base / "killed2");  // never destroyed
    leak->writeText("partial.csv", "1\n");
    _exit(0);
  }
  ASSERT_GT(child, 0);
  waitpid(child, &status, 0);
  EXPECT_EQ(stagingCount(base), 1);
  OutputSet alive(base / "alive");  // ours: alive, must survive
  EXPECT_EQ(stagingCount(base), 1);  // the dead one was removed, ours is there
  OutputSet other(base / "other");
  EXPECT_EQ(stagingCount(base), 2);
  // a folder with our prefix but not our naming scheme is left alone
  fs::create_directories(base / (std::string(OutputSet::kStagingPrefix) + "not-ours"));
  EXPECT_EQ(OutputSet::removeStaleStaging(base), 0);
  // another host's staging folder: removed only when older than a week
  const fs::path foreign = base / (std::string(OutputSet::kStagingPrefix) + "1234_0123456789abcdef_" +
                                   "fedcba9876543210_x");
  fs::create_directories(foreign);
  EXPECT_EQ(OutputSet::removeStaleStaging(base), 0);
  fs::last_write_time(foreign, fs::file_time_type::clock::now() - std::chrono::hours(24 * 8));
  EXPECT_EQ(OutputSet::removeStaleStaging(base), 1);
  EXPECT_FALSE(fs::exists(foreign));
}

TEST(OutputSet, AStagingFolderWhoseLockIsHeldIsAliveWhateverItsPid) {
  // A job in another PID namespace: its pid names no process here (found by a
  // probe: a second run removed the live staging folder, the first committed
  // without solution.csv). The lock tells, not the pid.
  const fs::path base = test::tempDir();
  std::optional<OutputSet> job(std::in_place, base / "job");
  fs::path staging;
  for (const auto& e : fs::directory_iterator(base)) staging = e.path();
  const std::string name = staging.filename().string(), prefix = OutputSet::kStagingPrefix;
  const fs::path foreignPid = base / (prefix + "2147483646" + name.substr(name.find('_', prefix.size())));
  fs::rename(staging, foreignPid);  // the lock moves with the folder
  EXPECT_EQ(OutputSet::removeStaleStaging(base), 0);
  job.reset();  // the job ends: its lock is released
  EXPECT_EQ(OutputSet::removeStaleStaging(base), 1);
}

TEST(OutputSet, AStagingFolderRemovedUnderTheJobFailsItInsteadOfCommittingPart) {
  const fs::path base = test::tempDir();
  {
    OutputSet out(base / "a");
    out.writeText("solution.csv", "1\n");
    fs::remove_all(out.stagingDir());
    EXPECT_THROW(out.writeText("summary.json", "{}\n"), Error);  // not made again
    EXPECT_THROW(out.commit(), Error);
  }
  {
    OutputSet out(base / "b");
    out.writeText("solution.csv", "1\n");
    out.writeText("summary.json", "{}\n");
    fs::remove(out.stagingDir() / "solution.csv");
    try {
      out.commit();
      ADD_FAILURE() << "committed without solution.csv";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("solution.csv vanished"), std::string::npos) << e.what();
    }
  }
  EXPECT_FALSE(fs::exists(base / "a"));
  EXPECT_FALSE(fs::exists(base / "b"));
  EXPECT_EQ(stagingCount(base), 0);
}

TEST(OutputSet, NamesUpToTheFileSystemLimitAndNoStagingLookalikes) {
  const fs::path base = test::tempDir();
  const std::string longName(255, 'e');  // a name the file system holds
  OutputSet out(base / longName);
  out.writeText("x.txt", "1\n");
  out.commit();
  EXPECT_TRUE(fs::exists(base / longName / "x.txt"));
  OutputSet file = OutputSet::singleFile(base / (longName.substr(0, 250) + ".yaml"));
  std::ofstream(file.stagedFile()) << "1\n";
  file.commit();
  EXPECT_TRUE(fs::exists(base / (longName.substr(0, 250) + ".yaml")));
  // one byte more fails when the output is set up, before any work, and leaves nothing
  for (const bool folder : {true, false}) {
    try {
      if (folder) OutputSet(base / (longName + "e"));
      else OutputSet::singleFile(base / (longName + "e"));
      ADD_FAILURE() << "a 256-byte name was accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("the output name is 256 bytes long, more than the 255"), std::string::npos)
          << e.what();
    }
  }
  EXPECT_EQ(stagingCount(base), 0);
  // an output named like a staging folder would be removed by a later run
  EXPECT_THROW(OutputSet(base / (std::string(OutputSet::kStagingPrefix) + "1_0123456789abcdef_0123456789abcdef_x")),
               Error);
}

TEST(OutputSet, OverwriteNeverReplacesAFolderHoldingAnInputOfTheRun) {
  const fs::path base = test::tempDir();
  touch(base / "old" / "config.yaml");
  touch(base / "old2" / "model.yaml");
  noteInput(base / "old" / "config.yaml");  // read before the output is made
  try {
    OutputSet out(base / "old", Overwrite::Replace);
    ADD_FAILURE() << "replaced a folder holding an input";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("an input of this run"), std::string::npos) << e.what();
  }
  OutputSet late(base / "old2", Overwrite::Replace);
  late.writeText("x.txt", "1\n");
  noteInput(base / "old2" / "model.yaml");  // read during the job
  EXPECT_THROW(late.commit(), Error);
  EXPECT_TRUE(fs::exists(base / "old" / "config.yaml"));
  EXPECT_TRUE(fs::exists(base / "old2" / "model.yaml"));
}

TEST(OutputSet, AnOutputFileNeverReplacesAnInputUnlessTheCommandSaysSo) {
  // import --out onto its own manifest replaced it with the rawlog (a probe)
  const fs::path base = test::tempDir();
  touch(base / "manifest.yaml", "imu: {}\n");
  noteInput(base / "manifest.yaml");
  {
    OutputSet out = OutputSet::singleFile(base / "manifest.yaml", Overwrite::Replace);
    std::ofstream(out.stagedFile()) << "rawlog";
    EXPECT_THROW(out.commit(), Error);
  }
  std::ifstream in(base / "manifest.yaml");
  EXPECT_EQ(std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>()), "imu: {}\n");
  // model convert --out onto its own model file: read whole first, allowed
  OutputSet conv = OutputSet::singleFile(base / "manifest.yaml", Overwrite::Replace);
  conv.mayReplaceAnInput();
  std::ofstream(conv.stagedFile()) << "converted\n";
  conv.commit();
  EXPECT_TRUE(fs::exists(base / "manifest.yaml"));
}
