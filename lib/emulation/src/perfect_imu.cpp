#include "navimpact/emulation/perfect_imu.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "navimpact/core/error.hpp"

namespace navimpact::emulation {

std::vector<ins::ImuSample> perfectImu(const SmoothTrajectory& tr, double rate_hz, double t_start,
                                       double t_end) {
  if (!(rate_hz > 0.0)) throw Error("perfect IMU: rate must be > 0 Hz");
  const double a = std::max(t_start, tr.tBegin());
  const double b = std::min(t_end, tr.tEnd());
  const double dt = 1.0 / rate_hz;
  const auto n = static_cast<std::size_t>(std::floor((b - a) * rate_hz + 1e-9));
  if (n == 0)
    throw Error("perfect IMU: the span [" + std::to_string(a) + ", " + std::to_string(b) +
                "] s holds no whole IMU interval at " + std::to_string(rate_hz) + " Hz");
  std::vector<ins::ImuSample> out(n);
  for (std::size_t k = 0; k < n; ++k) {
    ins::ImuSample& s = out[k];
    const double ta = a + double(k) * dt;
    s.t = a + double(k + 1) * dt;
    s.dt = s.t - ta;
    tr.increments(ta, s.t, s.dv_B, s.dtheta_B);
  }
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
