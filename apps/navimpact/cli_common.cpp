#include "cli_common.hpp"

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <fstream>
#include <memory>
#include <vector>

#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/text_io.hpp"
#include "navimpact/gmwm/wavelet_variance.hpp"

namespace navimpact::cli {

std::vector<Command>& registry() {
  static std::vector<Command> r;
  return r;
}

CLI::Validator within(const limits::Range& r, bool hi_open) {
  std::string text = limits::describe(r);
  if (hi_open) text[text.find(']')] = ')';
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return CLI::Validator(
      [r, hi_open, text](std::string& s) -> std::string {
        double v = 0.0;
        if (!parseDouble(s, v)) return "must be a number in " + text + ", got '" + printable(s, 40) + "'";
        const bool ok = std::isfinite(v) && (r.lo_open ? v > r.lo : v >= r.lo) && (hi_open ? v < r.hi : v <= r.hi);
        return ok ? std::string() : "must be in " + text + ", got " + printable(s, 40);
      },
      text);
}

CLI::Validator parsedBy(std::function<void(const std::string&)> parse, std::string text) {
  return CLI::Validator(
      [parse](std::string& s) -> std::string {
        try {
          parse(s);
          return std::string();
        } catch (const Error& e) {
          // "--flag: what" -> "what"; "--flag 'value': what" -> "'value': what" (CLI11 names the flag)
          std::string m = e.what();
          if (m.rfind("--", 0) == 0) {
            const auto end = m.find_first_of(" :");
            if (end != std::string::npos && m.compare(end, 2, ": ") == 0) m = m.substr(end + 2);
            else if (end != std::string::npos && m.compare(end, 2, " '") == 0) m = m.substr(end + 1);
          }
          return m;
        }
      },
      std::move(text));
}

CLI::Validator knownUnit(units::Quantity q) {
  return parsedBy(
      [q](const std::string& u) {
        try {
          units::toSiFactor(q, u);
        } catch (const Error&) {
          std::string accepted;
          for (const auto& a : units::acceptedUnits(q)) accepted += (accepted.empty() ? "" : ", ") + a;
          throw Error("'" + printable(u, 40) + "' is not a known unit (accepted: " + accepted + ")");
        }
      },
      "UNIT");
}

CLI::Validator zeroOrAtLeast(double min, std::string why) {
  return CLI::Validator(
      [min, why](std::string& s) {
        double v = 0.0;  // the range check before has read it as a number
        return parseDouble(s, v) && v > 0.0 && v < min
                   ? "must be 0 or at least " + formatNumber(min) + " (" + why + "), got " + printable(s, 40)
                   : std::string();
      },
      "0 or >= " + formatNumber(min));
}

CLI::Validator robustEfficiency() {
  return parsedBy(
      [](const std::string& s) {
        double v = 0.0;
        if (!parseDouble(s, v)) throw Error("'" + printable(s, 40) + "' is not a number");
        gmwm::checkRobustEfficiency(v);
      },
      "EFF");
}

CLI::Validator seedValue() {
  return CLI::Validator(
      [](std::string& s) -> std::string {
        const std::string max = std::to_string(std::numeric_limits<std::uint64_t>::max());
        const bool digits = !s.empty() && s.size() <= max.size() && s.find_first_not_of("0123456789") == std::string::npos;
        if (digits && (s.size() < max.size() || s <= max)) return std::string();
        return "must be an integer seed in 0.." + max + ", got '" + printable(s, 40) + "'";
      },
      "SEED");
}

void addOverwriteFlag(CLI::App& app, bool& flag) {
  app.add_flag("--overwrite", flag,
               "replace an existing, non-empty output whole (default: refuse it before any work)");
}

Command mergeCommand(std::string name, std::string help, std::function<int(const MergeOpts&)> run) {
  return {std::move(name), std::move(help), [run = std::move(run)](CLI::App& app) {
            auto o = std::make_shared<MergeOpts>();
            app.add_option("dirs", o->dirs, "shard folders")->required();
            app.add_option("--out", o->out, "output folder")->required();
            addOverwriteFlag(app, o->overwrite);
            return std::function<int()>([o, run]() -> int { return run(*o); });
          }};
}

std::string executablePath() {
  std::error_code ec;
  const auto p = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::string() : p.string();
}

std::string buildId() {
  static const std::string id = [] {
    std::uint64_t h = 1469598103934665603ull;  // FNV-1a 64 of the executable
    std::ifstream f("/proc/self/exe", std::ios::binary);
    std::vector<char> buf(1 << 20);
    bool any = false;
    while (f) {
      f.read(buf.data(), static_cast<std::streamsize>(buf.size()));
      const auto n = static_cast<std::size_t>(f.gcount());
      for (std::size_t i = 0; i < n; ++i) {
        h ^= static_cast<unsigned char>(buf[i]);
        h *= 1099511628211ull;
      }
      any = any || n > 0;
    }
    char hex[17];
    std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
    return std::string(NAVIMPACT_VERSION) + "+" + (any ? hex : "unknown");
  }();
  return id;
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
