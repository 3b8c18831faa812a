// Covariance analysis in static conditions (paper Figures 5 and 6).
#include "navimpact/analysis/covariance_study.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/units.hpp"
#include "navimpact/emulation/perfect_imu.hpp"
#include "navimpact/emulation/trajectory.hpp"
#include "navimpact/stochastic/model_file.hpp"
#include "navimpact/stochastic/model_text.hpp"
#include "navimpact/core/limits.hpp"

namespace navimpact::analysis {

namespace fs = std::filesystem;
using Eigen::Matrix3d;
using Eigen::Vector3d;

namespace {

std::string join(const std::set<std::string>& s) {
  std::string r;
  for (const auto& k : s) r += (r.empty() ? "" : ", ") + k;
  return r;
}

struct Reader {
  std::string file;
  void keys(const YAML::Node& n, const std::string& prefix, const std::set<std::string>& allowed) const {
    if (!n.IsMap()) throw keyError(file, prefix.empty() ? "(top level)" : prefix, "expected a mapping");
    for (const auto& kv : n) {
      const std::string k = kv.first.as<std::string>();
      if (!allowed.count(k))
        throw keyError(file, prefix.empty() ? k : prefix + "." + k,
                       "unknown key (accepted here: " + join(allowed) + ")");
    }
  }
  double num(const YAML::Node& n, const std::string& key, const std::string& prefix, double def,
             const char* unit) const {
    const std::string path = prefix.empty() ? key : prefix + "." + key;
    if (!n[key]) return def;
    const YAML::Node v = n[key];
    double x = 0.0;
    try {
      if (!v.IsScalar()) throw YAML::Exception(YAML::Mark(), "not a scalar");
      x = v.as<double>();
    } catch (const YAML::Exception&) {
      throw keyError(file, path, std::string("expected a number in ") + unit);
    }
    if (!std::isfinite(x)) throw keyError(file, path, "must be finite");
    return x;
  }
  std::string str(const YAML::Node& n, const std::string& key, const std::string& prefix,
                  const std::string& def) const {
    if (!n[key]) return def;
    try {
      if (!n[key].IsScalar()) throw YAML::Exception(YAML::Mark(), "not a scalar");
      return n[key].as<std::string>();
    } catch (const YAML::Exception&) {
      throw keyError(file, prefix.empty() ? key : prefix + "." + key, "expected a string");
    }
  }
};

void nonNegative(const std::string& file, const std::string& key, double v) {
  if (!(v >= 0.0)) throw keyError(file, key, "must be >= 0, got " + std::to_string(v));
}

std::string modelText(const stochastic::ImuModel& m) {
  const std::string g = stochastic::formatTerms(m.axis[0].terms);
  const std::string a = stochastic::formatTerms(m.axis[3].terms);
  return "gyroscope: " + g + "; accelerometer: " + a;
}

}  // namespace

static CovarianceStudyConfig loadCovarianceStudyConfigImpl(const std::string& path) {
  InputScope scope(path);
  CovarianceStudyConfig c;
  c.source = path;
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw fileError(path, 0, "cannot open configuration file");
  } catch (const YAML::Exception& e) {
    throw fileError(path, e.mark.line + 1, std::string("YAML syntax error: ") + printable(e.msg, 120));
  }
  const Reader r{path};
  r.keys(root, "", {"model_file", "duration_s", "imu_rate_hz", "output_rate_hz", "summary_times_s",
                    "static_state", "initial_sigma", "baro", "filter", "model_sets"});
  nlohmann::json echo;

  // model file, relative to the configuration file
  const std::string mf = r.str(root, "model_file", "", "");
  if (mf.empty()) throw keyError(path, "model_file", "required: path of the IMU error model file");
  fs::path mp(mf);
  if (mp.is_relative()) mp = fs::path(path).parent_path() / mp;
  c.model_file = mp.lexically_normal().string();
  echo["model_file"] = mf;

  c.duration_s = limits::check(path, "duration_s", r.num(root, "duration_s", "", 60.0, "s"), limits::kDurationS);
  c.imu_rate_hz = limits::check(path, "imu_rate_hz", r.num(root, "imu_rate_hz", "", 200.0, "Hz"), limits::kImuRateHz);
  c.output_rate_hz =
      limits::check(path, "output_rate_hz", r.num(root, "output_rate_hz", "", 10.0, "Hz"), limits::kAidingRateHz);
  if (c.output_rate_hz > c.imu_rate_hz)
    throw keyError(path, "output_rate_hz", "must not exceed imu_rate_hz");
  echo["duration_s"] = c.duration_s;
  echo["imu_rate_hz"] = c.imu_rate_hz;
  echo["output_rate_hz"] = c.output_rate_hz;

  if (root["summary_times_s"]) {
    const YAML::Node s = root["summary_times_s"];
    if (!s.IsSequence()) throw keyError(path, "summary_times_s", "expected a list of times in s");
    c.summary_times_s.clear();
    for (std::size_t i = 0; i < s.size(); ++i) {
      double t = 0;
      try {
        t = s[i].as<double>();
      } catch (const YAML::Exception&) {
        throw keyError(path, "summary_times_s[" + std::to_string(i) + "]", "expected a number in s");
      }
      if (!(t >= 0.0 && t <= c.duration_s))
        throw keyError(path, "summary_times_s[" + std::to_string(i) + "]",
                       "must be within [0, duration_s]");
      c.summary_times_s.push_back(t);
    }
  }
  echo["summary_times_s"] = c.summary_times_s;

  const YAML::Node st = root["static_state"];
  if (!st) throw keyError(path, "static_state", "required (lat_deg, lon_deg, h_m, roll_deg, pitch_deg, yaw_deg)");
  r.keys(st, "static_state", {"lat_deg", "lon_deg", "h_m", "roll_deg", "pitch_deg", "yaw_deg"});
  const double lat = r.num(st, "lat_deg", "static_state", 0.0, "deg");
  const double lon = r.num(st, "lon_deg", "static_state", 0.0, "deg");
  const double h = r.num(st, "h_m", "static_state", 0.0, "m");
  const double roll = r.num(st, "roll_deg", "static_state", 0.0, "deg");
  const double pitch = r.num(st, "pitch_deg", "static_state", 0.0, "deg");
  const double yaw = r.num(st, "yaw_deg", "static_state", 0.0, "deg");
  if (!(std::abs(lat) < 89.0)) throw keyError(path, "static_state.lat_deg", "must be within (-89, 89) deg");
  if (!(std::abs(pitch) < 89.0)) throw keyError(path, "static_state.pitch_deg", "must be within (-89, 89) deg");
  c.nominal.lat = lat * units::kDeg;
  c.nominal.lon = lon * units::kDeg;
  c.nominal.h = h;
  c.nominal.setRollPitchYaw(roll * units::kDeg, pitch * units::kDeg, yaw * units::kDeg);
  echo["static_state"] = {{"lat_deg", lat}, {"lon_deg", lon}, {"h_m", h},
                          {"roll_deg", roll}, {"pitch_deg", pitch}, {"yaw_deg", yaw}};

  if (const YAML::Node is = root["initial_sigma"]) {
    r.keys(is, "initial_sigma", {"position_m", "velocity_mps", "attitude_deg"});
    c.sigma0_position_m = r.num(is, "position_m", "initial_sigma", 0.0, "m");
    c.sigma0_velocity_mps = r.num(is, "velocity_mps", "initial_sigma", 0.0, "m/s");
    c.sigma0_attitude_rad = r.num(is, "attitude_deg", "initial_sigma", 0.0, "deg") * units::kDeg;
    nonNegative(path, "initial_sigma.position_m", c.sigma0_position_m);
    nonNegative(path, "initial_sigma.velocity_mps", c.sigma0_velocity_mps);
    nonNegative(path, "initial_sigma.attitude_deg", c.sigma0_attitude_rad);
  }
  echo["initial_sigma"] = {{"position_m", c.sigma0_position_m},
                           {"velocity_mps", c.sigma0_velocity_mps},
                           {"attitude_deg", c.sigma0_attitude_rad / units::kDeg}};

  if (const YAML::Node b = root["baro"]) {
    r.keys(b, "baro", {"rate_hz", "sigma_m"});
    c.baro_rate_hz = r.num(b, "rate_hz", "baro", 10.0, "Hz");
    c.baro_sigma_m = r.num(b, "sigma_m", "baro", 1e-3, "m");
    nonNegative(path, "baro.rate_hz", c.baro_rate_hz);
    if (c.baro_rate_hz > 0.0) limits::check(path, "baro.rate_hz", c.baro_rate_hz, limits::kAidingRateHz);
    limits::check(path, "baro.sigma_m", c.baro_sigma_m, limits::kPositionSigmaM);
    if (c.baro_rate_hz > c.imu_rate_hz) throw keyError(path, "baro.rate_hz", "must not exceed imu_rate_hz");
  }
  echo["baro"] = {{"rate_hz", c.baro_rate_hz}, {"sigma_m", c.baro_sigma_m}};

  std::string disc = "series";
  if (const YAML::Node f = root["filter"]) {
    r.keys(f, "filter", {"discretization", "propagate_every"});
    disc = r.str(f, "discretization", "filter", "series");
    try {
      c.filter.discretization = filter::parseDiscretization(disc);
    } catch (const Error& e) {
      throw keyError(path, "filter.discretization", e.what());
    }
    const double k = r.num(f, "propagate_every", "filter", 1.0, "IMU samples");
    if (!(k >= 1.0 && k == std::floor(k)))
      throw keyError(path, "filter.propagate_every", "must be an integer >= 1 (IMU samples)");
    c.filter.propagate_every = static_cast<int>(k);
  }
  echo["filter"] = {{"discretization", disc}, {"propagate_every", c.filter.propagate_every}};

  const YAML::Node sets = root["model_sets"];
  if (!sets || !sets.IsSequence() || sets.size() == 0)
    throw keyError(path, "model_sets", "required: a non-empty list of {name, title, models}");
  echo["model_sets"] = nlohmann::json::array();
  for (std::size_t i = 0; i < sets.size(); ++i) {
    const std::string pre = "model_sets[" + std::to_string(i) + "]";
    r.keys(sets[i], pre, {"name", "title", "models"});
    ModelSet ms;
    ms.name = r.str(sets[i], "name", pre, "");
    if (ms.name.empty() || ms.name.find_first_of("/\\ ,\"") != std::string::npos)
      throw keyError(path, pre + ".name", "required: a name without spaces, commas, quotes or slashes");
    for (const auto& other : c.model_sets)
      if (other.name == ms.name)
        throw keyError(path, pre + ".name", "'" + ms.name + "' is used by an earlier model set (names must be unique)");
    ms.title = r.str(sets[i], "title", pre, ms.name);
    const YAML::Node ml = sets[i]["models"];
    if (!ml || !ml.IsSequence() || ml.size() == 0)
      throw keyError(path, pre + ".models", "required: a non-empty list of model names");
    for (std::size_t j = 0; j < ml.size(); ++j) {
      const std::string key = pre + ".models[" + std::to_string(j) + "]";
      std::string name;
      try {
        name = ml[j].as<std::string>();
      } catch (const YAML::Exception&) {
        throw keyError(path, key, "expected a model name");
      }
      try {
        (void)stochastic::loadImuModel(c.model_file + ":" + name);  // validates early
      } catch (const Error& e) {
        throw keyError(path, key, e.what());
      }
      ms.models.push_back(name);
    }
    echo["model_sets"].push_back({{"name", ms.name}, {"title", ms.title}, {"models", ms.models}});
    c.model_sets.push_back(ms);
  }
  c.echo = echo.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  return c;
}

// A value of the wrong type (yaml-cpp's conversion errors, a list or map used
// as a key) is an error naming the file and line, never an internal error.
CovarianceStudyConfig loadCovarianceStudyConfig(const std::string& path) {
  try {
    return loadCovarianceStudyConfigImpl(path);
  } catch (const YAML::Exception& e) {
    throw Error(path + (e.mark.line >= 0 ? ":" + std::to_string(e.mark.line + 1) + ":" + std::to_string(e.mark.column + 1) : "") +
                ": " + printable(e.msg, 120) + " (a value or key of the wrong type)");
  }
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

  for (const ModelSet& set : cfg.model_sets) {
    for (const std::string& name : set.models) {
      const stochastic::ImuModel model = stochastic::loadImuModel(cfg.model_file + ":" + name);
      filter::ErrorStateEkf ekf(x0, P0, model, cfg.filter);
      CovarianceRun run;
      run.model_set = set.name;
      run.model = name;
      run.model_text = modelText(model);
      run.states = ekf.size();
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
      for (long k = 1; k <= n; ++k) {
        nominal(k, xk, w_B, f_B);
        ekf.predictCovariance(xk, w_B, f_B, dt);
        if (every_baro > 0 && k % every_baro == 0) ekf.update(dz0, ekf.H_baro(), Rb, /*feedback=*/false);
        if (k % every_out == 0) record(k * dt);
      }
      res.runs.push_back(std::move(run));
      if (progress) progress(++done, total);
    }
  }
  return res;
}
}  // namespace

CovarianceBudget estimateCovarianceBudget(const CovarianceStudyConfig& cfg, long n) {
  CovarianceBudget b;
  const double k = cfg.filter.propagate_every;
  const double rows = std::floor(double(n) * cfg.output_rate_hz / cfg.imu_rate_hz) + 1.0;
  for (const ModelSet& set : cfg.model_sets)
    for (const std::string& name : set.models) {
      const double N =
          filter::StateLayout::build(stochastic::loadImuModel(cfg.model_file + ":" + name), cfg.filter.imu).size();
      // per IMU step: the nominal-rate Jacobian and noise (N^2); per propagation: Phi P Phi^T (2 N^3)
      b.work += double(n) * (N * N + 2.0 * N * N * N / k);
      b.memory_bytes += rows * (sizeof(double) + 9 * sizeof(double));
    }
  return b;
}

void checkBudget(const CovarianceStudyConfig& cfg, long n) {
  const CovarianceBudget b = estimateCovarianceBudget(cfg, n);
  auto g = [](double v) {
    char s[32];
    std::snprintf(s, sizeof s, "%.3g", v);
    return std::string(s);
  };
  if (cfg.allow_large) return;
  if (b.work > limits::kDefaultWorkBudget)
    throw keyError(cfg.source, "duration_s",
                   "the run needs about " + g(b.work) + " floating-point operations (" + g(double(n)) +
                       " IMU steps; imu_rate_hz, filter.propagate_every and the models' state counts), above the budget of " +
                       g(limits::kDefaultWorkBudget) + ": shorten it or pass --allow-large");
  if (b.memory_bytes > limits::kDefaultMemoryBudgetBytes)
    throw keyError(cfg.source, "output_rate_hz",
                   "the results need about " + g(b.memory_bytes / 1e6) + " MB, above the budget of " +
                       g(limits::kDefaultMemoryBudgetBytes / 1e6) + " MB: lower it or duration_s, or pass --allow-large");
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
