// Rawlog replay through the shared navigation loop (runNav), and its report.
#include "navimpact/analysis/replay.hpp"

#include <yaml-cpp/yaml.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <limits>
#include <string_view>
#include <optional>
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
#include "navimpact/core/units.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/text_io.hpp"
#include "navimpact/core/yaml_load.hpp"
#include "navimpact/filter/error_model.hpp"
#include "navimpact/filter/model_entry.hpp"
#include "navimpact/rawlog/reader.hpp"
#include "navimpact/stochastic/model_file.hpp"
#include "navimpact/core/limits.hpp"

namespace navimpact::analysis {

namespace fs = std::filesystem;

namespace {

constexpr double kDeg = M_PI / 180.0;

/// Angles given in degrees (attitude, heading) [deg].
constexpr limits::Range kAngleDeg{-360.0, 360.0, false, "deg"};
/// Start of an outage from time zero [s].
constexpr limits::Range kOutageStartS{0.0, limits::kDurationS.hi, false, "s"};
/// The reference's own sigmas (0: exact) [m].
constexpr limits::Range kReferenceSigmaM{0.0, limits::kPositionSigmaM.hi, false, "m"};
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

ReplayConfig loadReplayConfig(const std::string& path, const std::vector<std::string>& given_by_flags) {
  return loadConfigFile(path, &ReplayConfig::config_file, given_by_flags);
}

void ReplayConfig::loadFrom(const ConfigNode& root, const std::vector<std::string>& given_by_flags) {
  ReplayConfig& c = *this;
  root.allowKeys({"rawlog", "model", "outages", "filter", "initial_sigma", "noise", "gnss_lever_arm_B_m",
                  "initial_attitude_deg", "record_interval_s", "outages_every", "reference_sigma",
                  "reference_lever_arm_B_m", "alignment", "imu_at_rest", "aids", "imu_label", "gnss_label"});
  // the files of rawlog and model are checked unless a flag replaces them
  auto flagged = [&](const char* k) {
    return std::find(given_by_flags.begin(), given_by_flags.end(), k) != given_by_flags.end();
  };
  if (root.has("rawlog"))
    c.rawlog = flagged("rawlog") ? root.text("rawlog") : root.inputFile("rawlog", "the rawlog to replay");
  if (root.has("imu_label")) c.imu_label = root.text("imu_label", "the sensor label of the IMU entries", true);
  if (root.has("gnss_label")) c.gnss_label = root.text("gnss_label", "the sensor label of the GNSS entries", true);
  if (root.has("model")) c.model_spec = flagged("model") ? root.text("model") : root.modelRef("model");
  for (const ConfigNode& o : root.list("outages", 0, SIZE_MAX, "a list of {start_s, duration_s}")) {
    o.allowKeys({"start_s", "duration_s"});
    const double st = o.number("start_s", kOutageStartS, "seconds from time zero");
    c.outages.push_back(Outage::fromStartDuration(st, o.number("duration_s", limits::kDurationS)));
    c.outage_names.push_back(o.error("outage " + outageText(c.outages.back())).what());
  }
  if (const auto f = root.optMap("filter")) {
    f->allowKeys({"propagate_every", "use_gnss_velocity", "gate_probability", "gate_readmit_after", "max_imu_gap_s",
                  "extra_states"});
    if (const auto x = f->optMap("extra_states")) c.extra_states.loadFrom(*x);
    f->read("max_imu_gap_s", c.max_imu_gap_s, limits::Range{0.0, kMaxImuGapS, false, "s"});
    f->read("propagate_every", c.propagate_every, 1, limits::kMaxPropagateEvery);
    f->read("use_gnss_velocity", c.use_gnss_velocity);
    if (f->read("gate_probability", c.gate_probability, limits::Range{0.0, 1.0, false, "(probability; 0 = gate off)"}) &&
        !(c.gate_probability == 0.0 ||
          (c.gate_probability >= filter::kMinGateProbability && c.gate_probability < 1.0)))
      throw f->error("gate_probability", "must be 0 (gate off) or in [" + formatNumber(filter::kMinGateProbability, 3) +
                                             ", 1) (a gate below the median rejects most consistent innovations), got " +
                                             formatNumber(c.gate_probability, 9));
    f->read("gate_readmit_after", c.gate_readmit_after, 0, 1000);
  }
  if (const auto p = root.optMap("initial_sigma")) {
    p->allowKeys({"pos_h_m", "pos_v_m", "vel_mps", "roll_pitch_deg", "yaw_deg"});
    p->read("pos_h_m", c.p0_pos_h_m, limits::kPositionSigmaM);
    p->read("pos_v_m", c.p0_pos_v_m, limits::kPositionSigmaM);
    p->read("vel_mps", c.p0_vel_mps, limits::kVelocitySigmaMps);
    p->read("roll_pitch_deg", c.p0_roll_pitch_deg, limits::kAttitudeSigmaDeg);
    p->read("yaw_deg", c.p0_yaw_deg, limits::kAttitudeSigmaDeg);
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
    a->allowKeys({"yaw_deg", "yaw_sigma_deg", "yaw_from_reference", "max_align_s", "max_course_sigma_deg",
                  "min_static_s", "max_level_s", "sideslip_sigma_deg"});
    a->read("yaw_from_reference", c.alignment_yaw_from_reference);
    double x = 0.0;
    if (a->read("yaw_deg", x, kAngleDeg)) {
      c.alignment.yaw_rad = x * kDeg;
      c.alignment.yaw_source = "configuration";
    }
    if (a->read("yaw_sigma_deg", x, limits::kAttitudeSigmaDeg)) c.alignment.yaw_sigma_rad = x * kDeg;
    a->read("max_align_s", c.alignment.max_align_s, limits::kDurationS);
    if (a->read("max_course_sigma_deg", x, limits::kAttitudeSigmaDeg)) c.alignment.max_course_sigma_rad = x * kDeg;
    if (a->read("sideslip_sigma_deg", x, limits::kAttitudeSigmaDeg)) c.alignment.sideslip_sigma_rad = x * kDeg;
    a->read("min_static_s", c.alignment.min_static_s, limits::kDurationS);
    a->read("max_level_s", c.alignment.max_level_s, limits::kDurationS);
  }
  if (const auto r = root.optMap("imu_at_rest")) {
    r->allowKeys({"gyro_sigma_rad_s", "acc_sigma_mps2", "window_s", "false_alarm", "max_mean_rate_rad_s"});
    auto& d = c.alignment.detector;
    if (r->has("gyro_sigma_rad_s")) d.gyro_sigma_rad_s = sigma3(*r, "gyro_sigma_rad_s", limits::kAtRestGyroSigmaRadS);
    if (r->has("acc_sigma_mps2")) d.acc_sigma_mps2 = sigma3(*r, "acc_sigma_mps2", limits::kAtRestAccSigmaMps2);
    r->read("window_s", d.window_s, limits::kDurationS);
    if (r->read("false_alarm", d.false_alarm, limits::Range{0.0, 0.5, true, "(probability)"}) &&
        !(d.false_alarm < 0.5))
      throw r->error("false_alarm", "must be in (0, 0.5)");
    r->read("max_mean_rate_rad_s", d.max_mean_rate_rad_s, limits::kAtRestGyroSigmaRadS);
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


namespace {

/// A replay read record by record: the rawlog, the records read ahead of the
/// filter, the IMU samples (gaps filled when allowed), and the runner once it
/// exists (then records go straight to it).
class ReplayDriver {
 public:
  ReplayDriver(const ReplayConfig& cfg, ReplayResult& r, ReplayObserver* obs) : cfg_(cfg), r_(r), obs_(obs) {
    reader_.emplace(cfg.rawlog, rawlog::RawlogReadOptions{cfg.imu_label, cfg.gnss_label});
  }
  /// From records in memory; the filter stops at the first IMU sample after
  /// @p stop_after_s from time zero (the rest of the data is still read).
  ReplayDriver(const ReplayConfig& cfg, ReplayResult& r, const rawlog::RawlogRecords& data, double stop_after_s)
      : cfg_(cfg), r_(r), obs_(nullptr), data_(&data), stopAfter_(stop_after_s) {
    cursor_.emplace(data);
  }

  void run();

 private:
  using Clock = std::chrono::steady_clock;
  const ReplayConfig& cfg_;
  ReplayResult& r_;
  ReplayObserver* obs_;
  std::optional<rawlog::RawlogReader> reader_;        // the rawlog read as the filter goes
  const rawlog::RawlogRecords* data_ = nullptr;       // or its records in memory
  std::optional<rawlog::RawlogRecordCursor> cursor_;
  double stopAfter_ = std::numeric_limits<double>::infinity();  // filter stop, from time zero [s]
  YAML::Node scen_;

  const Recording& header() const { return reader_ ? reader_->header() : data_->data; }

  // records read ahead (before the runner exists)
  std::deque<ImuRecord> imuQ_;
  std::deque<GnssFix> gnssQ_;
  std::deque<BaroSample> baroQ_;
  std::deque<ReferenceRecord> refQ_;
  bool eof_ = false;
  bool setup_ = false;       // noise, time zero and the reference decided: records are taken as they come
  double readT_ = -1e300;    // time of the last record read
  double lastImuT_ = -1e300; // time of the last IMU record read (the data's end once eof_)
  std::size_t imuRecords_ = 0;
  double readS_ = 0.0;

  // IMU samples
  double med_ = 0.0, dt_ = 0.0;
  double prevT_ = 0.0;               // time of the last IMU record turned into samples
  std::size_t produced_ = 0;         // samples produced (gap fillers included)
  struct Sample {
    ins::ImuSample s;
    double psd_w = 0.0, psd_f = 0.0;  // unmeasured (in a gap): the rates' uncertainty (nextSample)
  };
  std::deque<Sample> samples_;
  std::deque<ImuRecord> recent_;     // the last kRecentImu records (a gap's rate variability)
  std::size_t gaps_ = 0;
  std::string startNotice_;          // the filter starts at the first IMU sample (streams that start together)
  double longest_ = 0.0, longestAt_ = 0.0;
  bool firstRecord_ = true;

  // measurements
  double sBaro_ = NAN;
  bool hasTruth_ = false, refSigmaFromData_ = true;
  ReferenceInfo refInfo_;
  std::size_t truthInside_ = 0, ignoredRef_ = 0;
  struct RefFlags {
    double t;
    bool v, q;
    std::optional<Eigen::Vector3d> sigma;
  };
  std::deque<RefFlags> refTail_;  // reference entries after the last IMU record read (inside the data or not)
  earth::Geodetic origin_;

  // the filter
  NavRunOptions opt_;
  std::optional<NavRunner> runner_;
  std::optional<RunScorer> scorer_;
  std::vector<ins::NavState> truthKept_;
  TruthSeries truthAhead_;  // reference states read before the filter starts

  // outages every PERIOD:DURATION, decided one by one
  bool windowsOpen_ = false;
  long nextWindow_ = 0;
  double aidedFrom_ = 0.0;

  static std::string g10(double v) {  // 10 significant digits
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.10g", v);
    return std::string(buf);
  }

  bool readOne();
  void fillTo(double t) {
    while (!eof_ && readT_ <= t) readOne();
  }
  bool nextSample(ins::ImuSample& s, double* psd_w = nullptr, double* psd_f = nullptr);
  std::pair<double, double> gapPsd(const ImuRecord& after, double h) const;
  bool peekSample();
  void takeGnss(GnssFix f);
  void takeBaro(BaroSample b);
  void takeReference(const ReferenceRecord& g);
  void foldRefFlags(const RefFlags& f);
  void decideWindows(double t_now);
};

void ReplayDriver::foldRefFlags(const RefFlags& f) {
  refInfo_.has_velocity = refInfo_.has_velocity && f.v;
  refInfo_.has_attitude = refInfo_.has_attitude && f.q;
  if (refSigmaFromData_ && f.sigma) {  // the reference's own sigma as recorded (largest seen)
    refInfo_.sigma_h_m = std::max(refInfo_.sigma_h_m, f.sigma->head<2>().maxCoeff());
    refInfo_.sigma_v_m = std::max(refInfo_.sigma_v_m, (*f.sigma)[2]);
  }
  ++truthInside_;
}

// Read one record and hand it on: to the runner once it exists, else to the queues.
bool ReplayDriver::readOne() {
  rawlog::RawlogRecord rec;
  bool got = false;
  if (reader_) {
    const auto c0 = Clock::now();
    got = reader_->next(rec);
    readS_ += std::chrono::duration<double>(Clock::now() - c0).count();
  } else {
    got = cursor_->next(rec);
  }
  if (!got) {
    eof_ = true;
    refTail_.clear();  // reference entries after the data's end count for nothing
    return false;
  }
  readT_ = rec.t;
  switch (rec.kind) {
    case rawlog::RawlogRecord::Kind::Imu:
      ++imuRecords_;
      lastImuT_ = rec.t;
      while (!refTail_.empty() && refTail_.front().t <= lastImuT_ + 0.5 * dt_) {
        foldRefFlags(refTail_.front());
        refTail_.pop_front();
      }
      imuQ_.push_back(rec.imu);
      break;
    case rawlog::RawlogRecord::Kind::Gnss:
      if (setup_) takeGnss(std::move(rec.gnss));
      else gnssQ_.push_back(std::move(rec.gnss));
      break;
    case rawlog::RawlogRecord::Kind::Baro:
      if (setup_) takeBaro(rec.baro);
      else baroQ_.push_back(rec.baro);
      break;
    case rawlog::RawlogRecord::Kind::Reference:
      if (setup_) takeReference(rec.reference);
      else refQ_.push_back(rec.reference);
      break;
  }
  return true;
}

// Measurement noise: overridden by the configuration, else recorded with the
// sample, else (baro) the scenario's.
void ReplayDriver::takeGnss(GnssFix f) {
  const Eigen::Vector3d kNaN3 = Eigen::Vector3d::Constant(NAN);
  Eigen::Vector3d sp = f.cov_pos_N ? Eigen::Vector3d(f.cov_pos_N->diagonal().cwiseSqrt()) : kNaN3;
  Eigen::Vector3d sv = f.cov_vel_N ? Eigen::Vector3d(f.cov_vel_N->diagonal().cwiseSqrt()) : kNaN3;
  if (cfg_.sigma_pos_h_m) sp.head<2>().setConstant(*cfg_.sigma_pos_h_m);
  if (cfg_.sigma_pos_v_m) sp[2] = *cfg_.sigma_pos_v_m;
  if (cfg_.sigma_vel_h_mps) sv.head<2>().setConstant(*cfg_.sigma_vel_h_mps);
  if (cfg_.sigma_vel_v_mps) sv[2] = *cfg_.sigma_vel_v_mps;
  if (!sp.allFinite())
    throw Error(cfg_.rawlog + ": GNSS fix at t = " + formatNumber(f.t, 10) +
                " s has no position sigma: set noise.sigma_pos_h_m and noise.sigma_pos_v_m in the replay configuration");
  if (f.v_N && !sv.allFinite() && cfg_.use_gnss_velocity)
    throw Error(cfg_.rawlog + ": GNSS fix at t = " + formatNumber(f.t, 10) +
                " s has a velocity without sigma: set noise.sigma_vel_h_mps and noise.sigma_vel_v_mps in the replay "
                "configuration (or filter.use_gnss_velocity: false)");
  f.cov_pos_N = Eigen::Matrix3d(sp.cwiseAbs2().asDiagonal());
  if (sv.allFinite()) f.cov_vel_N = Eigen::Matrix3d(sv.cwiseAbs2().asDiagonal());
  if (runner_) {
    if (!obs_) r_.gnss.push_back(f);
    runner_->addGnss(f);
  } else {
    gnssQ_.push_back(std::move(f));
  }
}

void ReplayDriver::takeBaro(BaroSample b) {
  if (cfg_.sigma_baro_m) b.sigma_m = *cfg_.sigma_baro_m;
  else if (!b.sigma_m) b.sigma_m = sBaro_;
  if (!std::isfinite(*b.sigma_m))
    throw Error(cfg_.rawlog + ": barometer sigma not recorded in the scenario: set noise.sigma_baro_m");
  if (!obs_) r_.baro.push_back(b);
  if (runner_) runner_->addBaro(b);
  else baroQ_.push_back(b);
}

// Reference entries (GT: tangent-plane NED at the origin -> geodetic) inside
// the IMU data; each counts for the reference's content and own sigma.
void ReplayDriver::takeReference(const ReferenceRecord& g) {
  if (!hasTruth_) {
    if (cfg_.use_reference) ++ignoredRef_;
    return;
  }
  if (g.t < r_.t_zero - 0.5 * dt_) return;
  RefFlags fl{g.t, g.v_N.has_value(), g.q_BtoN.has_value(), g.sigma_p_L};
  if (g.t <= lastImuT_ + 0.5 * dt_) foldRefFlags(fl);
  else refTail_.push_back(fl);
  ins::NavState x;
  x.t = g.t;
  const earth::Geodetic p = earth::nedToGeodetic(origin_, g.p_L);
  x.lat = p.lat;
  x.lon = p.lon;
  x.h = p.h;
  x.v_N = g.v_N ? *g.v_N : Eigen::Vector3d::Constant(NAN);
  x.q_BtoN = g.q_BtoN ? g.q_BtoN->normalized() : Eigen::Quaterniond(NAN, NAN, NAN, NAN);
  if (runner_) {
    runner_->addTruth(g.t, x);
  } else {
    truthAhead_.t.push_back(g.t);
    truthAhead_.x.push_back(x);
  }
}

/// Records kept for a gap's rate variability (20 s at 200 Hz).
constexpr std::size_t kRecentImu = 4096;

// The rates' uncertainty across an IMU gap of @p h seconds ending at @p after:
// each rate is taken as a random walk of increment variance q per second,
// pinned at the samples before and after the gap (a Brownian bridge; the
// interpolated rates are its mean). Its integral over the gap, the attitude
// (velocity) error, has variance q h^3 / 12: white noise of PSD q h^2 / 12 over
// the gap's sub-steps gives the same. q per axis, the largest: the larger of
// the rates' change across the gap squared over h and the mean squared change
// over a lag of h (or the longest lag held, scaled as a random walk) in the
// records before it (sensor noise included: conservative). The bridge misses
// motion that is not a random walk (a rover's bumps), so the PSD is at least
// the measured one: the mean squared error of the same interpolation over every
// window of the gap's length in those records, integrated over the window
// (e = sum of x dt over the window - its length x the mean of its end samples),
// over h.
std::pair<double, double> ReplayDriver::gapPsd(const ImuRecord& after, double h) const {
  const ImuRecord& before = recent_.back();
  double qw = (after.w_IB_B - before.w_IB_B).cwiseAbs2().maxCoeff() / h;
  double qf = (after.f_B - before.f_B).cwiseAbs2().maxCoeff() / h;
  if (recent_.size() >= 2) {
    const std::size_t lag = std::min<std::size_t>(recent_.size() - 1,
                                                  std::max<std::size_t>(1, std::size_t(std::llround(h / med_))));
    Eigen::Vector3d dw = Eigen::Vector3d::Zero(), df = Eigen::Vector3d::Zero();
    for (std::size_t k = lag; k < recent_.size(); ++k) {
      dw += (recent_[k].w_IB_B - recent_[k - lag].w_IB_B).cwiseAbs2();
      df += (recent_[k].f_B - recent_[k - lag].f_B).cwiseAbs2();
    }
    const double n = double(recent_.size() - lag), tau = recent_.back().t - recent_[recent_.size() - 1 - lag].t;
    if (tau > 0.0) {
      qw = std::max(qw, dw.maxCoeff() / n / tau);
      qf = std::max(qf, df.maxCoeff() / n / tau);
    }
  }
  double pw = qw * h * h / 12.0, pf = qf * h * h / 12.0;
  // the measured interpolation error over windows of the gap's length
  const std::size_t lag = std::size_t(std::llround(h / med_));
  if (lag >= 1 && recent_.size() > lag + 1) {
    std::vector<Eigen::Vector3d> Sw(recent_.size(), Eigen::Vector3d::Zero()), Sf(recent_.size(), Eigen::Vector3d::Zero());
    for (std::size_t j = 1; j < recent_.size(); ++j) {
      const double dt = recent_[j].t - recent_[j - 1].t;
      Sw[j] = Sw[j - 1] + recent_[j].w_IB_B * dt;
      Sf[j] = Sf[j - 1] + recent_[j].f_B * dt;
    }
    Eigen::Vector3d ew = Eigen::Vector3d::Zero(), ef = Eigen::Vector3d::Zero();
    for (std::size_t k = lag; k < recent_.size(); ++k) {
      const std::size_t a = k - lag;
      const double len = recent_[k].t - recent_[a].t;
      ew += (Sw[k] - Sw[a] - 0.5 * len * (recent_[a].w_IB_B + recent_[k].w_IB_B)).cwiseAbs2();
      ef += (Sf[k] - Sf[a] - 0.5 * len * (recent_[a].f_B + recent_[k].f_B)).cwiseAbs2();
    }
    const double windows = double(recent_.size() - lag);
    pw = std::max(pw, ew.maxCoeff() / windows / h);
    pf = std::max(pf, ef.maxCoeff() / windows / h);
  }
  return {pw, pf};
}

// The next IMU sample: IMU records in order, an interval longer than
// kImuGapSteps nominal steps is a gap: an error unless the configuration
// allows gaps up to max_imu_gap_s, then the filter propagates across it in
// nominal-length sub-steps with the rates interpolated between the samples
// before and after it, their uncertainty (gapPsd) added to the covariance,
// and the outputs say so.
bool ReplayDriver::nextSample(ins::ImuSample& s, double* psd_w, double* psd_f) {
  while (samples_.empty()) {
    while (imuQ_.empty() && !eof_) readOne();
    if (imuQ_.empty()) return false;
    const ImuRecord rec = imuQ_.front();
    imuQ_.pop_front();
    const double h = rec.t - prevT_;
    if (!firstRecord_ && h > kImuGapSteps * med_) {
      if (!(h <= cfg_.max_imu_gap_s))
        throw Error(cfg_.rawlog + ": IMU gap of " + g10(h) + " s ending at t = " + g10(rec.t - r_.t_zero) +
                    " s (nominal step " + g10(med_) + " s; the filter would coast across it unnoticed): allow gaps "
                    "up to a length with filter.max_imu_gap_s or --max-imu-gap S (accepted 0-" +
                    g10(kMaxImuGapS) + " s)");
      const auto m = static_cast<std::size_t>(std::llround(h / med_));
      // the work gaps add is bounded: no more filled sub-steps than twice the
      // samples read so far, plus one longest allowed gap
      const auto oneGap = static_cast<std::size_t>(std::llround(cfg_.max_imu_gap_s / med_)) + 1;
      if (produced_ + m > 2 * imuRecords_ + 16 + oneGap)
        throw Error(cfg_.rawlog + ": IMU gaps hold more missing samples than the data has samples");
      const ImuRecord& before = recent_.back();
      const auto [pw, pf] = gapPsd(rec, h);
      // the attitude uncertainty the bridge adds (PSD pw over h): beyond the
      // filter's small-error range the gap cannot be bridged honestly (a probe on
      // the UAV run, gaps of up to 2 s inside a 30 s GNSS outage: those adding at
      // most 3 deg kept every error within 3.1 sigma to the outage's end; from
      // 5 deg on roll and pitch ended up to 65 sigma off)
      if (const double sigmaAtt = std::sqrt(pw * h); !(sigmaAtt <= filter::kSmallErrorAttitudeSigmaRad))
        throw Error(cfg_.rawlog + ": IMU gap of " + g10(h) + " s ending at t = " + g10(rec.t - r_.t_zero) +
                    " s: the rates change too fast around it to bridge it (an attitude uncertainty of " +
                    formatNumber(sigmaAtt / units::kDeg, 3) + " deg, 1 sigma, above the " +
                    formatNumber(filter::kSmallErrorAttitudeSigmaRad / units::kDeg, 3) +
                    " deg the linearised filter holds): cut the rawlog at the gap (rawlog-edit --cut) and replay the parts");
      double last = prevT_;
      for (std::size_t j = 1; j <= m; ++j) {
        const double t = j == m ? rec.t : prevT_ + h * static_cast<double>(j) / static_cast<double>(m);
        if (j == m) {  // the sample after the gap: measured over its own nominal step
          samples_.push_back({ins::ImuSample::fromRates(t, t - last, rec.w_IB_B, rec.f_B), pw, pf});
        } else {
          const double a = (0.5 * (t + last) - prevT_) / h;  // the sub-step's middle
          samples_.push_back({ins::ImuSample::fromRates(t, t - last, (1.0 - a) * before.w_IB_B + a * rec.w_IB_B,
                                                        (1.0 - a) * before.f_B + a * rec.f_B),
                              pw, pf});
        }
        last = t;
      }
      produced_ += m;
      ++gaps_;
      if (h > longest_) {
        longest_ = h;
        longestAt_ = rec.t - r_.t_zero;
      }
    } else {
      samples_.push_back({ins::ImuSample::fromRates(rec.t, h, rec.w_IB_B, rec.f_B)});
      ++produced_;
    }
    firstRecord_ = false;
    prevT_ = rec.t;
    recent_.push_back(rec);
    if (recent_.size() > kRecentImu) recent_.pop_front();
  }
  s = samples_.front().s;
  if (psd_w) *psd_w = samples_.front().psd_w;
  if (psd_f) *psd_f = samples_.front().psd_f;
  samples_.pop_front();
  return true;
}

bool ReplayDriver::peekSample() {
  if (!samples_.empty()) return true;
  Sample x;
  if (!nextSample(x.s, &x.psd_w, &x.psd_f)) return false;
  samples_.push_front(x);
  return true;
}

// Outages all along the run, each after period - duration of GNSS from the
// filter start, only those ending by the end of the IMU data. Each is decided
// one duration before it starts, by reading ahead to its end (so the records
// read ahead are at most about two outage durations).
void ReplayDriver::decideWindows(double t_now) {
  if (!windowsOpen_) return;
  const OutagePattern& p = *cfg_.outages_every;
  for (;;) {
    // start_k = aided_from + (k + 1) period - duration, computed from k (no accumulated rounding)
    const double a = aidedFrom_ + double(nextWindow_ + 1) * p.period_s - p.duration_s, b = a + p.duration_s;
    if (a - p.duration_s > t_now) return;
    while (!eof_ && lastImuT_ < b - 1e-9) readOne();
    if (b > lastImuT_ + 1e-9) {  // ends after the data
      windowsOpen_ = false;
      return;
    }
    if (nextWindow_ >= limits::kMaxOutagesPerRun)
      throw Error(cfg_.rawlog + ": outages every " + formatNumber(p.period_s, 10) + ":" + formatNumber(p.duration_s, 10) +
                  " s make more than " + formatNumber(double(limits::kMaxOutagesPerRun)) +
                  " outages over the run (at most that many per run): a longer period");
    // an outage laid twice was scored twice (7 outages, two the same 15 s from 25 s)
    for (const Outage& o : cfg_.outages)
      if (a - r_.t_zero < o.end_s && o.start_s < b - r_.t_zero)
        throw Error(cfg_.rawlog + ": the outage every " + formatNumber(p.period_s, 10) + ":" + formatNumber(p.duration_s, 10) +
                    " s at " + outageText({a - r_.t_zero, b - r_.t_zero}) + " overlaps the outage " + outageText(o) +
                    " given by itself (each GNSS gap once: move that outage between the pattern's)");
    runner_->addOutage({a, b});
    r_.cfg.outages.push_back({a - r_.t_zero, b - r_.t_zero});
    ++nextWindow_;
  }
}

void ReplayDriver::run() {
  ReplayResult& r = r_;
  const ReplayConfig& cfg = cfg_;
  const Recording& head = header();
  r.cfg = cfg;
  r.scenario_yaml = head.metadata;
  origin_ = head.origin;

  // The look-ahead: the first kReplayLookaheadImu IMU intervals set the nominal
  // step and tell whether the reference can start the filter.
  while (!eof_ && imuQ_.size() <= kReplayLookaheadImu) readOne();
  if (imuQ_.size() < 2) throw Error(cfg.rawlog + ": no IMU data (label IMU) to replay");
  origin_ = head.origin;

  try {
    if (!head.metadata.empty()) scen_ = loadYaml(head.metadata)["navimpact_scenario"];
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
  } else if (scen_ && scen_["imu_model_yaml"]) {
    model = stochastic::parseImuModel(scen_["imu_model_yaml"].as<std::string>(),
                                      cfg.rawlog + " (scenario imu_model_yaml)");
    const std::string src = scen_["imu"] && scen_["imu"]["model"] ? scen_["imu"]["model"].as<std::string>() : "";
    model.source = "rawlog scenario model (" + src + ")";
    r.model_source = model.source;
  } else {
    throw Error(cfg.rawlog + ": the scenario records no IMU error model: give one with --model FILE[:NAME]");
  }

  // The nominal step: nominalStep() of the look-ahead's intervals (their median, or
  // their mean when quantised or alternating stamps move the median); time zero one
  // step before the first sample.
  {
    std::vector<double> steps(imuQ_.size() - 1);
    for (std::size_t k = 1; k < imuQ_.size(); ++k) steps[k - 1] = imuQ_[k].t - imuQ_[k - 1].t;
    med_ = nominalStep(steps);
    const double dt0 = imuQ_[1].t - imuQ_[0].t;
    dt_ = std::abs(dt0 - med_) <= 0.01 * med_ ? dt0 : med_;
  }
  r.imu_rate_hz = 1.0 / dt_;
  r.t_zero = imuQ_.front().t - dt_;
  // Streams that start together: a complete reference entry at the first IMU
  // sample and none one step before it. The filter then starts at that sample
  // (time zero), whose increment, over the step before it, is left out.
  if (cfg.use_reference && imuQ_.size() > 2) {
    const double t1 = imuQ_.front().t;
    bool atFirst = false, before = false;
    for (const auto& g : refQ_) {
      atFirst = atFirst || (std::abs(g.t - t1) <= 0.5 * dt_ && g.v_N && g.q_BtoN);
      before = before || std::abs(g.t - r.t_zero) <= 0.5 * dt_;
    }
    if (atFirst && !before) {
      r.t_zero = t1;
      imuQ_.pop_front();
      startNotice_ = "the reference starts at the first IMU sample (t = " + g10(t1) +
                     " s in the rawlog): the filter starts there, that sample's increment (over the step before it) "
                     "left out";
    }
  }
  prevT_ = r.t_zero;

  // Outages in rawlog time (their end against the data's end is checked when it is known).
  checkOutages(cfg.outages, std::numeric_limits<double>::infinity(), "the data", "outage", cfg.outage_names);
  for (const auto& o : cfg.outages) opt_.outages.push_back(o.shifted(r.t_zero));

  if (scen_ && scen_["baro"] && scen_["baro"]["sigma_m"]) sBaro_ = scen_["baro"]["sigma_m"].as<double>();
  if (std::isfinite(sBaro_) && !cfg.sigma_baro_m)
    limits::check(cfg.rawlog, "scenario baro.sigma_m", sBaro_, limits::kPositionSigmaM);
  setup_ = true;
  {  // the measurements read ahead, with their noise
    std::deque<GnssFix> g;
    std::deque<BaroSample> b;
    g.swap(gnssQ_);
    b.swap(baroQ_);
    for (auto& f : g) takeGnss(std::move(f));
    for (auto& x : b) takeBaro(x);
  }
  Eigen::Vector3d lever = Eigen::Vector3d::Zero();
  if (scen_ && scen_["gnss"] && scen_["gnss"]["lever_arm_B_m"]) {
    const auto l = scen_["gnss"]["lever_arm_B_m"].as<std::vector<double>>();
    if (l.size() == 3 && !cfg.lever_arm_B) {
      for (int k = 0; k < 3; ++k)
        limits::check(cfg.rawlog, "scenario gnss.lever_arm_B_m[" + std::to_string(k) + "]", l[k], limits::kLeverArmM);
      lever = Eigen::Vector3d(l[0], l[1], l[2]);
    }
  }
  if (cfg.lever_arm_B) lever = *cfg.lever_arm_B;
  opt_.lever_arm_B = lever;

  // Reference series. A reference without velocity or attitude is scored on
  // what it has (the missing parts NaN); the filter starts from it only when it
  // is complete over the look-ahead and has an entry at time zero, else after
  // an aligning phase.
  refInfo_.sigma_h_m = cfg.reference_sigma_h_m;
  refInfo_.sigma_v_m = cfg.reference_sigma_v_m;
  refSigmaFromData_ = cfg.reference_sigma_h_m == 0.0 && cfg.reference_sigma_v_m == 0.0;
  bool fullRef = true, anyRef = false;
  {
    const double hi = eof_ ? lastImuT_ + 0.5 * dt_ : std::numeric_limits<double>::infinity();
    for (const auto& g : refQ_) {
      if (g.t < r.t_zero - 0.5 * dt_ || g.t > hi) continue;
      anyRef = true;
      fullRef = fullRef && g.v_N && g.q_BtoN;
    }
    hasTruth_ = cfg.use_reference && !refQ_.empty();
    if (hasTruth_ && !anyRef) throw Error(cfg.rawlog + ": the reference (GT) has no entry inside the IMU data");
    std::deque<ReferenceRecord> q;
    q.swap(refQ_);
    for (const auto& g : q) takeReference(g);
  }
  const bool startFromRef = hasTruth_ && fullRef && std::abs(truthAhead_.t.front() - r.t_zero) <= 0.5 * dt_;
  std::string refNotice;
  if (hasTruth_ && !startFromRef)
    refNotice = std::string("the reference ") +
                (fullRef ? "has no entry at the start of the IMU data"
                         : std::string("has no ") +
                               (!refInfo_.has_velocity && !refInfo_.has_attitude ? "velocity and attitude"
                                : refInfo_.has_velocity                         ? "attitude"
                                                                                : "velocity")) +
                ": the filter starts after an aligning phase and is scored on what the reference has";

  opt_.record_interval_s = cfg.record_interval_s;
  opt_.ekf.propagate_every = cfg.propagate_every;
  opt_.ekf.gate_probability = cfg.gate_probability;
  opt_.ekf.gate_readmit_after = cfg.gate_readmit_after;
  opt_.ekf.imu.extra = cfg.extra_states;
  opt_.use_gnss_velocity = cfg.use_gnss_velocity;
  opt_.P0_nav.setZero();
  const double ph = cfg.p0_pos_h_m, pv = cfg.p0_pos_v_m, vv = cfg.p0_vel_mps;
  const double rp = cfg.p0_roll_pitch_deg * kDeg, yw = cfg.p0_yaw_deg * kDeg;
  opt_.P0_nav.diagonal() << ph * ph, ph * ph, pv * pv, vv * vv, vv * vv, vv * vv, rp * rp, rp * rp, yw * yw;
  opt_.reference_lever_B = cfg.reference_lever_arm_B;
  opt_.zupt = cfg.aids.zupt;
  opt_.zupt_detector = cfg.alignment.detector;
  opt_.zupt_sigma_mps = cfg.aids.zupt_sigma_mps;
  opt_.zupt_interval_s = cfg.aids.zupt_interval_s;
  opt_.nhc = cfg.aids.nhc;
  opt_.nhc_sigma_lateral_mps = cfg.aids.nhc_sigma_lateral_mps;
  opt_.nhc_sigma_vertical_mps = cfg.aids.nhc_sigma_vertical_mps;
  opt_.nhc_interval_s = cfg.aids.nhc_interval_s;
  opt_.nhc_min_speed_mps = cfg.aids.nhc_min_speed_mps;
  opt_.nhc_point_B = cfg.aids.nhc_point_B;

  ins::NavState x0;
  std::vector<std::string> alignNotices;
  if (startFromRef) {
    x0 = truthAhead_.x.front();
    x0.t = r.t_zero;
  } else {
    // The aligning phase: from time zero until the aligner has an attitude,
    // a position and a velocity; the filter starts at the next IMU sample.
    filter::AlignmentOptions ao = cfg.alignment;
    ao.lever_arm_B = lever;
    if (!ao.yaw_rad && cfg.initial_attitude_deg) {
      ao.yaw_rad = (*cfg.initial_attitude_deg)[2] * kDeg;
      ao.yaw_source = "configuration (initial_attitude_deg)";
    }
    if (!ao.yaw_rad && hasTruth_ && cfg.alignment_yaw_from_reference) {
      // Heading from the reference's attitude: its first entry with one read
      // ahead, at time zero or later (the aligner then waits for that yaw and
      // carries it back to the start through the gyros), unless it comes after
      // alignment.max_align_s (then the GNSS course).
      std::size_t k = 0;
      while (k < truthAhead_.t.size() && !truthAhead_.x[k].q_BtoN.coeffs().allFinite()) ++k;
      if (k < truthAhead_.t.size() && truthAhead_.t[k] - r.t_zero <= ao.max_align_s) {
        ao.yaw_rad = truthAhead_.x[k].rollPitchYaw()[2];
        ao.yaw_t_s = truthAhead_.t[k];
        ao.yaw_source = "reference";
      } else if (k < truthAhead_.t.size()) {
        alignNotices.push_back("the reference's attitude starts at " + formatNumber(truthAhead_.t[k] - r.t_zero, 10) +
                               " s, after alignment.max_align_s = " + formatNumber(ao.max_align_s, 10) +
                               " s: the heading is not taken from it");
      }
    }
    auto aligning = [&](auto&& f) {
      try {
        return f();
      } catch (const Error& e) {
        throw Error(cfg.rawlog + ": aligning (no complete reference at the start): " + e.what());
      }
    };
    std::optional<filter::CoarseAligner> al;
    aligning([&] { al.emplace(ao, r.t_zero, r.imu_rate_hz); });
    std::size_t ig = 0;
    ins::ImuSample s;
    while (!al->done() && nextSample(s)) {
      // the aligner levels and heads on measured samples: a gap's interpolated
      // ones moved the levelled pitch by up to 1.1 deg at sigma 0.035 deg (found
      // by a probe on the Katwijk run's static start)
      if (gaps_ > 0)
        throw Error(cfg.rawlog + ": IMU gap of " + g10(longest_) + " s ending at t = " + g10(longestAt_) +
                    " s, in the aligning phase: the alignment uses measured samples only (cut the rawlog after the "
                    "gap with rawlog-edit --cut, or give the attitude at the start)");
      fillTo(s.t + 1e-9);
      aligning([&] {
        al->addImu(s);
        while (!al->done() && ig < gnssQ_.size() && gnssQ_[ig].t <= s.t + 1e-9) {
          const GnssFix& f = gnssQ_[ig++];
          bool out = false;
          for (const auto& o : opt_.outages) out = out || o.covers(f.t);
          if (out) continue;
          filter::AlignmentFix af;
          af.t = f.t;
          af.pos = f.pos;
          af.sigma_pos_N = f.cov_pos_N->diagonal().cwiseSqrt();
          if (cfg.use_gnss_velocity && f.v_N && f.cov_vel_N) {
            af.v_N = *f.v_N;
            af.sigma_vel_N = f.cov_vel_N->diagonal().cwiseSqrt();
          }
          al->addFix(af);
        }
      });
    }
    aligning([&] {
      if (!al->done()) throw Error("the IMU data end before the aligning phase does: " + al->missing());
    });
    const bool more = peekSample();
    aligning([&] {
      if (!more) throw Error("the aligning phase ends with the IMU data: nothing left to navigate");
      x0 = al->state();
      opt_.P0_nav = al->P0();
      r.alignment = al->report();
    });
    while (!gnssQ_.empty() && gnssQ_.front().t <= al->usedFixTime() + 1e-9) gnssQ_.pop_front();
    r.aided_from_s = x0.t - r.t_zero;
    alignNotices.push_back(std::string(hasTruth_ ? "" : "no ground truth in the rawlog: ") + "aligning phase from 0 to " +
                           formatNumber(r.aided_from_s, 10) + " s (levelling " + r.alignment->levelling +
                           ", heading from " + r.alignment->heading + "), the filter runs from there" +
                           (hasTruth_ ? "" : "; errors and NEES are not available"));
    for (const auto& n : r.alignment->notes) alignNotices.push_back("alignment: " + n);
  }
  std::vector<std::string> modelNotices;
  {
    // The one model-entry path: converted to the data's IMU rate (a rate within
    // 0.1 % of the model's is the same sensor's clock jitter, not another rate),
    // GMs the filter cannot carry entered as white noise; the notices say so.
    const double rate = std::abs(model.rate_hz - r.imu_rate_hz) <= 1e-3 * r.imu_rate_hz ? model.rate_hz : r.imu_rate_hz;
    filter::ModelEntry entry = filter::layoutFor(model, opt_.ekf, rate);
    model = std::move(entry.model);
    for (const auto& n : entry.notes) modelNotices.push_back("filter model: " + n);
  }

  // The filter, fed as the records come.
  if (!peekSample()) throw Error("navigation run: no IMU samples");
  const double dt0 = samples_.front().s.dt;
  runner_.emplace(x0, dt0, hasTruth_, model, opt_);
  NavRunner& run = *runner_;
  run.keep_epochs = obs_ == nullptr;
  aidedFrom_ = x0.t;
  if (hasTruth_) scorer_.emplace(x0.t);
  windowsOpen_ = cfg.outages_every.has_value();
  if (windowsOpen_) (void)outagesEvery(*cfg.outages_every, 0.0, 0.0);  // the one message for a bad pattern
  run.on_epoch = [&](const NavEpoch& e, const ins::NavState* truth) {
    if (scorer_) scorer_->add(e, run.outages());
    if (obs_) {
      obs_->epoch(r, e, truth, run.outages());
    } else {
      r.estimate.push_back(e.est);
      if (truth) r.truth.push_back(*truth);
    }
  };
  for (auto& f : gnssQ_) {
    if (!obs_) r.gnss.push_back(f);
    run.addGnss(f);
  }
  gnssQ_.clear();
  for (const auto& b : baroQ_) run.addBaro(b);
  baroQ_.clear();
  for (std::size_t i = 0; i < truthAhead_.t.size(); ++i) run.addTruth(truthAhead_.t[i], truthAhead_.x[i]);
  truthAhead_ = {};
  if (obs_) obs_->begin(r);
  decideWindows(x0.t + dt0);
  fillTo(x0.t + 0.5 * dt0);
  run.start(samples_.front().s);  // peekSample() above: the first sample is there
  // a negative time-offset estimate applies a fix before its own time stamp
  // (NavRunner): the records are read that far ahead
  const double fixLookahead = opt_.ekf.imu.extra.time_offset_sigma_s > 0.0 ? -limits::kTimeOffsetS.lo : 0.0;
  // the filter's errors (a covariance no longer positive definite, a fix
  // without sigma) name the rawlog whose data caused them; the reader's name it already
  try {
    ins::ImuSample s;
    double psd_w = 0.0, psd_f = 0.0;
    while (nextSample(s, &psd_w, &psd_f)) {
      if (s.t - r.t_zero > stopAfter_) {
        while (!eof_) readOne();  // what depends on the whole data (reference content, data end) as in a full replay
        break;
      }
      decideWindows(s.t + s.dt);
      fillTo(s.t + 0.5 * s.dt + fixLookahead);
      run.stepUnmeasured(s, psd_w, psd_f);  // psd 0: a measured sample (run.step)
    }
    r.run = run.finish();
  } catch (const Error& e) {
    if (std::string_view(e.what()).rfind(cfg.rawlog, 0) == 0) throw;
    throw Error(cfg.rawlog + ": " + e.what());
  }
  const double t_last = lastImuT_;
  r.nav = opt_;
  r.nav.outages = run.outages();
  r.read_s = readS_;
  r.imu_gaps = gaps_;

  // What needed the end of the data.
  checkOutages(cfg.outages, t_last - r.t_zero,
               "the data (IMU data span 0.." + formatNumber(t_last - r.t_zero, 10) + " s)", "outage", cfg.outage_names);
  if (hasTruth_ && truthInside_ == 0)
    throw Error(cfg.rawlog + ": the reference (GT) has no entry inside the IMU data");
  // notices in one order: the reader's, gaps, the reference, the alignment, the outages, the model
  r.notices = header().notices;
  if (!startNotice_.empty()) r.notices.push_back(startNotice_);
  if (gaps_ > 0)
    r.notices.push_back(std::to_string(gaps_) + " IMU gap(s) longer than " + g10(kImuGapSteps) +
                        " nominal steps accepted (longest " + g10(longest_) + " s, ending at t = " + g10(longestAt_) +
                        " s; filter.max_imu_gap_s = " + g10(cfg.max_imu_gap_s) +
                        " s): the filter propagated across each with the rates interpolated between the samples "
                        "around it and their uncertainty added");
  if (!refNotice.empty()) r.notices.push_back(refNotice);
  if (ignoredRef_ > 0)
    r.notices.push_back(std::to_string(ignoredRef_) + " reference (GT) entries ignored: the reference starts after the "
                        "first " + std::to_string(kReplayLookaheadImu) + " IMU samples the replay decides from");
  for (auto& n : alignNotices) r.notices.push_back(std::move(n));
  if (cfg.outages_every && r.cfg.outages.size() == cfg.outages.size())
    r.notices.push_back("outages every " + formatNumber(cfg.outages_every->period_s, 10) + ":" +
                        formatNumber(cfg.outages_every->duration_s, 10) + " s: none fits in the data after the filter start");
  for (auto& n : modelNotices) r.notices.push_back(std::move(n));
  // an outage between two fixes withholds none: scored, it is an aided run's error
  for (const auto& o : r.run.outages)
    if (o.gnss_dropped == 0)
      r.notices.push_back("outage " + outageText({o.window.start_s - r.t_zero, o.window.end_s - r.t_zero}) +
                          " withheld no GNSS fix (none falls inside it): its errors are those of the aided filter");
  if (scorer_) r.score = scorer_->finish(r.run, r.t_zero, refInfo_);
}

/// A replay needs a rawlog: named by the configuration's key when there is a configuration.
void requireRawlog(const ReplayConfig& cfg) {
  if (!cfg.rawlog.empty()) return;
  if (!cfg.config_file.empty()) throw keyError(cfg.config_file, "rawlog", "missing (the rawlog to replay, or --rawlog)");
  throw Error("replay: no rawlog given (--rawlog, or 'rawlog:' in a --config)");
}

}  // namespace

ReplayResult runReplay(const ReplayConfig& cfg) {
  requireRawlog(cfg);
  InputScope scope(cfg.rawlog);
  ReplayResult r;
  ReplayDriver(cfg, r, nullptr).run();
  return r;
}

ReplayResult runReplay(const ReplayConfig& cfg, const rawlog::RawlogRecords& data, double stop_after_s) {
  requireRawlog(cfg);
  InputScope scope(cfg.rawlog);
  ReplayResult r;
  ReplayDriver(cfg, r, data, stop_after_s).run();
  return r;
}

ReplayResult runReplay(const ReplayConfig& cfg, ReplayObserver& observer) {
  requireRawlog(cfg);
  InputScope scope(cfg.rawlog);
  ReplayResult r;
  ReplayDriver(cfg, r, &observer).run();
  return r;
}

}  // namespace navimpact::analysis
