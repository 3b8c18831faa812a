#include "navimpact/emulation/sensor_effects.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/limits.hpp"
#include "navimpact/stochastic/simulate.hpp"

namespace navimpact::emulation {

namespace {

constexpr double kStandardGravity = 9.80665;  // [m/s^2], reference of the motion test

Eigen::Matrix3d triad(const Eigen::Vector3d& s, const Eigen::Vector3d& m, const Eigen::Vector3d& n) {
  Eigen::Matrix3d N;
  N << 0.0, n.z(), n.y(), n.z(), 0.0, n.x(), n.y(), n.x(), 0.0;
  return Eigen::Matrix3d::Identity() + Eigen::Matrix3d(s.asDiagonal()) + ins::skew(m) + N;
}

void checkVec(const std::string& where, const std::string& key, const Eigen::Vector3d& v, const limits::Range& r) {
  for (int i = 0; i < 3; ++i) limits::check(where, key + "[" + std::to_string(i) + "]", v(i), r);
}

std::string vec(const Eigen::Vector3d& v) {
  return "[" + formatNumber(v(0)) + ", " + formatNumber(v(1)) + ", " + formatNumber(v(2)) + "]";
}

// Cumulative increments (angle, velocity) at the interval boundaries of the
// samples, and their 4-point Lagrange interpolation at any time.
class Cumulative {
 public:
  explicit Cumulative(const std::vector<ins::ImuSample>& s) : s_(s) {
    const std::size_t n = s.size();
    tau_.resize(n + 1);
    c_.resize(n + 1);
    tau_[0] = s[0].t - s[0].dt;
    c_[0].setZero();
    for (std::size_t k = 0; k < n; ++k) {
      tau_[k + 1] = s[k].t;
      c_[k + 1].head<3>() = c_[k].head<3>() + s[k].dtheta_B;
      c_[k + 1].tail<3>() = c_[k].tail<3>() + s[k].dv_B;
    }
  }

  Eigen::Matrix<double, 6, 1> at(double q) const {
    const std::size_t n = tau_.size() - 1;
    if (q <= tau_[0]) return rate(0) * (q - tau_[0]);
    if (q >= tau_[n]) return c_[n] + rate(n - 1) * (q - tau_[n]);
    // tau_[j] <= q < tau_[j + 1]
    const std::size_t j = std::size_t(std::upper_bound(tau_.begin(), tau_.end(), q) - tau_.begin()) - 1;
    if (n < 3) {  // too few nodes for a cubic: linear
      const double w = (q - tau_[j]) / (tau_[j + 1] - tau_[j]);
      return c_[j] + w * (c_[j + 1] - c_[j]);
    }
    // Nodes j-1 .. j+2, moved inside [0, n].
    std::size_t a = j >= 1 ? j - 1 : 0;
    if (a + 3 > n) a = n - 3;
    Eigen::Matrix<double, 6, 1> r = Eigen::Matrix<double, 6, 1>::Zero();
    for (std::size_t i = a; i < a + 4; ++i) {
      double L = 1.0;
      for (std::size_t m = a; m < a + 4; ++m)
        if (m != i) L *= (q - tau_[m]) / (tau_[i] - tau_[m]);
      r += L * c_[i];
    }
    return r;
  }

 private:
  Eigen::Matrix<double, 6, 1> rate(std::size_t k) const {
    Eigen::Matrix<double, 6, 1> r;
    r << s_[k].dtheta_B / s_[k].dt, s_[k].dv_B / s_[k].dt;
    return r;
  }
  const std::vector<ins::ImuSample>& s_;
  std::vector<double> tau_;
  std::vector<Eigen::Matrix<double, 6, 1>> c_;
};

}  // namespace

bool SensorEffects::none() const {
  return gyro_scale.isZero(0.0) && acc_scale.isZero(0.0) && gyro_misalignment_rad.isZero(0.0) &&
         acc_misalignment_rad.isZero(0.0) && gyro_nonorthogonality_rad.isZero(0.0) &&
         acc_nonorthogonality_rad.isZero(0.0) && time_offset_s == 0.0 && gyro_motion_noise_factor == 1.0 &&
         acc_motion_noise_factor == 1.0 && lever_arm_error_B_m.isZero(0.0);
}

Eigen::Matrix3d SensorEffects::gyroMatrix() const {
  return triad(gyro_scale, gyro_misalignment_rad, gyro_nonorthogonality_rad);
}

Eigen::Matrix3d SensorEffects::accMatrix() const {
  return triad(acc_scale, acc_misalignment_rad, acc_nonorthogonality_rad);
}

void validateEffects(const SensorEffects& fx, const std::string& where, const std::string& prefix) {
  checkVec(where, prefix + "gyro_scale", fx.gyro_scale, limits::kScaleFactor);
  checkVec(where, prefix + "acc_scale", fx.acc_scale, limits::kScaleFactor);
  checkVec(where, prefix + "gyro_misalignment_rad", fx.gyro_misalignment_rad, limits::kMisalignmentRad);
  checkVec(where, prefix + "acc_misalignment_rad", fx.acc_misalignment_rad, limits::kMisalignmentRad);
  checkVec(where, prefix + "gyro_nonorthogonality_rad", fx.gyro_nonorthogonality_rad, limits::kMisalignmentRad);
  checkVec(where, prefix + "acc_nonorthogonality_rad", fx.acc_nonorthogonality_rad, limits::kMisalignmentRad);
  limits::check(where, prefix + "time_offset_s", fx.time_offset_s, limits::kTimeOffsetS);
  limits::check(where, prefix + "gyro_motion_noise_factor", fx.gyro_motion_noise_factor, limits::kMotionNoiseFactor);
  limits::check(where, prefix + "acc_motion_noise_factor", fx.acc_motion_noise_factor, limits::kMotionNoiseFactor);
  limits::check(where, prefix + "motion_rate_threshold_rad_s", fx.motion_rate_threshold_rad_s,
                limits::kMotionRateThresholdRadS);
  limits::check(where, prefix + "motion_acc_threshold_mps2", fx.motion_acc_threshold_mps2,
                limits::kMotionAccThresholdMps2);
  checkVec(where, prefix + "lever_arm_error_B_m", fx.lever_arm_error_B_m, limits::kLeverArmErrorM);
}

std::string describeEffects(const SensorEffects& fx) {
  if (fx.none()) return "none";
  std::vector<std::string> parts;
  const Eigen::Vector3d z = Eigen::Vector3d::Zero();
  if (fx.gyro_scale != z) parts.push_back("gyro_scale " + vec(fx.gyro_scale));
  if (fx.acc_scale != z) parts.push_back("acc_scale " + vec(fx.acc_scale));
  if (fx.gyro_misalignment_rad != z) parts.push_back("gyro_misalignment_rad " + vec(fx.gyro_misalignment_rad));
  if (fx.acc_misalignment_rad != z) parts.push_back("acc_misalignment_rad " + vec(fx.acc_misalignment_rad));
  if (fx.gyro_nonorthogonality_rad != z)
    parts.push_back("gyro_nonorthogonality_rad " + vec(fx.gyro_nonorthogonality_rad));
  if (fx.acc_nonorthogonality_rad != z)
    parts.push_back("acc_nonorthogonality_rad " + vec(fx.acc_nonorthogonality_rad));
  if (fx.time_offset_s != 0.0) parts.push_back("time_offset_s " + formatNumber(fx.time_offset_s));
  if (fx.gyro_motion_noise_factor != 1.0 || fx.acc_motion_noise_factor != 1.0)
    parts.push_back("motion noise factor gyro " + formatNumber(fx.gyro_motion_noise_factor) + ", acc " +
                    formatNumber(fx.acc_motion_noise_factor) + " (moving above " +
                    formatNumber(fx.motion_rate_threshold_rad_s) + " rad/s or " +
                    formatNumber(fx.motion_acc_threshold_mps2) + " m/s^2 from 9.80665)");
  if (fx.lever_arm_error_B_m != z) parts.push_back("lever_arm_error_B_m " + vec(fx.lever_arm_error_B_m));
  std::string s;
  for (const auto& p : parts) s += (s.empty() ? "" : "; ") + p;
  return s;
}

std::array<double, 6> whiteNoiseSigma(const stochastic::ImuModel& model, double imu_rate_hz) {
  std::array<double, 6> s{};
  for (int i = 0; i < 6; ++i) {
    if (model.axis[i].empty()) continue;
    const stochastic::Model m = stochastic::convertRate(model.axis[i], imu_rate_hz);
    double v = 0.0;
    for (const auto& t : m.terms)
      if (t.kind == stochastic::ProcessKind::WN) v += t.sigma * t.sigma;
    s[i] = std::sqrt(v);
  }
  return s;
}

std::vector<ins::ImuSample> shiftImuTime(const std::vector<ins::ImuSample>& perfect, double time_offset_s) {
  if (time_offset_s == 0.0 || perfect.empty()) return perfect;
  const Cumulative c(perfect);
  std::vector<ins::ImuSample> out = perfect;
  for (std::size_t k = 0; k < perfect.size(); ++k) {
    const Eigen::Matrix<double, 6, 1> d =
        c.at(perfect[k].t - time_offset_s) - c.at(perfect[k].t - perfect[k].dt - time_offset_s);
    out[k].dtheta_B = d.head<3>();
    out[k].dv_B = d.tail<3>();
  }
  return out;
}

EffectedImu applySensorEffects(const std::vector<ins::ImuSample>& perfect,
                               const std::array<std::vector<double>, 6>& err, const SensorEffects& fx,
                               const std::array<double, 6>& white_sigma, std::uint64_t seed) {
  validateEffects(fx, "sensor effects");
  const std::size_t n = perfect.size();
  for (int a = 0; a < 6; ++a)
    if (!err[a].empty() && err[a].size() != n)
      throw Error("sensor effects: error sequence of axis " + std::to_string(a) + " has " +
                  std::to_string(err[a].size()) + " values, the IMU " + std::to_string(n) + " samples");
  EffectedImu out;
  out.imu = shiftImuTime(perfect, fx.time_offset_s);
  const Eigen::Matrix3d Mg = fx.gyroMatrix(), Ma = fx.accMatrix();
  const bool scaleG = !Mg.isIdentity(0.0), scaleA = !Ma.isIdentity(0.0);
  const bool inflate = fx.gyro_motion_noise_factor != 1.0 || fx.acc_motion_noise_factor != 1.0;
  std::array<std::vector<double>, 6> z;
  std::array<double, 6> extra{};
  if (inflate)
    for (std::size_t a = 0; a < 6; ++a) {
      const double k = a < 3 ? fx.gyro_motion_noise_factor : fx.acc_motion_noise_factor;
      extra[a] = white_sigma[a] * std::sqrt(k * k - 1.0);
      if (extra[a] > 0.0) z[a] = standardNormal(n, stochastic::deriveSeed(seed, a));
    }
  for (std::size_t k = 0; k < n; ++k) {
    ins::ImuSample& s = out.imu[k];
    const double dt = s.dt;
    const bool moving = (s.dtheta_B / dt).norm() > fx.motion_rate_threshold_rad_s ||
                        std::abs((s.dv_B / dt).norm() - kStandardGravity) > fx.motion_acc_threshold_mps2;
    if (moving) ++out.moving_samples;
    if (scaleG) s.dtheta_B = Mg * s.dtheta_B;
    if (scaleA) s.dv_B = Ma * s.dv_B;
    for (int a = 0; a < 3; ++a) {
      if (!err[a].empty()) s.dtheta_B(a) += err[a][k] * dt;
      if (!err[3 + a].empty()) s.dv_B(a) += err[3 + a][k] * dt;
    }
    if (moving && inflate)
      for (int a = 0; a < 3; ++a) {
        if (!z[a].empty()) s.dtheta_B(a) += extra[a] * z[a][k] * dt;
        if (!z[3 + a].empty()) s.dv_B(a) += extra[3 + a] * z[3 + a][k] * dt;
      }
  }
  std::ostringstream d;
  d << describeEffects(fx);
  if (inflate)
    d << "; " << out.moving_samples << " of " << n << " samples moving";
  out.description = d.str();
  return out;
}

GnssOptions gnssWithEffects(const GnssOptions& told, const SensorEffects& fx) {
  GnssOptions g = told;
  g.lever_arm_B = told.lever_arm_B - fx.lever_arm_error_B_m;
  return g;
}

}  // namespace navimpact::emulation
