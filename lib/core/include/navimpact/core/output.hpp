/**
 * @file output.hpp
 * @brief All-or-nothing output: a command's files appear together or not at all.
 *
 * Every file of a job is written into ONE staging folder created next to the
 * destination (same parent folder, hence the same file system), named
 * `.navimpact-staging_<pid>_<random>_<host>_<destination name>`. commit()
 * renames that one folder onto the destination (for a single-file output, the
 * staged file onto the file), so a failing or killed job leaves no partial
 * output: the staging folder is removed when the OutputSet is destroyed
 * without commit(), and the staging folders of runs that were killed (their
 * process no longer exists on this host, or older than a week for another
 * host) are removed by the next OutputSet created in the same folder.
 *
 * A destination that already exists and is not empty is refused when the
 * OutputSet is created, before any work, unless Overwrite::Replace is given:
 * then it is replaced whole (old files cannot survive beside the new ones).
 * Replace refuses the file-system root, the home folder, the current folder
 * or a folder containing it, a folder that holds anything but files and
 * folders of files (navimpact outputs are at most one level deep), and a
 * folder that holds an input of the run (noteInput(): the readers note every
 * file they open; checked when the OutputSet is made and again at commit()),
 * and a folder this user could not empty whole (it or a folder in it without
 * write permission, e.g. one a container wrote as root): the old output would
 * be deleted only in part.
 *
 * A run holds an exclusive flock() on its staging folder while it lives, so
 * a staging folder is stale only when no process holds its lock (a run in
 * another PID namespace, whose pid means nothing here, holds it too) and its
 * pid is gone. commit() checks that the staging folder is still the one the
 * run made and holds every file staged: a folder removed under a running job
 * fails the job instead of committing what it wrote after.
 */
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace navimpact {

/// Note @p path as an input of this process (readers call it when they open a
/// file): Overwrite::Replace refuses a destination that holds one. Thread-safe.
void noteInput(const std::filesystem::path& path);

/// Remove the staging folders of this process's live jobs (and their files),
/// for an application's SIGINT/SIGTERM handler before it dies: async-signal-
/// safe (system calls only). Without it a killed run's staging folder stays
/// until the next run in that folder removes it.
void removeLiveStaging() noexcept;

/// What to do when the destination exists and is not empty.
enum class Overwrite { Refuse, Replace };

class OutputSet {
 public:
  /// Output folder @p dir (created with its parents on commit).
  /// @throws Error when @p dir exists, is not empty and @p ow is Refuse, when
  ///         it is not a folder, or when the staging folder cannot be created.
  explicit OutputSet(std::filesystem::path dir, Overwrite ow = Overwrite::Refuse);
  /// A single output file @p file (e.g. a rawlog): write it at stagedFile().
  static OutputSet singleFile(std::filesystem::path file, Overwrite ow = Overwrite::Refuse);
  ~OutputSet();
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;
  OutputSet(OutputSet&&) noexcept;
  OutputSet& operator=(OutputSet&&) = delete;

  /// Staging path where the caller writes file @p name (relative to dir; may
  /// contain one sub-folder). Not for single-file outputs.
  std::filesystem::path stage(const std::string& name);
  /// Staging path of the one file of a singleFile() output.
  std::filesystem::path stagedFile() const;
  /// The staging folder itself (writers that name their own files write here).
  const std::filesystem::path& stagingDir() const { return staging_; }
  /// Write a whole text file to the staging area.
  void writeText(const std::string& name, const std::string& content);
  /// Move the staged output into place in one rename. Throws navimpact::Error on failure.
  void commit();
  /// A single-file output may replace an input of the run (model convert
  /// --out onto its own model file: read whole before); by default a file
  /// the run read is never replaced (import --out onto its manifest was).
  void mayReplaceAnInput() { mayReplaceInput_ = true; }
  /// Destination (folder, or the file of a singleFile() output).
  const std::filesystem::path& dir() const { return dest_; }
  /// Final paths of the files staged so far (sorted).
  std::vector<std::filesystem::path> finalPaths() const;

  /// Prefix of every staging folder name.
  static constexpr const char* kStagingPrefix = ".navimpact-staging_";
  /// Remove the staging folders of dead runs in @p folder; returns how many.
  static int removeStaleStaging(const std::filesystem::path& folder);

 private:
  enum class Kind { Directory, File };
  OutputSet(std::filesystem::path dest, Overwrite ow, Kind kind);
  void removeCreatedParents() noexcept;
  void releaseStaging() noexcept;
  void checkStaging() const;

  std::filesystem::path dest_;    ///< as given (messages, finalPaths)
  std::filesystem::path target_;  ///< absolute, normalised (file operations)
  std::filesystem::path staging_;
  int stagingFd_ = -1;  ///< the staging folder, open and flock()ed while the job lives
  int liveSlot_ = -1;   ///< its slot among the live staging folders (removeLiveStaging), -1: none
  std::vector<std::filesystem::path> createdParents_;  ///< folders we created, deepest last
  std::vector<std::string> names_;
  Overwrite ow_ = Overwrite::Refuse;
  Kind kind_ = Kind::Directory;
  bool committed_ = false;
  bool mayReplaceInput_ = false;
};

}  // namespace navimpact
