// Optional extra error states (state_layout.hpp, ExtraStates): scale factor,
// misalignment, lever arm, time offset. Their F columns against the nonlinear
// mechanization, their H columns against the nonlinear residuals, and an
// emulated run with a hidden effect drawn over its documented range (seed and
// values printed): the filter with the matching state estimates it within 3
// sigma and stays consistent, the filter without it does worse.
#include <gtest/gtest.h>

#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>
#include <cstdio>
#include <random>

#include "filter_test_util.hpp"
#include "navimpact/core/config.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/limits.hpp"
#include "navimpact/emulation/perfect_imu.hpp"
#include "navimpact/emulation/scenario.hpp"
#include "navimpact/emulation/sensor_effects.hpp"
#include "test_support.hpp"

using namespace navimpact;
using namespace ftest;
using filter::Extra;

namespace {

filter::ExtraStates allExtras() {
  filter::ExtraStates x;
  x.gyro_scale_sigma = 0.01;
  x.acc_scale_sigma = 0.01;
  x.gyro_misalignment_sigma_rad = 0.005;
  x.acc_misalignment_sigma_rad = 0.005;
  x.lever_arm_sigma_m = 1.0;
  x.time_offset_sigma_s = 0.1;
  return x;
}

double uni(std::mt19937_64& g, double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(g); }
Vector3d uni3(std::mt19937_64& g, double a) { return {uni(g, -a, a), uni(g, -a, a), uni(g, -a, a)}; }

// A random moving state and body rates / specific force.
void randomMotion(std::mt19937_64& g, ins::NavState& x, Vector3d& w, Vector3d& f) {
  x.lat = uni(g, -60, 60) * kDeg;
  x.lon = uni(g, -180, 180) * kDeg;
  x.h = uni(g, 0, 3000);
  x.v_N = uni3(g, 40.0);
  x.setRollPitchYaw(uni(g, -30, 30) * kDeg, uni(g, -20, 20) * kDeg, uni(g, -180, 180) * kDeg);
  w = uni3(g, 0.5);
  f = Vector3d(uni(g, -3, 3), uni(g, -3, 3), uni(g, -12, -7));
}

Matrix3d triadM(const Vector3d& s, const Vector3d& m) {
  return Matrix3d::Identity() + Matrix3d(s.asDiagonal()) + ins::skew(m);
}

// Index helpers: the extra sensor groups and their triad.
struct Group {
  Extra g;
  bool gyro, scale;
  const char* name;
};
const Group kSensorGroups[] = {{Extra::GyroScale, true, true, "gyro scale"},
                               {Extra::AccScale, false, true, "acc scale"},
                               {Extra::GyroMisalignment, true, false, "gyro misalignment"},
                               {Extra::AccMisalignment, false, false, "acc misalignment"}};

}  // namespace

TEST(ExtraStates, OffByDefaultAndLaidOutAfterTheModelStates) {
  using P = stochastic::Process;
  const auto mdl = model({P::wn(1e-3), P::gm(5e-5, 60.0)}, {P::wn(5e-3)}, 200.0);
  const auto base = filter::StateLayout::build(mdl);
  EXPECT_FALSE(base.hasExtra());
  for (int g = 0; g < filter::kExtraGroups; ++g) EXPECT_EQ(base.extraIndex(Extra(g)), -1);
  filter::ImuErrorOptions o;
  o.extra = allExtras();
  const auto L = filter::StateLayout::build(mdl, o);
  EXPECT_EQ(L.size(), base.size() + 16);
  EXPECT_EQ(L.extraIndex(Extra::GyroScale), base.size());
  EXPECT_EQ(L.extraIndex(Extra::TimeOffset), base.size() + 15);
  EXPECT_EQ(L.names()[base.size()], "gyro.scale_x(sigma=0.01)");
  EXPECT_EQ(L.names()[base.size() + 12], "gnss.lever_arm_error_x(sigma=1 m)");
  EXPECT_EQ(L.names().back(), "gnss.time_offset(sigma=0.1 s)");
  for (int i = 0; i < base.size(); ++i) EXPECT_EQ(L.names()[i], base.names()[i]);
  const MatrixXd P0 = L.imuP0();
  EXPECT_EQ(P0(L.extraIndex(Extra::LeverArm) - filter::kNav, L.extraIndex(Extra::LeverArm) - filter::kNav), 1.0);
  for (int c = 0; c < 6; ++c) EXPECT_EQ(L.sensorRow(c).tail(16).norm(), 0.0);
  o.extra.time_offset_sigma_s = -1.0;
  try {
    filter::StateLayout::build(mdl, o);
    ADD_FAILURE() << "negative sigma accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("time_offset_sigma_s"), std::string::npos) << e.what();
  }
}

TEST(ExtraStates, ConfigKeysSwitchThemOn) {
  const ConfigNode n = ConfigNode::parse(
      "extra_states:\n"
      "  scale_factor: {gyro_sigma: 0.005, acc_sigma: 0.004}\n"
      "  misalignment: {gyro_sigma_rad: 0.003}\n"
      "  lever_arm: {sigma_m: 0.5}\n"
      "  time_offset: {sigma_s: 0.05}\n",
      "f.yaml");
  filter::ExtraStates x;
  x.loadFrom(n.map("extra_states"));
  EXPECT_EQ(x.gyro_scale_sigma, 0.005);
  EXPECT_EQ(x.acc_scale_sigma, 0.004);
  EXPECT_EQ(x.gyro_misalignment_sigma_rad, 0.003);
  EXPECT_EQ(x.acc_misalignment_sigma_rad, 0.0);  // left out: off
  EXPECT_EQ(x.lever_arm_sigma_m, 0.5);
  EXPECT_EQ(x.time_offset_sigma_s, 0.05);
  auto err = [](const std::string& text) {
    try {
      filter::ExtraStates y;
      y.loadFrom(ConfigNode::parse(text, "f.yaml").map("extra_states"));
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(err("extra_states: {time_offset: {sigma_s: 0.5}}"),
            "f.yaml: key 'extra_states.time_offset.sigma_s': must be in [1e-07, 0.1] s, got 0.5");
  EXPECT_NE(err("extra_states: {scale: {gyro_sigma: 0.01}}").find("unknown key"), std::string::npos);
  EXPECT_NE(err("extra_states: {lever_arm: {sigma_m: 0}}").find("[0.0001, 10] m"), std::string::npos);
}

// Initial estimates (prior means): read from the configuration within the
// effects' ranges, and the filter starts from them (zero for a group that is off).
TEST(ExtraStates, InitialEstimatesAreReadAndUsed) {
  const ConfigNode n = ConfigNode::parse(
      "extra_states:\n"
      "  scale_factor: {gyro_sigma: 0.001, gyro: [0.002, -0.001, 0.0005], acc: [0.01, 0, 0]}\n"
      "  misalignment: {acc_sigma_rad: 0.002, acc_rad: [0.001, 0.002, -0.003]}\n"
      "  lever_arm: {sigma_m: 0.1, error_m: [0.3, -0.2, 0.1]}\n"
      "  time_offset: {sigma_s: 0.001, offset_s: -0.02}\n",
      "f.yaml");
  filter::ExtraStates x;
  x.loadFrom(n.map("extra_states"));
  EXPECT_EQ(x.gyro_scale0, Vector3d(0.002, -0.001, 0.0005));
  EXPECT_EQ(x.acc_misalignment0_rad, Vector3d(0.001, 0.002, -0.003));
  EXPECT_EQ(x.lever_arm_error0_m, Vector3d(0.3, -0.2, 0.1));
  EXPECT_EQ(x.time_offset0_s, -0.02);
  using P = stochastic::Process;
  const auto mdl = model({P::wn(1e-3)}, {P::wn(5e-3)}, 200.0);
  filter::EkfConfig cfg;
  cfg.imu.extra = x;
  ins::NavState x0;
  x0.lat = 0.8;
  filter::ErrorStateEkf ekf(x0, filter::Matrix9d::Identity(), mdl, cfg);
  const filter::SensorParams e = ekf.extraEstimates();
  EXPECT_EQ(e.gyro_scale, x.gyro_scale0);
  EXPECT_EQ(e.acc_scale, Vector3d::Zero());  // acc_sigma left out: off, its initial value unused
  EXPECT_EQ(e.acc_misalignment_rad, x.acc_misalignment0_rad);
  EXPECT_EQ(e.lever_arm_error_B_m, x.lever_arm_error0_m);
  EXPECT_EQ(e.time_offset_s, -0.02);
  EXPECT_EQ(ekf.extraSigmas().time_offset_s, 0.001);
  try {
    filter::ExtraStates y;
    y.loadFrom(ConfigNode::parse("extra_states: {time_offset: {sigma_s: 0.01, offset_s: 0.2}}", "f.yaml")
                   .map("extra_states"));
    FAIL() << "no error";
  } catch (const Error& err) {
    EXPECT_EQ(std::string(err.what()), "f.yaml: key 'extra_states.time_offset.offset_s': must be in [-0.1, 0.1] s, got 0.2");
  }
}

// F columns of the scale-factor and misalignment states: Phi from the exact
// exponential against central differences of the nonlinear mechanization fed
// the output the estimate corrects (corrected = M_est^-1 M_true true with the
// truth's M = I), at random moving states (seeded).
TEST(ExtraStates, TransitionColumnsMatchNonlinearMechanization) {
  const std::uint64_t seed = 31;
  std::mt19937_64 g(seed);
  using P = stochastic::Process;
  const auto mdl = model({P::wn(1e-3), P::gm(5e-5, 60.0)}, {P::wn(5e-3), P::gm(5e-4, 3.0)}, 200.0);
  for (int trial = 0; trial < 6; ++trial) {
    ins::NavState truth;
    Vector3d w, f;
    randomMotion(g, truth, w, f);
    filter::EkfConfig cfg;
    cfg.discretization = filter::Discretization::VanLoan;
    cfg.imu.extra = allExtras();
    filter::ErrorStateEkf ekf(truth, filter::Matrix9d::Identity(), mdl, cfg);
    const double dt = 0.02;
    const ins::NavState mid = ins::mechanize(truth, ins::ImuSample::fromRates(truth.t + dt / 2, dt / 2, w, f), nullptr);
    ekf.predictCovariance(mid, w, f, dt);
    MatrixXd Phi, Qd;
    ekf.discretize(dt, Phi, Qd);
    const ins::ImuSample s_true = ins::ImuSample::fromRates(truth.t + dt, dt, w, f);
    const ins::NavState t1 = ins::mechanize(truth, s_true, nullptr);
    for (const Group& gr : kSensorGroups) {
      const int k0 = ekf.layout().extraIndex(gr.g);
      ASSERT_GE(k0, 0);
      for (int i = 0; i < 3; ++i) {
        // large enough that the position response (f eps dt^2 / 2) stands above the
        // rounding of latitude (1e-9 m); central differences err by O(eps^2)
        const double eps = 1e-2;
        auto dx1 = [&](double d) {
          Vector3d v = Vector3d::Zero();
          v(i) = d;
          const Matrix3d Mest = gr.scale ? triadM(v, Vector3d::Zero()) : triadM(Vector3d::Zero(), v);
          ins::ImuSample s = s_true;
          if (gr.gyro) {
            s.dtheta_B = Mest.inverse() * s.dtheta_B;
          } else {
            s.dv_B = Mest.inverse() * s.dv_B;
          }
          return filter::navError(ins::mechanize(truth, s, nullptr), t1);
        };
        const filter::Vector9d J = (dx1(eps) - dx1(-eps)) / (2 * eps);
        const filter::Vector9d lin = Phi.block<9, 1>(0, k0 + i);
        // rows: velocity and attitude (first order in dt); position responds
        // at second order (accelerometer states) and is compared too, with the
        // rotation of the body over the interval as extra tolerance (as for the
        // bias states in test_jacobians.cpp).
        const double rot_rel = w.norm() * dt;
        for (int blk = 0; blk < 3; ++blk) {
          if (blk == 0 && gr.gyro) continue;  // third order: gyro -> attitude -> velocity -> position
          const Vector3d a = lin.segment<3>(3 * blk), b = J.segment<3>(3 * blk);
          const double scale = std::max(a.norm(), b.norm());
          // gyro -> velocity is second order in dt (through the attitude), where the
          // rotating body and the midpoint linearisation differ by O(|w| dt) with a
          // larger constant (up to 3 |w| dt here; the exact-exponential Phi is
          // linearised at the interval midpoint)
          const double rel = 2e-3 + (gr.gyro && blk == 1 ? 3.0 : 1.0) * rot_rel;
          EXPECT_LE((a - b).norm(), rel * scale + 1e-9 / eps)
              << "trial " << trial << " " << gr.name << " axis " << i << " block " << blk << "\nlinear: "
              << a.transpose() << "\nnonlinear: " << b.transpose();
        }
        // the coupling is there (a wrong sign fails above, a missing term here)
        EXPECT_GT(lin.segment<3>(gr.gyro ? 6 : 3).norm(), 1e-3 * dt) << gr.name << " axis " << i;
      }
    }
    // lever arm and time offset do not enter the dynamics; all extras are constants
    for (Extra e : {Extra::LeverArm, Extra::TimeOffset}) {
      const int k0 = ekf.layout().extraIndex(e), n = e == Extra::TimeOffset ? 1 : 3;
      EXPECT_EQ(Phi.block(0, k0, 9, n).norm(), 0.0);
    }
    const int x0 = ekf.layout().extraIndex(Extra::GyroScale);
    EXPECT_LT((Phi.block(x0, x0, 16, 16) - MatrixXd::Identity(16, 16)).norm(), 1e-12);
    EXPECT_EQ(Qd.block(x0, x0, 16, 16).norm(), 0.0);
  }
}

// H columns of every extra state against central differences of the nonlinear
// GNSS residuals: the true antenna is at lever_told - e (e the true lever-arm
// error), the estimate carries e_est = e + de, s_est, m_est, d_est.
TEST(ExtraStates, GnssMeasurementColumnsMatchNonlinearResiduals) {
  const std::uint64_t seed = 32;
  std::mt19937_64 g(seed);
  using P = stochastic::Process;
  const auto mdl = model({P::wn(1e-3)}, {P::wn(5e-3)}, 200.0);
  filter::EkfConfig cfg;
  cfg.imu.extra = allExtras();
  for (int trial = 0; trial < 6; ++trial) {
    ins::NavState truth;
    Vector3d w, f;
    randomMotion(g, truth, w, f);
    const Vector3d told = uni3(g, 2.0), e_true = uni3(g, 0.5);
    const Vector3d l_true = told - e_true;
    const Matrix3d C = truth.C_BtoN();
    const earth::Geodetic z_pos = earth::nedToGeodetic(truth.geodetic(), C * l_true);
    const Vector3d z_vel = truth.v_N + C * w.cross(l_true) - earth::w_IE_N(truth.lat).cross(C * l_true);
    const double dt_meas = trial % 2 ? 0.003 : 0.0;

    filter::ErrorStateEkf ref(truth, filter::Matrix9d::Identity(), mdl, cfg);
    const int N = ref.size(), m = ref.layout().imuSize();
    const int kl = ref.layout().extraIndex(Extra::LeverArm);
    VectorXd x_true = VectorXd::Zero(m);  // the extra states at the truth
    x_true.segment<3>(kl - filter::kNav) = e_true;

    auto residuals = [&](const VectorXd& dx) {
      filter::ErrorStateEkf e(truth, filter::Matrix9d::Identity(), mdl, cfg);
      const VectorXd xi = x_true + dx.tail(m);
      e.setImuStates(xi);
      const filter::SensorParams p = e.extraEstimates();
      // corrected output of the estimate: M_est^-1 times the true output (true M = I)
      const Vector3d wc = triadM(p.gyro_scale, p.gyro_misalignment_rad).inverse() * w;
      const Vector3d fc = triadM(p.acc_scale, p.acc_misalignment_rad).inverse() * f;
      e.predictCovariance(filter::applyNavError(truth, dx.head<9>()), wc, fc, 0.005);
      VectorXd r(6);
      r.head<3>() = e.residualGnssPosition(z_pos, told, dt_meas);
      r.tail<3>() = e.residualGnssVelocity(z_vel, told, dt_meas);
      return r;
    };
    ref.setImuStates(x_true);
    ref.predictCovariance(truth, w, f, 0.005);
    MatrixXd H(6, N);
    H << ref.H_gnssPosition(told, dt_meas), ref.H_gnssVelocity(told, dt_meas);
    if (dt_meas == 0.0) { EXPECT_LT(residuals(VectorXd::Zero(N)).norm(), 1e-6); }  // the truth predicts z
    for (int j = ref.layout().extraIndex(Extra::GyroScale); j < N; ++j) {
      const double eps = j >= kl && j < kl + 3 ? 1e-2 : 1e-4;
      VectorXd d = VectorXd::Zero(N);
      d(j) = eps;
      const VectorXd J = (residuals(d) - residuals(-d)) / (2 * eps);
      const double scale = std::max(H.col(j).norm(), J.norm());
      EXPECT_LE((H.col(j) - J).norm(), 1e-5 * scale + 1e-7)
          << "trial " << trial << " " << ref.layout().names()[j] << "\nH: " << H.col(j).transpose()
          << "\nnonlinear: " << J.transpose();
    }
    // the lever arm and the time offset are observable from a single fix
    EXPECT_GT(H.block(0, kl, 3, 3).norm(), 1.0);
    EXPECT_GT(H.col(N - 1).head<3>().norm(), 1.0);  // |v_ant| of a moving vehicle
  }
}

// ---------------------------------------------------------------------------
// Consistency on an emulated flight with a hidden effect.

namespace {

struct Flight {
  std::optional<emulation::SmoothTrajectory> tr;
  std::vector<ins::ImuSample> perfect;
  stochastic::ImuModel model;  // at the IMU rate
  double t0 = 0, t1 = 0, rate = 100.0;
};

const Flight& flight() {
  static const Flight F = [] {
    Flight f;
    emulation::EmulationConfig ec =
        emulation::loadEmulationConfig(test::sourcePath("config/emulation/uav_flight_260s_ref.yaml"));
    ec.trajectory.end_s = 200.0;
    f.tr.emplace(emulation::readTrajectoryCsv(ec.trajectory), ec.smoothing);
    f.perfect = emulation::perfectImu(*f.tr, f.rate);
    f.t0 = f.tr->tBegin();
    f.t1 = f.perfect.back().t;
    f.model = stochastic::convertRate(
        stochastic::loadImuModel(test::sourcePath("config/models/navchip_table1.yaml") + ":ref"), f.rate);
    return f;
  }();
  return F;
}

struct RunResult {
  double nees_sum = 0;   // position NEES summed over the scored epochs
  int epochs = 0;
  double err2_sum = 0;   // horizontal position error^2 summed over the scored epochs
  filter::SensorParams est, sig;
};

// One run: model errors + the effect, GNSS (1 Hz, Table 2 noise) at the true
// antenna, a 30 s outage from 140 s after the start; the filter is told
// `told` as lever arm. Scored every second from 60 s on (after convergence),
// inside and outside the outage. With a time offset d the filter state at IMU
// time t is the truth at t - d (state_layout.hpp): it starts from the truth at
// t - d and is scored against it.
RunResult runOnce(const emulation::SensorEffects& fx, const filter::ExtraStates& extra, std::uint64_t seed) {
  const Flight& F = flight();
  const std::size_t n = F.perfect.size();
  const auto err = emulation::modelImuErrors(F.model, F.rate, n, stochastic::deriveSeed(seed, 0));
  const auto imu = emulation::applySensorEffects(F.perfect, err.axis, fx,
                                                 emulation::whiteNoiseSigma(F.model, F.rate),
                                                 stochastic::deriveSeed(seed, 1)).imu;
  emulation::GnssOptions told;
  told.lever_arm_B = Vector3d(0.3, 0.1, -0.5);
  told.seed = stochastic::deriveSeed(seed, 2);
  const auto gnss = emulation::simulateGnss(*F.tr, emulation::gnssWithEffects(told, fx), F.t0, F.t1);
  const Vector3d sp(told.sigma_pos_h_m, told.sigma_pos_h_m, told.sigma_pos_v_m);
  const Vector3d sv(told.sigma_vel_h_mps, told.sigma_vel_h_mps, told.sigma_vel_v_mps);

  filter::Vector9d s0;
  s0 << 1.0, 1.0, 1.0, 0.1, 0.1, 0.1, 0.5 * kDeg, 0.5 * kDeg, 2.0 * kDeg;
  const auto z = emulation::standardNormal(9, stochastic::deriveSeed(seed, 3));
  filter::Vector9d dx0;
  for (int i = 0; i < 9; ++i) dx0(i) = s0(i) * z[i];
  const double d = fx.time_offset_s;
  // first IMU sample whose true time t - d lies on the trajectory
  std::size_t k0 = 0;
  while (imu[k0].t - imu[k0].dt - d < F.t0) ++k0;
  const double ts = imu[k0].t - imu[k0].dt;
  ins::NavState x0 = filter::applyNavError(emulation::truthNavState(*F.tr, ts - d), dx0);
  x0.t = ts;
  filter::EkfConfig cfg;
  cfg.propagate_every = 5;
  cfg.imu.extra = extra;
  filter::ErrorStateEkf ekf(x0, filter::Matrix9d(s0.cwiseAbs2().asDiagonal()), F.model, cfg);

  const double out0 = F.t0 + 140.0, out1 = out0 + 30.0;
  RunResult r;
  std::size_t gi = 0;
  const std::size_t step = std::size_t(std::llround(F.rate));
  for (std::size_t k = k0; k < n; ++k) {
    ekf.predict(imu[k]);
    const double t = imu[k].t;
    while (gi < gnss.size() && gnss[gi].t < t - 1e-6) ++gi;
    if (gi < gnss.size() && std::abs(gnss[gi].t - t) < 1e-6 && !(t > out0 && t <= out1)) {
      ekf.updateGnssPosition(gnss[gi].pos, sp, told.lever_arm_B);
      ekf.updateGnssVelocity(*gnss[gi].v_N, sv, told.lever_arm_B);
    }
    if ((k + 1) % step == 0 && t >= F.t0 + 60.0 && t - d <= F.t1) {
      ekf.flushPropagation();
      ins::NavState truth = emulation::truthNavState(*F.tr, t - d);
      truth.t = t;
      const filter::Vector9d e = filter::navError(ekf.state(), truth);
      const Vector3d ep = e.head<3>();
      r.nees_sum += ep.dot(ekf.P().topLeftCorner<3, 3>().ldlt().solve(ep));
      r.err2_sum += ep.head<2>().squaredNorm();
      ++r.epochs;
    }
  }
  r.est = ekf.extraEstimates();
  r.sig = ekf.extraSigmas();
  return r;
}

struct Summary {
  double mean_nees = 0, rms_h = 0;
  std::vector<RunResult> runs;
};

Summary monteCarlo(const emulation::SensorEffects& fx, const filter::ExtraStates& extra, std::uint64_t seed,
                   int runs) {
  Summary s;
  double nees = 0, e2 = 0;
  int ep = 0;
  for (int i = 0; i < runs; ++i) {
    s.runs.push_back(runOnce(fx, extra, stochastic::deriveSeed(seed, 100 + i)));
    nees += s.runs.back().nees_sum;
    e2 += s.runs.back().err2_sum;
    ep += s.runs.back().epochs;
  }
  s.mean_nees = nees / ep;
  s.rms_h = std::sqrt(e2 / ep);
  return s;
}

constexpr int kRuns = 6;

// Band of the mean position NEES over kRuns runs at one epoch (chi^2 with 3 kRuns
// dof, two-sided 99 %); averaging over correlated epochs only narrows the
// spread, so the band is conservative for the mean over epochs too.
std::pair<double, double> neesBand() {
  const boost::math::chi_squared c(3 * kRuns);
  return {boost::math::quantile(c, 0.005) / kRuns, boost::math::quantile(c, 0.995) / kRuns};
}

// Check estimates (per run, per component) within 3 sigma of the hidden value.
void expectCovered(const std::vector<RunResult>& runs, const char* what, const Vector3d& truth,
                   Eigen::Vector3d filter::SensorParams::*field) {
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const Vector3d est = runs[i].est.*field, sig = runs[i].sig.*field;
    for (int a = 0; a < 3; ++a)
      EXPECT_LE(std::abs(est(a) - truth(a)), 3.0 * sig(a))
          << what << " run " << i << " axis " << a << ": estimate " << est(a) << " truth " << truth(a) << " sigma "
          << sig(a);
  }
}

void report(const char* what, const Summary& with, const Summary& without) {
  const auto band = neesBand();
  std::printf("%s: with the state mean position NEES %.3f (band %.3f-%.3f), horizontal RMS %.3f m; without: "
              "NEES %.3f, RMS %.3f m\n",
              what, with.mean_nees, band.first, band.second, with.rms_h, without.mean_nees, without.rms_h);
}

// The filter without the state is worse: its position NEES leaves the band or its
// error is larger. Required when the hidden effect is at least `share` of its
// documented range (smaller effects may be below what 200 s of flight reveal;
// they are printed, and the filter with the state must still be consistent).
void expectWorseWithout(const Summary& with, const Summary& without, double share) {
  const auto band = neesBand();
  const bool worse = without.mean_nees > band.second || without.rms_h > with.rms_h;
  if (share >= 0.2) {
    EXPECT_TRUE(worse) << "effect at " << share << " of its range";
  } else {
    std::printf("effect at %.2f of its range: the check that the filter without it is worse is skipped\n", share);
  }
}

/// The Monte Carlo runs with the extra states @p x and without them, on
/// flights with the hidden effects @p fx (printed), reported as @p what.
struct Runs {
  Summary with, without;
};
Runs runWithAndWithout(const emulation::SensorEffects& fx, const filter::ExtraStates& x, std::uint64_t seed,
                       const char* what) {
  std::printf("seed %llu: hidden %s\n", (unsigned long long)seed, emulation::describeEffects(fx).c_str());
  const Runs r{monteCarlo(fx, x, seed, kRuns), monteCarlo(fx, {}, seed, kRuns)};
  report(what, r.with, r.without);
  return r;
}

/// The filter with the state is consistent (mean position NEES within its
/// band); the one without it is worse for an effect of @p share of its range.
void expectConsistentAndWorseWithout(const Runs& r, double share) {
  const auto band = neesBand();
  EXPECT_GE(r.with.mean_nees, band.first);
  EXPECT_LE(r.with.mean_nees, band.second);
  expectWorseWithout(r.with, r.without, share);
}

/// An effect on both triads (the gyro's and the accelerometer's vector), each
/// axis uniform over its documented range [-hi, hi], and the filter's state for it.
struct TriadEffect {
  const char* what;   ///< in the report
  const char* label;  ///< in the coverage messages, after "gyro " / "acc "
  double hi;
  Vector3d emulation::SensorEffects::*gyro;
  Vector3d emulation::SensorEffects::*acc;
  double filter::ExtraStates::*gyro_sigma;
  double filter::ExtraStates::*acc_sigma;
  Vector3d filter::SensorParams::*gyro_est;
  Vector3d filter::SensorParams::*acc_est;
};

/// The hidden triad effect drawn from @p seed is estimated within 3 sigma by
/// the filter with its state (sigma half the range), which stays consistent.
void checkTriadEstimated(const TriadEffect& e, std::uint64_t seed) {
  std::mt19937_64 g(seed);
  emulation::SensorEffects fx;
  fx.*e.gyro = uni3(g, e.hi);
  fx.*e.acc = uni3(g, e.hi);
  filter::ExtraStates x;
  x.*e.gyro_sigma = x.*e.acc_sigma = e.hi / 2;  // the documented range is +-2 sigma
  const Runs r = runWithAndWithout(fx, x, seed, e.what);
  for (std::size_t i = 0; i < r.with.runs.size(); ++i)
    std::printf("  run %zu: gyro %s estimate %s sigma %s\n", i, e.label,
                formatNumber((r.with.runs[i].est.*e.gyro_est).x()).c_str(),
                formatNumber((r.with.runs[i].sig.*e.gyro_est).x()).c_str());
  expectCovered(r.with.runs, (std::string("gyro ") + e.label).c_str(), fx.*e.gyro, e.gyro_est);
  expectCovered(r.with.runs, (std::string("acc ") + e.label).c_str(), fx.*e.acc, e.acc_est);
  expectConsistentAndWorseWithout(r, std::max((fx.*e.gyro).cwiseAbs().maxCoeff(), (fx.*e.acc).cwiseAbs().maxCoeff()) / e.hi);
}

}  // namespace

TEST(ExtraStatesConsistency, HiddenScaleFactorIsEstimated) {
  checkTriadEstimated({"scale factor", "scale", limits::kScaleFactor.hi, &emulation::SensorEffects::gyro_scale,
                       &emulation::SensorEffects::acc_scale, &filter::ExtraStates::gyro_scale_sigma,
                       &filter::ExtraStates::acc_scale_sigma, &filter::SensorParams::gyro_scale,
                       &filter::SensorParams::acc_scale},
                      41);
}

TEST(ExtraStatesConsistency, HiddenMisalignmentIsEstimated) {
  checkTriadEstimated({"misalignment", "misalignment", limits::kMisalignmentRad.hi,
                       &emulation::SensorEffects::gyro_misalignment_rad, &emulation::SensorEffects::acc_misalignment_rad,
                       &filter::ExtraStates::gyro_misalignment_sigma_rad, &filter::ExtraStates::acc_misalignment_sigma_rad,
                       &filter::SensorParams::gyro_misalignment_rad, &filter::SensorParams::acc_misalignment_rad},
                      42);
}

TEST(ExtraStatesConsistency, HiddenLeverArmErrorIsEstimated) {
  const std::uint64_t seed = 43;
  std::mt19937_64 g(seed);
  const double r = limits::kLeverArmErrorM.hi;
  emulation::SensorEffects fx;
  fx.lever_arm_error_B_m = uni3(g, r);
  filter::ExtraStates x;
  x.lever_arm_sigma_m = r / 2;
  const Runs runs = runWithAndWithout(fx, x, seed, "lever arm");
  expectCovered(runs.with.runs, "lever arm error", fx.lever_arm_error_B_m, &filter::SensorParams::lever_arm_error_B_m);
  expectConsistentAndWorseWithout(runs, fx.lever_arm_error_B_m.cwiseAbs().maxCoeff() / r);
}

TEST(ExtraStatesConsistency, HiddenTimeOffsetIsEstimated) {
  const std::uint64_t seed = 44;
  std::mt19937_64 g(seed);
  const double r = limits::kTimeOffsetS.hi;
  emulation::SensorEffects fx;
  fx.time_offset_s = uni(g, -r, r);
  filter::ExtraStates x;
  x.time_offset_sigma_s = r / 2;
  const Runs runs = runWithAndWithout(fx, x, seed, "time offset");
  const Summary& with = runs.with;
  // The filter's model is first order in d (v(t) = v(t - d) + a(t - d) d); the
  // value it can reach is the least-squares first-order offset of the truth at
  // the GNSS epochs, d1 = sum dv . a / sum |a|^2 with dv = v(t) - v(t - d) (the
  // GNSS velocity, far more precise than the position, dominates). On this
  // flight d1 = 0.9943 d at d = 0.05 s, 0.9795 d at 0.15 s, 0.962 d at 0.3 s.
  const Flight& F = flight();
  const double d = fx.time_offset_s;
  double num = 0, den = 0;
  for (double t = F.t0 + 1.0; t - d <= F.t1 && t <= F.t1; t += 1.0) {
    if (t - d < F.t0) continue;
    const auto a = F.tr->at(t - d), b = F.tr->at(t);
    num += (b.v_N - a.v_N).dot(a.a_N);
    den += a.a_N.squaredNorm();
  }
  const double d1 = num / den;
  std::printf("first-order least-squares offset of the truth %.5f s (hidden %.5f s)\n", d1, d);
  for (std::size_t i = 0; i < with.runs.size(); ++i) {
    const double e = with.runs[i].est.time_offset_s, s = with.runs[i].sig.time_offset_s;
    std::printf("  run %zu: time offset estimate %.5f s, sigma %.5f s\n", i, e, s);
    EXPECT_LE(std::abs(e - d1), 3.0 * s) << "run " << i;
  }
  expectConsistentAndWorseWithout(runs, std::abs(fx.time_offset_s) / r);
}
