/**
 * @file output.hpp
 * @brief All-or-nothing output: files are written to staging names and only
 *        renamed into place when the whole job succeeded.
 *
 * A command that fails half-way leaves no partial output behind: the staged
 * files are removed when the OutputSet is destroyed without commit().
 */
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace navimpact {

class OutputSet {
 public:
  /// @param[in] dir  output directory; created (with parents) on commit if missing.
  explicit OutputSet(std::filesystem::path dir);
  ~OutputSet();
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;

  /// Staging path where the caller writes file @p name (relative to dir).
  std::filesystem::path stage(const std::string& name);
  /// Write a whole text file to the staging area.
  void writeText(const std::string& name, const std::string& content);
  /// Move every staged file into place. Throws navimpact::Error on failure.
  void commit();
  const std::filesystem::path& dir() const { return dir_; }
  /// Final paths of the files staged so far.
  std::vector<std::filesystem::path> finalPaths() const;

 private:
  std::filesystem::path dir_;
  std::filesystem::path staging_;
  std::vector<std::string> names_;
  bool committed_ = false;
};

}  // namespace navimpact
