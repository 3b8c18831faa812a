// Rawlog replay through the shared navigation loop (runNav), and its report.
#include "navimpact/analysis/replay.hpp"

#include <yaml-cpp/yaml.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <algorithm>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <set>
#include <sstream>
#include <unistd.h>

#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/text_io.hpp"
#include "navimpact/filter/error_model.hpp"
#include "navimpact/rawlog/writer.hpp"
#include "navimpact/stochastic/model_file.hpp"
#include "navimpact/core/limits.hpp"

namespace navimpact::analysis {

namespace fs = std::filesystem;

namespace {

constexpr double kDeg = M_PI / 180.0;

std::string resolve(const fs::path& dir, const std::string& p) {
  if (p.empty() || fs::path(p).is_absolute() || dir.empty()) return p;
  return (dir / p).lexically_normal().string();
}

std::string resolveModel(const fs::path& dir, const std::string& spec) {
  const auto colon = spec.rfind(':');
  if (colon != std::string::npos && colon > 1) return resolve(dir, spec.substr(0, colon)) + spec.substr(colon);
  return resolve(dir, spec);
}

}  // namespace

static ReplayConfig loadReplayConfigImpl(const std::string& path) {
  InputScope scope(path);
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw Error(path + ": cannot open the replay configuration");
  } catch (const YAML::Exception& e) {
    throw fileError(path, e.mark.line + 1, std::string("YAML syntax: ") + printable(e.msg, 120));
  }
  ReplayConfig c;
  c.config_file = path;
  const fs::path dir = fs::path(path).parent_path();
  if (!root.IsMap()) throw keyError(path, "(root)", "expected a map");
  const std::set<std::string> allowed = {"rawlog", "model", "outages", "filter", "initial_sigma", "noise",
                                         "gnss_lever_arm_B_m", "initial_attitude_deg", "record_interval_s"};
  for (const auto& kv : root)
    if (!allowed.count(kv.first.as<std::string>()))
      throw keyError(path, kv.first.as<std::string>(),
                     "unknown key (expected rawlog, model, outages, filter, initial_sigma, noise, gnss_lever_arm_B_m, "
                     "initial_attitude_deg, record_interval_s)");
  auto num = [&](const YAML::Node& n, const std::string& key) {
    try {
      return n.as<double>();
    } catch (const YAML::Exception&) {
      throw keyError(path, key, "expected a number");
    }
  };
  auto pos = [&](const YAML::Node& n, const std::string& key) {
    const double v = num(n, key);
    if (!(v > 0.0)) throw keyError(path, key, "must be > 0");
    return v;
  };
  auto subKeys = [&](const YAML::Node& n, const std::string& name, const std::set<std::string>& ok) {
    if (!n.IsMap()) throw keyError(path, name, "expected a map");
    for (const auto& kv : n)
      if (!ok.count(kv.first.as<std::string>()))
        throw keyError(path, name + "." + kv.first.as<std::string>(), "unknown key");
  };
  if (root["rawlog"]) c.rawlog = resolve(dir, root["rawlog"].as<std::string>());
  if (root["model"]) c.model_spec = resolveModel(dir, root["model"].as<std::string>());
  if (const auto o = root["outages"]) {
    if (!o.IsSequence()) throw keyError(path, "outages", "expected a list of {start_s, duration_s}");
    for (std::size_t i = 0; i < o.size(); ++i) {
      const std::string k = "outages[" + std::to_string(i) + "]";
      subKeys(o[i], k, {"start_s", "duration_s"});
      if (!o[i]["start_s"] || !o[i]["duration_s"]) throw keyError(path, k, "needs start_s and duration_s [s]");
      const Outage w = Outage::fromStartDuration(num(o[i]["start_s"], k + ".start_s"), pos(o[i]["duration_s"], k + ".duration_s"));
      if (!(w.start_s >= 0.0)) throw keyError(path, k + ".start_s", "must be >= 0");
      c.outages.push_back(w);
    }
  }
  if (const auto f = root["filter"]) {
    subKeys(f, "filter", {"propagate_every", "use_gnss_velocity", "gate_probability", "max_imu_gap_s"});
    if (f["max_imu_gap_s"]) {
      c.max_imu_gap_s = limits::check(path, "filter.max_imu_gap_s", num(f["max_imu_gap_s"], "filter.max_imu_gap_s"),
                                      limits::Range{0.0, kMaxImuGapS, false, "s"});
    }
    if (f["propagate_every"]) {
      c.propagate_every = f["propagate_every"].as<int>();
      if (c.propagate_every < 1) throw keyError(path, "filter.propagate_every", "must be >= 1");
    }
    if (f["use_gnss_velocity"]) c.use_gnss_velocity = f["use_gnss_velocity"].as<bool>();
    if (f["gate_probability"]) c.gate_probability = num(f["gate_probability"], "filter.gate_probability");
  }
  if (const auto p = root["initial_sigma"]) {
    subKeys(p, "initial_sigma", {"pos_h_m", "pos_v_m", "vel_mps", "roll_pitch_deg", "yaw_deg"});
    if (p["pos_h_m"]) c.p0_pos_h_m = pos(p["pos_h_m"], "initial_sigma.pos_h_m");
    if (p["pos_v_m"]) c.p0_pos_v_m = pos(p["pos_v_m"], "initial_sigma.pos_v_m");
    if (p["vel_mps"]) c.p0_vel_mps = pos(p["vel_mps"], "initial_sigma.vel_mps");
    if (p["roll_pitch_deg"]) c.p0_roll_pitch_deg = pos(p["roll_pitch_deg"], "initial_sigma.roll_pitch_deg");
    if (p["yaw_deg"]) c.p0_yaw_deg = pos(p["yaw_deg"], "initial_sigma.yaw_deg");
  }
  if (const auto n = root["noise"]) {
    subKeys(n, "noise", {"sigma_pos_h_m", "sigma_pos_v_m", "sigma_vel_h_mps", "sigma_vel_v_mps", "sigma_baro_m"});
    auto ranged = [&](const char* k, const limits::Range& range) {
      return limits::check(path, std::string("noise.") + k, num(n[k], std::string("noise.") + k), range);
    };
    if (n["sigma_pos_h_m"]) c.sigma_pos_h_m = ranged("sigma_pos_h_m", limits::kPositionSigmaM);
    if (n["sigma_pos_v_m"]) c.sigma_pos_v_m = ranged("sigma_pos_v_m", limits::kPositionSigmaM);
    if (n["sigma_vel_h_mps"]) c.sigma_vel_h_mps = ranged("sigma_vel_h_mps", limits::kVelocitySigmaMps);
    if (n["sigma_vel_v_mps"]) c.sigma_vel_v_mps = ranged("sigma_vel_v_mps", limits::kVelocitySigmaMps);
    if (n["sigma_baro_m"]) c.sigma_baro_m = ranged("sigma_baro_m", limits::kPositionSigmaM);
  }
  if (const auto l = root["gnss_lever_arm_B_m"]) {
    if (!l.IsSequence() || l.size() != 3) throw keyError(path, "gnss_lever_arm_B_m", "expected [x, y, z] in metres");
    Eigen::Vector3d v;
    for (int k = 0; k < 3; ++k) {
      const std::string key = "gnss_lever_arm_B_m[" + std::to_string(k) + "]";
      v[k] = limits::check(path, key, num(l[k], key), limits::kLeverArmM);
    }
    c.lever_arm_B = v;
  }
  if (const auto a = root["initial_attitude_deg"]) {
    if (!a.IsSequence() || a.size() != 3)
      throw keyError(path, "initial_attitude_deg", "expected [roll, pitch, yaw] in degrees");
    c.initial_attitude_deg = Eigen::Vector3d(num(a[0], "initial_attitude_deg"), num(a[1], "initial_attitude_deg"),
                                             num(a[2], "initial_attitude_deg"));
  }
  if (root["record_interval_s"]) c.record_interval_s = pos(root["record_interval_s"], "record_interval_s");
  return c;
}

// A value of the wrong type (yaml-cpp's conversion errors, a list or map used
// as a key) is an error naming the file and line, never an internal error.
ReplayConfig loadReplayConfig(const std::string& path) {
  try {
    return loadReplayConfigImpl(path);
  } catch (const YAML::Exception& e) {
    throw Error(path + (e.mark.line >= 0 ? ":" + std::to_string(e.mark.line + 1) + ":" + std::to_string(e.mark.column + 1) : "") +
                ": " + printable(e.msg, 120) + " (a value or key of the wrong type)");
  }
}

namespace {
/// Initial state without GT: GNSS fix at time zero, levelling, GNSS course (see replay.hpp).
ins::NavState initialWithoutTruth(const Recording& d, const ReplayConfig& cfg, double t_zero,
                                  double dt, const Eigen::Vector3d& lever_B, filter::Matrix9d& P0,
                                  std::vector<std::string>& notices) {
  const GnssFix* fix = nullptr;
  for (const auto& f : d.gnss)
    if (std::abs(f.t - t_zero) <= 0.5 * dt) {
      fix = &f;
      break;
    }
  if (!fix)
    throw Error(cfg.rawlog + ": no ground truth (label GT) and no GNSS fix at the start of the IMU data (t = " +
                formatNumber(t_zero, 10) + " s) to initialise the filter from");
  if (!fix->v_N)
    throw Error(cfg.rawlog + ": no ground truth and the first GNSS fix has no velocity (GGA only)");
  Eigen::Vector3d rpy;
  std::string how;
  if (cfg.initial_attitude_deg) {
    rpy = *cfg.initial_attitude_deg * kDeg;
    how = "attitude from initial_attitude_deg";
  } else {
    // Yaw from the GNSS course at time zero (no sideslip assumed). Roll and
    // pitch: C_BtoN(0) maps the specific force integrated over the first GNSS
    // interval, resolved in the time-zero body frame with the gyros
    // (u = sum dC_k f_B,k dt), onto the measured velocity change minus gravity
    // (v = v1 - v0 - g_N T; Coriolis and transport rate neglected) - levelling
    // (Groves 2013 eq. 5.101) corrected for the vehicle's own acceleration.
    const Eigen::Vector3d& v0 = *fix->v_N;
    const double vh = v0.head<2>().norm();
    if (vh < 1.0)
      throw Error(cfg.rawlog + ": no ground truth and a horizontal GNSS speed of " + formatNumber(vh, 10) +
                  " m/s at the start, too slow for a course: give initial_attitude_deg: [roll, pitch, yaw]");
    rpy[2] = std::atan2(v0.y(), v0.x());
    const GnssFix* fix1 = nullptr;
    for (const auto& f : d.gnss)
      if (f.t > fix->t + 0.5 * dt && f.v_N) {
        fix1 = &f;
        break;
      }
    if (!fix1 || fix1->t - fix->t > 5.0)
      throw Error(cfg.rawlog + ": no ground truth and no second GNSS fix within 5 s of the start to level with: "
                  "give initial_attitude_deg: [roll, pitch, yaw]");
    Eigen::Quaterniond dq = Eigen::Quaterniond::Identity();
    Eigen::Vector3d u = Eigen::Vector3d::Zero();
    double prev = t_zero;
    for (const auto& s : d.imu) {
      if (s.t > fix1->t + 0.5 * dt) break;
      const double h = s.t - prev;
      dq = (dq * ins::quatFromRotVec(s.w_IB_B * h)).normalized();
      u += dq * (s.f_B * h);
      prev = s.t;
    }
    const double T = fix1->t - fix->t;
    const Eigen::Vector3d v = *fix1->v_N - v0 - earth::gravity_N(fix->pos.lat, fix->pos.h) * T;
    const Eigen::Vector3d uh = u.normalized(), vhat = v.normalized();
    auto resid = [&](double r, double p) {
      ins::NavState a;
      a.setRollPitchYaw(r, p, rpy[2]);
      return Eigen::Vector3d(a.C_BtoN() * uh - vhat);
    };
    double r = 0.0, p = 0.0;
    for (int it = 0; it < 20; ++it) {  // Gauss-Newton on (roll, pitch)
      const Eigen::Vector3d e = resid(r, p);
      Eigen::Matrix<double, 3, 2> J;
      J.col(0) = (resid(r + 1e-6, p) - e) / 1e-6;
      J.col(1) = (resid(r, p + 1e-6) - e) / 1e-6;
      const Eigen::Vector2d step = (J.transpose() * J).ldlt().solve(-J.transpose() * e);
      r += step[0];
      p = std::max(-1.5, std::min(1.5, p + step[1]));
      if (step.norm() < 1e-10) break;
    }
    rpy[0] = ins::wrapAngle(r);
    rpy[1] = p;
    how = "yaw from the GNSS course, roll and pitch from the specific force over the first GNSS interval "
          "matched to the GNSS velocity change minus gravity";
  }
  ins::NavState x;
  x.t = t_zero;
  x.setRollPitchYaw(rpy[0], rpy[1], rpy[2]);
  // antenna -> IMU: p_imu = p_ant - C l (NED offset), velocity lever-arm term neglected
  const earth::Geodetic p = earth::nedToGeodetic(fix->pos, -(x.C_BtoN() * lever_B));
  x.lat = p.lat;
  x.lon = p.lon;
  x.h = p.h;
  x.v_N = *fix->v_N;
  const double rp = std::max(cfg.p0_roll_pitch_deg, 2.0) * kDeg, yw = std::max(cfg.p0_yaw_deg, 5.0) * kDeg;
  P0.setZero();
  P0.topLeftCorner<3, 3>() = fix->cov_pos_N->diagonal().asDiagonal();
  P0.block<3, 3>(3, 3) = fix->cov_vel_N->diagonal().asDiagonal();
  P0.diagonal().tail<3>() << rp * rp, rp * rp, yw * yw;
  notices.push_back("no ground truth in the rawlog: filter initialised from the GNSS fix at time zero, " + how +
                    " (initial sigmas " + formatNumber(rp / kDeg, 10) + " deg roll/pitch, " + formatNumber(yw / kDeg, 10) +
                    " deg yaw); errors and NEES are not available");
  return x;
}
}  // namespace

ReplayResult runReplay(const ReplayConfig& cfg) {
  if (cfg.rawlog.empty()) throw Error("replay: no rawlog given (--rawlog or 'rawlog:' in the configuration)");
  const std::clock_t c0 = std::clock();
  Recording d = rawlog::readRawlog(cfg.rawlog, {cfg.imu_label, cfg.gnss_label});
  ReplayResult r;
  r.read_s = double(std::clock() - c0) / CLOCKS_PER_SEC;
  r.cfg = cfg;
  r.scenario_yaml = d.metadata;
  r.notices = d.notices;
  if (d.imu.size() < 2) throw Error(cfg.rawlog + ": no IMU data (label IMU) to replay");

  YAML::Node scen;
  try {
    if (!d.metadata.empty()) scen = YAML::Load(d.metadata)["navimpact_scenario"];
  } catch (const YAML::Exception&) {
  }
  // IMU model of the filter.
  stochastic::ImuModel model;
  if (!cfg.model_spec.empty()) {
    model = stochastic::loadImuModel(cfg.model_spec);
    r.model_source = model.source;
  } else if (scen && scen["imu_model_yaml"]) {
    const fs::path tmp = fs::temp_directory_path() / ("navimpact_replay_model_" + std::to_string(::getpid()) + ".yaml");
    std::ofstream(tmp) << scen["imu_model_yaml"].as<std::string>();
    try {
      model = stochastic::loadImuModel(tmp.string());
    } catch (...) {
      fs::remove(tmp);
      throw;
    }
    fs::remove(tmp);
    const std::string src = scen["imu"] && scen["imu"]["model"] ? scen["imu"]["model"].as<std::string>() : "";
    model.source = "rawlog scenario model (" + src + ")";
    r.model_source = model.source;
  } else {
    throw Error(cfg.rawlog + ": the scenario records no IMU error model: give one with --model FILE[:NAME]");
  }

  // IMU samples and time zero. The nominal step is the median interval; an
  // interval longer than kGapSteps nominal steps is a gap: an error unless the
  // configuration allows gaps up to max_imu_gap_s, then the filter propagates
  // across it in nominal-length sub-steps with the rates of the sample after
  // the gap held constant, and the outputs say so.
  std::vector<double> steps(d.imu.size() - 1);
  for (std::size_t k = 1; k < d.imu.size(); ++k) steps[k - 1] = d.imu[k].t - d.imu[k - 1].t;
  std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
  const double med = steps[steps.size() / 2];
  const double dt0 = d.imu[1].t - d.imu[0].t;
  const double dt = std::abs(dt0 - med) <= 0.01 * med ? dt0 : med;
  r.imu_rate_hz = 1.0 / dt;
  r.t_zero = d.imu.front().t - dt;
  std::vector<ins::ImuSample> imu;
  imu.reserve(d.imu.size());
  double prev = r.t_zero;
  auto g10 = [](double v) {  // 10 significant digits
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.10g", v);
    return std::string(buf);
  };
  std::size_t gaps = 0;
  double longest = 0.0, longestAt = 0.0;
  for (std::size_t k = 0; k < d.imu.size(); ++k) {
    const double h = d.imu[k].t - prev;
    if (k > 0 && h > kImuGapSteps * med) {
      if (!(h <= cfg.max_imu_gap_s))
        throw Error(cfg.rawlog + ": IMU gap of " + g10(h) + " s ending at t = " + g10(d.imu[k].t - r.t_zero) +
                    " s (nominal step " + g10(med) + " s; the filter would coast across it unnoticed): allow gaps "
                    "up to a length with filter.max_imu_gap_s or --max-imu-gap S (accepted 0-" +
                    g10(kMaxImuGapS) + " s)");
      const auto m = static_cast<std::size_t>(std::llround(h / med));
      if (imu.size() + m > 2 * d.imu.size() + 16)
        throw Error(cfg.rawlog + ": IMU gaps hold more missing samples than the data has samples");
      for (std::size_t j = 1; j <= m; ++j) {
        const double t = j == m ? d.imu[k].t : prev + h * static_cast<double>(j) / static_cast<double>(m);
        imu.push_back(ins::ImuSample::fromRates(t, t - imu.back().t, d.imu[k].w_IB_B, d.imu[k].f_B));
      }
      ++gaps;
      if (h > longest) {
        longest = h;
        longestAt = d.imu[k].t - r.t_zero;
      }
    } else {
      imu.push_back(ins::ImuSample::fromRates(d.imu[k].t, h, d.imu[k].w_IB_B, d.imu[k].f_B));
    }
    prev = d.imu[k].t;
  }
  if (gaps > 0)
    r.notices.push_back(std::to_string(gaps) + " IMU gap(s) longer than " + g10(kImuGapSteps) +
                        " nominal steps accepted (longest " + g10(longest) + " s, ending at t = " + g10(longestAt) +
                        " s; filter.max_imu_gap_s = " + g10(cfg.max_imu_gap_s) +
                        " s): the filter propagated across each with the rates of the sample after it held constant");
  r.imu_gaps = gaps;
  const double t_last = d.imu.back().t;

  // Outages in rawlog time.
  NavRunOptions opt;
  checkOutages(cfg.outages, t_last - r.t_zero,
               "the data (IMU data span 0.." + formatNumber(t_last - r.t_zero, 10) + " s)");
  for (const auto& o : cfg.outages) opt.outages.push_back(o.shifted(r.t_zero));

  // Measurement noise: overridden by the configuration, else recorded with the
  // sample, else (baro) the scenario's.
  double sBaro = NAN;
  if (scen && scen["baro"] && scen["baro"]["sigma_m"]) sBaro = scen["baro"]["sigma_m"].as<double>();
  if (std::isfinite(sBaro) && !cfg.sigma_baro_m)
    limits::check(cfg.rawlog, "scenario baro.sigma_m", sBaro, limits::kPositionSigmaM);
  for (auto& b : d.baro) {
    if (cfg.sigma_baro_m) b.sigma_m = *cfg.sigma_baro_m;
    else if (!b.sigma_m) b.sigma_m = sBaro;
    if (!std::isfinite(*b.sigma_m))
      throw Error(cfg.rawlog + ": barometer sigma not recorded in the scenario: set noise.sigma_baro_m");
  }
  const Eigen::Vector3d kNaN3 = Eigen::Vector3d::Constant(NAN);
  for (auto& f : d.gnss) {
    Eigen::Vector3d sp = f.cov_pos_N ? Eigen::Vector3d(f.cov_pos_N->diagonal().cwiseSqrt()) : kNaN3;
    Eigen::Vector3d sv = f.cov_vel_N ? Eigen::Vector3d(f.cov_vel_N->diagonal().cwiseSqrt()) : kNaN3;
    if (cfg.sigma_pos_h_m) sp.head<2>().setConstant(*cfg.sigma_pos_h_m);
    if (cfg.sigma_pos_v_m) sp[2] = *cfg.sigma_pos_v_m;
    if (cfg.sigma_vel_h_mps) sv.head<2>().setConstant(*cfg.sigma_vel_h_mps);
    if (cfg.sigma_vel_v_mps) sv[2] = *cfg.sigma_vel_v_mps;
    if (!sp.allFinite() || (f.v_N && !sv.allFinite()))
      throw Error(cfg.rawlog + ": GNSS fix at t = " + formatNumber(f.t, 10) + " s has no covariance: set the noise.* sigmas");
    f.cov_pos_N = Eigen::Matrix3d(sp.cwiseAbs2().asDiagonal());
    if (sv.allFinite()) f.cov_vel_N = Eigen::Matrix3d(sv.cwiseAbs2().asDiagonal());
  }
  Eigen::Vector3d lever = Eigen::Vector3d::Zero();
  if (scen && scen["gnss"] && scen["gnss"]["lever_arm_B_m"]) {
    const auto l = scen["gnss"]["lever_arm_B_m"].as<std::vector<double>>();
    if (l.size() == 3 && !cfg.lever_arm_B) {
      for (int k = 0; k < 3; ++k)
        limits::check(cfg.rawlog, "scenario gnss.lever_arm_B_m[" + std::to_string(k) + "]", l[k], limits::kLeverArmM);
      lever = Eigen::Vector3d(l[0], l[1], l[2]);
    }
  }
  if (cfg.lever_arm_B) lever = *cfg.lever_arm_B;
  opt.lever_arm_B = lever;

  // Truth series from GT (tangent-plane NED at the origin -> geodetic).
  const bool hasTruth = !d.reference.empty();
  TruthSeries truth;
  for (const auto& g : d.reference) {
    if (g.t < r.t_zero - 0.5 * dt || g.t > t_last + 0.5 * dt) continue;
    if (!g.v_N || !g.q_BtoN)
      throw Error(cfg.rawlog + ": the reference (GT) at t = " + formatNumber(g.t, 10) +
                  " s has no velocity or attitude; a replay scores against a full reference");
    truth.t.push_back(g.t);
    truth.x.push_back(ins::navStateOf(g, d.origin));
  }
  if (hasTruth && (truth.t.empty() || std::abs(truth.t.front() - r.t_zero) > 0.5 * dt))
    throw Error(cfg.rawlog + ": no GT entry at the start of the IMU data (t = " + formatNumber(r.t_zero, 10) +
                " s) to initialise the filter from");

  NavRunInput in;
  in.imu = &imu;
  in.gnss = &d.gnss;
  in.baro = &d.baro;
  in.truth = hasTruth ? &truth : nullptr;
  opt.record_interval_s = cfg.record_interval_s;
  opt.ekf.propagate_every = cfg.propagate_every;
  opt.ekf.gate_probability = cfg.gate_probability;
  opt.use_gnss_velocity = cfg.use_gnss_velocity;
  opt.P0_nav.setZero();
  const double ph = cfg.p0_pos_h_m, pv = cfg.p0_pos_v_m, vv = cfg.p0_vel_mps;
  const double rp = cfg.p0_roll_pitch_deg * kDeg, yw = cfg.p0_yaw_deg * kDeg;
  opt.P0_nav.diagonal() << ph * ph, ph * ph, pv * pv, vv * vv, vv * vv, vv * vv, rp * rp, rp * rp, yw * yw;
  if (hasTruth) {
    in.x0 = truth.x.front();
    in.x0.t = r.t_zero;
  } else {
    in.x0 = initialWithoutTruth(d, cfg, r.t_zero, dt, lever, opt.P0_nav, r.notices);
  }
  r.run = runNav(in, model, opt);
  std::size_t i = 0;
  for (const auto& e : r.run.epochs) {
    r.estimate.push_back(e.est);
    if (!hasTruth) continue;
    while (i < truth.t.size() && truth.t[i] < e.t - 1e-9) ++i;
    r.truth.push_back(truth.x[std::min(i, truth.t.size() - 1)]);
  }
  return r;
}

}  // namespace navimpact::analysis
