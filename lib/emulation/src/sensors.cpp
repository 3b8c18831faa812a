#include "navimpact/emulation/sensors.hpp"

#include <cmath>
#include <sstream>

#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/imu_series.hpp"
#include "navimpact/core/units.hpp"
#include "navimpact/stochastic/model_text.hpp"
#include "navimpact/stochastic/simulate.hpp"

namespace navimpact::emulation {

namespace {
}  // namespace

std::vector<double> standardNormal(std::size_t n, std::uint64_t seed) {
  stochastic::Model wn;
  wn.rate_hz = 1.0;
  wn.terms.push_back(stochastic::Process::wn(1.0));
  return stochastic::simulate(wn, n, seed);
}

ImuErrors modelImuErrors(const stochastic::ImuModel& model, double imu_rate_hz, std::size_t n,
                         std::uint64_t seed) {
  ImuErrors e;
  const stochastic::ImuModel m = stochastic::atRate(model, imu_rate_hz, &e.notices);
  for (std::size_t i = 0; i < 6; ++i) {
    e.axis[i].assign(n, 0.0);
    if (!m.axis[i].empty()) stochastic::simulateAdd(m.axis[i], stochastic::deriveSeed(seed, i), e.axis[i].data(), n);
  }
  e.description = "simulated from model " + model.source + " at " + formatNumber(imu_rate_hz) + " Hz, seed " +
                  std::to_string(seed) + " (axis i: deriveSeed(seed, i))";
  return e;
}

ImuErrors staticImuErrors(const StaticRecordingSpec& spec, double imu_rate_hz, std::size_t n) {
  return staticImuErrors(readImuCsv(spec.file, spec.csv), spec, imu_rate_hz, n);
}

ImuErrors staticImuErrors(const ImuSeries& rec, const StaticRecordingSpec& spec, double imu_rate_hz,
                          std::size_t n) {
  const double ratio = rec.rate_hz / imu_rate_hz;
  const double m_real = std::round(ratio);
  if (m_real < 1.0 || std::abs(ratio - m_real) > 1e-6 * ratio)
    throw Error(spec.file + ": static recording is at " + formatNumber(rec.rate_hz) + " Hz, emulation at " +
                formatNumber(imu_rate_hz) + " Hz (the recording's rate must equal the IMU rate or be an exact integer multiple of it)");
  const std::size_t m = static_cast<std::size_t>(m_real);
  const std::size_t need = n * m, have = rec.size();
  if (need > have)
    throw Error(spec.file + ": static recording too short: " + formatNumber(have / rec.rate_hz) + " s available, " +
                formatNumber(need / rec.rate_hz) + " s needed for " + std::to_string(n) + " IMU samples");
  std::size_t start = 0;
  ImuErrors e;
  if (spec.offset_s) {
    if (*spec.offset_s < 0.0) throw Error(spec.file + ": static recording offset must be >= 0 s");
    start = static_cast<std::size_t>(std::llround(*spec.offset_s * rec.rate_hz));
    if (start + need > have)
      throw Error(spec.file + ": offset " + formatNumber(*spec.offset_s) + " s leaves " +
                  formatNumber((have > start ? have - start : 0) / rec.rate_hz) + " s of the recording, " +
                  formatNumber(need / rec.rate_hz) + " s needed");
  } else {
    const std::uint64_t r = stochastic::deriveSeed(spec.seed, 0);
    start = static_cast<std::size_t>(r % (have - need + 1));
    e.notices.push_back("static recording window chosen by seed " + std::to_string(spec.seed) + ": offset " +
                        formatNumber(start / rec.rate_hz) + " s");
  }
  if (m > 1)
    e.notices.push_back("static recording at " + formatNumber(rec.rate_hz) + " Hz decimated by " + std::to_string(m) +
                        " (block means) to the IMU rate " + formatNumber(imu_rate_hz) + " Hz");
  for (std::size_t i = 0; i < 6; ++i) {
    auto& out = e.axis[i];
    out.assign(n, 0.0);
    if (!rec.has(kChannelNames[i])) {
      e.notices.push_back(std::string("static recording has no ") + kChannelNames[i] + ": no error on that axis");
      continue;
    }
    const auto& x = rec.channel(kChannelNames[i]).x;
    double mean = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
      double s = 0.0;
      for (std::size_t j = 0; j < m; ++j) s += x[start + k * m + j];
      out[k] = s / double(m);
      mean += out[k];
    }
    mean /= double(n);
    for (auto& v : out) v -= mean;
  }
  e.description = "measured static recording " + spec.file + ", window from " + formatNumber(start / rec.rate_hz) +
                  " s, mean removed per axis";
  return e;
}

std::vector<GnssFix> simulateGnss(const SmoothTrajectory& tr, const GnssOptions& opt, double t_start,
                                  double t_end) {
  if (!(opt.rate_hz > 0.0)) throw Error("gnss.rate_hz must be > 0");
  const auto n = static_cast<std::size_t>(std::floor((t_end - t_start) * opt.rate_hz + 1e-9)) + 1;
  const auto z = standardNormal(6 * n, opt.seed);
  std::vector<GnssFix> out(n);
  const Eigen::Vector3d sp(opt.sigma_pos_h_m, opt.sigma_pos_h_m, opt.sigma_pos_v_m);
  const Eigen::Vector3d sv(opt.sigma_vel_h_mps, opt.sigma_vel_h_mps, opt.sigma_vel_v_mps);
  for (std::size_t k = 0; k < n; ++k) {
    const double t = t_start + double(k) / opt.rate_hz;
    const TruthState s = tr.at(t);
    GnssFix& f = out[k];
    f.t = t;
    const Eigen::Vector3d lever_N = s.C_BtoN * opt.lever_arm_B;
    const Eigen::Vector3d dpos_N = lever_N + sp.cwiseProduct(Eigen::Vector3d(z[6 * k], z[6 * k + 1], z[6 * k + 2]));
    f.pos = earth::nedToGeodetic(s.pos, dpos_N);
    f.v_N = Eigen::Vector3d(s.v_N + s.C_BtoN * s.w_NB_B.cross(opt.lever_arm_B) +
                            sv.cwiseProduct(Eigen::Vector3d(z[6 * k + 3], z[6 * k + 4], z[6 * k + 5])));
    f.cov_pos_N = Eigen::Matrix3d(sp.cwiseAbs2().asDiagonal());
    f.cov_vel_N = Eigen::Matrix3d(sv.cwiseAbs2().asDiagonal());
  }
  return out;
}

std::vector<BaroSample> simulateBaro(const SmoothTrajectory& tr, const BaroOptions& opt, double t_start,
                                     double t_end) {
  if (!(opt.rate_hz > 0.0)) throw Error("baro.rate_hz must be > 0");
  const auto n = static_cast<std::size_t>(std::floor((t_end - t_start) * opt.rate_hz + 1e-9)) + 1;
  const auto z = standardNormal(n, opt.seed);
  std::vector<BaroSample> out(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double t = t_start + double(k) / opt.rate_hz;
    out[k] = {t, tr.at(t).pos.h + opt.sigma_m * z[k], opt.sigma_m};
  }
  return out;
}

}  // namespace navimpact::emulation

namespace navimpact::emulation {

void GnssOptions::loadFrom(const ConfigNode& n, bool with_seed) {
  std::vector<std::string> keys{"rate_hz", "sigma_pos_h_m", "sigma_pos_v_m", "sigma_vel_h_mps", "sigma_vel_v_mps",
                                "lever_arm_B_m"};
  if (with_seed) keys.push_back("seed");
  n.allowKeys(keys);
  n.read("rate_hz", rate_hz, limits::kAidingRateHz);
  n.read("sigma_pos_h_m", sigma_pos_h_m, limits::kPositionSigmaM);
  n.read("sigma_pos_v_m", sigma_pos_v_m, limits::kPositionSigmaM);
  n.read("sigma_vel_h_mps", sigma_vel_h_mps, limits::kVelocitySigmaMps);
  n.read("sigma_vel_v_mps", sigma_vel_v_mps, limits::kVelocitySigmaMps);
  n.read("lever_arm_B_m", lever_arm_B, limits::kLeverArmM);
  if (with_seed) n.readSeed("seed", seed);
}

void BaroOptions::loadFrom(const ConfigNode& n, bool with_seed, const std::vector<std::string>& extra_keys) {
  std::vector<std::string> keys{"rate_hz", "sigma_m"};
  if (with_seed) keys.push_back("seed");
  keys.insert(keys.end(), extra_keys.begin(), extra_keys.end());
  n.allowKeys(keys);
  n.read("rate_hz", rate_hz, limits::kAidingRateHz);
  n.read("sigma_m", sigma_m, limits::kPositionSigmaM);
  if (with_seed) n.readSeed("seed", seed);
}

void StaticRecordingSpec::loadFrom(const ConfigNode& n, bool with_window) {
  std::vector<std::string> keys{"file", "gyro_unit", "acc_unit", "rate_hz", "axes"};
  if (with_window) keys.insert(keys.end(), {"offset_s", "seed"});
  n.allowKeys(keys);
  file = n.resolve(n.text("file", "the static recording CSV", true));
  n.readChoice("gyro_unit", csv.gyro_unit, units::acceptedUnits(units::Quantity::AngularRate));
  n.readChoice("acc_unit", csv.acc_unit, units::acceptedUnits(units::Quantity::SpecificForce));
  double rate = 0.0;
  if (n.read("rate_hz", rate, limits::kImuRateHz)) csv.rate_hz = rate;
  n.read("axes", csv.axes);
  if (with_window) {
    double off = 0.0;
    if (n.read("offset_s", off, limits::Range{0.0, limits::kDurationS.hi, false, "s"})) offset_s = off;
    n.readSeed("seed", seed);
  }
}

}  // namespace navimpact::emulation
