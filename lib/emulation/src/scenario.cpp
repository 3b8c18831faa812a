#include "navimpact/emulation/scenario.hpp"

#include <ctime>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <limits>
#include <memory>
#include <optional>
#include <set>
#include <sstream>

#include "navimpact/core/config.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/imu_series.hpp"
#include "navimpact/emulation/perfect_imu.hpp"
#include "navimpact/stochastic/model_file.hpp"
#include "navimpact/core/limits.hpp"

namespace navimpact::emulation {

namespace fs = std::filesystem;

namespace {

struct Ctx {
  std::string file;
};

/// A UTC time YYYY-MM-DDTHH:MM:SSZ between 1970 and 2286 (Unix time 0 .. 1e10 s,
/// as an import's time_zero_unix_s). Read whole and written back identically:
/// get_time alone took "0" for the year 0 and "2026-02-30" for March 2.
long long parseUtc(const std::string& s, const Ctx& c) {
  const std::string what = "must be a UTC time YYYY-MM-DDTHH:MM:SSZ from 1970 to 2286, got '" + printable(s, 40) + "'";
  std::tm tm{};
  std::istringstream in(s);
  in >> std::get_time(&tm, "%Y-%m-%dT%H:%M:%SZ");
  if (in.fail() || s.size() != 20) throw keyError(c.file, "output.start_utc", what);
  const long long t = static_cast<long long>(timegm(&tm));
  std::tm back{};
  const std::time_t tt = static_cast<std::time_t>(t);
  char buf[32] = {0};
  if (t < 0 || t > 10000000000LL || !gmtime_r(&tt, &back) ||
      std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &back) != 20 || s != buf)
    throw keyError(c.file, "output.start_utc", what);
  return t;
}

std::string quote(const std::string& s) {
  std::string o = "\"";
  for (char ch : s) {
    if (ch == '"' || ch == '\\') o += '\\';
    o += ch;
  }
  return o + "\"";
}

}  // namespace

EmulationConfig loadEmulationConfig(const std::string& path) {
  InputScope scope(path);
  const ConfigNode root = ConfigNode::load(path);
  Ctx c{path};
  EmulationConfig cfg;
  cfg.config_file = path;
  root.allowKeys({"trajectory", "smoothing", "imu", "gnss", "baro", "effects", "ground_truth", "output"});
  cfg.trajectory.loadFrom(root.map("trajectory", "file, system, columns, ..."));
  if (const auto s = root.optMap("smoothing")) cfg.smoothing.loadFrom(*s);

  if (const auto i = root.optMap("imu")) {
    i->allowKeys({"rate_hz", "errors", "model", "seed", "static"});
    i->read("rate_hz", cfg.imu_rate_hz, limits::kImuRateHz);
    i->readChoice("errors", cfg.imu_errors, {"model", "static", "none"});
    cfg.model_spec = i->modelRef("model");
    i->readSeed("seed", cfg.imu_seed);
    if (const auto st = i->optMap("static")) cfg.static_rec.loadFrom(*st, true);
  }
  if (cfg.imu_errors == "model" && cfg.model_spec.empty())
    throw keyError(path, "imu.model", "missing (FILE[:NAME] of the IMU error model) for imu.errors: model");
  if (cfg.imu_errors == "static" && cfg.static_rec.file.empty())
    throw keyError(path, "imu.static.file", "missing for imu.errors: static");

  if (const auto g = root.optMap("gnss")) cfg.gnss.loadFrom(*g, true);
  if (const auto b = root.optMap("baro")) cfg.baro.loadFrom(*b, true);
  if (const auto e = root.optMap("effects")) {
    SensorEffects& fx = cfg.effects;
    e->allowKeys({"gyro_scale", "acc_scale", "gyro_misalignment_rad", "acc_misalignment_rad",
                  "gyro_nonorthogonality_rad", "acc_nonorthogonality_rad", "time_offset_s",
                  "gyro_motion_noise_factor", "acc_motion_noise_factor", "motion_rate_threshold_rad_s",
                  "motion_acc_threshold_mps2", "lever_arm_error_m", "seed"});
    e->read("gyro_scale", fx.gyro_scale, limits::kScaleFactor);
    e->read("acc_scale", fx.acc_scale, limits::kScaleFactor);
    e->read("gyro_misalignment_rad", fx.gyro_misalignment_rad, limits::kMisalignmentRad);
    e->read("acc_misalignment_rad", fx.acc_misalignment_rad, limits::kMisalignmentRad);
    e->read("gyro_nonorthogonality_rad", fx.gyro_nonorthogonality_rad, limits::kMisalignmentRad);
    e->read("acc_nonorthogonality_rad", fx.acc_nonorthogonality_rad, limits::kMisalignmentRad);
    e->read("time_offset_s", fx.time_offset_s, limits::kTimeOffsetS);
    e->read("gyro_motion_noise_factor", fx.gyro_motion_noise_factor, limits::kMotionNoiseFactor);
    e->read("acc_motion_noise_factor", fx.acc_motion_noise_factor, limits::kMotionNoiseFactor);
    e->read("motion_rate_threshold_rad_s", fx.motion_rate_threshold_rad_s, limits::kMotionRateThresholdRadS);
    e->read("motion_acc_threshold_mps2", fx.motion_acc_threshold_mps2, limits::kMotionAccThresholdMps2);
    e->read("lever_arm_error_m", fx.lever_arm_error_B_m, limits::kLeverArmErrorM);
    e->readSeed("seed", cfg.effects_seed);
    validateEffects(fx, path, "effects.");
    if ((fx.gyro_motion_noise_factor != 1.0 || fx.acc_motion_noise_factor != 1.0) && cfg.imu_errors != "model")
      throw keyError(path, fx.gyro_motion_noise_factor != 1.0 ? "effects.gyro_motion_noise_factor"
                                                               : "effects.acc_motion_noise_factor",
                     "needs imu.errors: model (the factor multiplies the model's white noise)");
  }
  if (const auto gt = root.optMap("ground_truth")) {
    gt->allowKeys({"rate_hz"});
    gt->read("rate_hz", cfg.truth_rate_hz, limits::kAidingRateHz);
  }
  if (const auto o = root.optMap("output")) {
    o->allowKeys({"start_utc"});
    o->read("start_utc", cfg.start_utc);
  }
  parseUtc(cfg.start_utc, c);
  return cfg;
}

namespace {

/// The scenario text (YAML), stored as the rawlog's first entry.
std::string scenarioText(const EmulationConfig& cfg, const std::string& version, long long startUnix,
                         const earth::Geodetic& origin, double t0, double t1, const std::string& err_description,
                         const std::string& effects, const std::vector<std::string>& notices,
                         const stochastic::ImuModel& model) {
  std::ostringstream y;
  const auto& g = cfg.gnss;
  y << "navimpact_scenario:\n"
    << "  navimpact_version: " << quote(version) << "\n"
    << "  frames: {body: FRD, navigation: NED, ground_truth_position: tangent-plane NED at origin,"
       " attitude: C_BtoN quaternion (Hamilton, active)}\n"
    << "  units: {IMU: \"IMU_WX..IMU_WZ rad/s, IMU_X_ACC..IMU_Z_ACC m/s^2, means over the interval ending at the timestamp\","
       " BARO: \"IMU_ALTITUDE m above the WGS84 ellipsoid\","
       " GNSS: \"GGA lat/lon deg, altitude_meters ellipsoidal, geoidal_distance 0; TOPCON_PZS ECEF m, m/s, covariances m^2, m^2/s^2\","
       " GT: \"IMU_X..IMU_Z m (tangent NED at origin), IMU_X_VEL..IMU_Z_VEL m/s (local NED), IMU_ORI_QUAT_X..W of C_BtoN\"}\n"
    << "  origin: {lat_deg: " << formatNumber(origin.lat * 180 / M_PI, 17) << ", lon_deg: " << formatNumber(origin.lon * 180 / M_PI, 17)
    << ", height_m: " << formatNumber(origin.h, 17) << "}\n"
    << "  time: {start_utc: " << quote(cfg.start_utc) << ", start_unix_s: " << startUnix
    << ", trajectory_time_at_start_s: " << formatNumber(t0, 17) << ", duration_s: " << formatNumber(t1 - t0, 17) << "}\n"
    << "  trajectory: {file: " << quote(cfg.trajectory.file) << ", system: " << cfg.trajectory.system
    << ", position_cutoff_hz: " << formatNumber(cfg.smoothing.position_cutoff_hz, 17)
    << ", attitude_cutoff_hz: " << formatNumber(cfg.smoothing.attitude_cutoff_hz, 17)
    << ", knot_step_s: " << formatNumber(cfg.smoothing.knot_step_s, 17) << ", penalty_order: " << cfg.smoothing.penalty_order << "}\n"
    << "  imu: {rate_hz: " << formatNumber(cfg.imu_rate_hz, 17) << ", errors: " << cfg.imu_errors
    << ", model: " << quote(cfg.model_spec) << ", seed: " << cfg.imu_seed
    << ", description: " << quote(err_description) << "}\n"
    << "  gnss: {rate_hz: " << formatNumber(g.rate_hz, 17) << ", sigma_pos_h_m: " << formatNumber(g.sigma_pos_h_m, 17)
    << ", sigma_pos_v_m: " << formatNumber(g.sigma_pos_v_m, 17) << ", sigma_vel_h_mps: " << formatNumber(g.sigma_vel_h_mps, 17)
    << ", sigma_vel_v_mps: " << formatNumber(g.sigma_vel_v_mps, 17) << ", lever_arm_B_m: [" << formatNumber(g.lever_arm_B[0], 17) << ", "
    << formatNumber(g.lever_arm_B[1], 17) << ", " << formatNumber(g.lever_arm_B[2], 17) << "], seed: " << g.seed << "}\n"
    << "  baro: {rate_hz: " << formatNumber(cfg.baro.rate_hz, 17) << ", sigma_m: " << formatNumber(cfg.baro.sigma_m, 17)
    << ", seed: " << cfg.baro.seed << "}\n"
    << "  ground_truth: {rate_hz: " << formatNumber(cfg.truth_rate_hz, 17) << "}\n";
  if (!cfg.effects.none())  // a run without effects keeps its scenario text
    y << "  effects: {description: " << quote(effects) << ", seed: " << cfg.effects_seed << "}\n";
  y
    << "  notices:\n";
  for (const auto& nline : notices) y << "    - " << quote(nline) << "\n";
  if (notices.empty()) y << "    []\n";
  if (cfg.imu_errors == "model") {
    std::string mt = stochastic::toYaml(model, "IMU error model " + model.source);
    y << "  imu_model_yaml: |\n";
    std::istringstream in(mt);
    std::string line;
    while (std::getline(in, line)) y << "    " << line << "\n";
  }
  return y.str();
}

constexpr std::size_t kBlockSamples = std::size_t(1) << 16;  // IMU samples per block of a streamed run

/// Collects the blocks into one Recording.
class Collect : public RecordingSink {
 public:
  Recording d;
  void begin(const Recording& header) override { d = header; }
  void append(const Recording& b, double) override {
    d.imu.insert(d.imu.end(), b.imu.begin(), b.imu.end());
    d.gnss.insert(d.gnss.end(), b.gnss.begin(), b.gnss.end());
    d.baro.insert(d.baro.end(), b.baro.begin(), b.baro.end());
    d.reference.insert(d.reference.end(), b.reference.begin(), b.reference.end());
  }
};

}  // namespace

EmulationBudget emulationBudget(const EmulationConfig& cfg, double duration_s) {
  EmulationBudget b;
  b.duration_s = duration_s;
  b.imu_samples = std::max(0.0, duration_s) * cfg.imu_rate_hz;
  b.rawlog_bytes = b.imu_samples * kRawlogBytesPerSample;
  b.work_s = b.imu_samples * kCpuSecondsPerSample;
  if (!cfg.effects.none()) b.memory_bytes = b.imu_samples * kEffectsBytesPerSample;
  limits::checkBudget(
      {{keyPlace(cfg.config_file, "imu.rate_hz"), "the run", b.imu_samples, kSampleBudget, "IMU samples",
        formatNumber(duration_s) + " s at " + formatNumber(cfg.imu_rate_hz) + " Hz; about " +
            formatNumber(b.rawlog_bytes / 1e9, 3) + " GB of rawlog, " + formatNumber(b.work_s / 60.0, 3) + " min of CPU",
        "lower it or shorten the trajectory (start_s, end_s)"},
       {keyPlace(cfg.config_file, "effects"), "the run held in memory with sensor effects", b.memory_bytes / 1e9,
        limits::kDefaultMemoryBudgetBytes / 1e9, "GB", "", "shorten the run"}},
      cfg.allow_large);
  return b;
}

namespace {

/// An emulated IMU sample within what every reader accepts (core/imu_series.hpp,
/// maxAbsSample): navimpact must read back the rawlogs it writes (a model with
/// a WN sigma of 1e4 rad/s wrote one that replay refused at its fifth entry).
/// @p perfect_B: the error-free rate and specific force, to tell the trajectory's
/// motion from the errors added to it in the message's key.
void checkSample(const ImuRecord& r, const Eigen::Vector3d& perfect_w, const Eigen::Vector3d& perfect_f,
                 const EmulationConfig& cfg) {
  for (int k = 0; k < 6; ++k) {
    const double v = k < 3 ? r.w_IB_B[k] : r.f_B[k - 3];
    const double p = k < 3 ? perfect_w[k] : perfect_f[k - 3];
    const double lim = k < 3 ? kMaxAbsAngularRate : kMaxAbsSpecificForce;
    if (std::abs(v) <= lim) continue;  // (false for NaN)
    const bool motion = !(std::abs(p) <= lim);
    const std::string key = motion ? "trajectory.file"
                            : !cfg.effects.none() ? "effects"
                            : cfg.imu_errors == "static" ? "imu.static.file" : "imu.model";
    throw keyError(cfg.config_file, key,
                   std::string("the emulated IMU sample ") + kChannelNames[k] + " = " + formatNumber(v) +
                       (k < 3 ? " rad/s" : " m/s^2") + " at t = " + formatNumber(r.t, 10) + " s is beyond any IMU (|value| <= " +
                       formatNumber(lim) + (k < 3 ? " rad/s" : " m/s^2") + "; no reader would take the rawlog): " +
                       (motion ? "the trajectory's motion" : "the errors added to it") + " are too large");
  }
}

}  // namespace

Recording runEmulation(const EmulationConfig& cfg, const std::string& version) {
  Collect c;
  runEmulation(cfg, version, c);
  return std::move(c.d);
}

void runEmulation(const EmulationConfig& cfg, const std::string& version, RecordingSink& sink) {
  Ctx c{cfg.config_file};
  const long long startUnix = parseUtc(cfg.start_utc, c);
  std::optional<SmoothTrajectory> trOpt;
  {
    const SampledTrajectory samples = readTrajectoryCsv(cfg.trajectory);
    emulationBudget(cfg, samples.t.empty() ? 0.0 : samples.t.back() - samples.t.front());
    trOpt.emplace(samples, cfg.smoothing);
  }  // the samples are freed here; the spline holds the trajectory
  const SmoothTrajectory& tr = *trOpt;
  Recording d;
  d.source = cfg.config_file.empty() ? "emulation" : cfg.config_file;
  d.origin = tr.origin();
  d.imu_rate_hz = cfg.imu_rate_hz;
  d.start_unix_s = startUnix;
  d.t_start_s = tr.tBegin();
  d.lever_arm_B = cfg.gnss.lever_arm_B;
  const double t0 = tr.tBegin();
  stochastic::ImuModel model;
  if (cfg.imu_errors == "model") model = stochastic::loadImuModel(cfg.model_spec);

  if (!cfg.effects.none()) {  // the effects are applied to the whole run (time shift, motion test)
    const auto perfect = perfectImu(tr, cfg.imu_rate_hz);
    const std::size_t n = perfect.size();
    ImuErrors err;
    if (cfg.imu_errors == "model") {
      err = modelImuErrors(model, cfg.imu_rate_hz, n, cfg.imu_seed);
    } else if (cfg.imu_errors == "static") {
      err = staticImuErrors(cfg.static_rec, cfg.imu_rate_hz, n);
    } else {
      for (auto& a : err.axis) a.assign(n, 0.0);
      err.description = "none (perfect IMU)";
    }
    d.notices = err.notices;
    // the sensor's output with the effects (sensor_effects.hpp); the white noise the
    // motion factors inflate is the model's
    std::array<double, 6> ws{};
    if (cfg.imu_errors == "model") ws = whiteNoiseSigma(model, cfg.imu_rate_hz);
    const EffectedImu e = applySensorEffects(perfect, err.axis, cfg.effects, ws, cfg.effects_seed);
    d.imu.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      ImuRecord& r = d.imu[k];
      r.t = e.imu[k].t;
      r.w_IB_B = e.imu[k].dtheta_B / e.imu[k].dt;
      r.f_B = e.imu[k].dv_B / e.imu[k].dt;
      checkSample(r, perfect[k].dtheta_B / perfect[k].dt, perfect[k].dv_B / perfect[k].dt, cfg);
    }
    const double t1 = perfect.back().t;
    // GNSS of the true antenna (told - lever-arm error); the rawlog states the told one
    d.gnss = simulateGnss(tr, gnssWithEffects(cfg.gnss, cfg.effects), t0, t1);
    d.baro = simulateBaro(tr, cfg.baro, t0, t1);
    const auto nt = static_cast<std::size_t>(std::floor((t1 - t0) * cfg.truth_rate_hz + 1e-9)) + 1;
    d.reference.resize(nt);
    for (std::size_t k = 0; k < nt; ++k) {
      const double t = t0 + double(k) / cfg.truth_rate_hz;
      const TruthState s = tr.at(t);
      d.reference[k] = {t, s.p_L, s.v_N, Eigen::Quaterniond(s.C_BtoN).normalized(), {}, {}, {}};
    }
    d.metadata = scenarioText(cfg, version, startUnix, d.origin, t0, t1, err.description, e.description, d.notices,
                              model);
    Recording header = d;
    header.imu.clear();
    header.gnss.clear();
    header.baro.clear();
    header.reference.clear();
    sink.begin(header);
    sink.append(d, std::numeric_limits<double>::infinity());
    return;
  }

  // Without effects the run streams: the perfect IMU, its errors, GNSS, barometer and
  // truth block by block, each record as the whole-run computation makes it.
  const double a = tr.tBegin(), rate = cfg.imu_rate_hz;
  const std::size_t n = perfectImuCount(rate, a, tr.tEnd());
  if (n == 0) perfectImu(tr, rate);  // throws its error: no whole IMU interval
  const double t1 = a + double(n) * (1.0 / rate);  // the last sample's time, as perfectImu computes it
  ImuErrorStream err = cfg.imu_errors == "model"    ? ImuErrorStream::fromModel(model, rate, n, cfg.imu_seed)
                       : cfg.imu_errors == "static" ? ImuErrorStream::fromStatic(
                                                          std::make_shared<const ImuSeries>(
                                                              readImuCsv(cfg.static_rec.file, cfg.static_rec.csv)),
                                                          cfg.static_rec, rate, n)
                                                    : ImuErrorStream::none(n);
  d.notices = err.notices();
  d.metadata = scenarioText(cfg, version, startUnix, d.origin, t0, t1, err.description(), "none", d.notices, model);
  sink.begin(d);
  GnssSimulator gnss(tr, cfg.gnss, t0, t1);
  BaroSimulator baro(tr, cfg.baro, t0, t1);
  const auto nt = static_cast<std::size_t>(std::floor((t1 - t0) * cfg.truth_rate_hz + 1e-9)) + 1;
  std::size_t kt = 0;
  std::vector<ins::ImuSample> perfect;
  std::array<std::vector<double>, 6> e;
  Recording blk;
  for (std::size_t k0 = 0; k0 < n; k0 += kBlockSamples) {
    const std::size_t k1 = std::min(n, k0 + kBlockSamples);
    perfectImuBlock(tr, rate, a, k0, k1, perfect);
    err.next(k1 - k0, e);
    blk.imu.resize(k1 - k0);
    blk.gnss.clear();
    blk.baro.clear();
    blk.reference.clear();
    for (std::size_t k = 0; k < k1 - k0; ++k) {
      const auto& s = perfect[k];
      ImuRecord& r = blk.imu[k];
      r.t = s.t;
      r.w_IB_B = s.dtheta_B / s.dt + Eigen::Vector3d(e[0][k], e[1][k], e[2][k]);
      r.f_B = s.dv_B / s.dt + Eigen::Vector3d(e[3][k], e[4][k], e[5][k]);
      checkSample(r, s.dtheta_B / s.dt, s.dv_B / s.dt, cfg);
    }
    const double until = k1 == n ? std::numeric_limits<double>::infinity() : perfect.back().t;
    gnss.next(until, blk.gnss);
    baro.next(until, blk.baro);
    for (; kt < nt; ++kt) {
      const double t = t0 + double(kt) / cfg.truth_rate_hz;
      if (t > until) break;
      const TruthState s = tr.at(t);
      blk.reference.push_back({t, s.p_L, s.v_N, Eigen::Quaterniond(s.C_BtoN).normalized(), {}, {}, {}});
    }
    sink.append(blk, until);
  }
}

}  // namespace navimpact::emulation
