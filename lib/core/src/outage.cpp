// The one GNSS outage: text form and validation (see outage.hpp).
#include "navimpact/core/outage.hpp"

#include <cmath>
#include <string_view>

#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
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
  if (!(start >= 0.0) || !(duration > 0.0) || !std::isfinite(start) || !std::isfinite(duration))
    throw Error(what + " '" + printable(text, 60) + "': START must be >= 0 s and DURATION > 0 s");
  return Outage::fromStartDuration(start, duration);
}

void checkOutages(const std::vector<Outage>& outages, double span_s, const std::string& after,
                  const std::string& what) {
  for (std::size_t i = 0; i < outages.size(); ++i) {
    const Outage& o = outages[i];
    if (!(o.start_s >= 0.0) || !(o.end_s > o.start_s) || !std::isfinite(o.end_s))
      throw Error(what + " " + outageText(o) + ": START must be >= 0 s and DURATION > 0 s");
    if (i > 0 && o.start_s < outages[i - 1].end_s)
      throw Error(what + " " + outageText(o) + " starts before the previous outage ends at " +
                  formatNumber(outages[i - 1].end_s) + " s (outages in time order, no overlap)");
    if (o.end_s > span_s + 1e-6)
      throw Error(what + " " + outageText(o) + " ends at " + formatNumber(o.end_s) + " s, after " + after);
  }
}

}  // namespace navimpact
