#include "cli_common.hpp"

#include <unistd.h>

#include <cstdio>

namespace navimpact::cli {

std::vector<Command>& registry() {
  static std::vector<Command> r;
  return r;
}

void addOverwriteFlag(CLI::App& app, bool& flag) {
  app.add_flag("--overwrite", flag,
               "replace an existing, non-empty output whole (default: refuse it before any work)");
}

bool stderrIsTerminal() { return isatty(fileno(stderr)) != 0; }

Progress::Progress(std::string label, std::size_t total)
    : label_(std::move(label)), total_(total), tty_(stderrIsTerminal()) {}

void Progress::update(std::size_t done) {
  if (!tty_ || total_ == 0) return;
  const int pct = static_cast<int>(100.0 * static_cast<double>(done) / static_cast<double>(total_));
  if (pct == lastPct_) return;
  lastPct_ = pct;
  const int width = 30, fill = pct * width / 100;
  std::fprintf(stderr, "\r%s [%.*s%*s] %3d%% (%zu/%zu)", label_.c_str(), fill,
               "##############################", width - fill, "", pct, done, total_);
  std::fflush(stderr);
}

void Progress::finish() {
  if (!tty_) return;
  update(total_);
  std::fprintf(stderr, "\n");
}

}  // namespace navimpact::cli
