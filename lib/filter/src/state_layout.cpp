#include "navimpact/filter/state_layout.hpp"

#include <cmath>
#include <map>
#include <sstream>

#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/imu_series.hpp"
#include "navimpact/core/limits.hpp"

namespace navimpact::filter {

namespace {
// A GM with T <= t_max becomes white noise of the same long-run variance
// (AR(1) spectrum at f = 0: sigma^2 (1 + phi) / (1 - phi) per sample), merged
// into the axis' WN term (or added as one).
stochastic::Model whiteShortGms(const stochastic::Model& in, double t_max, const std::string& ch,
                                std::vector<std::string>& notes) {
  if (!(t_max > 0.0)) return in;
  stochastic::Model out = in;
  out.terms.clear();
  double add = 0.0;
  for (const stochastic::Process& p : in.terms) {
    if (p.kind == stochastic::ProcessKind::GM && p.T <= t_max) {
      const double phi = std::exp(-1.0 / (in.rate_hz * p.T));
      add += p.sigma * p.sigma * (1.0 + phi) / (1.0 - phi);
      notes.push_back(ch + ": GM(sigma=" + formatNumber(p.sigma, 4) + ", T=" + formatNumber(p.T, 4) +
                      ") is shorter than the covariance propagation interval (" + formatNumber(t_max, 4) +
                      " s) and enters as white noise of the same long-run variance");
    } else {
      out.terms.push_back(p);
    }
  }
  if (add == 0.0) return in;
  for (stochastic::Process& p : out.terms)
    if (p.kind == stochastic::ProcessKind::WN) {
      p.sigma = std::sqrt(p.sigma * p.sigma + add);
      return out;
    }
  out.terms.push_back(stochastic::Process::wn(std::sqrt(add)));
  return out;
}

/// The section of an effect on both triads (scale_factor, misalignment): the
/// prior sigma and initial value of the gyro's and the accelerometer's,
/// keys gyro_sigma, acc_sigma, gyro, acc with the unit @p suffix ("" or "_rad").
void readTriadSection(const ConfigNode& s, const std::string& suffix, double& gyro_sigma, double& acc_sigma,
                      Eigen::Vector3d& gyro0, Eigen::Vector3d& acc0, const limits::Range& sigma_range,
                      const limits::Range& range) {
  s.allowKeys(std::vector<std::string>{"gyro_sigma" + suffix, "acc_sigma" + suffix, "gyro" + suffix, "acc" + suffix});
  s.read("gyro_sigma" + suffix, gyro_sigma, sigma_range);
  s.read("acc_sigma" + suffix, acc_sigma, sigma_range);
  s.read("gyro" + suffix, gyro0, range);
  s.read("acc" + suffix, acc0, range);
}

}  // namespace

void ExtraStates::loadFrom(const ConfigNode& n) {
  n.allowKeys({"scale_factor", "misalignment", "lever_arm", "time_offset"});
  if (const auto s = n.optMap("scale_factor"))
    readTriadSection(*s, "", gyro_scale_sigma, acc_scale_sigma, gyro_scale0, acc_scale0, limits::kScaleFactorSigma,
                     limits::kScaleFactor);
  if (const auto m = n.optMap("misalignment"))
    readTriadSection(*m, "_rad", gyro_misalignment_sigma_rad, acc_misalignment_sigma_rad, gyro_misalignment0_rad,
                     acc_misalignment0_rad, limits::kMisalignmentSigmaRad, limits::kMisalignmentRad);
  if (const auto l = n.optMap("lever_arm")) {
    l->allowKeys({"sigma_m", "error_m"});
    l->read("sigma_m", lever_arm_sigma_m, limits::kLeverArmErrorSigmaM);
    l->read("error_m", lever_arm_error0_m, limits::kLeverArmErrorM);
  }
  if (const auto t = n.optMap("time_offset")) {
    t->allowKeys({"sigma_s", "offset_s"});
    t->read("sigma_s", time_offset_sigma_s, limits::kTimeOffsetSigmaS);
    t->read("offset_s", time_offset0_s, limits::kTimeOffsetS);
  }
}

StateLayout StateLayout::build(const stochastic::ImuModel& model, const ImuErrorOptions& opt) {
  StateLayout L;
  L.model_ = model;
  L.names_ = {"pos_N", "pos_E", "pos_D", "vel_N", "vel_E", "vel_D", "att_N", "att_E", "att_D"};
  for (int c = 0; c < 6; ++c) {
    const std::string ch = kChannelNames[c];
    if (opt.turn_on_bias) {
      const double s = opt.turn_on_sigma[c];
      if (!(std::isfinite(s) && s > 0.0))
        throw Error("turn-on bias sigma of " + ch + " must be finite and > 0, got " + formatNumber(s, 4));
      ProcessBlock b;
      b.channel = c;
      b.offset = static_cast<int>(L.names_.size());
      b.ss.n = 1;
      b.ss.F = Eigen::MatrixXd::Zero(1, 1);
      b.ss.Qc = Eigen::MatrixXd::Zero(1, 1);
      b.ss.H = Eigen::RowVectorXd::Ones(1);
      b.ss.P0 = Eigen::MatrixXd::Constant(1, 1, s * s);
      b.ss.names = {"turn-on bias"};
      L.names_.push_back(ch + ".TOB(sigma=" + formatNumber(s, 4) + ")");
      L.blocks_.push_back(b);
    }
    if (model.axis[c].empty()) continue;
    stochastic::validate(model.axis[c]);
    const std::size_t axisStart = L.names_.size();
    const stochastic::Model m = whiteShortGms(model.axis[c], opt.white_gm_below_s, ch, L.notes_);
    std::map<stochastic::ProcessKind, int> count;
    for (const stochastic::Process& p : m.terms) {
      const int k = ++count[p.kind];
      stochastic::StateSpaceBlock ss = stochastic::stateSpace(p, m.rate_hz);
      L.white_psd_[c] += ss.white_psd;
      if (ss.n == 0) continue;
      ProcessBlock b;
      b.channel = c;
      b.offset = static_cast<int>(L.names_.size());
      b.ss = ss;
      // "<channel>.<KIND><k>" plus the kind's label of each state (state_space.hpp).
      const std::string base = ch + "." + stochastic::kindName(p.kind) + std::to_string(k);
      for (const std::string& label : ss.names) L.names_.push_back(base + label);
      if (static_cast<int>(L.names_.size()) != b.offset + ss.n)
        throw Error("internal: state-space block of " + base + " has " + std::to_string(ss.n) +
                    " states, expected a different number");
      L.blocks_.push_back(b);
      const std::size_t axisStates = L.names_.size() - axisStart;
      if (axisStates > static_cast<std::size_t>(limits::kMaxImuStatesPerAxis))
        throw Error((model.source.empty() ? std::string("IMU model") : "model " + model.source) + ": " + ch +
                    " needs more than " + std::to_string(limits::kMaxImuStatesPerAxis) + " error states (" +
                    std::to_string(m.terms.size()) + " terms), more than the filter accepts per axis");
    }
  }
  // Extra states: random constants (F = 0, Qc = 0) with a zero sensor row;
  // ErrorStateEkf adds their couplings (state_layout.hpp).
  const ExtraStates& x = opt.extra;
  const double sig[kExtraGroups] = {x.gyro_scale_sigma,           x.acc_scale_sigma,
                                    x.gyro_misalignment_sigma_rad, x.acc_misalignment_sigma_rad,
                                    x.lever_arm_sigma_m,           x.time_offset_sigma_s};
  const char* key[kExtraGroups] = {"gyro_scale_sigma",           "acc_scale_sigma",
                                   "gyro_misalignment_sigma_rad", "acc_misalignment_sigma_rad",
                                   "lever_arm_sigma_m",           "time_offset_sigma_s"};
  const char* base[kExtraGroups] = {"gyro.scale_",         "acc.scale_",         "gyro.misalignment_",
                                    "acc.misalignment_",   "gnss.lever_arm_error_", "gnss.time_offset"};
  const char* unit[kExtraGroups] = {"", "", " rad", " rad", " m", " s"};
  for (int g = 0; g < kExtraGroups; ++g) {
    if (!(std::isfinite(sig[g]) && sig[g] >= 0.0))
      throw Error("extra state " + std::string(key[g]) + " must be finite and >= 0 (0 = off), got " +
                  formatNumber(sig[g], 4));
    if (sig[g] == 0.0) continue;
    L.extra_[g] = static_cast<int>(L.names_.size());
    L.has_extra_ = true;
    const int n = g == static_cast<int>(Extra::TimeOffset) ? 1 : 3;
    for (int i = 0; i < n; ++i) {
      ProcessBlock b;
      b.channel = 0;  // unused: the sensor row is zero
      b.offset = static_cast<int>(L.names_.size());
      b.ss.n = 1;
      b.ss.F = Eigen::MatrixXd::Zero(1, 1);
      b.ss.Qc = Eigen::MatrixXd::Zero(1, 1);
      b.ss.H = Eigen::RowVectorXd::Zero(1);
      b.ss.P0 = Eigen::MatrixXd::Constant(1, 1, sig[g] * sig[g]);
      b.ss.names = {"random constant"};
      L.names_.push_back(std::string(base[g]) + (n == 3 ? std::string(1, "xyz"[i]) : std::string()) +
                         "(sigma=" + formatNumber(sig[g], 4) + unit[g] + ")");
      L.blocks_.push_back(b);
    }
  }
  const int m = L.imuSize();
  for (int c = 0; c < 6; ++c) L.h_[c] = Eigen::RowVectorXd::Zero(m);
  for (const ProcessBlock& b : L.blocks_)
    L.h_[b.channel].segment(b.offset - kNav, b.ss.n) = b.ss.H;
  return L;
}

Eigen::MatrixXd StateLayout::gyroRows() const {
  Eigen::MatrixXd Hg(3, imuSize());
  for (int c = 0; c < 3; ++c) Hg.row(c) = h_[static_cast<std::size_t>(c)];
  return Hg;
}

Eigen::MatrixXd StateLayout::imuP0() const {
  Eigen::MatrixXd P = Eigen::MatrixXd::Zero(imuSize(), imuSize());
  for (const ProcessBlock& b : blocks_)
    P.block(b.offset - kNav, b.offset - kNav, b.ss.n, b.ss.n) = b.ss.P0;
  return P;
}

std::string StateLayout::describe() const {
  std::ostringstream s;
  for (int i = 0; i < size(); ++i) s << i << " " << names_[i] << "\n";
  for (int c = 0; c < 6; ++c)
    if (white_psd_[c] > 0.0)
      s << "noise " << kChannelNames[c] << " white PSD " << white_psd_[c] << " (SI unit^2 s)\n";
  return s.str();
}

}  // namespace navimpact::filter
