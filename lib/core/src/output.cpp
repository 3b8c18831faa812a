#include "navimpact/core/output.hpp"

#include <fstream>
#include <random>

#include "navimpact/core/error.hpp"

namespace fs = std::filesystem;

namespace navimpact {

OutputSet::OutputSet(fs::path dir) : dir_(std::move(dir)) {
  std::random_device rd;
  const fs::path parent = dir_.has_parent_path() ? dir_.parent_path() : fs::path(".");
  std::error_code ec;
  fs::create_directories(parent, ec);
  staging_ = parent / (".navimpact-staging-" + dir_.filename().string() + "-" + std::to_string(rd()));
  fs::create_directories(staging_, ec);
  if (ec) throw Error(staging_.string() + ": cannot create staging directory (" + ec.message() + ")");
}

OutputSet::~OutputSet() {
  std::error_code ec;
  fs::remove_all(staging_, ec);
}

fs::path OutputSet::stage(const std::string& name) {
  names_.push_back(name);
  const fs::path p = staging_ / name;
  std::error_code ec;
  fs::create_directories(p.parent_path(), ec);
  return p;
}

void OutputSet::writeText(const std::string& name, const std::string& content) {
  const fs::path p = stage(name);
  std::ofstream f(p, std::ios::binary);
  f << content;
  if (!f) throw Error(p.string() + ": cannot write");
}

void OutputSet::commit() {
  std::error_code ec;
  fs::create_directories(dir_, ec);
  if (ec) throw Error(dir_.string() + ": cannot create output directory (" + ec.message() + ")");
  for (const auto& n : names_) {
    const fs::path dst = dir_ / n;
    fs::create_directories(dst.parent_path(), ec);
    fs::rename(staging_ / n, dst, ec);
    if (ec) {
      // Different file systems: copy then remove.
      ec.clear();
      fs::copy_file(staging_ / n, dst, fs::copy_options::overwrite_existing, ec);
      if (ec) throw Error(dst.string() + ": cannot write (" + ec.message() + ")");
    }
  }
  committed_ = true;
}

std::vector<fs::path> OutputSet::finalPaths() const {
  std::vector<fs::path> out;
  for (const auto& n : names_) out.push_back(dir_ / n);
  return out;
}

}  // namespace navimpact
