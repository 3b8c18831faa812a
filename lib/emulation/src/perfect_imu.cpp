#include "navimpact/emulation/perfect_imu.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"

namespace navimpact::emulation {

std::size_t perfectImuCount(double rate_hz, double t_first, double t_last) {
  return static_cast<std::size_t>(std::floor((t_last - t_first) * rate_hz + 1e-9));
}

void perfectImuBlock(const SmoothTrajectory& tr, double rate_hz, double a, std::size_t k0, std::size_t k1,
                     std::vector<ins::ImuSample>& out) {
  const double dt = 1.0 / rate_hz;
  out.resize(k1 > k0 ? k1 - k0 : 0);
  for (std::size_t k = k0; k < k1; ++k) {
    ins::ImuSample& s = out[k - k0];
    const double ta = a + double(k) * dt;
    s.t = a + double(k + 1) * dt;
    s.dt = s.t - ta;
    tr.increments(ta, s.t, s.dv_B, s.dtheta_B);
  }
}

std::vector<ins::ImuSample> perfectImu(const SmoothTrajectory& tr, double rate_hz, double t_start,
                                       double t_end) {
  if (!(rate_hz > 0.0)) throw Error("perfect IMU: rate must be > 0 Hz");
  const double a = std::max(t_start, tr.tBegin());
  const double b = std::min(t_end, tr.tEnd());
  const auto n = perfectImuCount(rate_hz, a, b);
  if (n == 0)
    throw Error("perfect IMU: the span [" + formatNumber(a, 10) + ", " + formatNumber(b, 10) +
                "] s holds no whole IMU interval at " + formatNumber(rate_hz) + " Hz");
  std::vector<ins::ImuSample> out;
  perfectImuBlock(tr, rate_hz, a, 0, n, out);
  return out;
}

ins::NavState truthNavState(const SmoothTrajectory& tr, double t) {
  const TruthState s = tr.at(t);
  ins::NavState x;
  x.t = t;
  x.lat = s.pos.lat;
  x.lon = s.pos.lon;
  x.h = s.pos.h;
  x.v_N = s.v_N;
  x.q_BtoN = Eigen::Quaterniond(s.C_BtoN).normalized();
  return x;
}

}  // namespace navimpact::emulation
