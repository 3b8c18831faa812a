// navimpact diagnose --run: measured outage errors of a real run against the
// distribution the simulation with the IMU model predicts (see run_diagnosis.hpp).
#include "navimpact/analysis/run_diagnosis.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <random>

#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/fisher_f.hpp>
#include <boost/math/distributions/gamma.hpp>
#include <boost/math/distributions/students_t.hpp>

#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/limits.hpp"
#include "navimpact/core/parallel.hpp"
#include "navimpact/analysis/run_plan.hpp"
#include "navimpact/emulation/perfect_imu.hpp"
#include "navimpact/emulation/sensor_effects.hpp"
#include "navimpact/emulation/sensors.hpp"
#include "navimpact/core/imu_series.hpp"
#include "navimpact/rawlog/reader.hpp"
#include "navimpact/filter/error_model.hpp"
#include "navimpact/stochastic/model_file.hpp"
#include "navimpact/stochastic/simulate.hpp"

namespace navimpact::analysis {

namespace {

constexpr double kDenseRefStepS = 0.25;  // a reference this dense (with attitude) is the trajectory itself
const char* const kQuantities[4] = {"horizontal_position", "vertical_position", "velocity", "attitude"};
const char* const kUnits[4] = {"m", "m", "m/s", "rad"};
constexpr int kDof[4] = {2, 1, 3, 3};

/// Magnitude of quantity q of a nine-error vector (dp NED, dv NED, psi).
double magnitude(int q, const filter::Vector9d& e) {
  switch (q) {
    case 0: return std::hypot(e(0), e(1));
    case 1: return std::abs(e(2));
    case 2: return e.segment<3>(3).norm();
    default: return e.segment<3>(6).norm();
  }
}

double meanSquare(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x * x;
  return v.empty() ? NAN : s / static_cast<double>(v.size());
}

/// The trajectory of the run as the emulation's smooth truth.
emulation::SmoothTrajectory buildTrajectory(const ReplayResult& scored, const RunDiagnosisOptions& opt,
                                            const rawlog::RawlogRecords& data, std::string& source) {
  emulation::SampledTrajectory s;
  s.source = scored.cfg.rawlog;
  bool dense = scored.score && scored.score->reference.has_velocity && scored.score->reference.has_attitude &&
               scored.truth.size() >= 8;
  for (std::size_t k = 1; dense && k < scored.truth.size(); ++k)
    dense = scored.truth[k].t - scored.truth[k - 1].t <= kDenseRefStepS + 1e-9;
  std::vector<ins::NavState> x;
  if (dense) {
    x = scored.truth;
    source = "the run's reference (velocity and attitude, at most " + formatNumber(kDenseRefStepS) +
             " s apart), smoothed by P-splines";
  } else {
    ReplayConfig c = opt.replay;
    c.setOutages({});
    c.outages_every.reset();
    c.use_reference = false;
    c.record_interval_s = 0.1;
    const ReplayResult aided = runReplay(c, data);
    for (const auto& e : aided.run.epochs) x.push_back(e.est);
    source = "the GNSS-aided filter solution of the run without outages (the reference lacks velocity, attitude or "
             "density), every 0.1 s, smoothed by P-splines";
  }
  if (x.size() < 8) throw Error(s.source + ": too short a run to emulate its trajectory (" + std::to_string(x.size()) + " epochs)");
  s.origin = x.front().geodetic();
  Eigen::Vector3d prev = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < x.size(); ++k) {
    if (!s.t.empty() && !(x[k].t > s.t.back())) continue;
    s.t.push_back(x[k].t);
    s.p_L.push_back(earth::geodeticToNed(s.origin, x[k].geodetic()));
    Eigen::Vector3d rpy = x[k].rollPitchYaw();
    if (k > 0)
      for (int a = 0; a < 3; a += 2) rpy(a) = prev(a) + ins::wrapAngle(rpy(a) - prev(a));  // unwrap roll, yaw
    s.rpy.push_back(rpy);
    prev = rpy;
  }
  return emulation::SmoothTrajectory(s, emulation::SmoothingOptions{});
}

/// Density of the accelerometer bias random walk added to every realisation
/// once more (same seed) when the causes are diagnosed: the paired excess of
/// the outage-end errors measures what a unit density does to each outage
/// end through this filter (bias_instability) [m/s^2/sqrt(s)].
constexpr double kCalibrationRwDensity = 1e-3;

/// One realisation's outage-end errors and NEES per duration.
struct RealisationOut {
  std::vector<std::vector<filter::Vector9d>> err;     // [duration][outage]
  std::vector<std::vector<double>> nees;              // [duration][outage]
  std::vector<std::vector<filter::Vector9d>> err_rw;  // the same with the calibration random walk (causes only)
};


/// Where a measured run-level statistic (log) falls among the realisations' (log):
/// t = (x - mu) / (sd sqrt(1 + 1/R)), Student t with R - 1 dof (a prediction
/// interval, Gaussian logs assumed); interval of x - mu at level 1 - a.
struct LogTest {
  double mu = 0.0, sd = 0.0, log_ratio = 0.0, lo = 0.0, hi = 0.0, p = 1.0;
};
LogTest logTest(double x, const std::vector<double>& logs, double a) {
  LogTest r;
  const double R = static_cast<double>(logs.size());
  if (R < 2) {
    r.p = NAN;
    return r;
  }
  for (double v : logs) r.mu += v;
  r.mu /= R;
  for (double v : logs) r.sd += (v - r.mu) * (v - r.mu);
  r.sd = std::sqrt(r.sd / (R - 1.0));
  r.log_ratio = x - r.mu;
  const double se = r.sd * std::sqrt(1.0 + 1.0 / R);
  boost::math::students_t st(R - 1.0);
  const double tq = boost::math::quantile(boost::math::complement(st, a / 2));
  r.lo = r.log_ratio - tq * se;
  r.hi = r.log_ratio + tq * se;
  if (se > 0) r.p = std::min(1.0, 2.0 * boost::math::cdf(boost::math::complement(st, std::abs(r.log_ratio) / se)));
  else r.p = r.log_ratio == 0.0 ? 1.0 : 0.0;
  return r;
}

/// Error and predicted sigma (nine navigation errors) at the end of the outage
/// of @p r that starts at @p start_s from time zero (NaN when it has no end epoch).
std::pair<filter::Vector9d, filter::Vector9d> endOf(const ReplayResult& r, double start_s) {
  std::pair<filter::Vector9d, filter::Vector9d> e{filter::Vector9d::Constant(NAN), filter::Vector9d::Constant(NAN)};
  for (const auto& ro : r.run.outages)
    if (std::abs(ro.window.start_s - r.t_zero - start_s) <= 1e-6 && ro.end_epoch >= 0) {
      const auto& ep = r.run.epochs[static_cast<std::size_t>(ro.end_epoch)];
      e = {ep.err, ep.sigma};
    }
  return e;
}

/// endOf for each scored outage of @p r.
std::vector<std::pair<filter::Vector9d, filter::Vector9d>> scoredEnds(const ReplayResult& r) {
  std::vector<std::pair<filter::Vector9d, filter::Vector9d>> v;
  for (const auto& o : r.score->outages) v.push_back(endOf(r, o.start_s));
  return v;
}

/// Negative log-likelihood of the velocity and attitude errors at an outage end
/// (diagonal), for the parts the reference has.
double navNll(const std::pair<filter::Vector9d, filter::Vector9d>& e, const ReferenceInfo& ref) {
  double nll = 0.0;
  for (int k = 3; k < 9; ++k) {
    if ((k < 6 && !ref.has_velocity) || (k >= 6 && !ref.has_attitude)) continue;
    const double v = e.second(k) * e.second(k);
    if (!(v > 0.0) || !std::isfinite(e.first(k))) continue;
    nll += 0.5 * (e.first(k) * e.first(k) / v + std::log(v));
  }
  return nll;
}

/// Position negative log-likelihood of one outage end (diagonal covariance, reference counted).
double outageNll(const OutageScore& o, const ReferenceInfo& ref) {
  double nll = 0.0;
  for (int i = 0; i < 3; ++i) {
    const double r = i < 2 ? ref.sigma_h_m : ref.sigma_v_m;
    const double v = o.sigma_N(i) * o.sigma_N(i) + r * r;
    nll += 0.5 * (o.err_N(i) * o.err_N(i) / v + std::log(v));
  }
  return nll;
}

/// One-sided paired sign-flip permutation p-value of mean(d) > 0 (seeded Monte Carlo).
double signFlipP(const std::vector<double>& d, std::uint64_t seed, int flips = 20000) {
  if (d.empty()) return 1.0;
  double obs = 0.0;
  bool any = false;
  for (double x : d) {
    obs += x;
    any = any || x != 0.0;
  }
  if (!any) return 1.0;
  std::mt19937_64 rng(seed);
  int count = 0;
  for (int b = 0; b < flips; ++b) {
    double s = 0.0;
    for (double x : d) s += (rng() & 1u) ? x : -x;
    if (s >= obs - 1e-12 * std::abs(obs)) ++count;
  }
  return (count + 1.0) / (flips + 1.0);
}

/// A time interval excluded from a fit (the held-out block).
struct Exclusion {
  double a = 0.0, b = -1.0;  // empty when b < a
  bool covers(double t) const { return t >= a && t <= b; }
  bool overlaps(double s, double e) const { return b >= a && s <= b && e >= a; }
};

/// Per-channel high-frequency residual of the real IMU against the trajectory.
struct ImuResidual {
  std::vector<double> t;                      // sample times
  std::vector<char> moving;                   // the trajectory moves at the sample
  std::array<std::vector<double>, 6> r;       // residual rates [rad/s, m/s^2]
};

/// White-noise sigma^2 batches from second differences over samples k-2..k all
/// selected (moving == want_moving) and outside @p ex; 20 batch means.
std::vector<double> wnBatches(const ImuResidual& res, int ch, bool want_moving, const Exclusion& ex) {
  std::vector<double> d2;
  for (std::size_t k = 2; k < res.t.size(); ++k) {
    bool ok = true;
    for (std::size_t j = k - 2; j <= k && ok; ++j)
      ok = (res.moving[j] != 0) == want_moving && !ex.covers(res.t[j]);
    if (!ok) continue;
    const double v = res.r[ch][k] - 2 * res.r[ch][k - 1] + res.r[ch][k - 2];
    d2.push_back(v * v / 6.0);
  }
  std::vector<double> b;
  const std::size_t B = 20;
  if (d2.size() < 10 * B) return b;
  for (std::size_t i = 0; i < B; ++i) {
    const std::size_t lo = i * d2.size() / B, hi = (i + 1) * d2.size() / B;
    double s = 0.0;
    for (std::size_t k = lo; k < hi; ++k) s += d2[k];
    b.push_back(s / double(hi - lo));
  }
  return b;
}

/// Mean and 99 % Student-t interval of batch means.
void batchInterval(const std::vector<double>& b, double& mean, double& lo, double& hi) {
  const double n = static_cast<double>(b.size());
  mean = 0.0;
  for (double x : b) mean += x;
  mean /= n;
  double v = 0.0;
  for (double x : b) v += (x - mean) * (x - mean);
  v /= (n - 1.0);
  boost::math::students_t st(n - 1.0);
  const double h = boost::math::quantile(boost::math::complement(st, 0.005)) * std::sqrt(v / n);
  lo = std::max(0.0, mean - h);
  hi = mean + h;
}

/// Scale every WN term of channel @p ch by @p k (or add WN(sigma_imu) converted to the model rate).
void inflateWhite(stochastic::ImuModel& m, int ch, double k, double sigma_imu, double imu_rate) {
  bool has = false;
  for (auto& p : m.axis[ch].terms)
    if (p.kind == stochastic::ProcessKind::WN) {
      p.sigma *= k;
      has = true;
    }
  if (!has && sigma_imu > 0.0) {
    const double r = m.axis[ch].rate_hz > 0 ? m.axis[ch].rate_hz : m.rate_hz;
    m.axis[ch].terms.push_back(stochastic::Process::wn(sigma_imu * std::sqrt(r / imu_rate)));
  }
}

/// Add an RW of continuous density q [(unit)^2/s] to channel @p ch (merged with an existing RW).
void addRandomWalk(stochastic::ImuModel& m, int ch, double q) {
  if (!(q > 0.0)) return;
  const double r = m.axis[ch].rate_hz > 0 ? m.axis[ch].rate_hz : m.rate_hz;
  for (auto& p : m.axis[ch].terms)
    if (p.kind == stochastic::ProcessKind::RW) {
      p.gamma = std::sqrt(p.gamma * p.gamma + q / r);
      return;
    }
  m.axis[ch].terms.push_back(stochastic::Process::rw(std::sqrt(q / r)));
}

/// @p base with the IMU model @p m (an extension); @p cr, when given, records
/// the model and what the extension changes.
ReplayConfig withModel(const ReplayConfig& base, const stochastic::ImuModel& m, CauseResult* cr,
                       const std::string& extension) {
  if (cr) {
    cr->model_after = m;
    cr->extension = extension;
  }
  ReplayConfig c = base;
  c.model = m;
  return c;
}

/// The causes an optional filter state carries (filter::ExtraStates).
enum class ExtraCause { ScaleFactor, Misalignment, TimeOffset, LeverArm };

// Prior sigmas of the fitting replays when the replay configuration has the
// state off: half the documented range of the effect (limits.hpp), so that an
// effect anywhere in the range is within about two sigma.
constexpr double kFitScaleSigma = 0.5 * limits::kScaleFactor.hi;        // [ratio]
constexpr double kFitMisalignmentSigmaRad = 0.5 * limits::kMisalignmentRad.hi;  // [rad]
constexpr double kFitTimeOffsetSigmaS = 0.5 * limits::kTimeOffsetS.hi;  // [s]
constexpr double kFitLeverArmSigmaM = 0.5 * limits::kLeverArmErrorM.hi; // [m]
constexpr double kZ95 = 1.959963984540054;                              // two-sided 95 % normal quantile

/// The filter groups of a cause acting on both triads (scale factor,
/// misalignment), gyro [0] and accelerometer [1]: their prior sigmas and
/// initial values (ExtraStates), their estimates (SensorParams), the prior
/// of the fitting replays, the ranges, and how a finding names them.
struct TriadGroups {
  double filter::ExtraStates::*sigma[2];
  Eigen::Vector3d filter::ExtraStates::*initial[2];
  Eigen::Vector3d filter::SensorParams::*estimate[2];
  double fit_sigma;
  limits::Range sigma_range, range;
  const char* cause;
  const char* param;
  const char* note;
};

/// The triad groups of @p kind (ScaleFactor or Misalignment).
const TriadGroups& triadGroups(ExtraCause kind) {
  using X = filter::ExtraStates;
  using P = filter::SensorParams;
  static const TriadGroups scale{{&X::gyro_scale_sigma, &X::acc_scale_sigma}, {&X::gyro_scale0, &X::acc_scale0},
                                 {&P::gyro_scale, &P::acc_scale}, kFitScaleSigma, limits::kScaleFactorSigma,
                                 limits::kScaleFactor, "scale_factor", "scale", "scale factor [ratio]: "};
  static const TriadGroups misalignment{
      {&X::gyro_misalignment_sigma_rad, &X::acc_misalignment_sigma_rad},
      {&X::gyro_misalignment0_rad, &X::acc_misalignment0_rad}, {&P::gyro_misalignment_rad, &P::acc_misalignment_rad},
      kFitMisalignmentSigmaRad, limits::kMisalignmentSigmaRad, limits::kMisalignmentRad, "misalignment", "angle",
      "misalignment angle of the triad about this axis [rad]: "};
  return kind == ExtraCause::ScaleFactor ? scale : misalignment;
}

/// @p base with the group(s) of @p kind on at the fitting prior (the configured one when larger).
filter::ExtraStates withFitPrior(ExtraCause kind, filter::ExtraStates x) {
  switch (kind) {
    case ExtraCause::ScaleFactor:
    case ExtraCause::Misalignment:
      for (const auto sigma : triadGroups(kind).sigma) x.*sigma = std::max(x.*sigma, triadGroups(kind).fit_sigma);
      break;
    case ExtraCause::TimeOffset:
      x.time_offset_sigma_s = std::max(x.time_offset_sigma_s, kFitTimeOffsetSigmaS);
      break;
    case ExtraCause::LeverArm:
      x.lever_arm_sigma_m = std::max(x.lever_arm_sigma_m, kFitLeverArmSigmaM);
      break;
  }
  return x;
}

/// Prior sigma of a group fitted from a replay's sigmas: max_i s_i, within (0, hi].
double fittedSigma(const Eigen::Vector3d& s, int n, const limits::Range& r) {
  double v = 0.0;
  for (int i = 0; i < n; ++i) v = std::max(v, s(i));
  return std::min(r.hi, std::max(r.lo, v));  // within the range filter_extended.yaml is read back with
}

/// An estimate clamped into the effect's range (the extension's initial value).
Eigen::Vector3d clampTo(const Eigen::Vector3d& e, const limits::Range& r) {
  return e.cwiseMax(r.lo).cwiseMin(r.hi);
}

/// @p x with the group(s) of @p kind on, initialised at a replay's estimates with its sigmas as prior.
filter::ExtraStates withFitted(ExtraCause kind, filter::ExtraStates x, const filter::SensorParams& e,
                               const filter::SensorParams& s) {
  switch (kind) {
    case ExtraCause::ScaleFactor:
    case ExtraCause::Misalignment: {
      const TriadGroups& t = triadGroups(kind);
      for (int i = 0; i < 2; ++i) {
        x.*t.sigma[i] = fittedSigma(s.*t.estimate[i], 3, t.sigma_range);
        x.*t.initial[i] = clampTo(e.*t.estimate[i], t.range);
      }
      break;
    }
    case ExtraCause::TimeOffset:
      x.time_offset_sigma_s = fittedSigma(Eigen::Vector3d(s.time_offset_s, 0, 0), 1, limits::kTimeOffsetSigmaS);
      x.time_offset0_s = std::min(limits::kTimeOffsetS.hi, std::max(limits::kTimeOffsetS.lo, e.time_offset_s));
      break;
    case ExtraCause::LeverArm:
      x.lever_arm_sigma_m = fittedSigma(s.lever_arm_error_B_m, 3, limits::kLeverArmErrorSigmaM);
      x.lever_arm_error0_m = clampTo(e.lever_arm_error_B_m, limits::kLeverArmErrorM);
      break;
  }
  return x;
}

/// Findings of a filter-state cause: each state's estimate and its 95 % interval (estimate +- 1.96 sigma).
std::vector<RunFinding> extraFindings(ExtraCause kind, const filter::SensorParams& e, const filter::SensorParams& s) {
  std::vector<RunFinding> v;
  auto add = [&](const std::string& cause, const std::string& channel, const std::string& name, double est, double sd,
                 const std::string& note) {
    RunFinding f;
    f.cause = cause;
    f.channel = channel;
    f.params = {{name, est}, {name + "_sigma", sd}};
    f.interval = {{name, {est - kZ95 * sd, est + kZ95 * sd}}};
    f.note = note;
    v.push_back(f);
  };
  const std::string how = "the filter's estimate of the state at the end of the whole run (GNSS throughout), 95 % "
                          "interval +- 1.96 sigma from its covariance";
  switch (kind) {
    case ExtraCause::ScaleFactor:
    case ExtraCause::Misalignment: {
      const TriadGroups& t = triadGroups(kind);
      for (int c = 0; c < 6; ++c)
        add(t.cause, kChannelNames[c], t.param, (e.*t.estimate[c / 3])(c % 3), (s.*t.estimate[c / 3])(c % 3),
            t.note + how);
      break;
    }
    case ExtraCause::TimeOffset:
      add("time_offset", "all", "time_offset", e.time_offset_s, s.time_offset_s,
          "IMU-GNSS time offset t_IMU - t_true [s]: " + how);
      break;
    case ExtraCause::LeverArm: {
      RunFinding f;
      f.cause = "lever_arm";
      f.channel = "gnss";
      const char* ax[3] = {"x", "y", "z"};
      for (int i = 0; i < 3; ++i) {
        const double est = e.lever_arm_error_B_m(i), sd = s.lever_arm_error_B_m(i);
        f.params.push_back({std::string("error_") + ax[i], est});
        f.params.push_back({std::string("error_") + ax[i] + "_sigma", sd});
        f.interval.push_back({std::string("error_") + ax[i], {est - kZ95 * sd, est + kZ95 * sd}});
      }
      f.note = "antenna lever-arm error told - true, body FRD [m]: " + how;
      v.push_back(f);
      break;
    }
  }
  return v;
}

/// What the extension of a filter-state cause changes, in words.
std::string extraExtension(ExtraCause kind) {
  switch (kind) {
    case ExtraCause::ScaleFactor:
      return "filter scale-factor states (gyro and accelerometer) initialised at the fitted estimates, their sigma as prior";
    case ExtraCause::Misalignment:
      return "filter misalignment states (gyro and accelerometer) initialised at the fitted estimates, their sigma as prior";
    case ExtraCause::TimeOffset:
      return "a filter IMU-GNSS time-offset state initialised at the fitted estimate, its sigma as prior";
    case ExtraCause::LeverArm:
      return "filter lever-arm error states initialised at the fitted estimates, their sigma as prior";
  }
  return "";
}

}  // namespace

PairedOutageScores replayOnMeasuredOutages(const ReplayConfig& extension, const ReplayResult& measured,
                                           const rawlog::RawlogRecords& data, double stop_after_s) {
  if (!measured.score) throw Error(measured.cfg.rawlog + ": the measured replay has no reference (GT) to score against");
  ReplayConfig c = extension;
  c.setOutages(measured.cfg.outages);  // every window of the measured replay, from time zero
  c.outages_every.reset();
  const ReplayResult r = runReplay(c, data, stop_after_s);
  if (!r.score) throw Error(c.rawlog + ": the extended replay has no reference (GT) to score against");
  PairedOutageScores p;
  p.aided_from_s = r.aided_from_s;
  for (const OutageScore& m : measured.score->outages) {
    std::optional<OutageScore> q;
    if (m.start_s > r.aided_from_s && m.start_s + m.duration_s <= stop_after_s)
      for (const OutageScore& o : r.score->outages)
        if (std::abs(o.start_s - m.start_s) <= 1e-9 && std::abs(o.duration_s - m.duration_s) <= 1e-9) q = o;
    p.ends.push_back(q ? endOf(r, q->start_s)
                       : std::pair{filter::Vector9d::Constant(NAN).eval(), filter::Vector9d::Constant(NAN).eval()});
    p.outages.push_back(std::move(q));
  }
  return p;
}

/// The causes: fitted per fold outside the held-out block, scored on the held-out outages.
template <class SimOutages, class Progress>
void diagnoseCauses(const RunDiagnosisOptions& opt, const rawlog::RawlogRecords& data, RunDiagnosis& out,
                    const std::vector<ReplayResult>& measured,
                    const SimOutages& simOut, const std::vector<RealisationOut>& sims,
                    const emulation::SmoothTrajectory& tr, double t0, double t1, const stochastic::ImuModel& model,
                    const Progress& progress) {
  if (opt.folds < 2) throw Error("diagnose --run: --folds must be >= 2");
  const std::size_t D = measured.size();
  // At most one fold per outage (leave one outage out): more would be empty time
  // blocks, and a fold count from the command line must not size memory.
  std::size_t outages = 0;
  for (const auto& so : simOut) outages += so.size();
  const int K = static_cast<int>(std::min<std::size_t>(static_cast<std::size_t>(opt.folds), std::max<std::size_t>(outages, 2)));
  if (K < opt.folds)
    out.notices.push_back("--folds " + std::to_string(opt.folds) + " is more than the run's " + std::to_string(outages) +
                          " outages: " + std::to_string(K) + " folds (time blocks), about one outage each");
  out.folds = K;
  const ReferenceInfo& ref = out.reference;
  const double rate = out.imu_rate_hz;
  const double L = (t1 - t0) / K;

  // Outages: (duration, index into simOut), their fold and window (absolute).
  struct Item {
    std::size_t i, j;
    int fold;
    double a, b;     // window
    double T;        // coasting time at the scored end [s]
    double pred_h2, pred_v2;  // simulated mean squares at this outage end
    // per realisation: its paired excess with the calibration random walk,
    // per unit density q [m^2 / (m^2/s^3)]
    std::vector<double> d_h, d_v;
  };
  std::vector<Item> items;
  for (std::size_t i = 0; i < D; ++i) {
    const auto& sc = *measured[i].score;
    const double tz = measured[i].t_zero;
    for (std::size_t j = 0; j < simOut[i].size(); ++j) {
      const auto& o = sc.outages[simOut[i][j].score_index];
      Item it{i, j, 0, o.start_s + tz, o.start_s + tz + o.duration_s, o.end_s - o.start_s, 0.0, 0.0, {}, {}};
      const double mid = 0.5 * (it.a + it.b);
      it.fold = std::min(K - 1, std::max(0, static_cast<int>(std::floor((mid - t0) / L))));
      double h2 = 0.0, v2 = 0.0;
      for (const auto& s : sims) {
        const auto& e = s.err[i][j];
        h2 += e(0) * e(0) + e(1) * e(1);
        v2 += e(2) * e(2);
      }
      it.pred_h2 = h2 / double(sims.size());
      it.pred_v2 = v2 / double(sims.size());
      const double q0 = kCalibrationRwDensity * kCalibrationRwDensity;
      for (const auto& s : sims) {
        const auto &e = s.err_rw[i][j], &e0 = s.err[i][j];
        it.d_h.push_back((e(0) * e(0) + e(1) * e(1) - e0(0) * e0(0) - e0(1) * e0(1)) / q0);
        it.d_v.push_back((e(2) * e(2) - e0(2) * e0(2)) / q0);
      }
      items.push_back(it);
    }
  }
  std::vector<Exclusion> excl(K);
  std::vector<int> heldCount(K, 0);
  for (int f = 0; f < K; ++f) {
    excl[f] = {t0 + f * L, t0 + (f + 1) * L};
    for (const auto& it : items)
      if (it.fold == f) {
        excl[f].a = std::min(excl[f].a, it.a);
        excl[f].b = std::max(excl[f].b, it.b);
        ++heldCount[f];
      }
  }

  // IMU residual against the trajectory (the real IMU of the run).
  ImuResidual res;
  {
    const double dt = 1.0 / rate;
    for (const auto& s : data.data.imu) {
      if (s.t - dt < tr.tBegin() || s.t > tr.tEnd()) continue;
      Eigen::Vector3d dv, dth;
      tr.increments(s.t - dt, s.t, dv, dth);
      const emulation::TruthState x = tr.at(s.t);
      const emulation::SensorEffects fx;  // the emulation's motion test, its default thresholds
      const bool mv = x.w_IB_B.norm() > fx.motion_rate_threshold_rad_s ||
                      std::abs(x.f_B.norm() - 9.80665) > fx.motion_acc_threshold_mps2;
      res.t.push_back(s.t);
      res.moving.push_back(mv ? 1 : 0);
      for (int a = 0; a < 3; ++a) {
        res.r[a].push_back(s.w_IB_B(a) - dth(a) / dt);
        res.r[3 + a].push_back(s.f_B(a) - dv(a) / dt);
      }
    }
  }
  const std::array<double, 6> wnModel = emulation::whiteNoiseSigma(model, rate);
  const auto& innov = measured.front().run.gnss_innovations;

  // The fits; each returns the extended replay configuration and, for the whole run, findings.
  // @p base is the configuration extended (today's, or another cause's extension).
  using Fit = std::function<ReplayConfig(const ReplayConfig& base, const Exclusion&, std::vector<RunFinding>*, CauseResult*)>;
  auto baseModel = [&](const ReplayConfig& base) { return base.model ? *base.model : model; };
  auto fitMotion = [&](const ReplayConfig& base, const Exclusion& ex, std::vector<RunFinding>* fnd, CauseResult* cr) {
    stochastic::ImuModel m = baseModel(base);
    for (int c = 0; c < 6; ++c) {
      const auto b = wnBatches(res, c, true, ex);
      if (b.empty()) continue;
      double mean, lo, hi;
      batchInterval(b, mean, lo, hi);
      const double sig = std::sqrt(mean);
      const double k = wnModel[c] > 0 ? sig / wnModel[c] : NAN;
      inflateWhite(m, c, std::isfinite(k) ? k : 1.0, sig, rate);
      if (fnd) {
        RunFinding f;
        f.cause = "in_motion_noise";
        f.channel = kChannelNames[c];
        f.params = {{"factor", k}, {"white_sigma_in_motion", sig}};
        f.interval = {{"factor", {std::sqrt(lo) / wnModel[c], std::sqrt(hi) / wnModel[c]}},
                      {"white_sigma_in_motion", {std::sqrt(lo), std::sqrt(hi)}}};
        const auto bs = wnBatches(res, c, false, ex);
        if (!bs.empty()) {
          double ms, l2, h2;
          batchInterval(bs, ms, l2, h2);
          f.params.push_back({"factor_at_rest", std::sqrt(ms) / wnModel[c]});
          f.interval.push_back({"factor_at_rest", {std::sqrt(l2) / wnModel[c], std::sqrt(h2) / wnModel[c]}});
        }
        f.note = "second differences of the IMU residual while moving, 20 batch means, 99 % Student-t interval";
        fnd->push_back(f);
      }
    }
    m.source += " with in-motion white noise";
    return withModel(base, m, cr, "each channel's white noise multiplied by its in-motion factor");
  };
  auto fitGnss = [&](const ReplayConfig& base, const Exclusion& ex, std::vector<RunFinding>* fnd, CauseResult* cr) {
    // per axis group (horizontal N, E pooled; vertical): innovations outside the block
    std::array<std::vector<double>, 2> dz2, hph, rr;
    std::array<double, 3> nis{0, 0, 0}, lag{0, 0, 0};
    std::array<std::size_t, 3> nn{0, 0, 0}, nl{0, 0, 0};
    std::vector<double> rh, rv;
    std::array<double, 3> prevZ{NAN, NAN, NAN};
    for (const auto& g : innov) {
      if (!g.accepted || ex.covers(g.t)) {
        prevZ = {NAN, NAN, NAN};
        continue;
      }
      for (int a = 0; a < 3; ++a) {
        const int grp = a < 2 ? 0 : 1;
        dz2[grp].push_back(g.dz(a) * g.dz(a));
        hph[grp].push_back(std::max(0.0, g.S_diag(a) - g.R_diag(a)));
        rr[grp].push_back(g.R_diag(a));
        const double z = g.dz(a) / std::sqrt(g.S_diag(a));
        nis[a] += z * z;
        ++nn[a];
        if (std::isfinite(prevZ[a])) {
          lag[a] += z * prevZ[a];
          ++nl[a];
        }
        prevZ[a] = z;
      }
      rh.push_back(std::sqrt(0.5 * (g.R_diag(0) + g.R_diag(1))));
      rv.push_back(std::sqrt(g.R_diag(2)));
    }
    if (dz2[0].size() < 6 || dz2[1].size() < 3)
      throw Error("diagnose --run: too few GNSS innovations outside the held-out block");
    // s solves mean(dz^2 / (HPH' + s^2 R)) = target (decreasing in s), by bisection on log s in [0.01, 1000]
    auto solve = [&](int grp, double target) {
      auto F = [&](double sc) {
        double m = 0.0;
        for (std::size_t k = 0; k < dz2[grp].size(); ++k) m += dz2[grp][k] / (hph[grp][k] + sc * sc * rr[grp][k]);
        return m / double(dz2[grp].size());
      };
      double lo = std::log(0.01), hi = std::log(1000.0);
      if (F(std::exp(lo)) <= target) return std::exp(lo);
      if (F(std::exp(hi)) >= target) return std::exp(hi);
      for (int it = 0; it < 60; ++it) {
        const double mid = 0.5 * (lo + hi);
        (F(std::exp(mid)) > target ? lo : hi) = mid;
      }
      return std::exp(0.5 * (lo + hi));
    };
    double scale[2], slo[2], shi[2];
    for (int grp = 0; grp < 2; ++grp) {
      const double N = double(dz2[grp].size());
      boost::math::chi_squared chi(N);
      scale[grp] = solve(grp, 1.0);
      slo[grp] = solve(grp, boost::math::quantile(chi, 0.995) / N);
      shi[grp] = solve(grp, boost::math::quantile(chi, 0.005) / N);
    }
    ReplayConfig c = base;
    c.sigma_pos_h_m = scale[0] * percentile(rh, 0.5);
    c.sigma_pos_v_m = scale[1] * percentile(rv, 0.5);
    if (fnd) {
      RunFinding f;
      f.cause = "gnss_noise";
      f.channel = "gnss";
      f.params = {{"sigma_scale_h", scale[0]}, {"sigma_scale_v", scale[1]},
                  {"sigma_pos_h_m", *c.sigma_pos_h_m}, {"sigma_pos_v_m", *c.sigma_pos_v_m}};
      f.interval = {{"sigma_scale_h", {slo[0], shi[0]}}, {"sigma_scale_v", {slo[1], shi[1]}}};
      const char* ax[3] = {"n", "e", "d"};
      for (int a = 0; a < 3; ++a) {
        const double N = double(nn[a]);
        boost::math::chi_squared chi(N);
        f.params.push_back({std::string("mean_nis_") + ax[a], nis[a] / N});
        f.interval.push_back({std::string("mean_nis_") + ax[a],
                              {boost::math::quantile(chi, 0.005) / N, boost::math::quantile(chi, 0.995) / N}});
        const double rho = nl[a] ? (lag[a] / double(nl[a])) / (nis[a] / N) : NAN;
        f.params.push_back({std::string("lag1_correlation_") + ax[a], rho});
        const double zb = 2.576 / std::sqrt(std::max<double>(1.0, double(nl[a])));
        f.interval.push_back({std::string("lag1_correlation_") + ax[a], {-zb, zb}});
      }
      f.note = "GNSS position innovations of the aided phases: the scale s of the fix sigmas that makes the mean NIS 1 "
               "(horizontal, vertical; 99 % interval from chi-square on the count, innovations treated as independent); "
               "mean NIS and lag-1 correlation intervals are the 99 % bands of a consistent filter with white GNSS errors";
      fnd->push_back(f);
    }
    if (cr) {
      cr->model_after = model;
      cr->gnss_sigma_h_m = c.sigma_pos_h_m;
      cr->gnss_sigma_v_m = c.sigma_pos_v_m;
      cr->extension = "the filter's GNSS position sigmas set to the fitted scale times the median fix sigma";
    }
    return c;
  };
  auto fitBias = [&](const ReplayConfig& base, const Exclusion& ex, std::vector<RunFinding>* fnd, CauseResult* cr) {
    std::vector<const Item*> tr_items;
    for (const auto& it : items)
      if (!ex.overlaps(it.a, it.b)) tr_items.push_back(&it);
    if (tr_items.empty()) throw Error("diagnose --run: no training outage outside the held-out block");
    // What density 1 adds at an outage end through this filter: the mean
    // paired excess over the realisations @p rs (nullptr: all), >= 0. The
    // bias the filter lacks has wandered since it last estimated it, so this
    // is far above q T^5/20 per axis of a bias known at the outage start.
    auto perUnit = [](const std::vector<double>& d, const std::vector<std::size_t>* rs) {
      const double n = static_cast<double>(rs ? rs->size() : d.size());
      double x = 0.0;
      if (rs) {
        for (std::size_t r : *rs) x += d[r] / n;
      } else {
        for (double v : d) x += v / n;
      }
      return std::max(0.0, x);
    };
    auto lsq = [&](const std::vector<const Item*>& v, double& qh, double& qv, const std::vector<std::size_t>* rs) {
      double nh = 0, dh = 0, nv = 0, dv = 0;
      for (const Item* it : v) {
        const auto& o = measured[it->i].score->outages[simOut[it->i][it->j].score_index];
        const double eh2 = o.err_N(0) * o.err_N(0) + o.err_N(1) * o.err_N(1), ev2 = o.err_N(2) * o.err_N(2);
        const double xh = perUnit(it->d_h, rs), xv = perUnit(it->d_v, rs);
        nh += (eh2 - it->pred_h2 - 2 * ref.sigma_h_m * ref.sigma_h_m) * xh;
        dh += xh * xh;
        nv += (ev2 - it->pred_v2 - ref.sigma_v_m * ref.sigma_v_m) * xv;
        dv += xv * xv;
      }
      qh = dh > 0 ? std::max(0.0, nh / dh) : 0.0;
      qv = dv > 0 ? std::max(0.0, nv / dv) : 0.0;
    };
    double qh, qv;
    lsq(tr_items, qh, qv, nullptr);
    stochastic::ImuModel m = baseModel(base);
    addRandomWalk(m, 3, qh);
    addRandomWalk(m, 4, qh);
    addRandomWalk(m, 5, qv);
    m.source += " with an accelerometer bias random walk";
    if (fnd) {
      // seeded bootstrap over the outages and over the realisations that
      // calibrate them (their Monte Carlo error is part of the interval)
      std::mt19937_64 rng(stochastic::deriveSeed(opt.seed, 9001));
      const std::size_t nr = sims.size();
      std::vector<double> bh, bv;
      for (int b = 0; b < 999; ++b) {
        std::vector<const Item*> v;
        for (std::size_t k = 0; k < tr_items.size(); ++k) v.push_back(tr_items[rng() % tr_items.size()]);
        std::vector<std::size_t> rs;
        for (std::size_t k = 0; k < nr; ++k) rs.push_back(rng() % nr);
        double a1, a2;
        lsq(v, a1, a2, &rs);
        bh.push_back(a1);
        bv.push_back(a2);
      }
      // The outages of one run share its bias path (consecutive outage ends are
      // far from independent: the filter's bias error wanders slowly), which
      // the bootstrap over outages cannot see. Each calibrating realisation r,
      // its random walk scaled to density sqrt(q) (errors are linear in the
      // walk: e = e0 + sqrt(q / q0) (e_rw - e0)), is a run whose truth is q;
      // the estimator applied to it (r left out of the calibration) shows its
      // spread at q. q is kept where the estimate lies inside the 99 % range
      // of a gamma law with that mean and variance (test inversion on a grid);
      // the interval is the union with the bootstrap's.
      const double q0 = kCalibrationRwDensity * kCalibrationRwDensity;
      auto pseudoEstimate = [&](std::size_t r, double q, bool vertical, bool clamp = true) {
        const double sc = std::sqrt(q / q0), R = static_cast<double>(nr);
        double num = 0.0, den = 0.0;
        for (const Item* it : tr_items) {
          const auto &e0 = sims[r].err[it->i][it->j], &e1 = sims[r].err_rw[it->i][it->j];
          const Eigen::Vector3d e = e0.head(3) + sc * (e1.head(3) - e0.head(3));  // position error N, E, D [m]
          const double e2 = vertical ? e(2) * e(2) : e(0) * e(0) + e(1) * e(1);
          const double e02 = vertical ? e0(2) * e0(2) : e0(0) * e0(0) + e0(1) * e0(1);
          const auto& d = vertical ? it->d_v : it->d_h;
          const double pred = ((vertical ? it->pred_v2 : it->pred_h2) * R - e02) / (R - 1.0);
          const double x = std::max(0.0, (perUnit(d, nullptr) * R - d[r]) / (R - 1.0));
          num += (e2 - pred) * x;
          den += x * x;
        }
        const double est = den > 0 ? num / den : 0.0;
        return clamp ? std::max(0.0, est) : est;
      };
      // An estimate clamped at 0 lies within the estimator's noise floor s0 (its
      // sd over the realisations at q = 0, unclamped): q is kept where the gamma
      // law of its simulated runs reaches down to s0 with probability >= 0.5 %.
      // Mean and sample variance of the estimates over the realisations at q.
      auto moments = [&](double q, bool vertical, bool clamp) {
        double m = 0.0, m2 = 0.0;
        for (std::size_t r = 0; r < nr; ++r) {
          const double v = pseudoEstimate(r, q, vertical, clamp);
          m += v;
          m2 += v * v;
        }
        m /= double(nr);
        return std::pair{m, std::max(0.0, (m2 - double(nr) * m * m) / double(nr - 1))};
      };
      auto noiseFloor = [&](bool vertical) { return std::sqrt(moments(0.0, vertical, false).second); };
      auto parametric = [&](double obs, double boot_hi, bool vertical) -> std::optional<std::pair<double, double>> {
        if (nr < 3) return std::nullopt;
        const bool zero = !(obs > 0.0);
        const double s0 = zero ? noiseFloor(vertical) : 0.0;
        if (zero && !(s0 > 0.0)) return std::nullopt;
        const double top = zero ? std::max(boot_hi, s0) : std::max(obs, boot_hi);
        std::optional<std::pair<double, double>> kept;
        for (int g = -1; g <= 270; ++g) {
          const double q = g < 0 ? 0.0 : top * std::pow(10.0, -6.0 + g / 30.0);  // 0, then 1e-6 .. 1e3 x top
          const auto [m, var] = moments(q, vertical, true);
          if (!(m > 0.0) || !(var > 0.0)) continue;
          const boost::math::gamma_distribution<double> law(m * m / var, var / m);
          if (zero ? boost::math::cdf(law, s0) < 0.005
                   : obs < boost::math::quantile(law, 0.005) || obs > boost::math::quantile(law, 0.995))
            continue;
          if (!kept) kept = std::pair{zero ? 0.0 : q, q};
          kept->first = std::min(kept->first, q);
          kept->second = std::max(kept->second, q);
        }
        return kept;
      };
      for (int c = 3; c < 6; ++c) {
        const double q = c < 5 ? qh : qv;
        const auto& bb = c < 5 ? bh : bv;
        double lo = percentile(bb, 0.005), hi = percentile(bb, 0.995);
        const auto par = parametric(q, hi, c == 5);
        if (par) {
          lo = std::min(lo, par->first);
          hi = std::max(hi, par->second);
        }
        RunFinding f;
        f.cause = "bias_instability";
        f.channel = kChannelNames[c];
        f.params = {{"rw_density", std::sqrt(q)}};
        f.interval = {{"rw_density", {std::sqrt(lo), std::sqrt(hi)}}};
        f.note = std::string("accelerometer bias random walk density [m/s^2/sqrt(s)] from the ") +
                 (c < 5 ? "horizontal" : "vertical") + " outage-end errors' excess over the simulation, against what a random walk "
                 "of known density adds to the same simulated runs (least squares over the outages); "
                 "99 % interval: a seeded bootstrap over " + std::to_string(tr_items.size()) + " outages and the " +
                 std::to_string(nr) + " calibrating realisations, joined with the densities whose simulated runs "
                 "(the realisations with their random walk scaled) give this estimate inside their 99 % range, "
                 "as the outages of one run share its bias path";
        fnd->push_back(f);
      }
    }
    return withModel(base, m, cr,
                     "an accelerometer bias random walk added (horizontal channels from the horizontal errors, acc_z "
                     "from the vertical)");
  };
  // Causes a filter state carries (scale factor, misalignment, lever arm, time
  // offset): fitted by replaying the run with that state on, GNSS dropped in
  // the held-out block (no other outage); the state's estimate at the end of
  // the run, its 95 % interval from the filter's covariance. The extension is
  // the filter with that state on, initialised at the fitted estimate (clamped
  // to the documented range) with the largest fitted sigma of the group as prior.
  const double tz = measured.front().t_zero;
  auto fitExtra = [&](ExtraCause kind) -> Fit {
    return [&, kind](const ReplayConfig& base, const Exclusion& ex, std::vector<RunFinding>* fnd, CauseResult* cr) {
      ReplayConfig c = base;
      c.setOutages({});
      c.outages_every.reset();
      if (ex.b >= ex.a) {
        const double a = std::max(0.0, ex.a - tz), b = std::min(ex.b - tz, out.run_end_s);
        if (b > a) c.outages.push_back(Outage{a, b});
      }
      c.extra_states = withFitPrior(kind, base.extra_states);
      const ReplayResult r = runReplay(c, data);
      const filter::SensorParams& e = r.run.extra_estimates;
      const filter::SensorParams& sg = r.run.extra_sigmas;
      ReplayConfig x = base;
      x.extra_states = withFitted(kind, base.extra_states, e, sg);
      if (fnd) *fnd = extraFindings(kind, e, sg);
      if (cr) {
        cr->model_after = model;
        cr->extra_states = x.extra_states;
        cr->extension = extraExtension(kind);
      }
      return x;
    };
  };
  const std::vector<std::pair<std::string, Fit>> cands = {
      {"in_motion_noise", fitMotion},
      {"gnss_noise", fitGnss},
      {"bias_instability", fitBias},
      {"scale_factor", fitExtra(ExtraCause::ScaleFactor)},
      {"misalignment", fitExtra(ExtraCause::Misalignment)},
      {"time_offset", fitExtra(ExtraCause::TimeOffset)},
      {"lever_arm", fitExtra(ExtraCause::LeverArm)}};
  const int C = static_cast<int>(cands.size());

  // Held-out scores: task (cause, fold) replays every duration with the fold's
  // extension; task (cause, K) fits the cause on the whole run (its findings).
  // The extended replay runs on the measured run's outage windows
  // (replayOnMeasuredOutages), so its outages are today's by construction and
  // are paired with them by window, also when the extension's filter starts
  // elsewhere (an aligning phase that ends later with larger GNSS sigmas). A
  // held-out replay of fold f stops 1 s after the end of its last held-out
  // outage (the filter is causal: those outages score as in a full replay).
  using Ends = std::vector<std::pair<filter::Vector9d, filter::Vector9d>>;
  struct Scored {
    std::vector<std::vector<OutageScore>> per;  // [duration][today's outage index] (held-out ones filled)
    std::vector<Ends> ends;                     // [duration][today's outage index] end errors and sigmas
  };
  std::vector<double> stopAfter(K, -1e300);  // [fold] from time zero [s]
  for (const auto& it : items)
    stopAfter[it.fold] = std::max(stopAfter[it.fold], it.b - measured[it.i].t_zero + 1.0);
  auto replayScored = [&](const ReplayConfig& cfg, int f, const std::string& cause) {
    Scored sc;
    for (std::size_t i = 0; i < D; ++i) {
      PairedOutageScores r = replayOnMeasuredOutages(cfg, measured[i], data, stopAfter[f]);
      std::vector<OutageScore> per;
      for (std::size_t k = 0; k < r.outages.size(); ++k) per.push_back(r.outages[k].value_or(OutageScore{}));
      for (const auto& it : items) {
        if (it.fold != f || it.i != i) continue;
        const OutageScore& o = measured[i].score->outages[simOut[i][it.j].score_index];
        if (!r.outages[simOut[i][it.j].score_index])
          throw Error("diagnose --run: the " + cause + " extension's filter starts at " + formatNumber(r.aided_from_s, 6) +
                      " s (the measured run's at " + formatNumber(measured[i].aided_from_s, 6) +
                      " s), at or after the start of the held-out outage at " + formatNumber(o.start_s, 6) +
                      " s: it cannot score that outage (give a longer --reconverge)");
      }
      sc.per.push_back(std::move(per));
      sc.ends.push_back(std::move(r.ends));
    }
    return sc;
  };
  Scored today;
  for (std::size_t i = 0; i < D; ++i) {
    today.per.push_back(measured[i].score->outages);
    today.ends.push_back(scoredEnds(measured[i]));
  }
  std::vector<Scored> after(C * K);
  std::vector<ReplayConfig> foldCfg(C * K);
  std::vector<CauseResult> whole(C);
  const unsigned threads = static_cast<unsigned>(std::max(opt.threads, 0));
  parallelFor(std::size_t(C * (K + 1)), threads, [&](std::size_t i) {
    const int t = static_cast<int>(i), c = t / (K + 1), f = t % (K + 1);
    if (f == K) {
      whole[c].cause = cands[c].first;
      cands[c].second(opt.replay, Exclusion{}, &whole[c].findings, &whole[c]);
      return;
    }
    const int task = c * K + f;
    if (heldCount[f] == 0) return;
    foldCfg[task] = cands[c].second(opt.replay, excl[f], nullptr, nullptr);
    after[task] = replayScored(foldCfg[task], f, cands[c].first);
  }, [&](std::size_t done, std::size_t count) { progress(0.80 + 0.17 * double(done) / double(count), "causes"); });

  // Paired held-out comparison: every outage scored by @p before and @p after of its fold.
  struct Paired {
    double eb = 0, ea = 0, vb = 0, va = 0, nb = 0, na = 0, gain = 0, p = 1, error_p = 1;
  };
  auto paired = [&](const std::function<const Scored&(int)>& before, const std::function<const Scored&(int)>& aft,
                    std::uint64_t seed_tag) {
    std::vector<double> g, ge;
    Paired r;
    for (const auto& it : items) {
      const std::size_t si = simOut[it.i][it.j].score_index;
      const Scored& B = before(it.fold);
      const Scored& A = aft(it.fold);
      const auto& ob = B.per[it.i][si];
      const auto& oa = A.per[it.i][si];
      g.push_back(outageNll(ob, ref) + navNll(B.ends[it.i][si], ref) - outageNll(oa, ref) - navNll(A.ends[it.i][si], ref));
      ge.push_back(ob.err_N.norm() - oa.err_N.norm());
      r.eb += ob.horizontal_error_m * ob.horizontal_error_m;
      r.ea += oa.horizontal_error_m * oa.horizontal_error_m;
      r.vb += ob.vertical_error_m * ob.vertical_error_m;
      r.va += oa.vertical_error_m * oa.vertical_error_m;
      r.nb += ob.nees;
      r.na += oa.nees;
    }
    const double n = double(items.size());
    for (double x : g) r.gain += x;
    r.gain /= n;
    r.eb = std::sqrt(r.eb / n);
    r.ea = std::sqrt(r.ea / n);
    r.vb = std::sqrt(r.vb / n);
    r.va = std::sqrt(r.va / n);
    r.nb /= n;
    r.na /= n;
    r.p = signFlipP(g, stochastic::deriveSeed(opt.seed, seed_tag));
    r.error_p = signFlipP(ge, stochastic::deriveSeed(opt.seed, seed_tag + 100));
    return r;
  };

  std::vector<int> order;
  for (int c = 0; c < C; ++c) {
    CauseResult& cr = whole[c];
    const Paired pr = paired([&](int) -> const Scored& { return today; },
                             [&](int f) -> const Scored& { return after[c * K + f]; }, 7000 + c);
    cr.heldout_outages = items.size();
    cr.error_before_m = pr.eb;
    cr.error_after_m = pr.ea;
    cr.vertical_before_m = pr.vb;
    cr.vertical_after_m = pr.va;
    cr.anees_before = pr.nb;
    cr.anees_after = pr.na;
    cr.gain = pr.gain;
    cr.p_value = pr.p;
    cr.error_p_value = pr.error_p;
    cr.significant = cr.gain > 0 && cr.p_value < opt.alpha / C;
    order.push_back(c);
  }
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return whole[a].gain > whole[b].gain; });

  // The top-ranked cause (largest held-out gain) is named when it is
  // significant. Every other significant cause is added to the top cause's
  // extension (fitted per fold on top of it) and scored against that extension
  // on the same held-out outages; it is named only if that gain is significant
  // at the same level too: a cause that shares part of the top one's signature
  // (a misalignment absorbing part of a scale factor, a lever arm part of a
  // misalignment) is not named beside or instead of it.
  //
  // The top cause itself is compared with the runner-up (the next by gain,
  // when that gains at all) both ways: each added to the other's extension.
  // It is named when it gains on top of the runner-up (one comparison, at
  // alpha), or when the runner-up adds nothing at all on top of it (gain
  // <= 0) while it still adds something on top of the runner-up (gain > 0,
  // not significant: the evidence leans its way); otherwise the held-out
  // outages do not tell the two apart (a 1.2 mrad accelerometer misalignment
  // and a bias random walk each adding nothing on top of the other):
  // undecided, neither is named.
  const int top = order.front();
  const int runner = C > 1 && whole[top].significant && whole[order[1]].gain > 0 ? order[1] : -1;
  {
    std::vector<std::pair<int, int>> pairs;  // (cause added, cause it is added to)
    for (int c : order)
      if (c != top && (whole[c].significant || c == runner)) pairs.push_back({c, top});
    if (runner >= 0) pairs.push_back({top, runner});
    const int O = static_cast<int>(pairs.size());
    std::vector<Scored> both(O * K);
    parallelFor(std::size_t(O * K), threads, [&](std::size_t t) {
      const auto [c, given] = pairs[t / K];
      const int f = static_cast<int>(t % K);
      if (heldCount[f] == 0) return;
      both[t] = replayScored(cands[c].second(foldCfg[given * K + f], excl[f], nullptr, nullptr), f,
                             cands[c].first + " on top of " + cands[given].first);
    }, [&](std::size_t done, std::size_t count) { progress(0.97 + 0.02 * double(done) / double(count), "causes"); });
    for (int k = 0; k < O; ++k) {
      const auto [c, given] = pairs[static_cast<std::size_t>(k)];
      const Paired pr = paired([&, given = given](int f) -> const Scored& { return after[given * K + f]; },
                               [&](int f) -> const Scored& { return both[k * K + f]; }, 7200 + c);
      CauseResult& cr = whole[c];
      cr.given = whole[given].cause;
      cr.gain_given = pr.gain;
      cr.p_given = pr.p;
      // Beside the top cause, a discovery among C causes (alpha / C); the
      // top cause over the runner-up, one comparison of two explanations
      // that the top one already won on its own (alpha).
      cr.adds = pr.gain > 0 && pr.p < (c == top ? opt.alpha : opt.alpha / C);
    }
    if (runner >= 0 && !whole[top].adds) {
      const CauseResult &a = whole[top], &b = whole[runner];
      whole[top].adds = b.gain_given <= 0 && a.gain_given > 0;
    }
  }
  for (int c : order) out.causes.push_back(std::move(whole[c]));
  for (std::size_t k = 0; k < out.causes.size(); ++k)
    if (out.causes[k].significant && (out.causes[k].given.empty() || out.causes[k].adds)) {
      if (out.best < 0) out.best = static_cast<int>(k);
      for (const auto& f : out.causes[k].findings) out.findings.push_back(f);
    }
}

/// Most outage durations of one run diagnosis (each is a replay of the run per realisation).
constexpr std::size_t kMaxRunDurations = 16;

/// Memory of diagnose --run per IMU sample of the run: the run read and its
/// measured replays, and per worker a realisation's errors, emulation and
/// filter runs (peak resident size measured at 200 and 2000 Hz with 1 and 2
/// workers: 89 MB + n x (115 + 180 x workers) bytes).
constexpr double kRunBytesPerSample = 120.0, kRunBytesPerSampleAndWorker = 180.0;

RunDiagnosis diagnoseRun(const RunDiagnosisOptions& opt_in) {
  const auto wall0 = std::chrono::steady_clock::now();
  RunDiagnosisOptions opt = opt_in;  // its threads set by the memory budget below
  if (opt.durations_s.empty()) throw Error("diagnose --run: give at least one outage duration (--durations)");
  // a handful of durations, each once, each a duration (limits::kDurationS); 2000 durations held 1.3 GB and ran on
  if (opt.durations_s.size() > kMaxRunDurations)
    throw Error("diagnose --run: --durations: at most " + std::to_string(kMaxRunDurations) + " outage durations, got " +
                std::to_string(opt.durations_s.size()));
  for (std::size_t i = 0; i < opt.durations_s.size(); ++i) {
    const double d = opt.durations_s[i];
    if (!(d >= limits::kDurationS.lo && d <= limits::kDurationS.hi))
      throw Error("diagnose --run: --durations: " + formatNumber(d) + " s is outside " + limits::describe(limits::kDurationS));
    for (std::size_t j = 0; j < i; ++j)
      if (opt.durations_s[j] == d) throw Error("diagnose --run: --durations: " + formatNumber(d) + " s is listed twice");
  }
  if (!(opt.reconverge_s >= limits::kDurationS.lo && opt.reconverge_s <= limits::kDurationS.hi))
    throw Error("diagnose --run: --reconverge must be in " + limits::describe(limits::kDurationS) + ", got " +
                formatNumber(opt.reconverge_s));
  if (opt.realisations < 2 || opt.realisations > limits::kMaxMonteCarloRuns)
    throw Error("diagnose --run: --realisations must be in [2, " + std::to_string(limits::kMaxMonteCarloRuns) +
                "], got " + std::to_string(opt.realisations));
  if (!(opt.alpha > 0.0 && opt.alpha < 0.5)) throw Error("diagnose --run: --alpha must be in (0, 0.5)");
  if (opt.replay.model_spec.empty())
    throw Error("diagnose --run: give the IMU model with --model FILE[:NAME] (the model whose simulation is judged)");
  auto progress = [&](double f, const std::string& stage) {
    if (opt.progress) opt.progress(std::min(1.0, std::max(0.0, f)), stage);
  };
  const std::size_t D = opt.durations_s.size();
  // Progress: the measured replays count as 10 %, the trajectory 5 %, the simulation 85 %.

  // The run, read and decoded once: every replay below runs from these records.
  if (opt.replay.rawlog.empty()) throw Error("replay: no rawlog given (--rawlog or 'rawlog:' in the configuration)");
  const rawlog::RawlogRecords data =
      rawlog::readRawlogRecords(opt.replay.rawlog, {opt.replay.imu_label, opt.replay.gnss_label});
  {
    // Memory, estimated before the replays (README "Ranges and budgets"); all
    // cores (--threads 0) means as many workers as the budget holds, at least one.
    const double n = double(data.data.imu.size());
    const double budget = limits::kDefaultMemoryBudgetBytes;
    unsigned workers = workerThreads(static_cast<unsigned>(std::max(opt.threads, 0)), std::size_t(opt.realisations));
    if (opt.threads == 0)
      workers = limits::budgetWorkers(double(workers), n, kRunBytesPerSample, kRunBytesPerSampleAndWorker);
    opt.threads = static_cast<int>(workers);
    const double bytes = n * (kRunBytesPerSample + kRunBytesPerSampleAndWorker * workers);
    limits::checkBudget({{opt.replay.rawlog, "diagnose --run", bytes / 1e6, budget / 1e6, "MB",
                          formatNumber(n, 3) + " samples x (" + formatNumber(kRunBytesPerSample) + " + " +
                              formatNumber(kRunBytesPerSampleAndWorker) + " x " + std::to_string(workers) +
                              " workers) bytes",
                          "lower --threads or diagnose an excerpt of the run"}},
                        opt.allow_large);
  }

  RunDiagnosis out;
  out.rawlog = opt.replay.rawlog;
  out.realisations = opt.realisations;
  out.seed = opt.seed;
  out.alpha = opt.alpha;
  out.reconverge_s = opt.reconverge_s;

  // 1. Measured: one scored replay per duration.
  std::vector<ReplayResult> measured;
  for (std::size_t i = 0; i < D; ++i) {
    ReplayConfig c = opt.replay;
    c.setOutages({});
    c.outages_every = OutagePattern{opt.durations_s[i] + opt.reconverge_s, opt.durations_s[i]};
    progress(0.10 * double(i) / double(D), "replay");
    measured.push_back(runReplay(c, data));
    const ReplayResult& r = measured.back();
    if (!r.score)
      throw Error(opt.replay.rawlog + ": the rawlog has no reference (GT): a run diagnosis compares outage errors "
                                      "with a reference (import one, e.g. an RTK track)");
    if (r.score->outages.empty())
      throw Error(opt.replay.rawlog + ": no outage of " + formatNumber(opt.durations_s[i]) + " s after " +
                  formatNumber(opt.reconverge_s) + " s of GNSS fits in the run after the filter start (" +
                  formatNumber(r.aided_from_s) + " s)");
  }
  const ReplayResult& r0 = measured.front();
  out.model_source = r0.model_source;
  out.imu_rate_hz = r0.imu_rate_hz;
  out.aided_from_s = r0.aided_from_s;
  out.reference = r0.score->reference;
  out.notices = r0.notices;
  {
    const auto& ep = r0.run.epochs;
    out.run_end_s = ep.empty() ? 0.0 : ep.back().t - r0.t_zero;
  }
  const stochastic::ImuModel model = stochastic::loadImuModel(opt.replay.model_spec);

  // 2. The trajectory and the emulation span: the run plan (run_plan.hpp) along the
  // run's own trajectory from the start of GNSS aiding, with the filter's initial
  // sigmas. It holds no outages and no record epochs: the outages differ per
  // duration and are the measured ones (below), and the GNSS and barometer of
  // each realisation are the run's own (section 3), with the filter options of
  // the measured replay.
  progress(0.10, "trajectory");
  RunPlanOptions po;
  po.smoothed =
      std::make_shared<const emulation::SmoothTrajectory>(buildTrajectory(r0, opt, data, out.trajectory_source));
  po.start_s = r0.t_zero + r0.aided_from_s;
  po.imu_rate_hz = r0.imu_rate_hz;
  po.record_rate_hz = 0.0;
  po.outage_record_rate_hz = 0.0;
  po.initial_sigma = r0.nav.P0_nav.diagonal().cwiseSqrt();
  if (imuSamples(runStart(*po.smoothed, po.start_s), po.smoothed->tEnd(), po.imu_rate_hz) < 16)
    throw Error(opt.replay.rawlog + ": the emulated span is too short");
  const RunPlan plan = planRuns(po);
  const emulation::SmoothTrajectory& tr = *plan.traj;
  const double rate = plan.rate_hz, t0 = plan.t0, t1 = plan.t1;
  const std::size_t n = plan.samples();

  // Outages of each duration in the emulation: the measured ones inside the span,
  // ends at the measured end epochs snapped to the IMU grid.
  struct SimOutage {
    std::size_t score_index;  // into measured[i].score->outages
    double t_end;             // absolute, on the IMU grid
  };
  std::vector<std::vector<SimOutage>> simOut(D);
  std::vector<NavRunOptions> navs(D);
  std::vector<TruthSeries> truths(D);
  for (std::size_t i = 0; i < D; ++i) {
    const auto& sc = *measured[i].score;
    const double tz = measured[i].t_zero;
    NavRunOptions nav = measured[i].nav;
    nav.outages.clear();
    nav.reference_lever_B = Eigen::Vector3d::Zero();  // the emulation's truth is the IMU point
    for (std::size_t q = 0; q < sc.outages.size(); ++q) {
      const auto& o = sc.outages[q];
      const double a = o.start_s + tz, b = a + o.duration_s;
      if (a < t0 + 1.0 || b > t1) continue;
      const double ke = std::floor((o.end_s + tz - t0) * rate + 0.5);
      const double te = t0 + ke / rate;
      if (!(te > a) || te > t1) continue;
      nav.outages.push_back({a, b});
      simOut[i].push_back({q, te});
      truths[i].t.push_back(te);
      truths[i].x.push_back(emulation::truthNavState(tr, te));
    }
    if (simOut[i].empty())
      throw Error(opt.replay.rawlog + ": no outage of " + formatNumber(opt.durations_s[i]) +
                  " s falls inside the emulated span");
    navs[i] = nav;
  }

  // Static recording (optional), loaded once.
  std::optional<ImuSeries> rec;
  if (!opt.static_file.empty()) {
    rec = readImuCsv(opt.static_file, opt.static_csv);
    out.errors_source = "windows of the static recording " + opt.static_file + " (start drawn per realisation)";
  } else {
    out.errors_source = "simulated from the model " + r0.model_source;
  }

  // Antenna, GNSS and barometer of the emulation: the run's own fix times and covariances.
  const Eigen::Vector3d lever = r0.nav.lever_arm_B;
  const std::vector<GnssFix>& realGnss = r0.gnss;
  const std::vector<BaroSample>& realBaro = r0.baro;

  // 3. Simulated realisations. Their work and memory, estimated before they start
  // (README "Ranges and budgets"): per realisation its emulation and a filter run
  // per duration (two with the causes: the calibration random walk), and per
  // outage end 9 + 1 numbers (19 with the causes).
  const int R = opt.realisations;
  {
    std::size_t outs = 0;
    for (const auto& so : simOut) outs += so.size();
    const double passes = 1.0 + double(D) * (opt.causes ? 2.0 : 1.0);
    const double steps = double(R) * double(n) * passes;
    const double bytes = double(R) * double(outs) * (opt.causes ? 19.0 : 10.0) * 8.0;
    const std::string place = "diagnose --run: --realisations " + std::to_string(R);
    const std::string remedy = "lower --realisations or --durations";
    limits::checkBudget({{place, "the simulation", steps, limits::kDefaultFilterStepBudget, "IMU steps",
                          std::to_string(R) + " realisations x " + std::to_string(n) + " samples x " +
                              formatNumber(passes) + " passes",
                          remedy},
                         {place, "the simulated outage ends", bytes / 1e6, limits::kDefaultMemoryBudgetBytes / 1e6,
                          "MB", "", remedy}},
                        opt.allow_large);
  }
  std::vector<RealisationOut> sims(R);
  parallelFor(std::size_t(R), static_cast<unsigned>(std::max(opt.threads, 0)), [&](std::size_t r) {
    const std::uint64_t seed = stochastic::deriveSeed(opt.seed, static_cast<std::uint64_t>(r));
    std::array<std::vector<double>, 6> err;
    if (rec) {
      emulation::StaticRecordingSpec spec;
      spec.file = opt.static_file;
      spec.seed = stochastic::deriveSeed(seed, 4);
      err = emulation::staticImuErrors(*rec, spec, rate, n).axis;
    } else {
      err = emulation::modelImuErrors(model, rate, n, stochastic::deriveSeed(seed, 0)).axis;
    }
    EmulatedRun run = plan.emulate(err, seed);
    // GNSS and baro at the run's own epochs with its own sigmas.
    run.gnss.clear();
    run.baro.clear();
    const auto zg = emulation::standardNormal(6 * realGnss.size() + 1, stochastic::deriveSeed(seed, 5));
    for (std::size_t k = 0; k < realGnss.size(); ++k) {
      const GnssFix& f = realGnss[k];
      if (f.t < t0 || f.t > t1) continue;
      const emulation::TruthState s = tr.at(f.t);
      const Eigen::Matrix3d Lp = f.cov_pos_N->llt().matrixL();
      const Eigen::Vector3d np(zg[6 * k], zg[6 * k + 1], zg[6 * k + 2]);
      GnssFix g;
      g.t = f.t;
      g.pos = earth::nedToGeodetic(tr.origin(), s.p_L + s.C_BtoN * lever + Lp * np);
      g.cov_pos_N = f.cov_pos_N;
      if (f.v_N && f.cov_vel_N) {
        const Eigen::Matrix3d Lv = f.cov_vel_N->llt().matrixL();
        const Eigen::Vector3d nv(zg[6 * k + 3], zg[6 * k + 4], zg[6 * k + 5]);
        g.v_N = s.v_N + s.C_BtoN * s.w_NB_B.cross(lever) + Lv * nv;
        g.cov_vel_N = f.cov_vel_N;
      }
      run.gnss.push_back(g);
    }
    const auto zb = emulation::standardNormal(realBaro.size() + 1, stochastic::deriveSeed(seed, 6));
    for (std::size_t k = 0; k < realBaro.size(); ++k) {
      const BaroSample& b = realBaro[k];
      if (b.t < t0 || b.t > t1 || !b.sigma_m) continue;
      BaroSample o = b;
      o.h = tr.at(b.t).pos.h + *b.sigma_m * zb[k];
      run.baro.push_back(o);
    }
    // The filter of every duration over @p er: its outage ends, one per
    // simulated outage, each passed to keep(duration, epoch).
    auto filterEnds = [&](const EmulatedRun& er, const std::string& with, auto&& keep) {
      for (std::size_t i = 0; i < D; ++i) {
        const NavRunResult res = runNav(er.input(truths[i]), model, navs[i]);
        if (res.epochs.size() != simOut[i].size())
          throw Error("diagnose --run: realisation " + std::to_string(r) + with + " recorded " +
                      std::to_string(res.epochs.size()) + " outage ends, expected " + std::to_string(simOut[i].size()));
        for (const auto& e : res.epochs) keep(i, e);
      }
    };
    RealisationOut& ro = sims[r];
    ro.err.resize(D);
    ro.nees.resize(D);
    filterEnds(run, "", [&](std::size_t i, const NavEpoch& e) {
      ro.err[i].push_back(e.err);
      ro.nees[i].push_back(e.nees[0]);
    });
    if (opt.causes) {
      // The same realisation with an accelerometer bias random walk of
      // density kCalibrationRwDensity on the three axes (its own stream).
      const double gamma = kCalibrationRwDensity / std::sqrt(rate);  // per sample
      for (int c = 3; c < 6; ++c) {
        const auto w = emulation::standardNormal(n, stochastic::deriveSeed(seed, 7 + static_cast<std::uint64_t>(c)));
        double b = 0.0;
        for (std::size_t k = 0; k < n && k < err[c].size(); ++k) {
          b += gamma * w[k];
          err[c][k] += b;
        }
      }
      EmulatedRun rw = plan.emulate(err, seed);
      rw.gnss = run.gnss;
      rw.baro = run.baro;
      ro.err_rw.resize(D);
      filterEnds(rw, " with the calibration random walk",
                 [&](std::size_t i, const NavEpoch& e) { ro.err_rw[i].push_back(e.err); });
    }
  }, [&](std::size_t done, std::size_t count) {
    progress(0.15 + (opt.causes ? 0.65 : 0.85) * double(done) / double(count), "simulation");
  });

  // 4. Comparisons and NEES bands.
  const ReferenceInfo& ref = out.reference;
  const bool has[4] = {true, true, ref.has_velocity, ref.has_attitude};
  std::size_t m = 0;
  for (std::size_t i = 0; i < D; ++i) m += 1 + (has[2] ? 1 : 0) + (has[3] ? 1 : 0) + 2;
  out.tests = m;
  out.test_level = opt.alpha / double(m);
  const double a = out.test_level;
  for (std::size_t i = 0; i < D; ++i) {
    const ReplayResult& mr = measured[i];
    const RunScore& sc = *mr.score;
    DurationDiagnosis dd;
    dd.duration_s = opt.durations_s[i];
    dd.period_s = opt.durations_s[i] + opt.reconverge_s;
    // the measured outages the emulation also has
    for (const auto& so : simOut[i]) dd.measured.push_back(sc.outages[so.score_index]);
    dd.distribution = sc.distribution;
    const std::size_t K = dd.measured.size();
    double sn = 0.0;
    for (const auto& o : dd.measured) sn += o.nees;
    dd.anees = sn / double(K);
    boost::math::chi_squared chi(3.0 * double(K));
    dd.chi2_lo = boost::math::quantile(chi, a / 2) / double(K);
    dd.chi2_hi = boost::math::quantile(chi, 1 - a / 2) / double(K);
    {
      // the measured mean NEES against the same statistic of each realisation
      std::vector<double> logs;
      for (const auto& s : sims) {
        double m = 0.0;
        std::size_t n = 0;
        for (double v : s.nees[i])
          if (std::isfinite(v)) {
            m += v;
            ++n;
          }
        if (n > 0 && m > 0) logs.push_back(std::log(m / double(n)));
      }
      const LogTest lt = logTest(std::log(std::max(dd.anees, 1e-300)), logs, a);
      dd.anees_lo = std::exp(lt.mu + (lt.lo - lt.log_ratio));
      dd.anees_hi = std::exp(lt.mu + (lt.hi - lt.log_ratio));
      dd.anees_p = lt.p;
      dd.anees_rejects = lt.p < a;
    }
    double ps = 0.0;
    std::size_t pn = 0;
    for (const auto& s : sims)
      for (double v : s.nees[i])
        if (std::isfinite(v)) {
          ps += v;
          ++pn;
        }
    dd.predicted_anees = pn ? ps / double(pn) : NAN;
    dd.simulated_outages = static_cast<std::size_t>(R) * simOut[i].size();
    if (dd.anees_rejects)
      out.reasons.push_back("measured mean NEES " + formatNumber(dd.anees, 3) + " at " + formatNumber(dd.duration_s) +
                            " s outages outside the simulated band [" + formatNumber(dd.anees_lo, 3) + ", " +
                            formatNumber(dd.anees_hi, 3) + "], p = " + formatNumber(dd.anees_p, 3));

    // measured errors: the end epoch of each run outage (velocity, attitude from the run's epochs)
    std::vector<filter::Vector9d> mErr;
    for (const auto& so : simOut[i]) {
      const OutageScore& o = sc.outages[so.score_index];
      filter::Vector9d e = endOf(mr, o.start_s).first;
      e.head<3>() = o.err_N;
      mErr.push_back(e);
    }
    for (int q = 0; q < 4; ++q) {
      if (!has[q]) continue;
      QuantityComparison c;
      c.quantity = kQuantities[q];
      c.unit = kUnits[q];
      c.duration_s = dd.duration_s;
      c.dof = kDof[q];
      for (const auto& e : mErr) c.measured.push_back(magnitude(q, e));
      for (const auto& s : sims)
        for (const auto& e : s.err[i]) c.predicted.push_back(magnitude(q, e));
      const double refVar = q == 0 ? 2 * ref.sigma_h_m * ref.sigma_h_m : q == 1 ? ref.sigma_v_m * ref.sigma_v_m : 0.0;
      c.measured_rms = std::sqrt(meanSquare(c.measured));
      // the same statistic (RMS over these outages) for each realisation
      std::vector<double> logs;
      for (const auto& s : sims) {
        std::vector<double> m;
        for (const auto& e : s.err[i]) m.push_back(magnitude(q, e));
        logs.push_back(0.5 * std::log(meanSquare(m) + refVar));
      }
      const LogTest lt = logTest(std::log(c.measured_rms), logs, a);
      c.predicted_rms = std::exp(lt.mu);
      c.predicted_log_sd = lt.sd;
      c.predicted_p05 = percentile(c.predicted, 0.05);
      c.predicted_p50 = percentile(c.predicted, 0.50);
      c.predicted_p95 = percentile(c.predicted, 0.95);
      c.ratio = std::exp(lt.log_ratio);
      c.ratio_lo = std::exp(lt.lo);
      c.ratio_hi = std::exp(lt.hi);
      c.p_value = lt.p;
      c.rejects = c.p_value < a;
      if (c.rejects)
        out.reasons.push_back(c.quantity + " at " + formatNumber(c.duration_s) + " s outages: measured/predicted RMS " +
                              formatNumber(c.ratio, 3) + " [" + formatNumber(c.ratio_lo, 3) + ", " +
                              formatNumber(c.ratio_hi, 3) + "], p = " + formatNumber(c.p_value, 3));
      out.comparisons.push_back(std::move(c));
    }
    out.durations.push_back(std::move(dd));
  }
  // Could every test have said no? The half-width of its interval as a factor.
  out.resolution_factor = 1.0;
  const auto widen = [&](double lo, double hi) {
    const double f = lo > 0.0 ? std::sqrt(hi / lo) : std::numeric_limits<double>::infinity();
    out.resolution_factor = std::isnan(f) || std::isnan(out.resolution_factor) ? NAN : std::max(out.resolution_factor, f);
  };
  for (const auto& c : out.comparisons) widen(c.ratio_lo, c.ratio_hi);
  for (const auto& dd : out.durations) widen(dd.anees_lo, dd.anees_hi);
  if (!out.reasons.empty()) {
    out.verdict = "inadequate";
  } else if (out.resolution_factor <= kResolvableFactor) {
    out.verdict = "adequate";
  } else {
    out.verdict = "undetermined";
    const std::string size = std::isfinite(out.resolution_factor)
                                 ? "by a factor of " + formatNumber(out.resolution_factor, 3) + " (more than " +
                                       formatNumber(kResolvableFactor) + ")"
                                 : "of any size";
    out.reasons.push_back("no test rejects, but the weakest would miss a misprediction " + size +
                          ": too few realisations (" + std::to_string(R) + ") or outages; raise --realisations");
  }
  out.model_before = model;
  if (opt.causes) diagnoseCauses(opt, data, out, measured, simOut, sims, tr, t0, t1, model, progress);
  progress(1.0, "done");
  out.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return out;
}

}  // namespace navimpact::analysis
