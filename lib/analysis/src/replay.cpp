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

#include "navimpact/core/config.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/text_io.hpp"
#include "navimpact/filter/error_model.hpp"
#include "navimpact/filter/model_entry.hpp"
#include "navimpact/rawlog/writer.hpp"
#include "navimpact/stochastic/model_file.hpp"
#include "navimpact/core/limits.hpp"

namespace navimpact::analysis {

namespace fs = std::filesystem;

namespace {

constexpr double kDeg = M_PI / 180.0;

/// Angles given in degrees (attitude, heading) [deg].
constexpr limits::Range kAngleDeg{-360.0, 360.0, false, "deg"};
/// Angle sigmas [deg].
constexpr limits::Range kAngleSigmaDeg{0.0, 180.0, true, "deg"};
/// Start of an outage from time zero [s].
constexpr limits::Range kOutageStartS{0.0, limits::kDurationS.hi, false, "s"};
/// The reference's own sigmas (0: exact) [m].
constexpr limits::Range kReferenceSigmaM{0.0, limits::kPositionSigmaM.hi, false, "m"};
/// Sigmas of the at-rest detector: gyroscope [rad/s], accelerometer [m/s^2].
constexpr limits::Range kGyroSigmaRadS{0.0, 1000.0, true, "rad/s"};
constexpr limits::Range kAccSigmaMps2{0.0, 1.0e5, true, "m/s^2"};
/// A speed (0 allowed) [m/s].
constexpr limits::Range kSpeedMps{0.0, 1.0e3, false, "m/s"};

/// A sigma given for all three axes (one number) or per axis ([x, y, z]).
Eigen::Vector3d sigma3(const ConfigNode& n, const std::string& k, const limits::Range& r) {
  if (n.child(k).isList()) {
    Eigen::Vector3d v;
    n.read(k, v, r);
    return v;
  }
  return Eigen::Vector3d::Constant(n.number(k, r));
}

}  // namespace

ReplayConfig loadReplayConfig(const std::string& path) {
  InputScope scope(path);
  ReplayConfig c;
  c.config_file = path;
  c.loadFrom(ConfigNode::load(path));
  return c;
}

void ReplayConfig::loadFrom(const ConfigNode& root) {
  ReplayConfig& c = *this;
  root.allowKeys({"rawlog", "model", "outages", "filter", "initial_sigma", "noise", "gnss_lever_arm_B_m",
                  "initial_attitude_deg", "record_interval_s", "outages_every", "reference_sigma",
                  "reference_lever_arm_B_m", "alignment", "imu_at_rest", "aids", "imu_label", "gnss_label"});
  if (root.has("rawlog")) c.rawlog = root.filePath("rawlog");
  if (root.has("imu_label")) c.imu_label = root.text("imu_label", "the sensor label of the IMU entries", true);
  if (root.has("gnss_label")) c.gnss_label = root.text("gnss_label", "the sensor label of the GNSS entries", true);
  if (root.has("model")) c.model_spec = root.modelRef("model");
  for (const ConfigNode& o : root.list("outages", 0, SIZE_MAX, "a list of {start_s, duration_s}")) {
    o.allowKeys({"start_s", "duration_s"});
    const double st = o.number("start_s", kOutageStartS, "seconds from time zero");
    c.outages.push_back(Outage::fromStartDuration(st, o.number("duration_s", limits::kDurationS)));
  }
  if (const auto f = root.optMap("filter")) {
    f->allowKeys({"propagate_every", "use_gnss_velocity", "gate_probability", "gate_readmit_after", "max_imu_gap_s",
                  "extra_states"});
    if (const auto x = f->optMap("extra_states")) c.extra_states.loadFrom(*x);
    f->read("max_imu_gap_s", c.max_imu_gap_s, limits::Range{0.0, kMaxImuGapS, false, "s"});
    f->read("propagate_every", c.propagate_every, 1, limits::kMaxPropagateEvery);
    f->read("use_gnss_velocity", c.use_gnss_velocity);
    f->read("gate_probability", c.gate_probability, limits::Range{0.0, 1.0, false, "(probability; 0 = gate off)"});
    f->read("gate_readmit_after", c.gate_readmit_after, 0, 1000);
  }
  if (const auto p = root.optMap("initial_sigma")) {
    p->allowKeys({"pos_h_m", "pos_v_m", "vel_mps", "roll_pitch_deg", "yaw_deg"});
    p->read("pos_h_m", c.p0_pos_h_m, limits::kPositionSigmaM);
    p->read("pos_v_m", c.p0_pos_v_m, limits::kPositionSigmaM);
    p->read("vel_mps", c.p0_vel_mps, limits::kVelocitySigmaMps);
    p->read("roll_pitch_deg", c.p0_roll_pitch_deg, kAngleSigmaDeg);
    p->read("yaw_deg", c.p0_yaw_deg, kAngleSigmaDeg);
  }
  if (const auto n = root.optMap("noise")) {
    n->allowKeys({"sigma_pos_h_m", "sigma_pos_v_m", "sigma_vel_h_mps", "sigma_vel_v_mps", "sigma_baro_m"});
    n->read("sigma_pos_h_m", c.sigma_pos_h_m, limits::kPositionSigmaM);
    n->read("sigma_pos_v_m", c.sigma_pos_v_m, limits::kPositionSigmaM);
    n->read("sigma_vel_h_mps", c.sigma_vel_h_mps, limits::kVelocitySigmaMps);
    n->read("sigma_vel_v_mps", c.sigma_vel_v_mps, limits::kVelocitySigmaMps);
    n->read("sigma_baro_m", c.sigma_baro_m, limits::kPositionSigmaM);
  }
  Eigen::Vector3d v;
  if (root.read("gnss_lever_arm_B_m", v, limits::kLeverArmM)) c.lever_arm_B = v;
  if (root.read("initial_attitude_deg", v, kAngleDeg)) c.initial_attitude_deg = v;
  root.read("record_interval_s", c.record_interval_s, limits::kDurationS);
  if (const auto o = root.optMap("outages_every")) {
    o->allowKeys({"period_s", "duration_s"});
    OutagePattern p{o->number("period_s", limits::kDurationS), o->number("duration_s", limits::kDurationS)};
    if (!(p.period_s > p.duration_s))
      throw o->error("period_s", "must exceed duration_s (GNSS time to reconverge)");
    c.outages_every = p;
  }
  if (const auto r = root.optMap("reference_sigma")) {
    r->allowKeys({"horizontal_m", "vertical_m"});
    r->read("horizontal_m", c.reference_sigma_h_m, kReferenceSigmaM);
    r->read("vertical_m", c.reference_sigma_v_m, kReferenceSigmaM);
  }
  root.read("reference_lever_arm_B_m", c.reference_lever_arm_B, limits::kLeverArmM);
  if (const auto a = root.optMap("alignment")) {
    a->allowKeys({"yaw_deg", "yaw_sigma_deg", "max_align_s", "max_course_sigma_deg", "min_static_s", "max_level_s",
                  "sideslip_sigma_deg"});
    double x = 0.0;
    if (a->read("yaw_deg", x, kAngleDeg)) {
      c.alignment.yaw_rad = x * kDeg;
      c.alignment.yaw_source = "configuration";
    }
    if (a->read("yaw_sigma_deg", x, kAngleSigmaDeg)) c.alignment.yaw_sigma_rad = x * kDeg;
    a->read("max_align_s", c.alignment.max_align_s, limits::kDurationS);
    if (a->read("max_course_sigma_deg", x, kAngleSigmaDeg)) c.alignment.max_course_sigma_rad = x * kDeg;
    if (a->read("sideslip_sigma_deg", x, kAngleSigmaDeg)) c.alignment.sideslip_sigma_rad = x * kDeg;
    a->read("min_static_s", c.alignment.min_static_s, limits::kDurationS);
    a->read("max_level_s", c.alignment.max_level_s, limits::kDurationS);
  }
  if (const auto r = root.optMap("imu_at_rest")) {
    r->allowKeys({"gyro_sigma_rad_s", "acc_sigma_mps2", "window_s", "false_alarm", "max_mean_rate_rad_s"});
    auto& d = c.alignment.detector;
    if (r->has("gyro_sigma_rad_s")) d.gyro_sigma_rad_s = sigma3(*r, "gyro_sigma_rad_s", kGyroSigmaRadS);
    if (r->has("acc_sigma_mps2")) d.acc_sigma_mps2 = sigma3(*r, "acc_sigma_mps2", kAccSigmaMps2);
    r->read("window_s", d.window_s, limits::kDurationS);
    if (r->read("false_alarm", d.false_alarm, limits::Range{0.0, 0.5, true, "(probability)"}) &&
        !(d.false_alarm < 0.5))
      throw r->error("false_alarm", "must be in (0, 0.5)");
    r->read("max_mean_rate_rad_s", d.max_mean_rate_rad_s, kGyroSigmaRadS);
  }
  c.aids.zupt_detector = c.alignment.detector;
  if (const auto a = root.optMap("aids")) {
    a->allowKeys({"zupt", "nhc"});
    if (const auto z = a->optMap("zupt")) {
      z->allowKeys({"sigma_mps", "interval_s"});
      c.aids.zupt = true;
      z->read("sigma_mps", c.aids.zupt_sigma_mps, limits::kVelocitySigmaMps);
      z->read("interval_s", c.aids.zupt_interval_s, limits::kDurationS);
    }
    if (const auto n = a->optMap("nhc")) {
      n->allowKeys({"sigma_lateral_mps", "sigma_vertical_mps", "interval_s", "min_speed_mps", "point_B_m"});
      c.aids.nhc = true;
      n->read("sigma_lateral_mps", c.aids.nhc_sigma_lateral_mps, limits::kVelocitySigmaMps);
      n->read("sigma_vertical_mps", c.aids.nhc_sigma_vertical_mps, limits::kVelocitySigmaMps);
      n->read("interval_s", c.aids.nhc_interval_s, limits::kDurationS);
      n->read("min_speed_mps", c.aids.nhc_min_speed_mps, kSpeedMps);
      n->read("point_B_m", c.aids.nhc_point_B, limits::kLeverArmM);
    }
  }
}


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
  if (cfg.model) {
    model = *cfg.model;
    r.model_source = model.source.empty() ? cfg.model_spec : model.source;
  } else if (!cfg.model_spec.empty()) {
    model = stochastic::loadImuModel(cfg.model_spec);
    r.model_source = model.source;
  } else if (scen && scen["imu_model_yaml"]) {
    model = stochastic::parseImuModel(scen["imu_model_yaml"].as<std::string>(),
                                      cfg.rawlog + " (scenario imu_model_yaml)");
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

  // Reference series (GT: tangent-plane NED at the origin -> geodetic). A
  // reference without velocity or attitude is scored on what it has (the
  // missing parts NaN); the filter starts from it only when it is complete
  // and has an entry at time zero, else after an aligning phase.
  const bool hasTruth = cfg.use_reference && !d.reference.empty();
  TruthSeries truth;
  bool fullRef = true;
  ReferenceInfo refInfo;
  refInfo.sigma_h_m = cfg.reference_sigma_h_m;
  refInfo.sigma_v_m = cfg.reference_sigma_v_m;
  bool refSigmaFromData = cfg.reference_sigma_h_m == 0.0 && cfg.reference_sigma_v_m == 0.0;
  for (const auto& g : d.reference) {
    if (g.t < r.t_zero - 0.5 * dt || g.t > t_last + 0.5 * dt) continue;
    ins::NavState x;
    x.t = g.t;
    const earth::Geodetic p = earth::nedToGeodetic(d.origin, g.p_L);
    x.lat = p.lat;
    x.lon = p.lon;
    x.h = p.h;
    x.v_N = g.v_N ? *g.v_N : Eigen::Vector3d::Constant(NAN);
    x.q_BtoN = g.q_BtoN ? g.q_BtoN->normalized() : Eigen::Quaterniond(NAN, NAN, NAN, NAN);
    refInfo.has_velocity = refInfo.has_velocity && g.v_N.has_value();
    refInfo.has_attitude = refInfo.has_attitude && g.q_BtoN.has_value();
    fullRef = fullRef && g.v_N && g.q_BtoN;
    if (refSigmaFromData && g.sigma_p_L) {  // the reference's own sigma as recorded (largest seen)
      refInfo.sigma_h_m = std::max(refInfo.sigma_h_m, g.sigma_p_L->head<2>().maxCoeff());
      refInfo.sigma_v_m = std::max(refInfo.sigma_v_m, (*g.sigma_p_L)[2]);
    }
    truth.t.push_back(g.t);
    truth.x.push_back(x);
  }
  if (hasTruth && truth.t.empty())
    throw Error(cfg.rawlog + ": the reference (GT) has no entry inside the IMU data");
  const bool startFromRef = hasTruth && fullRef && std::abs(truth.t.front() - r.t_zero) <= 0.5 * dt;
  if (hasTruth && !startFromRef)
    r.notices.push_back(std::string("the reference ") +
                        (fullRef ? "has no entry at the start of the IMU data"
                                 : std::string("has no ") +
                                       (!refInfo.has_velocity && !refInfo.has_attitude ? "velocity and attitude"
                                        : refInfo.has_velocity                         ? "attitude"
                                                                                       : "velocity")) +
                        ": the filter starts after an aligning phase and is scored on what the reference has");

  NavRunInput in;
  in.imu = &imu;
  in.gnss = &d.gnss;
  in.baro = &d.baro;
  in.truth = hasTruth ? &truth : nullptr;
  opt.record_interval_s = cfg.record_interval_s;
  opt.ekf.propagate_every = cfg.propagate_every;
  opt.ekf.gate_probability = cfg.gate_probability;
  opt.ekf.gate_readmit_after = cfg.gate_readmit_after;
  opt.ekf.imu.extra = cfg.extra_states;
  opt.use_gnss_velocity = cfg.use_gnss_velocity;
  opt.P0_nav.setZero();
  const double ph = cfg.p0_pos_h_m, pv = cfg.p0_pos_v_m, vv = cfg.p0_vel_mps;
  const double rp = cfg.p0_roll_pitch_deg * kDeg, yw = cfg.p0_yaw_deg * kDeg;
  opt.P0_nav.diagonal() << ph * ph, ph * ph, pv * pv, vv * vv, vv * vv, vv * vv, rp * rp, rp * rp, yw * yw;
  opt.reference_lever_B = cfg.reference_lever_arm_B;
  opt.zupt = cfg.aids.zupt;
  opt.zupt_detector = cfg.alignment.detector;
  opt.zupt_sigma_mps = cfg.aids.zupt_sigma_mps;
  opt.zupt_interval_s = cfg.aids.zupt_interval_s;
  opt.nhc = cfg.aids.nhc;
  opt.nhc_sigma_lateral_mps = cfg.aids.nhc_sigma_lateral_mps;
  opt.nhc_sigma_vertical_mps = cfg.aids.nhc_sigma_vertical_mps;
  opt.nhc_interval_s = cfg.aids.nhc_interval_s;
  opt.nhc_min_speed_mps = cfg.aids.nhc_min_speed_mps;
  opt.nhc_point_B = cfg.aids.nhc_point_B;
  std::vector<GnssFix> gnssAfter;
  if (startFromRef) {
    in.x0 = truth.x.front();
    in.x0.t = r.t_zero;
  } else {
    // The aligning phase: from time zero until the aligner has an attitude,
    // a position and a velocity; the filter starts at that IMU sample.
    filter::AlignmentOptions ao = cfg.alignment;
    ao.lever_arm_B = lever;
    if (!ao.yaw_rad && cfg.initial_attitude_deg) {
      ao.yaw_rad = (*cfg.initial_attitude_deg)[2] * kDeg;
      ao.yaw_source = "configuration (initial_attitude_deg)";
    }
    std::size_t k = 0, ig = 0;
    try {
      filter::CoarseAligner al(ao, r.t_zero, r.imu_rate_hz);
      for (; k < imu.size() && !al.done(); ++k) {
        al.addImu(imu[k]);
        while (!al.done() && ig < d.gnss.size() && d.gnss[ig].t <= imu[k].t + 1e-9) {
          const GnssFix& f = d.gnss[ig++];
          bool out = false;
          for (const auto& o : opt.outages) out = out || o.covers(f.t);
          if (out) continue;
          filter::AlignmentFix af;
          af.t = f.t;
          af.pos = f.pos;
          af.sigma_pos_N = f.cov_pos_N->diagonal().cwiseSqrt();
          if (cfg.use_gnss_velocity && f.v_N && f.cov_vel_N) {
            af.v_N = *f.v_N;
            af.sigma_vel_N = f.cov_vel_N->diagonal().cwiseSqrt();
          }
          al.addFix(af);
        }
      }
      if (!al.done())
        throw Error("the IMU data end before the aligning phase does: " + al.missing());
      if (k >= imu.size()) throw Error("the aligning phase ends with the IMU data: nothing left to navigate");
      in.x0 = al.state();
      opt.P0_nav = al.P0();
      r.alignment = al.report();
      for (const auto& f : d.gnss)
        if (f.t > al.usedFixTime() + 1e-9) gnssAfter.push_back(f);
    } catch (const Error& e) {
      throw Error(cfg.rawlog + ": aligning (no complete reference at the start): " + e.what());
    }
    imu.erase(imu.begin(), imu.begin() + static_cast<std::ptrdiff_t>(k));
    in.gnss = &gnssAfter;
    r.aided_from_s = in.x0.t - r.t_zero;
    r.notices.push_back(std::string(hasTruth ? "" : "no ground truth in the rawlog: ") + "aligning phase from 0 to " +
                        formatNumber(r.aided_from_s, 10) + " s (levelling " + r.alignment->levelling + ", heading from " +
                        r.alignment->heading + "), the filter runs from there" +
                        (hasTruth ? "" : "; errors and NEES are not available"));
    for (const auto& n : r.alignment->notes) r.notices.push_back("alignment: " + n);
  }
  // Outages all along the run, each after period - duration of GNSS from the filter start.
  if (cfg.outages_every) {
    for (const Outage& w : outagesEvery(*cfg.outages_every, in.x0.t, t_last)) {
      opt.outages.push_back(w);
      r.cfg.outages.push_back({w.start_s - r.t_zero, w.end_s - r.t_zero});
    }
    if (opt.outages.size() == cfg.outages.size())
      r.notices.push_back("outages every " + formatNumber(cfg.outages_every->period_s, 10) + ":" +
                          formatNumber(cfg.outages_every->duration_s, 10) + " s: none fits in the data after the filter start");
  }
  {
    // The one model-entry path: converted to the data's IMU rate (a rate within
    // 0.1 % of the model's is the same sensor's clock jitter, not another rate),
    // GMs the filter cannot carry entered as white noise; the notices say so.
    const double rate = std::abs(model.rate_hz - r.imu_rate_hz) <= 1e-3 * r.imu_rate_hz ? model.rate_hz : r.imu_rate_hz;
    filter::ModelEntry entry = filter::layoutFor(model, opt.ekf, rate);
    model = std::move(entry.model);
    for (const auto& n : entry.notes) r.notices.push_back("filter model: " + n);
  }
  r.run = runNav(in, model, opt);
  r.nav = opt;
  r.gnss = *in.gnss;
  r.baro = d.baro;
  if (hasTruth) r.score = scoreRun(r.run, r.t_zero, in.x0.t, refInfo);
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
