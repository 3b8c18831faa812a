#include "navimpact/emulation/sensors.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/imu_series.hpp"
#include "navimpact/core/units.hpp"
#include "navimpact/stochastic/model_text.hpp"
#include "navimpact/stochastic/simulate.hpp"

namespace navimpact::emulation {

namespace {

stochastic::Model unitWhiteNoise() {
  stochastic::Model wn;
  wn.rate_hz = 1.0;
  wn.terms.push_back(stochastic::Process::wn(1.0));
  return wn;
}

}  // namespace

std::vector<double> standardNormal(std::size_t n, std::uint64_t seed) {
  return stochastic::simulate(unitWhiteNoise(), n, seed);
}

ImuErrorStream ImuErrorStream::none(std::size_t n) {
  ImuErrorStream e;
  e.n_ = n;
  e.description_ = "none (perfect IMU)";
  return e;
}

ImuErrorStream ImuErrorStream::fromModel(const stochastic::ImuModel& model, double imu_rate_hz, std::size_t n,
                                         std::uint64_t seed) {
  ImuErrorStream e;
  e.n_ = n;
  e.kind_ = 1;
  const stochastic::ImuModel m = stochastic::atRate(model, imu_rate_hz, &e.notices_);
  e.model_.resize(6);
  for (std::size_t i = 0; i < 6; ++i)
    if (!m.axis[i].empty() && !m.axis[i].terms.empty())
      e.model_[i].emplace(m.axis[i], stochastic::deriveSeed(seed, i));
  e.description_ = "simulated from model " + model.source + " at " + formatNumber(imu_rate_hz) + " Hz, seed " +
                   std::to_string(seed) + " (axis i: deriveSeed(seed, i))";
  return e;
}

ImuErrorStream ImuErrorStream::fromStatic(std::shared_ptr<const ImuSeries> recp, const StaticRecordingSpec& spec,
                                          double imu_rate_hz, std::size_t n) {
  const ImuSeries& rec = *recp;
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
  ImuErrorStream e;
  e.n_ = n;
  e.kind_ = 2;
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
    e.notices_.push_back("static recording window chosen by seed " + std::to_string(spec.seed) + ": offset " +
                         formatNumber(start / rec.rate_hz) + " s");
  }
  if (m > 1)
    e.notices_.push_back("static recording at " + formatNumber(rec.rate_hz) + " Hz decimated by " + std::to_string(m) +
                         " (block means) to the IMU rate " + formatNumber(imu_rate_hz) + " Hz");
  e.start_ = start;
  e.m_ = m;
  for (std::size_t i = 0; i < 6; ++i) {
    if (!rec.has(kChannelNames[i])) {
      e.notices_.push_back(std::string("static recording has no ") + kChannelNames[i] + ": no error on that axis");
      continue;
    }
    e.has_[i] = true;
    // the window's mean of the block means (removed from every value)
    const auto& x = rec.channel(kChannelNames[i]).x;
    double mean = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
      double sum = 0.0;
      for (std::size_t j = 0; j < m; ++j) sum += x[start + k * m + j];
      mean += sum / double(m);
    }
    e.mean_[i] = mean / double(n);
  }
  e.description_ = "measured static recording " + spec.file + ", window from " + formatNumber(start / rec.rate_hz) +
                   " s, mean removed per axis";
  e.rec_ = std::move(recp);
  return e;
}

void ImuErrorStream::next(std::size_t count, std::array<std::vector<double>, 6>& out) {
  if (count > n_ - k_) throw Error("IMU errors: " + std::to_string(count) + " samples asked, " +
                                   std::to_string(n_ - k_) + " left");
  for (std::size_t i = 0; i < 6; ++i) {
    out[i].assign(count, 0.0);
    if (kind_ == 1 && model_[i]) model_[i]->addNext(out[i].data(), count);
    if (kind_ == 2 && has_[i]) {
      const auto& x = rec_->channel(kChannelNames[i]).x;
      for (std::size_t c = 0; c < count; ++c) {
        const std::size_t k = k_ + c;
        double sum = 0.0;
        for (std::size_t j = 0; j < m_; ++j) sum += x[start_ + k * m_ + j];
        out[i][c] = sum / double(m_) - mean_[i];
      }
    }
  }
  k_ += count;
}

namespace {

ImuErrors collect(ImuErrorStream s) {
  ImuErrors e;
  s.next(s.size(), e.axis);
  e.notices = s.notices();
  e.description = s.description();
  return e;
}

}  // namespace

ImuErrors modelImuErrors(const stochastic::ImuModel& model, double imu_rate_hz, std::size_t n,
                         std::uint64_t seed) {
  return collect(ImuErrorStream::fromModel(model, imu_rate_hz, n, seed));
}

ImuErrors staticImuErrors(const StaticRecordingSpec& spec, double imu_rate_hz, std::size_t n) {
  return staticImuErrors(readImuCsv(spec.file, spec.csv), spec, imu_rate_hz, n);
}

ImuErrors staticImuErrors(const ImuSeries& rec, const StaticRecordingSpec& spec, double imu_rate_hz,
                          std::size_t n) {
  // the recording is the caller's: an aliasing pointer that owns nothing
  return collect(ImuErrorStream::fromStatic(std::shared_ptr<const ImuSeries>(std::shared_ptr<const ImuSeries>(), &rec),
                                            spec, imu_rate_hz, n));
}

GnssSimulator::GnssSimulator(const SmoothTrajectory& tr, const GnssOptions& opt, double t_start, double t_end)
    : tr_(tr), opt_(opt), t_start_(t_start), z_(unitWhiteNoise(), opt.seed) {
  if (!(opt.rate_hz > 0.0)) throw Error("gnss.rate_hz must be > 0");
  n_ = static_cast<std::size_t>(std::floor((t_end - t_start) * opt.rate_hz + 1e-9)) + 1;
}

void GnssSimulator::next(double t_until, std::vector<GnssFix>& out) {
  const Eigen::Vector3d sp(opt_.sigma_pos_h_m, opt_.sigma_pos_h_m, opt_.sigma_pos_v_m);
  const Eigen::Vector3d sv(opt_.sigma_vel_h_mps, opt_.sigma_vel_h_mps, opt_.sigma_vel_v_mps);
  double z[6];
  for (; k_ < n_; ++k_) {
    const double t = t_start_ + double(k_) / opt_.rate_hz;
    if (t > t_until) break;
    std::fill(z, z + 6, 0.0);
    z_.addNext(z, 6);  // the fix's six draws of standardNormal(6 n, seed)
    const TruthState s = tr_.at(t);
    GnssFix f;
    f.t = t;
    const Eigen::Vector3d lever_N = s.C_BtoN * opt_.lever_arm_B;
    const Eigen::Vector3d dpos_N = lever_N + sp.cwiseProduct(Eigen::Vector3d(z[0], z[1], z[2]));
    f.pos = earth::nedToGeodetic(s.pos, dpos_N);
    f.v_N = Eigen::Vector3d(s.v_N + s.C_BtoN * s.w_NB_B.cross(opt_.lever_arm_B) +
                            sv.cwiseProduct(Eigen::Vector3d(z[3], z[4], z[5])));
    f.cov_pos_N = Eigen::Matrix3d(sp.cwiseAbs2().asDiagonal());
    f.cov_vel_N = Eigen::Matrix3d(sv.cwiseAbs2().asDiagonal());
    out.push_back(f);
  }
}

BaroSimulator::BaroSimulator(const SmoothTrajectory& tr, const BaroOptions& opt, double t_start, double t_end)
    : tr_(tr), opt_(opt), t_start_(t_start), z_(unitWhiteNoise(), opt.seed) {
  if (!(opt.rate_hz > 0.0)) throw Error("baro.rate_hz must be > 0");
  n_ = static_cast<std::size_t>(std::floor((t_end - t_start) * opt.rate_hz + 1e-9)) + 1;
}

void BaroSimulator::next(double t_until, std::vector<BaroSample>& out) {
  for (; k_ < n_; ++k_) {
    const double t = t_start_ + double(k_) / opt_.rate_hz;
    if (t > t_until) break;
    double z = 0.0;
    z_.addNext(&z, 1);
    out.push_back({t, tr_.at(t).pos.h + opt_.sigma_m * z, opt_.sigma_m});
  }
}

namespace {

/// Every record of a block simulator in one block.
template <class Record, class Simulator>
std::vector<Record> allRecords(Simulator&& s) {
  std::vector<Record> out;
  out.reserve(s.size());
  s.next(std::numeric_limits<double>::infinity(), out);
  return out;
}

}  // namespace

std::vector<GnssFix> simulateGnss(const SmoothTrajectory& tr, const GnssOptions& opt, double t_start,
                                  double t_end) {
  return allRecords<GnssFix>(GnssSimulator(tr, opt, t_start, t_end));
}

std::vector<BaroSample> simulateBaro(const SmoothTrajectory& tr, const BaroOptions& opt, double t_start,
                                     double t_end) {
  return allRecords<BaroSample>(BaroSimulator(tr, opt, t_start, t_end));
}

}  // namespace navimpact::emulation

namespace navimpact::emulation {

void GnssOptions::loadFrom(const ConfigNode& n, bool with_seed) {
  std::vector<std::string> keys{"rate_hz", "sigma_pos_h_m", "sigma_pos_v_m", "sigma_vel_h_mps", "sigma_vel_v_mps",
                                "lever_arm_B_m"};
  if (with_seed) keys.push_back("seed");
  n.allowKeys(keys);
  n.read("rate_hz", rate_hz, limits::kGnssRateHz);
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
  file = n.inputFile("file", "the static recording CSV");
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
