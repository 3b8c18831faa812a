// Covariance analysis in static conditions (paper Figures 5 and 6).
#include "navimpact/analysis/covariance_study.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "navimpact/core/config.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/units.hpp"
#include "navimpact/emulation/perfect_imu.hpp"
#include "navimpact/filter/model_entry.hpp"
#include "navimpact/emulation/trajectory.hpp"
#include "navimpact/stochastic/model_file.hpp"
#include "navimpact/stochastic/model_text.hpp"
#include "navimpact/core/limits.hpp"

namespace navimpact::analysis {

namespace fs = std::filesystem;
using Eigen::Matrix3d;
using Eigen::Vector3d;

namespace {

/// Angles of the static state [deg]; latitude and pitch are further kept off the poles.
constexpr limits::Range kAngleDeg{-360.0, 360.0, false, "deg"};
/// Initial sigmas (0 allowed: a perfectly known start).
constexpr limits::Range kSigma0M{0.0, limits::kPositionSigmaM.hi, false, "m"};
constexpr limits::Range kSigma0Mps{0.0, limits::kVelocitySigmaMps.hi, false, "m/s"};
constexpr limits::Range kSigma0Deg{0.0, 180.0, false, "deg"};
/// Barometer rate, 0 = no barometer [Hz].
constexpr limits::Range kBaroRateHz{0.0, limits::kAidingRateHz.hi, false, "Hz"};

std::string modelText(const stochastic::ImuModel& m) {
  const std::string g = stochastic::formatTerms(m.axis[0].terms);
  const std::string a = stochastic::formatTerms(m.axis[3].terms);
  return "gyroscope: " + g + "; accelerometer: " + a;
}

}  // namespace

CovarianceStudyConfig loadCovarianceStudyConfig(const std::string& path) {
  return loadConfigFile(path, &CovarianceStudyConfig::source);
}

namespace {
/// @p rate_hz is imu_rate_hz / k, k whole (to 1e-9).
bool dividesImuRate(double rate_hz, double imu_rate_hz) {
  const double k = imu_rate_hz / rate_hz;
  return std::abs(k - std::round(k)) <= 1e-9 * k;
}
}  // namespace

void CovarianceStudyConfig::loadFrom(const ConfigNode& root) {
  CovarianceStudyConfig& c = *this;
  const std::string& path = root.file();
  root.allowKeys({"model_file", "duration_s", "imu_rate_hz", "output_rate_hz", "summary_times_s", "static_state",
                  "initial_sigma", "baro", "filter", "model_sets"});
  nlohmann::json echo;

  // model file, relative to the configuration file
  const std::string mf = root.has("model_file") ? root.text("model_file") : std::string();
  if (mf.empty()) throw root.error("model_file", "required: path of the IMU error model file");
  c.model_file = root.inputFile("model_file", "the IMU error model file");
  echo["model_file"] = mf;

  root.read("duration_s", c.duration_s, limits::kDurationS);
  root.read("imu_rate_hz", c.imu_rate_hz, limits::kImuRateHz);
  root.read("output_rate_hz", c.output_rate_hz, limits::kAidingRateHz);
  if (c.output_rate_hz > c.imu_rate_hz) throw root.error("output_rate_hz", "must not exceed imu_rate_hz");
  // rows come every k-th IMU step, k whole: a rate that does not divide the
  // IMU's gave rows every 0.335 s for 3 Hz at 200 Hz and moved the summary times
  if (!dividesImuRate(c.output_rate_hz, c.imu_rate_hz))
    throw root.error("output_rate_hz", "must divide imu_rate_hz = " + formatNumber(c.imu_rate_hz) +
                                           " Hz (a row every k-th IMU step, k whole), got " + formatNumber(c.output_rate_hz) + " Hz");
  echo["duration_s"] = c.duration_s;
  echo["imu_rate_hz"] = c.imu_rate_hz;
  echo["output_rate_hz"] = c.output_rate_hz;

  if (root.has("summary_times_s")) {
    c.summary_times_s.clear();
    root.read("summary_times_s", c.summary_times_s, limits::Range{0.0, c.duration_s, false, "s (within duration_s)"});
    // each a row of the results (an output time, or the end), in increasing order
    for (std::size_t i = 0; i < c.summary_times_s.size(); ++i) {
      const double t = c.summary_times_s[i], k = t * c.output_rate_hz;
      if (i > 0 && !(t > c.summary_times_s[i - 1]))
        throw root.error("summary_times_s", "must increase strictly, got " + formatNumber(t) + " s after " +
                                                formatNumber(c.summary_times_s[i - 1]) + " s");
      if (std::abs(k - std::round(k)) > 1e-9 * std::max(1.0, k) && t != c.duration_s)
        throw root.error("summary_times_s", formatNumber(t) + " s is not a time of the results (every " +
                                                formatNumber(1.0 / c.output_rate_hz) + " s from 0, or duration_s)");
    }
  }
  echo["summary_times_s"] = c.summary_times_s;

  const ConfigNode st = root.map("static_state", "lat_deg, lon_deg, h_m, roll_deg, pitch_deg, yaw_deg");
  st.allowKeys({"lat_deg", "lon_deg", "h_m", "roll_deg", "pitch_deg", "yaw_deg"});
  double lat = 0.0, lon = 0.0, h = 0.0, roll = 0.0, pitch = 0.0, yaw = 0.0;
  st.read("lat_deg", lat, limits::kLatitudeDeg);
  st.read("lon_deg", lon, limits::kLongitudeDeg);
  st.read("h_m", h, limits::kHeightM);
  st.read("roll_deg", roll, kAngleDeg);
  st.read("pitch_deg", pitch, kAngleDeg);
  st.read("yaw_deg", yaw, kAngleDeg);
  if (!(std::abs(lat) < 89.0)) throw st.error("lat_deg", "must be within (-89, 89) deg");
  if (!(std::abs(pitch) < 89.0)) throw st.error("pitch_deg", "must be within (-89, 89) deg");
  c.nominal.lat = lat * units::kDeg;
  c.nominal.lon = lon * units::kDeg;
  c.nominal.h = h;
  c.nominal.setRollPitchYaw(roll * units::kDeg, pitch * units::kDeg, yaw * units::kDeg);
  echo["static_state"] = {{"lat_deg", lat}, {"lon_deg", lon}, {"h_m", h},
                          {"roll_deg", roll}, {"pitch_deg", pitch}, {"yaw_deg", yaw}};

  if (const auto is = root.optMap("initial_sigma")) {
    is->allowKeys({"position_m", "velocity_mps", "attitude_deg"});
    c.sigma0_position_m = c.sigma0_velocity_mps = c.sigma0_attitude_rad = 0.0;
    is->read("position_m", c.sigma0_position_m, kSigma0M);
    is->read("velocity_mps", c.sigma0_velocity_mps, kSigma0Mps);
    double att = 0.0;
    is->read("attitude_deg", att, kSigma0Deg);
    c.sigma0_attitude_rad = att * units::kDeg;
  }
  echo["initial_sigma"] = {{"position_m", c.sigma0_position_m},
                           {"velocity_mps", c.sigma0_velocity_mps},
                           {"attitude_deg", c.sigma0_attitude_rad / units::kDeg}};

  if (const auto b = root.optMap("baro")) {
    b->allowKeys({"rate_hz", "sigma_m"});
    c.baro_rate_hz = 10.0;
    c.baro_sigma_m = 1e-3;
    b->read("rate_hz", c.baro_rate_hz, kBaroRateHz);
    if (c.baro_rate_hz > 0.0) limits::check(path, b->keyPath("rate_hz"), c.baro_rate_hz, limits::kAidingRateHz);
    b->read("sigma_m", c.baro_sigma_m, limits::kPositionSigmaM);
    if (c.baro_rate_hz > c.imu_rate_hz) throw b->error("rate_hz", "must not exceed imu_rate_hz");
    if (c.baro_rate_hz > 0.0 && !dividesImuRate(c.baro_rate_hz, c.imu_rate_hz))
      throw b->error("rate_hz", "must divide imu_rate_hz = " + formatNumber(c.imu_rate_hz) +
                                    " Hz (an update every k-th IMU step, k whole), got " + formatNumber(c.baro_rate_hz) + " Hz");
  }
  echo["baro"] = {{"rate_hz", c.baro_rate_hz}, {"sigma_m", c.baro_sigma_m}};

  std::string disc = "series";
  if (const auto f = root.optMap("filter")) {
    f->allowKeys({"discretization", "propagate_every", "extra_states"});
    if (const auto x = f->optMap("extra_states")) c.filter.imu.extra.loadFrom(*x);
    f->readChoice("discretization", disc, {"series", "vanloan"});
    c.filter.discretization = filter::parseDiscretization(disc);
    c.filter.propagate_every = 1;
    f->read("propagate_every", c.filter.propagate_every, 1, limits::kMaxPropagateEvery);
  }
  echo["filter"] = {{"discretization", disc}, {"propagate_every", c.filter.propagate_every}};

  echo["model_sets"] = nlohmann::json::array();
  for (const ConfigNode& set : root.list("model_sets", 1, SIZE_MAX, "a non-empty list of {name, title, models}")) {
    set.allowKeys({"name", "title", "models"});
    ModelSet ms;
    set.read("name", ms.name);
    if (ms.name.empty() || ms.name.find_first_of("/\\ ,\"") != std::string::npos)
      throw set.error("name", "required: a name without spaces, commas, quotes or slashes");
    for (const auto& other : c.model_sets)
      if (other.name == ms.name)
        throw set.error("name", "'" + ms.name + "' is used by an earlier model set (names must be unique)");
    ms.title = ms.name;
    set.read("title", ms.title);
    for (const ConfigNode& m : set.list("models", 1, SIZE_MAX, "a non-empty list of model names")) {
      const std::string name = m.asText();
      if (std::find(ms.models.begin(), ms.models.end(), name) != ms.models.end())
        throw m.error("'" + name + "' is listed twice in this model set (its rows would appear twice)");
      try {
        (void)stochastic::loadImuModel(c.model_file + ":" + name);  // validates early
      } catch (const Error& e) {
        throw m.error(e.what());
      }
      ms.models.push_back(name);
    }
    echo["model_sets"].push_back({{"name", ms.name}, {"title", ms.title}, {"models", ms.models}});
    c.model_sets.push_back(ms);
  }
  c.echo = echo.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

Eigen::Vector3d eulerSigmas(const Matrix3d& P_psi, const ins::NavState& x) {
  const Vector3d rpy = x.rollPitchYaw();
  const Matrix3d Rz = Eigen::AngleAxisd(rpy.z(), Vector3d::UnitZ()).toRotationMatrix();
  const Matrix3d Ry = Eigen::AngleAxisd(rpy.y(), Vector3d::UnitY()).toRotationMatrix();
  Matrix3d M;
  M.col(0) = Rz * Ry * Vector3d::UnitX();
  M.col(1) = Rz * Vector3d::UnitY();
  M.col(2) = Vector3d::UnitZ();
  const Matrix3d Mi = M.inverse();
  return (Mi * P_psi * Mi.transpose()).diagonal().cwiseMax(0.0).cwiseSqrt();
}

void checkBudget(const CovarianceStudyConfig& cfg, long n);

void assessSmallError(CovarianceRun& run) {
  run.small_error_exceeded_s = std::numeric_limits<double>::quiet_NaN();
  run.small_error_column = -1;
  run.max_attitude_sigma_rad = 0.0;
  for (std::size_t i = 0; i < run.sigma.size(); ++i)
    for (int c = 6; c < 9; ++c) {
      const double v = run.sigma[i][c];
      run.max_attitude_sigma_rad = std::max(run.max_attitude_sigma_rad, v);
      if (run.small_error_column < 0 && !(v <= kSmallErrorAttitudeSigmaRad)) {
        run.small_error_exceeded_s = run.t[i];
        run.small_error_column = c;
      }
    }
}

namespace {
/// Nominal state and rates at sample k (k = 0 .. n) of the horizon.
using NominalFn = std::function<void(long k, ins::NavState& x, Vector3d& w_B, Vector3d& f_B)>;

CovarianceStudyResult runAlong(const CovarianceStudyConfig& cfg, long n, const NominalFn& nominal,
                               const std::function<void(int, int)>& progress) {
  CovarianceStudyResult res;
  int total = 0, done = 0;
  for (const auto& s : cfg.model_sets) total += static_cast<int>(s.models.size());
  checkBudget(cfg, n);
  const double dt = 1.0 / cfg.imu_rate_hz;
  const long every_out = std::max(1L, std::lround(cfg.imu_rate_hz / cfg.output_rate_hz));
  const long every_baro =
      cfg.baro_rate_hz > 0.0 ? std::max(1L, std::lround(cfg.imu_rate_hz / cfg.baro_rate_hz)) : 0;
  filter::Vector9d s0;
  s0 << Vector3d::Constant(cfg.sigma0_position_m), Vector3d::Constant(cfg.sigma0_velocity_mps),
      Vector3d::Constant(cfg.sigma0_attitude_rad);
  const filter::Matrix9d P0 = s0.cwiseAbs2().asDiagonal();
  ins::NavState x0;
  Vector3d w_B, f_B;
  nominal(0, x0, w_B, f_B);

  for (const CovarianceModel& cm : covarianceModels(cfg)) {
    const std::string& name = cm.model;
    const filter::ModelEntry& entry = cm.entry;
    const stochastic::ImuModel& model = entry.model;
    filter::ErrorStateEkf ekf(x0, P0, model, cfg.filter);
    CovarianceRun run;
    run.model_set = cm.model_set;
    run.model = name;
    run.model_text = modelText(model);
    run.states = ekf.size();
    run.notes = entry.notes;
    const Eigen::MatrixXd Rb = Eigen::MatrixXd::Constant(1, 1, cfg.baro_sigma_m * cfg.baro_sigma_m);
    const Eigen::VectorXd dz0 = Eigen::VectorXd::Zero(1);
    ins::NavState xk = x0;
    auto record = [&](double t) {
      ekf.flushPropagation();
      const Eigen::MatrixXd& P = ekf.P();
      std::array<double, 9> s{};
      for (int i = 0; i < 6; ++i) s[i] = std::sqrt(std::max(0.0, P(i, i)));
      const Vector3d e = eulerSigmas(P.block<3, 3>(filter::kAtt, filter::kAtt), xk);
      s[6] = e.x();
      s[7] = e.y();
      s[8] = e.z();
      run.t.push_back(t);
      run.sigma.push_back(s);
    };
    record(0.0);
    try {
      for (long k = 1; k <= n; ++k) {
        nominal(k, xk, w_B, f_B);
        ekf.predictCovariance(xk, w_B, f_B, dt);
        if (every_baro > 0 && k % every_baro == 0) ekf.update(dz0, ekf.H_baro(), Rb, /*feedback=*/false);
        if (k % every_out == 0 || k == n) record(k * dt);  // and the end, also off the output grid
      }
    } catch (const Error& e) {  // say which model of which set (the filter knows neither)
      throw Error(cfg.source + ": model set " + cm.model_set + ", model " + name + ": " + e.what());
    }
    run.pd_repairs = ekf.pdRepairs();
    run.pd_worst_eigenvalue = ekf.pdWorstRepaired();
    run.pd_first_repair_s = ekf.pdFirstRepairTime() - x0.t;
    assessSmallError(run);
    res.runs.push_back(std::move(run));
    if (progress) progress(++done, total);
  }
  return res;
}
}  // namespace

std::vector<CovarianceModel> covarianceModels(const CovarianceStudyConfig& cfg) {
  std::vector<CovarianceModel> out;
  for (const ModelSet& set : cfg.model_sets)
    for (const std::string& name : set.models)
      out.push_back({set.name, name,
                     filter::layoutFor(stochastic::loadImuModel(cfg.model_file + ":" + name), cfg.filter,
                                       cfg.imu_rate_hz)});
  return out;
}

CovarianceBudget estimateCovarianceBudget(const CovarianceStudyConfig& cfg, long n) {
  CovarianceBudget b;
  const double k = cfg.filter.propagate_every;
  const double rows = std::floor(double(n) * cfg.output_rate_hz / cfg.imu_rate_hz) + 1.0;
  for (const CovarianceModel& cm : covarianceModels(cfg)) {
    const double N = cm.entry.layout.size();
    // per IMU step: the nominal-rate Jacobian and noise (N^2); per propagation: Phi P Phi^T (2 N^3)
    b.work += double(n) * (N * N + 2.0 * N * N * N / k);
    b.memory_bytes += rows * (sizeof(double) + 9 * sizeof(double));
  }
  return b;
}

void checkBudget(const CovarianceStudyConfig& cfg, long n) {
  const CovarianceBudget b = estimateCovarianceBudget(cfg, n);
  limits::checkBudget(
      {{keyPlace(cfg.source, "duration_s"), "the run", b.work, limits::kDefaultWorkBudget, "operations",
        formatNumber(double(n), 3) + " IMU steps", "shorten it (or lower imu_rate_hz or the models' states)"},
       {keyPlace(cfg.source, "output_rate_hz"), "the results", b.memory_bytes / 1e6,
        limits::kDefaultMemoryBudgetBytes / 1e6, "MB", "", "lower it or duration_s"}},
      cfg.allow_large);
}

CovarianceStudyResult runCovarianceStudy(const CovarianceStudyConfig& cfg,
                                         const std::function<void(int, int)>& progress) {
  const double dt = 1.0 / cfg.imu_rate_hz;
  const long n = std::lround(cfg.duration_s * cfg.imu_rate_hz);
  const ins::NavState& x0 = cfg.nominal;
  // perfect static rates: f_B = -C_NtoB g_N, w_IB_B = C_NtoB w_IE_N
  const Matrix3d C_NtoB = x0.C_BtoN().transpose();
  const Vector3d f0 = -(C_NtoB * earth::gravity_N(x0.lat, x0.h));
  const Vector3d w0 = C_NtoB * earth::w_IE_N(x0.lat);
  return runAlong(cfg, n,
                  [&](long k, ins::NavState& x, Vector3d& w, Vector3d& f) {
                    x = x0;
                    x.t = k * dt;
                    w = w0;
                    f = f0;
                  },
                  progress);
}

CovarianceStudyResult runCovarianceStudyAlongTrajectory(
    const CovarianceStudyConfig& cfg, const std::string& trajectory_csv,
    const std::function<void(int, int)>& progress) {
  emulation::TrajectorySpec spec;
  spec.file = trajectory_csv;
  const emulation::SmoothTrajectory tr(emulation::readTrajectoryCsv(spec),
                                       emulation::SmoothingOptions{});
  const double dt = 1.0 / cfg.imu_rate_hz;
  const double t0 = tr.tBegin();
  const long n = std::lround(std::min(cfg.duration_s, tr.tEnd() - t0) * cfg.imu_rate_hz);
  if (n < 1) throw Error(trajectory_csv + ": trajectory shorter than one IMU interval");
  return runAlong(cfg, n,
                  [&](long k, ins::NavState& x, Vector3d& w, Vector3d& f) {
                    // nominal at the end of interval k; rates at its middle
                    const double t = t0 + k * dt;
                    x = emulation::truthNavState(tr, t);
                    x.t = k * dt;
                    const emulation::TruthState s = tr.at(k > 0 ? t - 0.5 * dt : t);
                    w = s.w_IB_B;
                    f = s.f_B;
                  },
                  progress);
}

}  // namespace navimpact::analysis
