// Outputs of navimpact diagnose-power: the power table (Markdown) and power.json.
#include "navimpact/report/power_report.hpp"

#include <sstream>

#include <nlohmann/json.hpp>

#include "navimpact/core/format.hpp"
#include "navimpact/report/timing.hpp"

namespace navimpact::report {

using namespace analysis;
using namespace analysis::power;

std::string powerTable(const PowerResult& r) {
  std::ostringstream t;
  t << "| cause |";
  const auto& b = r.bins;
  for (std::size_t i = 0; i < b.size(); ++i)
    t << " SNR " << formatNumber(b[i], 3) << "–" << (i + 1 < b.size() ? formatNumber(b[i + 1], 3) : std::string("")) << " |";
  t << "\n|---|";
  for (std::size_t i = 0; i < b.size(); ++i) t << "---|";
  t << "\n";
  for (Cause c : r.options.causes) {
    t << "| " << causeName(c) << " |";
    for (std::size_t i = 0; i < b.size(); ++i) {
      int n = 0, det = 0, right = 0;
      for (const auto& run : r.runs) {
        if (run.cause != c || run.snr < b[i] || (i + 1 < b.size() && run.snr >= b[i + 1])) continue;
        ++n;
        det += run.detected;
        right += run.right;
      }
      if (n == 0) t << " — |";
      else t << " " << det << "/" << n << " (" << right << ") |";
    }
    t << "\n";
  }
  t << "\nCells: detected / runs (right cause and parameter). Null records (six channels, drawn from the model): "
    << r.null_alarms << " of " << r.null_runs << " called inadequate at alpha " << formatNumber(r.options.alpha, 3) << ".\n";
  return t.str();
}

std::string powerJson(const PowerResult& r) {
  nlohmann::json j;
  j["seed"] = r.options.seed;
  j["alpha"] = r.options.alpha;
  j["simulations"] = r.options.simulations;
  j["snr_range"] = {r.options.min_snr, r.options.max_snr};
  j["ranges"] = {{"rate_hz", {r.options.ranges.min_rate_hz, r.options.ranges.max_rate_hz}},
                 {"duration_s", {r.options.ranges.min_duration_s, r.options.ranges.max_duration_s}},
                 {"samples", {r.options.ranges.min_samples, r.options.ranges.max_samples}},
                 {"wn_sigma", {r.options.ranges.min_wn, r.options.ranges.max_wn}}};
  j["null"] = {{"runs", r.null_runs}, {"inadequate", r.null_alarms}};
  nlohmann::json runs = nlohmann::json::array();
  for (const auto& x : r.runs)
    runs.push_back({{"cause", causeName(x.cause)}, {"snr", x.snr}, {"rate_hz", x.rate_hz},
                    {"duration_s", x.duration_s}, {"detected", x.detected}, {"right", x.right}, {"why", x.why}});
  j["runs"] = runs;
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

void writePowerTiming(const PowerResult& r, OutputSet& out) { writeTiming(out, {{"cpu_s", r.cpu_s}, {"wall_s", r.wall_s}}); }

}  // namespace navimpact::report
