// The in-memory navigation loop shared by the emulation study and the replay.
#include "navimpact/analysis/nav_run.hpp"

#include <Eigen/Cholesky>

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

NavRunResult runNav(const NavRunInput& in, const stochastic::ImuModel& model,
                    const NavRunOptions& opt) {
  if (!in.imu || in.imu->empty()) throw Error("navigation run: no IMU samples");
  const TruthSeries noTruth;
  const bool hasTruth = in.truth != nullptr;
  if (!hasTruth && !(opt.record_interval_s > 0.0 && std::isfinite(opt.record_interval_s)))
    throw Error("navigation run: record interval must be > 0 s without truth, got " + formatNumber(opt.record_interval_s, 10));
  const auto& imu = *in.imu;
  const auto& truth = hasTruth ? *in.truth : noTruth;
  if (truth.t.size() != truth.x.size())
    throw Error("navigation run: truth series has " + std::to_string(truth.t.size()) + " times but " +
                std::to_string(truth.x.size()) + " states");
  for (const auto& o : opt.outages)
    if (!(o.end_s > o.start_s))
      throw Error("navigation run: outage (" + formatNumber(o.start_s, 10) + ", " + formatNumber(o.end_s, 10) + "] is empty");

  const auto t_start = std::chrono::steady_clock::now();
  filter::ErrorStateEkf ekf(in.x0, opt.P0_nav, model, opt.ekf);
  NavRunResult res;
  res.has_truth = hasTruth;
  res.states = ekf.size();
  res.outages.resize(opt.outages.size());
  for (std::size_t i = 0; i < opt.outages.size(); ++i) res.outages[i].window = opt.outages[i];

  std::size_t ig = 0, ib = 0, it = 0;
  const std::size_t ng = in.gnss ? in.gnss->size() : 0, nb = in.baro ? in.baro->size() : 0;
  const double dt0 = imu.front().dt;
  // Truth epochs before the first sample end that are not at x0.t are skipped.
  while (it < truth.t.size() && truth.t[it] < in.x0.t - 0.5 * dt0) ++it;

  auto check = [&](const filter::UpdateResult& u, const char* kind) {
    if (!u.accepted) res.rejected.push_back({u.t, kind, u.nis, u.gate, 1.0});
    if (u.readmitted) res.readmitted.push_back({u.t, kind, u.nis, u.gate, u.inflation});
    return u.accepted;
  };
  auto applyAiding = [&](double t_now, double half_dt) {
    while (ig < ng && (*in.gnss)[ig].t <= t_now + half_dt) {
      const GnssFix& f = (*in.gnss)[ig++];
      if (f.t < in.x0.t - half_dt) continue;  // before the run
      if (inOutage(f.t, opt.outages)) continue;
      if (!f.cov_pos_N) throw Error("navigation run: GNSS fix at " + formatNumber(f.t, 10) + " s has no position covariance");
      // the fix's own epoch relative to the filter time (0 when on a sample)
      const double dt_meas = std::abs(f.t - t_now) > 1e-9 ? f.t - t_now : 0.0;
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
    while (ib < nb && (*in.baro)[ib].t <= t_now + half_dt) {
      const BaroSample& b = (*in.baro)[ib++];
      if (b.t < in.x0.t - half_dt) continue;
      if (!opt.baro_in_outage && inOutage(b.t, opt.outages)) continue;
      if (!b.sigma_m) throw Error("navigation run: baro sample at " + formatNumber(b.t, 10) + " s has no sigma");
      if (check(ekf.updateBaro(b.h, *b.sigma_m), "baro")) ++res.baro_updates;
    }
  };
  // ground-vehicle aids (off by default)
  std::optional<filter::StaticDetector> detector;
  if (opt.zupt) {
    if (!(opt.zupt_sigma_mps > 0.0) || !(opt.zupt_interval_s > 0.0))
      throw Error("navigation run: ZUPT sigma and interval must be > 0");
    detector.emplace(opt.zupt_detector, 1.0 / imu.front().dt);
  }
  if (opt.nhc && (!(opt.nhc_sigma_lateral_mps > 0.0) || !(opt.nhc_sigma_vertical_mps > 0.0) ||
                  !(opt.nhc_interval_s > 0.0) || !(opt.nhc_min_speed_mps >= 0.0)))
    throw Error("navigation run: non-holonomic sigmas and interval must be > 0, minimum speed >= 0");
  double next_zupt = -1e300, next_nhc = -1e300;
  auto applyAids = [&](const ins::ImuSample& s) {
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
  };
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  double next_record = in.x0.t;  // without truth
  auto record = [&](double t_now, double half_dt) {
    if (!hasTruth) {
      if (t_now + half_dt < next_record) return;
      while (next_record <= t_now + half_dt) next_record += opt.record_interval_s;
      ekf.flushPropagation();
      NavEpoch e;
      e.t = t_now;
      e.est = ekf.state();
      e.err.setConstant(kNaN);
      const filter::Matrix9d P9 = ekf.P().topLeftCorner<9, 9>();
      e.sigma = P9.diagonal().cwiseMax(0.0).cwiseSqrt();
      e.P_pos = P9.topLeftCorner<3, 3>();
      e.nees.fill(kNaN);
      res.epochs.push_back(e);
      return;
    }
    while (it < truth.t.size() && truth.t[it] <= t_now + half_dt) {
      // nearest sample; an epoch exactly between two samples may land on either
      if (std::abs(truth.t[it] - t_now) > half_dt * (1.0 + 1e-6) + 1e-9)
        throw Error("navigation run: truth epoch " + formatNumber(truth.t[it], 10) +
                    " s does not fall on an IMU sample (nearest " + formatNumber(t_now, 10) + " s)");
      ekf.flushPropagation();
      NavEpoch e;
      e.t = truth.t[it];
      e.est = ekf.state();
      e.err = filter::navError(ekf.state(), truth.x[it]);
      if (opt.reference_lever_B.squaredNorm() > 0.0) e.err.head<3>() += ekf.state().C_BtoN() * opt.reference_lever_B;
      const filter::Matrix9d P9 = ekf.P().topLeftCorner<9, 9>();
      e.sigma = P9.diagonal().cwiseMax(0.0).cwiseSqrt();
      e.P_pos = P9.topLeftCorner<3, 3>();
      e.nees = navNees(e.err, P9);
      res.epochs.push_back(e);
      ++it;
    }
  };

  applyAiding(in.x0.t, 0.5 * dt0);
  record(in.x0.t, 0.5 * dt0);
  double t_prev = in.x0.t;
  for (const ins::ImuSample& s : imu) {
    if (!(s.dt > 0.0) || std::abs(s.t - s.dt - t_prev) > 1e-6 * (1.0 + std::abs(t_prev)))
      throw Error("navigation run: IMU sample at " + formatNumber(s.t, 10) + " s (dt " + formatNumber(s.dt, 10) +
                  " s) does not follow the previous one at " + formatNumber(t_prev, 10) + " s");
    ekf.predict(s);
    ++res.steps;
    applyAids(s);
    applyAiding(s.t, 0.5 * s.dt);
    record(s.t, 0.5 * s.dt);
    t_prev = s.t;
  }
  res.rejections = ekf.rejections();

  // Outage summaries from the recorded epochs.
  for (auto& o : res.outages) {
    for (std::size_t k = 0; k < res.epochs.size(); ++k) {
      const NavEpoch& e = res.epochs[k];
      if (e.t <= o.window.start_s || e.t > o.window.end_s + 1e-9) continue;
      o.end_epoch = static_cast<int>(k);
      if (!hasTruth) continue;
      o.max_drift_h = std::max(o.max_drift_h, e.err.head<2>().norm());
      o.max_drift_3d = std::max(o.max_drift_3d, e.err.head<3>().norm());
    }
  }
  res.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  if (ekf.layout().hasExtra()) {
    ekf.flushPropagation();
    res.extra_estimates = ekf.extraEstimates();
    res.extra_sigmas = ekf.extraSigmas();
  }
  return res;
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
