// Shared plumbing of the navimpact CLI: command registry and small helpers.
// Commands stay thin: parse -> load config -> call lib -> print.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

#include "navimpact/core/limits.hpp"
#include "navimpact/core/output.hpp"
#include "navimpact/core/units.hpp"

namespace navimpact::cli {

/// A sub-command: setup() declares its options on the CLI11 sub-app and
/// returns the function to run after parsing (returns the exit code).
struct Command {
  std::string name;
  std::string help;
  std::function<std::function<int()>(CLI::App&)> setup;
};

std::vector<Command>& registry();

struct Registrar {
  explicit Registrar(Command c) { registry().push_back(std::move(c)); }
};

/// Options of a command that merges the shard folders of a run into one
/// output (study-merge, sweep-merge).
struct MergeOpts {
  std::vector<std::string> dirs;
  std::string out;
  bool overwrite = false;
};

/// The merge command @p name: the shard folders, --out and --overwrite, then @p run.
Command mergeCommand(std::string name, std::string help, std::function<int(const MergeOpts&)> run);

/// Declare --overwrite on a command that writes an output folder or file:
/// without it a non-empty output is refused before any work; with it the
/// output is replaced whole when the job succeeds.
void addOverwriteFlag(CLI::App& app, bool& flag);
inline Overwrite overwriteMode(bool flag) { return flag ? Overwrite::Replace : Overwrite::Refuse; }

/// A flag's number checked against a documented range (core/limits.hpp), NaN
/// and text refused: "--rate: must be in [1, 10000] Hz, got nan". (CLI11's
/// PositiveNumber let NaN and 1e308 through and printed DBL_MAX in 309 digits.)
/// @p hi_open excludes the upper end too (an efficiency in (0, 1)).
CLI::Validator within(const limits::Range& r, bool hi_open = false);
/// A family-wise level --alpha: [1e-10, 0.5) (with hi_open). From 1e-10: split
/// over causes, channels and samples, a smaller one underflowed to a per-test
/// level of 0, refused deep inside with wording that blamed the input.
inline constexpr limits::Range kAlpha{1e-10, 0.5, false, ""};
/// Worker threads --threads: 0 (all cores) .. 1024, as monte_carlo.threads.
inline constexpr limits::Range kThreads{0.0, 1024.0, false, ""};

/// A flag's text checked by the library's own parser @p parse (which throws
/// navimpact::Error on a bad value) when the command line is read, so that a
/// value it refuses is a command-line error (exit 2, "see --help") like a
/// number out of its range; the parser's message is kept, without a leading
/// "FLAG: " (CLI11 names the flag). @p text is the value's form in --help.
CLI::Validator parsedBy(std::function<void(const std::string&)> parse, std::string text);

/// A unit name of quantity @p q that units::toSiFactor knows (--gyro-unit deg/h):
/// "'furlong/s' is not a known unit (accepted: rad/s, deg/s, ...)".
CLI::Validator knownUnit(units::Quantity q);

/// A seed: an integer 0 .. 2^64 - 1 in decimal digits (CLI11 read "-1" as
/// 2^64 - 1, a silent wrap), the same seeds as a configuration's seed keys.
CLI::Validator seedValue();

/// A count that is 0 (off) or at least @p min, after a within() range check:
/// "must be 0 or at least 2 (one simulation has no spread), got 1", @p why in
/// the brackets (diagnose --simulations, fit --bootstrap).
CLI::Validator zeroOrAtLeast(double min, std::string why);

/// A robust WV efficiency --eff: a number the biweight reaches (0.05 ..
/// 0.999985, gmwm::checkRobustEfficiency); 0.9999999 passed a (0, 1)
/// check and failed after the file was read, blaming the file.
CLI::Validator robustEfficiency();

/// Identity of this build: navimpact version plus an FNV-1a 64 hash of the
/// running executable (/proc/self/exe), e.g. "0.1.0+3f2a...". Shards of a
/// sweep record it so that a merge refuses results of another build.
std::string buildId();

/// Absolute path of the running executable ("" when unknown).
std::string executablePath();

/// True when stderr is a terminal (progress bars are shown only then).
bool stderrIsTerminal();

/// Simple progress bar on stderr, shown only on a terminal.
class Progress {
 public:
  Progress(std::string label, std::size_t total);
  void update(std::size_t done);
  void finish();

 private:
  std::string label_;
  std::size_t total_;
  bool tty_;
  int lastPct_ = -1;
};

}  // namespace navimpact::cli
