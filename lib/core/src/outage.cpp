// The one GNSS outage: text form and validation (see outage.hpp).
#include "navimpact/core/outage.hpp"

#include <cmath>
#include <string_view>

#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/limits.hpp"
#include "navimpact/core/text_io.hpp"

namespace navimpact {

bool inOutage(double t, const std::vector<Outage>& outages) {
  for (const auto& o : outages)
    if (o.covers(t)) return true;
  return false;
}

std::string outageText(const Outage& o) { return formatNumber(o.start_s) + ":" + formatNumber(o.duration_s()); }

Outage parseOutage(const std::string& text, const std::string& what) {
  const auto c = text.find(':');
  double start = 0.0, duration = 0.0;
  if (c == std::string::npos || !parseDouble(trim(std::string_view(text).substr(0, c)), start) ||
      !parseDouble(trim(std::string_view(text).substr(c + 1)), duration))
    throw Error(what + " '" + printable(text, 60) + "': expected START:DURATION in seconds, e.g. 200:60");
  // the ranges of a configuration's outages: times on a run's axis, durations (limits.hpp)
  if (!(start >= 0.0 && start <= limits::kFileTimeS.hi) || !(duration >= limits::kDurationS.lo && duration <= limits::kDurationS.hi))
    throw Error(what + " '" + printable(text, 60) + "': START must be in [0, " + formatNumber(limits::kFileTimeS.hi) +
                "] s and DURATION in " + limits::describe(limits::kDurationS));
  return Outage::fromStartDuration(start, duration);
}

OutagePattern parseOutagePattern(const std::string& text) {
  const auto c = text.find(':');
  OutagePattern p;
  if (c == std::string::npos || !parseDouble(trim(std::string_view(text).substr(0, c)), p.period_s) ||
      !parseDouble(trim(std::string_view(text).substr(c + 1)), p.duration_s))
    throw Error("outages every '" + printable(text, 60) + "': expected PERIOD:DURATION in seconds, e.g. 120:30");
  const auto in = [](double v) { return v >= limits::kDurationS.lo && v <= limits::kDurationS.hi; };
  if (!in(p.duration_s) || !in(p.period_s) || !(p.period_s > p.duration_s))
    throw Error("outages every '" + printable(text, 60) + "': PERIOD and DURATION must be in " +
                limits::describe(limits::kDurationS) + ", PERIOD > DURATION (GNSS time between outages to reconverge)");
  return p;
}

std::vector<Outage> outagesEvery(const OutagePattern& p, double aided_from, double end) {
  if (!(p.duration_s > 0.0) || !(p.period_s > p.duration_s))
    throw Error("outages every " + formatNumber(p.period_s, 10) + ":" + formatNumber(p.duration_s, 10) + ": PERIOD must exceed DURATION > 0");
  std::vector<Outage> out;
  for (long k = 0;; ++k) {
    // start_k = aided_from + (k + 1) period - duration, computed from k (no accumulated rounding)
    const double a = aided_from + double(k + 1) * p.period_s - p.duration_s, b = a + p.duration_s;
    if (b > end + 1e-9) break;
    out.push_back({a, b});
  }
  return out;
}

void checkOutages(const std::vector<Outage>& outages, double span_s, const std::string& after,
                  const std::string& what, const std::vector<std::string>& names) {
  if (names.size() > outages.size())
    throw Error("checkOutages: " + std::to_string(names.size()) + " names for " + std::to_string(outages.size()) + " outages");
  for (std::size_t i = 0; i < outages.size(); ++i) {
    const Outage& o = outages[i];
    const std::string name = i < names.size() ? names[i] : what + " " + outageText(o);
    if (!(o.start_s >= 0.0) || !(o.end_s > o.start_s) || !std::isfinite(o.end_s))
      throw Error(name + ": START must be >= 0 s and DURATION > 0 s");
    if (i > 0 && o.start_s < outages[i - 1].end_s)
      throw Error(name + " starts before the previous outage ends at " + formatNumber(outages[i - 1].end_s) +
                  " s (outages in time order, no overlap)");
    if (o.end_s > span_s + 1e-6)
      throw Error(name + " ends at " + formatNumber(o.end_s) + " s, after " + after);
  }
}

}  // namespace navimpact
