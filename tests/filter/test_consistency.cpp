// Discretization order, lower-rate covariance propagation, textbook error
// growth and Monte Carlo consistency (NEES) of the error-state EKF.
#include <gtest/gtest.h>

#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>
#include <iostream>
#include <random>

#include "filter_test_util.hpp"
#include "navimpact/emulation/scenario.hpp"
#include "navimpact/stochastic/model_file.hpp"
#include "test_support.hpp"

using namespace navimpact;
using namespace ftest;
using P = stochastic::Process;

namespace {
ins::NavState movingState() { return navState(-33.9, 151.2, 300.0, Vector3d(-40.0, 25.0, -2.0), -8.0, 5.0, -100.0); }
}  // namespace

// Series Phi is second order (error O(dt^3)), series Qd third order (error
// O(dt^4)): halving dt must shrink the differences to Van Loan by ~8 and ~16.
TEST(Discretization, SeriesAgreesWithVanLoanToExpectedOrder) {
  const stochastic::ImuModel m = model({P::wn(1e-3), P::gm(5e-4, 20.0), P::rw(1e-5)},
                                       {P::wn(5e-3), P::gm(2e-3, 3.0), P::dr(1e-8)}, 200.0);
  const Vector3d w(0.3, -0.2, 0.5), f(3.0, -2.0, -9.0);
  double ePhi[2], eQ[2];
  const double dts[2] = {0.08, 0.04};
  for (int i = 0; i < 2; ++i) {
    filter::EkfConfig cs, cv;
    cv.discretization = filter::Discretization::VanLoan;
    filter::ErrorStateEkf s(movingState(), filter::Matrix9d::Identity(), m, cs);
    filter::ErrorStateEkf v(movingState(), filter::Matrix9d::Identity(), m, cv);
    s.predictCovariance(movingState(), w, f, dts[i]);
    v.predictCovariance(movingState(), w, f, dts[i]);
    MatrixXd Ps, Qs, Pv, Qv;
    s.discretize(dts[i], Ps, Qs);
    v.discretize(dts[i], Pv, Qv);
    ePhi[i] = (Ps - Pv).norm();
    eQ[i] = (Qs - Qv).norm();
    EXPECT_LT(ePhi[i], 5e-3 * (Pv - MatrixXd::Identity(Pv.rows(), Pv.cols())).norm());
    EXPECT_LT(eQ[i], 1e-2 * Qv.norm());
  }
  std::cout << "series vs Van Loan: Phi error ratio " << ePhi[0] / ePhi[1] << ", Qd error ratio "
            << eQ[0] / eQ[1] << "\n";
  EXPECT_NEAR(ePhi[0] / ePhi[1], 8.0, 2.0);
  EXPECT_NEAR(eQ[0] / eQ[1], 16.0, 4.0);
}

// Static free-inertial error growth well below the Schuler period (84 min):
// accelerometer white noise N_a: sigma_v = N_a sqrt(t), sigma_p = N_a t^1.5/sqrt(3);
// gyro white noise N_g: sigma_psi = N_g sqrt(t); tilt-induced
// sigma_v = g N_g t^1.5/sqrt(3), sigma_p = g N_g t^2.5/sqrt(20).
TEST(Textbook, WhiteNoiseErrorGrowthFollowsClosedForms) {
  const double rate = 200.0, dt = 1.0 / rate;
  const double sa = 5.526e-3, sg = 9.791e-4;  // Table 1 model-1 per-sample sigmas
  const double Na = sa * std::sqrt(dt), Ng = sg * std::sqrt(dt);
  const ins::NavState x = staticState();
  Vector3d w, f;
  staticRates(x, w, f);
  const double g = earth::gravity_N(x.lat, x.h).z();
  for (const double T : {10.0, 60.0}) {
    filter::ErrorStateEkf acc(x, filter::Matrix9d::Zero(), model({}, {P::wn(sa)}, rate));
    filter::ErrorStateEkf gyr(x, filter::Matrix9d::Zero(), model({P::wn(sg)}, {}, rate));
    const int n = static_cast<int>(std::lround(T * rate));
    for (int k = 0; k < n; ++k) {
      acc.predictCovariance(x, w, f, dt);
      gyr.predictCovariance(x, w, f, dt);
    }
    const Eigen::VectorXd sA = acc.sigmas(), sG = gyr.sigmas();
    const double v_a = Na * std::sqrt(T), p_a = Na * std::pow(T, 1.5) / std::sqrt(3.0);
    const double psi = Ng * std::sqrt(T), v_g = g * Ng * std::pow(T, 1.5) / std::sqrt(3.0),
                 p_g = g * Ng * std::pow(T, 2.5) / std::sqrt(20.0);
    std::cout << "t=" << T << " ratios acc: vN " << sA(3) / v_a << " vD " << sA(5) / v_a
              << " pN " << sA(0) / p_a << " pD " << sA(2) / p_a << "; gyro: psiN " << sG(6) / psi
              << " psiD " << sG(8) / psi << " vN " << sG(3) / v_g << " pN " << sG(0) / p_g << "\n";
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(sA(3 + i) / v_a, 1.0, 0.02) << "acc WN velocity axis " << i << " t=" << T;
      EXPECT_NEAR(sA(0 + i) / p_a, 1.0, 0.02) << "acc WN position axis " << i << " t=" << T;
      EXPECT_NEAR(sG(6 + i) / psi, 1.0, 0.02) << "gyro WN attitude axis " << i << " t=" << T;
    }
    for (int i = 0; i < 2; ++i) {  // horizontal channels driven by tilt
      EXPECT_NEAR(sG(3 + i) / v_g, 1.0, 0.03) << "tilt velocity axis " << i << " t=" << T;
      EXPECT_NEAR(sG(0 + i) / p_g, 1.0, 0.03) << "tilt position axis " << i << " t=" << T;
    }
    // perfect gyros: attitude error only through the transport rate (dv / R)
    EXPECT_LT(sA(6), 1e-6);
  }
}

namespace {
struct RunResult {
  std::vector<double> nees;     // at the check epochs
  std::vector<Eigen::VectorXd> sig;
};

// One static run with the filter fed data simulated from its own model:
// initial errors drawn from P0, GNSS position + velocity at 1 Hz.
RunResult staticRun(const stochastic::ImuModel& m, const filter::EkfConfig& cfg,
                    std::uint64_t seed, double T, const std::vector<double>& checks) {
  const ins::NavState truth = staticState();
  filter::Vector9d p0;
  p0 << 1.0, 1.0, 1.5, 0.1, 0.1, 0.1, 1e-3, 1e-3, 5e-3;
  const filter::Matrix9d P0 = p0.cwiseAbs2().asDiagonal();
  std::mt19937_64 rng(stochastic::deriveSeed(seed, 1000));
  std::normal_distribution<double> nd(0.0, 1.0);
  filter::Vector9d dx0;
  for (int i = 0; i < 9; ++i) dx0(i) = p0(i) * nd(rng);
  filter::ErrorStateEkf ekf(filter::applyNavError(truth, dx0), P0, m, cfg);
  const int n = static_cast<int>(std::lround(T * m.rate_hz));
  const std::vector<ins::ImuSample> imu = simulateStatic(truth, m, n, seed);
  const int per_s = static_cast<int>(std::lround(m.rate_hz));
  RunResult r;
  std::size_t next = 0;
  const Vector3d sp(0.5, 0.5, 0.8), sv(0.05, 0.05, 0.05);
  for (int k = 0; k < n; ++k) {
    ekf.predict(imu[k]);
    if ((k + 1) % per_s == 0) {
      const Vector3d np(sp.x() * nd(rng), sp.y() * nd(rng), sp.z() * nd(rng));
      const Vector3d nv(sv.x() * nd(rng), sv.y() * nd(rng), sv.z() * nd(rng));
      ekf.updateGnssPosition(earth::nedToGeodetic(truth.geodetic(), np), sp);
      ekf.updateGnssVelocity(nv, sv);
      const double t = (k + 1) / m.rate_hz;
      if (next < checks.size() && std::abs(t - checks[next]) < 1e-9) {
        ins::NavState tr = truth;
        const filter::Vector9d e = filter::navError(ekf.state(), tr);
        const filter::Matrix9d Pn = ekf.P().topLeftCorner<9, 9>();
        r.nees.push_back(e.dot(Pn.ldlt().solve(e)));
        r.sig.push_back(ekf.sigmas());
        ++next;
      }
    }
  }
  return r;
}
}  // namespace

// Monte Carlo: 30 runs, seeds 1..30 (fixed before looking at results). The
// mean NEES of the 9 navigation states must lie inside the two-sided 95 %
// band of chi2(9*30)/30.
TEST(MonteCarlo, FilterIsConsistentOnDataFromItsOwnModel) {
  const stochastic::ImuModel m = model({P::wn(1e-3), P::gm(1e-4, 30.0)},
                                       {P::wn(5e-3), P::gm(1e-3, 20.0)}, 100.0);
  const int runs = 30;
  const std::vector<double> checks = {20.0, 40.0, 60.0};
  std::vector<double> mean(checks.size(), 0.0);
  for (int r = 1; r <= runs; ++r) {
    const RunResult rr = staticRun(m, filter::EkfConfig{}, static_cast<std::uint64_t>(r), 60.0, checks);
    ASSERT_EQ(rr.nees.size(), checks.size());
    for (std::size_t i = 0; i < checks.size(); ++i) mean[i] += rr.nees[i] / runs;
  }
  const boost::math::chi_squared chi(9.0 * runs);
  const double lo = boost::math::quantile(chi, 0.025) / runs;
  const double hi = boost::math::quantile(chi, 0.975) / runs;
  for (std::size_t i = 0; i < checks.size(); ++i) {
    std::cout << "mean NEES at t=" << checks[i] << " s: " << mean[i] << " (95% band " << lo
              << " .. " << hi << ")\n";
    EXPECT_GT(mean[i], lo) << "t=" << checks[i];
    EXPECT_LT(mean[i], hi) << "t=" << checks[i];
  }
}

// Covariance propagation every 10th sample (20 Hz) against every sample
// (200 Hz), Table 1 reference model, same data: sigmas and NEES within 1 %.
TEST(LowerRate, PropagationEveryTenSamplesMatchesEverySample) {
  const stochastic::ImuModel m =
      stochastic::loadImuModel(test::sourcePath("config/models/navchip_table1.yaml") + ":ref");
  const std::vector<double> checks = {5.0, 15.0, 30.0};
  filter::EkfConfig every, tenth;
  tenth.propagate_every = 10;
  const RunResult a = staticRun(m, every, 7, 30.0, checks);
  const RunResult b = staticRun(m, tenth, 7, 30.0, checks);
  ASSERT_EQ(a.nees.size(), checks.size());
  double worst_sig = 0.0, worst_nees = 0.0;
  for (std::size_t i = 0; i < checks.size(); ++i) {
    for (int j = 0; j < a.sig[i].size(); ++j)
      if (a.sig[i](j) > 0.0)
        worst_sig = std::max(worst_sig, std::abs(b.sig[i](j) / a.sig[i](j) - 1.0));
    worst_nees = std::max(worst_nees, std::abs(b.nees[i] / a.nees[i] - 1.0));
  }
  std::cout << "propagate_every=10 vs 1: max relative sigma change " << worst_sig
            << ", max relative NEES change " << worst_nees << "\n";
  EXPECT_LT(worst_sig, 0.01);
  EXPECT_LT(worst_nees, 0.01);
}

namespace {
struct DynRun {
  std::vector<double> t;                 // record epochs (1 Hz and every 5 s in the outage)
  std::vector<Eigen::VectorXd> sig;      // predicted sigmas of the 9 navigation errors
  std::vector<ins::NavState> est;        // estimates
  std::vector<ins::NavState> truth;
};

// The committed UAV excerpt (first 150 s) through the emulation with the
// Table 1 Ref errors on all six axes, filtered with the Ref model: GNSS
// position + velocity at 1 Hz except in the outage (90, 150] s, baro at 10 Hz.
DynRun dynamicRun(const Recording& d, const stochastic::ImuModel& m, int every) {
  filter::EkfConfig cfg;
  cfg.propagate_every = every;
  const double dt = 1.0 / d.imu_rate_hz;
  auto truthAt = [&](std::size_t i) { return ins::navStateOf(d.reference[i], d.origin); };
  ins::NavState x0 = truthAt(0);
  x0.t = d.imu.front().t - dt;
  filter::Vector9d p0;
  p0 << 1.0, 1.0, 1.0, 0.1, 0.1, 0.1, 0.2 * kDeg, 0.2 * kDeg, 1.0 * kDeg;
  filter::ErrorStateEkf ekf(x0, p0.cwiseAbs2().asDiagonal(), m, cfg);
  DynRun r;
  std::size_t ig = 0, ib = 0, it = 0;
  double prev = x0.t;
  const double outage0 = 90.0, outage1 = 150.0;
  for (const ImuRecord& rec : d.imu) {
    ekf.predict(ins::ImuSample::fromRates(rec.t, rec.t - prev, rec.w_IB_B, rec.f_B));
    prev = rec.t;
    while (ig < d.gnss.size() && d.gnss[ig].t <= rec.t + 0.5 * dt) {
      const GnssFix& f = d.gnss[ig++];
      if (f.t - d.t_start_s > outage0 && f.t - d.t_start_s <= outage1) continue;
      ekf.updateGnssPosition(f.pos, f.cov_pos_N->diagonal().cwiseSqrt());
      ekf.updateGnssVelocity(*f.v_N, f.cov_vel_N->diagonal().cwiseSqrt());
    }
    while (ib < d.baro.size() && d.baro[ib].t <= rec.t + 0.5 * dt) {
      ekf.updateBaro(d.baro[ib].h, *d.baro[ib].sigma_m);
      ++ib;
    }
    while (it < d.reference.size() && d.reference[it].t <= rec.t + 0.5 * dt) {
      const double tr = d.reference[it].t - d.t_start_s;
      if (std::abs(tr - std::round(tr)) < 1e-6) {  // 1 Hz
        ekf.flushPropagation();
        r.t.push_back(tr);
        r.sig.push_back(ekf.sigmas().head<9>());
        r.est.push_back(ekf.state());
        r.truth.push_back(truthAt(it));
      }
      ++it;
    }
  }
  return r;
}
}  // namespace

// Lower-rate covariance propagation on a DYNAMIC flight (the real UAV
// trajectory: climbing turns, |w| up to ~0.5 rad/s, |f_horizontal| up to
// ~5 m/s^2), 200 Hz, Ref model: propagate_every = 10 (one Phi and Qd per
// 50 ms from the interval means) against every sample. Tolerances: predicted
// sigmas of position, velocity and attitude within 0.5 % at every epoch,
// including the end of a 60 s GNSS outage, and estimates within 1 % of the
// predicted sigma of each other. What the study can resolve sets the scale:
// with 100 Monte Carlo runs the mean NEES of a 3-dof block has a standard
// error of sqrt(2/3/100) = 8 % (a sigma change of x moves the NEES by 2x),
// and the candidate models differ in their sigmas by factors of 1.5-10, so a
// 0.5 % sigma change (1 % in NEES) cannot move a model across the paper's
// consistency verdicts. (Measured: ~5e-5 relative, see the printed line.)
TEST(LowerRate, PropagationEveryTenSamplesOnTurningFlightWithOutage) {
  emulation::EmulationConfig ec =
      emulation::loadEmulationConfig(test::sourcePath("config/emulation/uav_flight_260s_ref.yaml"));
  ec.trajectory.end_s = 150.0;
  const Recording d = emulation::runEmulation(ec, "test");
  const stochastic::ImuModel m =
      stochastic::loadImuModel(test::sourcePath("config/models/navchip_table1.yaml") + ":ref");
  const DynRun a = dynamicRun(d, m, 1);
  const DynRun b = dynamicRun(d, m, 10);
  ASSERT_EQ(a.t.size(), b.t.size());
  ASSERT_GE(a.t.size(), 140u);
  double worst_sig[3] = {0, 0, 0}, worst_est = 0.0, worst_err_a = 0.0;
  for (std::size_t i = 0; i < a.t.size(); ++i) {
    for (int j = 0; j < 9; ++j)
      worst_sig[j / 3] = std::max(worst_sig[j / 3], std::abs(b.sig[i](j) / a.sig[i](j) - 1.0));
    const filter::Vector9d dab = filter::navError(b.est[i], a.est[i]);
    const filter::Vector9d ea = filter::navError(a.est[i], a.truth[i]);
    for (int j = 0; j < 9; ++j) {
      worst_est = std::max(worst_est, std::abs(dab(j)) / a.sig[i](j));
      worst_err_a = std::max(worst_err_a, std::abs(ea(j)) / a.sig[i](j));
    }
  }
  std::cout << "turning flight, propagate_every=10 vs 1: max relative sigma change pos "
            << worst_sig[0] << " vel " << worst_sig[1] << " att " << worst_sig[2]
            << "; max |estimate difference| / sigma " << worst_est
            << " (max |error| / sigma of the every-sample filter " << worst_err_a << ")\n";
  // the outage really happened: horizontal sigma at its end well above the GNSS-aided level
  const std::size_t k_end = a.t.size() - 1, k_aided = 80;
  EXPECT_GT(a.sig[k_end].head<2>().norm(), 3.0 * a.sig[k_aided].head<2>().norm());
  for (int blk = 0; blk < 3; ++blk) EXPECT_LT(worst_sig[blk], 0.005) << "block " << blk;
  EXPECT_LT(worst_est, 0.01);
}
