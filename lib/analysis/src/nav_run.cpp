// The in-memory navigation loop shared by the emulation study and the replay.
#include "navimpact/analysis/nav_run.hpp"

#include <Eigen/Cholesky>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>

#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/filter/error_model.hpp"
#include "navimpact/stochastic/simulate.hpp"

namespace navimpact::analysis {

namespace {

template <int N>
double blockNees(const Eigen::Matrix<double, N, 1>& e, const Eigen::Matrix<double, N, N>& P) {
  Eigen::LLT<Eigen::Matrix<double, N, N>> llt(P);
  if (llt.info() != Eigen::Success) return std::numeric_limits<double>::quiet_NaN();
  return e.dot(llt.solve(e));
}

}  // namespace

std::array<double, 4> navNees(const filter::Vector9d& err, const filter::Matrix9d& P9) {
  std::array<double, 4> out{};
  for (int b = 0; b < 3; ++b)
    out[b] = blockNees<3>(err.segment<3>(3 * b), P9.block<3, 3>(3 * b, 3 * b));
  out[3] = blockNees<9>(err, P9);
  return out;
}

struct NavRunner::Impl {
  Impl(const ins::NavState& x0_, double dt0_, bool hasTruth_, const stochastic::ImuModel& model,
       const NavRunOptions& opt_)
      : x0(x0_), dt0(dt0_), hasTruth(hasTruth_), opt(opt_), t_start(std::chrono::steady_clock::now()),
        ekf(x0_, opt_.P0_nav, model, opt_.ekf) {}

  ins::NavState x0;
  double dt0;
  bool hasTruth;
  NavRunOptions opt;  // its outages grow with addOutage
  std::chrono::steady_clock::time_point t_start;
  filter::ErrorStateEkf ekf;
  NavRunResult res;
  std::deque<GnssFix> gnss;
  std::deque<BaroSample> baro;
  std::deque<std::pair<double, ins::NavState>> truth;
  std::vector<std::size_t> live;  // outages that may still contain an epoch
  std::optional<filter::StaticDetector> detector;
  double next_zupt = -1e300, next_nhc = -1e300;
  double next_record = 0.0;  // without truth
  double t_prev = 0.0;
  std::size_t epochs = 0;
  bool started = false;
  std::function<void(const NavEpoch&, const ins::NavState*)>* on_epoch = nullptr;
  bool* keep_epochs = nullptr;

  bool check(const filter::UpdateResult& u, const char* kind) {
    if (!u.accepted) res.rejected.push_back({u.t, kind, u.nis, u.gate, 1.0});
    if (u.readmitted) res.readmitted.push_back({u.t, kind, u.nis, u.gate, u.inflation});
    return u.accepted;
  }

  /// A measurement's epoch @p t relative to the filter time (0 when on the sample).
  static double epochOffset(double t, double t_now) { return std::abs(t - t_now) > 1e-9 ? t - t_now : 0.0; }

  void applyAiding(double t_now, double half_dt) {
    // With a time-offset state d = t_IMU - t_true, a fix taken at true time t
    // is the state at IMU time t + d: it waits for that epoch, so that its
    // carry (tau = dt_meas + d) stays within half a sample. A first-order carry
    // over the whole offset left it short by terms in d^2 (84 ms read 82.4 ms,
    // 2.7 sigma, on a UAV run). 0 without the state: the fix at its own epoch.
    const double d = ekf.timeOffsetEstimate();
    while (!gnss.empty() && gnss.front().t + d <= t_now + half_dt) {
      const GnssFix f = std::move(gnss.front());
      gnss.pop_front();
      if (f.t < x0.t - half_dt) continue;  // before the run
      bool withheld = false;
      for (std::size_t i = 0; i < opt.outages.size(); ++i)
        if (opt.outages[i].covers(f.t)) {
          ++res.outages[i].gnss_dropped;
          withheld = true;
        }
      if (withheld) continue;
      if (!f.cov_pos_N) throw Error("navigation run: GNSS fix at " + formatNumber(f.t, 10) + " s has no position covariance");
      // the fix's own epoch relative to the filter time (0 when on a sample)
      const double dt_meas = epochOffset(f.t, t_now);
      const Eigen::Vector3d sp = f.cov_pos_N->diagonal().cwiseSqrt();
      const filter::UpdateResult up = ekf.updateGnssPosition(f.pos, sp, opt.lever_arm_B, dt_meas);
      if (up.innovation.size() == 3 && up.S.rows() == 3)
        res.gnss_innovations.push_back({f.t, up.innovation, up.S.diagonal(), sp.cwiseAbs2(), up.accepted});
      bool used = check(up, "gnss_position");
      if (opt.use_gnss_velocity && f.v_N) {
        if (!f.cov_vel_N) throw Error("navigation run: GNSS fix at " + formatNumber(f.t, 10) + " s has no velocity covariance");
        const Eigen::Vector3d sv = f.cov_vel_N->diagonal().cwiseSqrt();
        used = check(ekf.updateGnssVelocity(*f.v_N, sv, opt.lever_arm_B, dt_meas), "gnss_velocity") || used;
      }
      if (used) ++res.gnss_updates;
    }
    while (!baro.empty() && baro.front().t + d <= t_now + half_dt) {  // on the true clock as GNSS
      const BaroSample b = baro.front();
      baro.pop_front();
      if (b.t < x0.t - half_dt) continue;
      if (!opt.baro_in_outage && inOutage(b.t, opt.outages)) continue;
      if (!b.sigma_m) throw Error("navigation run: baro sample at " + formatNumber(b.t, 10) + " s has no sigma");
      const double dt_meas = epochOffset(b.t, t_now);
      if (check(ekf.updateBaro(b.h, *b.sigma_m, dt_meas), "baro")) ++res.baro_updates;
    }
  }

  // ground-vehicle aids (off by default)
  void applyAids(const ins::ImuSample& s) {
    if (detector && detector->push(s) && s.t >= next_zupt) {
      next_zupt = s.t + opt.zupt_interval_s - 0.5 * s.dt;
      if (check(ekf.updateZeroVelocity(opt.zupt_sigma_mps), "zupt")) ++res.zupt_updates;
    }
    if (opt.nhc && s.t >= next_nhc && ekf.state().v_N.head<2>().norm() >= opt.nhc_min_speed_mps) {
      next_nhc = s.t + opt.nhc_interval_s - 0.5 * s.dt;
      if (check(ekf.updateNonHolonomic(opt.nhc_sigma_lateral_mps, opt.nhc_sigma_vertical_mps, opt.nhc_point_B),
                "nhc"))
        ++res.nhc_updates;
    }
  }

  // One recorded epoch: the outages containing it, the observer, the kept series.
  void emit(NavEpoch&& e, const ins::NavState* x) {
    const std::size_t k = epochs++;
    for (std::size_t j = 0; j < live.size();) {
      OutageSummary& o = res.outages[live[j]];
      if (e.t > o.window.end_s + 1e-9) {  // epochs only move on: this outage is over
        live.erase(live.begin() + static_cast<std::ptrdiff_t>(j));
        continue;
      }
      ++j;
      if (e.t <= o.window.start_s) continue;
      o.end_epoch = static_cast<int>(k);
      o.end = e;
      if (!hasTruth) continue;
      o.max_drift_h = std::max(o.max_drift_h, e.err.head<2>().norm());
      o.max_drift_v = std::max(o.max_drift_v, std::abs(e.err[2]));
      o.max_drift_3d = std::max(o.max_drift_3d, e.err.head<3>().norm());
    }
    if (*on_epoch) (*on_epoch)(e, x);
    if (*keep_epochs) res.epochs.push_back(std::move(e));
  }

  void record(double t_now, double half_dt) {
    constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
    if (!hasTruth) {
      if (t_now + half_dt < next_record) return;
      while (next_record <= t_now + half_dt) next_record += opt.record_interval_s;
      ekf.flushPropagation();
      NavEpoch e;
      e.t = t_now;
      e.est = ekf.state();
      e.err.setConstant(kNaN);
      const filter::Matrix9d P9 = ekf.navCovarianceOnTrueClock();
      e.sigma = P9.diagonal().cwiseMax(0.0).cwiseSqrt();
      e.P_pos = P9.topLeftCorner<3, 3>();
      e.nees.fill(kNaN);
      emit(std::move(e), nullptr);
      return;
    }
    // With a time-offset state the truth of true time t is compared with the
    // state at the IMU epoch of t + d_est carried the rest (half a sample at
    // most): a first-order carry over the whole offset left errors of order
    // (dw/dt) d^2 / 2 in the scored attitude (1.8 mrad for 84 ms at 0.5 rad/s^2).
    const bool offset = ekf.layout().extraIndex(filter::Extra::TimeOffset) >= 0;
    const double d = ekf.timeOffsetEstimate();  // 0 without the state
    while (!truth.empty() && truth.front().first + d <= t_now + half_dt) {
      const double tt = truth.front().first;
      const ins::NavState& xt = truth.front().second;
      // nearest sample; an epoch exactly between two samples may land on either
      if (!offset && std::abs(tt - t_now) > half_dt * (1.0 + 1e-6) + 1e-9)
        throw Error("navigation run: truth epoch " + formatNumber(tt, 10) +
                    " s does not fall on an IMU sample (nearest " + formatNumber(t_now, 10) + " s)");
      ekf.flushPropagation();
      NavEpoch e;
      e.t = tt;
      e.est = ekf.state();
      e.err = filter::navError(ekf.state(), xt);
      // with a time-offset state: the state at IMU time t_now carried to the IMU epoch of tt + d_est
      if (offset) e.err += ekf.carry(tt + d - t_now);
      if (opt.reference_lever_B.squaredNorm() > 0.0) e.err.head<3>() += ekf.state().C_BtoN() * opt.reference_lever_B;
      // the scored error holds the offset's own error too: its covariance on the true clock
      const filter::Matrix9d P9 = ekf.navCovarianceOnTrueClock();
      e.sigma = P9.diagonal().cwiseMax(0.0).cwiseSqrt();
      e.P_pos = P9.topLeftCorner<3, 3>();
      e.nees = navNees(e.err, P9);
      emit(std::move(e), &xt);
      truth.pop_front();
    }
  }
};

NavRunner::NavRunner(const ins::NavState& x0, double dt0, bool has_truth, const stochastic::ImuModel& model,
                     const NavRunOptions& opt) {
  if (!has_truth && !(opt.record_interval_s > 0.0 && std::isfinite(opt.record_interval_s)))
    throw Error("navigation run: record interval must be > 0 s without truth, got " + formatNumber(opt.record_interval_s, 10));
  for (const auto& o : opt.outages)
    if (!(o.end_s > o.start_s))
      throw Error("navigation run: outage (" + formatNumber(o.start_s, 10) + ", " + formatNumber(o.end_s, 10) + "] is empty");
  if (!(dt0 > 0.0)) throw Error("navigation run: the first IMU interval must be > 0 s, got " + formatNumber(dt0, 10));
  impl_ = std::make_unique<Impl>(x0, dt0, has_truth, model, opt);
  Impl& m = *impl_;
  m.on_epoch = &on_epoch;
  m.keep_epochs = &keep_epochs;
  m.res.has_truth = has_truth;
  m.res.states = m.ekf.size();
  m.res.outages.resize(opt.outages.size());
  for (std::size_t i = 0; i < opt.outages.size(); ++i) {
    m.res.outages[i].window = opt.outages[i];
    m.live.push_back(i);
  }
  if (opt.zupt) {
    if (!(opt.zupt_sigma_mps > 0.0) || !(opt.zupt_interval_s > 0.0))
      throw Error("navigation run: ZUPT sigma and interval must be > 0");
    m.detector.emplace(opt.zupt_detector, 1.0 / dt0);
  }
  if (opt.nhc && (!(opt.nhc_sigma_lateral_mps > 0.0) || !(opt.nhc_sigma_vertical_mps > 0.0) ||
                  !(opt.nhc_interval_s > 0.0) || !(opt.nhc_min_speed_mps >= 0.0)))
    throw Error("navigation run: non-holonomic sigmas and interval must be > 0, minimum speed >= 0");
  m.next_record = x0.t;
  m.t_prev = x0.t;
}

NavRunner::~NavRunner() = default;

void NavRunner::addGnss(const GnssFix& f) { impl_->gnss.push_back(f); }
void NavRunner::addBaro(const BaroSample& b) { impl_->baro.push_back(b); }
void NavRunner::addTruth(double t, const ins::NavState& x) {
  Impl& m = *impl_;
  // truth epochs before the first sample end that are not at x0.t are skipped
  if (!m.started && t < m.x0.t - 0.5 * m.dt0) return;
  m.truth.emplace_back(t, x);
}
void NavRunner::addOutage(const Outage& o) {
  Impl& m = *impl_;
  if (!(o.end_s > o.start_s))
    throw Error("navigation run: outage (" + formatNumber(o.start_s, 10) + ", " + formatNumber(o.end_s, 10) + "] is empty");
  m.opt.outages.push_back(o);
  m.res.outages.emplace_back();
  m.res.outages.back().window = o;
  m.live.push_back(m.res.outages.size() - 1);
}
const std::vector<Outage>& NavRunner::outages() const { return impl_->opt.outages; }
std::size_t NavRunner::epochCount() const { return impl_->epochs; }

void NavRunner::start(const ins::ImuSample& first) {
  Impl& m = *impl_;
  if (m.started) throw Error("navigation run: started twice");
  m.started = true;
  m.ekf.primeRates(first);
  m.ekf.carryInitialStateToImuClock();
  while (!m.truth.empty() && m.truth.front().first < m.x0.t - 0.5 * m.dt0) m.truth.pop_front();
  m.applyAiding(m.x0.t, 0.5 * m.dt0);
  m.record(m.x0.t, 0.5 * m.dt0);
}

void NavRunner::step(const ins::ImuSample& s) { stepUnmeasured(s, 0.0, 0.0); }

void NavRunner::stepUnmeasured(const ins::ImuSample& s, double psd_w, double psd_f) {
  Impl& m = *impl_;
  if (!(s.dt > 0.0) || std::abs(s.t - s.dt - m.t_prev) > 1e-6 * (1.0 + std::abs(m.t_prev)))
    throw Error("navigation run: IMU sample at " + formatNumber(s.t, 10) + " s (dt " + formatNumber(s.dt, 10) +
                " s) does not follow the previous one at " + formatNumber(m.t_prev, 10) + " s");
  m.ekf.predict(s);
  if (psd_w > 0.0 || psd_f > 0.0) m.ekf.addSensorNoise(s.dt, psd_w, psd_f);
  ++m.res.steps;
  m.applyAids(s);
  m.applyAiding(s.t, 0.5 * s.dt);
  m.record(s.t, 0.5 * s.dt);
  m.t_prev = s.t;
}

NavRunResult NavRunner::finish() {
  Impl& m = *impl_;
  // Truth epochs inside the data on the true clock whose IMU epoch t + d_est
  // (a positive time-offset estimate) lies past the last sample are not
  // scored: the state there would be a carry over up to d_est beyond the data,
  // first order, whose (dw/dt) d^2 / 2 made the attitude NEES of a perfect IMU
  // reach 200-1,700 at those epochs alone.
  if (m.started && m.res.has_truth)
    for (const auto& e : m.truth)
      if (e.first <= m.t_prev + 0.5 * m.dt0) ++m.res.epochs_past_imu_clock;
  m.res.rejections = m.ekf.rejections();
  m.res.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - m.t_start).count();
  if (m.ekf.layout().hasExtra()) {
    m.ekf.flushPropagation();
    m.res.extra_estimates = m.ekf.extraEstimates();
    m.res.extra_sigmas = m.ekf.extraSigmas();
  }
  return std::move(m.res);
}

NavRunResult runNav(const NavRunInput& in, const stochastic::ImuModel& model,
                    const NavRunOptions& opt) {
  if (!in.imu || in.imu->empty()) throw Error("navigation run: no IMU samples");
  const auto& imu = *in.imu;
  if (in.truth && in.truth->t.size() != in.truth->x.size())
    throw Error("navigation run: truth series has " + std::to_string(in.truth->t.size()) + " times but " +
                std::to_string(in.truth->x.size()) + " states");
  NavRunner run(in.x0, imu.front().dt, in.truth != nullptr, model, opt);
  if (in.gnss)
    for (const auto& f : *in.gnss) run.addGnss(f);
  if (in.baro)
    for (const auto& b : *in.baro) run.addBaro(b);
  if (in.truth)
    for (std::size_t i = 0; i < in.truth->t.size(); ++i) run.addTruth(in.truth->t[i], in.truth->x[i]);
  run.start(imu.front());
  for (const ins::ImuSample& s : imu) run.step(s);
  return run.finish();
}

NavRunInput EmulatedRun::input(const TruthSeries& truth) const {
  NavRunInput in;
  in.x0 = x0;
  in.imu = &imu;
  in.gnss = &gnss;
  in.baro = &baro;
  in.truth = &truth;
  return in;
}

EmulatedRun emulateRun(const std::vector<ins::ImuSample>& perfect,
                       const std::array<std::vector<double>, 6>& err,
                       const emulation::SmoothTrajectory& traj, double t0, double t1,
                       emulation::GnssOptions gnss, emulation::BaroOptions baro,
                       const ins::NavState& truth0, const filter::Vector9d& initial_sigma,
                       std::uint64_t run_seed) {
  EmulatedRun run;
  const std::size_t n = perfect.size();
  run.imu = perfect;
  for (std::size_t k = 0; k < n; ++k) {
    ins::ImuSample& s = run.imu[k];
    for (int a = 0; a < 3; ++a) {
      s.dtheta_B(a) += err[a][k] * s.dt;
      s.dv_B(a) += err[3 + a][k] * s.dt;
    }
  }
  gnss.seed = stochastic::deriveSeed(run_seed, 1);
  baro.seed = stochastic::deriveSeed(run_seed, 2);
  run.gnss = emulation::simulateGnss(traj, gnss, t0, t1);
  run.baro = emulation::simulateBaro(traj, baro, t0, t1);
  const auto z = emulation::standardNormal(9, stochastic::deriveSeed(run_seed, 3));
  filter::Vector9d dx0;
  for (int i = 0; i < 9; ++i) dx0(i) = initial_sigma(i) * z[i];
  run.x0 = filter::applyNavError(truth0, dx0);
  run.x0.t = t0;
  return run;
}

}  // namespace navimpact::analysis
