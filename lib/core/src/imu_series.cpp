#include "navimpact/core/imu_series.hpp"

#include <cmath>

#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"

namespace navimpact {

int channelIndex(const std::string& name) {
  for (std::size_t i = 0; i < kChannelNames.size(); ++i)
    if (name == kChannelNames[i]) return static_cast<int>(i);
  return -1;
}

units::Quantity channelQuantity(const std::string& name) {
  return name.rfind("gyro", 0) == 0 ? units::Quantity::AngularRate
                                    : units::Quantity::SpecificForce;
}

const ImuChannel& ImuSeries::channel(const std::string& name) const {
  for (const auto& c : channels)
    if (c.name == name) return c;
  throw Error(source + ": no channel '" + name + "'");
}

bool ImuSeries::has(const std::string& name) const {
  for (const auto& c : channels)
    if (c.name == name) return true;
  return false;
}

void cutWindow(ImuSeries& s, double start_s, std::optional<double> end_s) {
  const std::size_t n = s.size();
  const double duration = static_cast<double>(n) / s.rate_hz;
  auto fail = [&](const std::string& flag, double v, const std::string& why) {
    return Error(s.source + ": " + flag + " " + formatNumber(v, 10) + " s " + why + " (the record has " +
                 std::to_string(n) + " samples, 0 to " + formatNumber(duration, 10) + " s at " +
                 formatNumber(s.rate_hz, 10) + " Hz)");
  };
  if (!std::isfinite(start_s) || start_s < 0.0) throw fail("--start", start_s, "must be a finite time >= 0");
  if (!(start_s < duration)) throw fail("--start", start_s, "is not before the end of the record");
  if (end_s) {
    if (!std::isfinite(*end_s)) throw fail("--end", *end_s, "must be a finite time");
    if (!(*end_s > start_s)) throw fail("--end", *end_s, "must be after --start " + formatNumber(start_s, 10) + " s");
    if (*end_s > duration * (1.0 + 1e-12)) throw fail("--end", *end_s, "is beyond the end of the record");
  }
  // First index k with k / rate >= start, first index beyond the window (exclusive).
  const double tol = 1e-6;
  const auto k0 = static_cast<std::size_t>(std::ceil(start_s * s.rate_hz - tol));
  const std::size_t k1 =
      end_s ? std::min(n, static_cast<std::size_t>(std::ceil(*end_s * s.rate_hz - tol))) : n;
  if (k1 < k0 + 2) throw fail(end_s ? "--end" : "--start", end_s ? *end_s : start_s, "leaves fewer than 2 samples");
  for (auto& c : s.channels) {
    c.x.erase(c.x.begin() + static_cast<std::ptrdiff_t>(k1), c.x.end());
    c.x.erase(c.x.begin(), c.x.begin() + static_cast<std::ptrdiff_t>(k0));
  }
  s.t0_s += static_cast<double>(k0) / s.rate_hz;
}

}  // namespace navimpact
