// Static detector, levelling and the coarse aligner (see alignment.hpp).
#include "navimpact/filter/alignment.hpp"

#include <boost/math/distributions/chi_squared.hpp>

#include <cmath>
#include <sstream>

#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"

namespace navimpact::filter {

using Eigen::Quaterniond;
using Eigen::Vector3d;

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kRad2Deg = 180.0 / kPi;

Quaterniond quatZ(double yaw) { return Quaterniond(Eigen::AngleAxisd(yaw, Vector3d::UnitZ())); }

/// C = Ry(pitch) Rx(roll): the levelled attitude with zero yaw.
Quaterniond quatLevel(double roll, double pitch) { return ins::quatFromRollPitchYaw(roll, pitch, 0.0); }

double yawOf(const Quaterniond& q) { return ins::rollPitchYaw(q.toRotationMatrix())[2]; }
}  // namespace

Eigen::Vector2d levelRollPitch(const Vector3d& f_B) {
  if (!f_B.allFinite() || f_B.norm() < 1.0)
    throw Error("levelling: mean specific force of " + formatNumber(f_B.norm(), 4) +
                " m/s^2 is not gravity (accelerometer units or axes wrong?)");
  // Groves 2013 eq. 5.101
  return {std::atan2(-f_B.y(), -f_B.z()), std::atan2(f_B.x(), std::hypot(f_B.y(), f_B.z()))};
}

// ---- static detector ------------------------------------------------------

StaticDetector::StaticDetector(const StaticDetectorOptions& opt, double rate) : opt_(opt) {
  if (!(rate > 0.0) || !std::isfinite(rate)) throw Error("static detector: IMU rate must be > 0 Hz");
  if (!(opt.window_s > 0.0) || !std::isfinite(opt.window_s))
    throw Error("static detector: window must be > 0 s, got " + formatNumber(opt.window_s, 4));
  w_ = static_cast<int>(std::lround(opt.window_s * rate));
  if (w_ < 2) throw Error("static detector: window of " + formatNumber(opt.window_s, 4) + " s holds fewer than 2 IMU samples");
  if (!(opt.gyro_sigma_rad_s.array() > 0.0).all() || !opt.gyro_sigma_rad_s.allFinite() ||
      !(opt.acc_sigma_mps2.array() > 0.0).all() || !opt.acc_sigma_mps2.allFinite())
    throw Error("static detector: at-rest sigmas must be > 0");
  if (!(opt.false_alarm > 0.0 && opt.false_alarm < 0.5))
    throw Error("static detector: false-alarm probability must be in (0, 0.5), got " + formatNumber(opt.false_alarm, 4));
  if (!(opt.max_mean_rate_rad_s > 0.0)) throw Error("static detector: max_mean_rate_rad_s must be > 0");
  thr_ = boost::math::quantile(boost::math::chi_squared(6.0 * (w_ - 1)), 1.0 - opt.false_alarm);
  for (int a = 0; a < 3; ++a) {
    inv_var_(a) = 1.0 / (opt.gyro_sigma_rad_s(a) * opt.gyro_sigma_rad_s(a));
    inv_var_(3 + a) = 1.0 / (opt.acc_sigma_mps2(a) * opt.acc_sigma_mps2(a));
  }
  sum_.setZero();
  sum2_.setZero();
  ref_.setZero();
}

void StaticDetector::recompute() {
  // shifted sums (against cancellation: the reference is a sample of the window)
  ref_ = buf_.front();
  sum_.setZero();
  sum2_.setZero();
  for (const auto& x : buf_) {
    const Eigen::Matrix<double, 6, 1> d = x - ref_;
    sum_ += d;
    sum2_ += d.cwiseAbs2();
  }
  since_recompute_ = 0;
}

Vector3d StaticDetector::meanRate() const {
  if (n_ == 0) return Vector3d::Zero();
  return ref_.head<3>() + sum_.head<3>() / n_;
}

bool StaticDetector::push(const ins::ImuSample& s) {
  Eigen::Matrix<double, 6, 1> x;
  x << s.w_IB_B(), s.f_B();
  if (n_ == 0) ref_ = x;
  buf_.push_back(x);
  const Eigen::Matrix<double, 6, 1> d = x - ref_;
  sum_ += d;
  sum2_ += d.cwiseAbs2();
  if (n_ < w_) {
    ++n_;
  } else {
    const Eigen::Matrix<double, 6, 1> o = buf_.front() - ref_;
    sum_ -= o;
    sum2_ -= o.cwiseAbs2();
    buf_.pop_front();
  }
  if (++since_recompute_ >= w_) recompute();
  if (n_ < w_) {
    static_ = false;
    return false;
  }
  // sum (x - mean)^2 = sum d^2 - (sum d)^2 / W per channel, weighted
  const Eigen::Matrix<double, 6, 1> ss = (sum2_ - sum_.cwiseAbs2() / w_).cwiseMax(0.0);
  stat_ = ss.dot(inv_var_);
  static_ = stat_ <= thr_ && meanRate().norm() <= opt_.max_mean_rate_rad_s;
  return static_;
}

// ---- coarse aligner ---------------------------------------------------------

namespace {
constexpr double kG = 9.80665;  // for sigmas only
}

CoarseAligner::CoarseAligner(const AlignmentOptions& opt, double t0, double rate)
    : opt_(opt), t0_(t0), rate_(rate), det_(opt.detector, rate) {
  auto pos = [](double v) { return v > 0.0 && std::isfinite(v); };
  if (!pos(opt.yaw_sigma_rad) || !pos(opt.min_static_s) || !pos(opt.max_level_s) ||
      !pos(opt.level_window_s) || !pos(opt.max_course_sigma_rad) || !pos(opt.sideslip_sigma_rad) ||
      !pos(opt.accel_sigma_mps2) || !pos(opt.static_velocity_sigma_mps) || !pos(opt.max_align_s) ||
      !(opt.acc_bias_sigma_mps2 >= 0.0) || !(opt.gyro_bias_sigma_rad_s >= 0.0) ||
      !opt.lever_arm_B.allFinite() || (opt.yaw_rad && !std::isfinite(*opt.yaw_rad)) ||
      (opt.yaw_t_s && !std::isfinite(*opt.yaw_t_s)))
    throw Error("alignment: every sigma and duration must be finite and > 0 (biases >= 0)");
  t_last_ = t0;
  rep_.t_start = t0;
  if (opt.yaw_rad && opt.yaw_t_s && *opt.yaw_t_s > t0 + 0.5 / rate) {
    if (*opt.yaw_t_s - t0 > opt.max_align_s)
      throw Error("alignment: the heading from the " + opt.yaw_source + " at t = " + formatNumber(*opt.yaw_t_s, 10) +
                  " s comes more than max_align_s = " + formatNumber(opt.max_align_s, 6) +
                  " s after the start of the IMU data");
    later_yaw_ = true;
  } else if (opt.yaw_rad) {
    heading_ = true;
    yaw0_ = *opt.yaw_rad;
    sigma_yaw_ = opt.yaw_sigma_rad;
    t_heading_ = t0;
    rep_.heading = opt.yaw_source;
  }
}

Quaterniond CoarseAligner::q_B0toN() const { return quatZ(yaw0_) * quatLevel(rp0_[0], rp0_[1]); }

Vector3d CoarseAligner::imuPosition(const FixRec& r) const {
  // p_imu = p_ant - C_BtoN l (Groves 14.110)
  return r.p_L - (q_B0toN() * r.q_BtoB0).toRotationMatrix() * opt_.lever_arm_B;
}

Vector3d CoarseAligner::imuVelocity(const FixRec& r) const {
  // v_imu = v_ant - C_BtoN (w_IB_B x l) (Groves 14.111, Earth rate neglected)
  return *r.fix.v_N - (q_B0toN() * r.q_BtoB0).toRotationMatrix() * r.w_B.cross(opt_.lever_arm_B);
}

void CoarseAligner::levelStatic(const Sums& sums) {
  const double span = sums.n / rate_;
  const Vector3d mf = sums.f / sums.n;
  rp0_ = levelRollPitch(mf);
  gyro_bias_ = sums.w / sums.n;
  // tilt sigma: accelerometer bias and the noise of the mean (at-rest spread / sqrt(N))
  const Vector3d var_f = (sums.f2 / sums.n - mf.cwiseAbs2()).cwiseMax(0.0);
  const double noise = std::sqrt(var_f.head<2>().maxCoeff() / sums.n);
  sigma_tilt_ = std::hypot(opt_.acc_bias_sigma_mps2, noise) / kG;
  levelled_ = true;
  t_levelled_ = t_last_;
  rep_.levelling = "static";
  rep_.level_span_s = span;
  // B0 := the body at rest; rotations since the end of the rest are re-referred
  // to it (the gyro output there, bias and Earth rate, is left in: <= 2 windows)
  const Quaterniond qi = q_rest_end_.conjugate();
  q_BtoB0_ = (qi * q_BtoB0_).normalized();
  for (FixRec& r : fixes_) r.q_BtoB0 = r.fix.t <= t_rest_end_ ? Quaterniond::Identity() : (qi * r.q_BtoB0).normalized();
  if (later_yaw_seen_)
    q_later_yaw_ = t_later_yaw_ <= t_rest_end_ ? Quaterniond::Identity() : (qi * q_later_yaw_).normalized();
  rep_.notes.push_back("levelled from the accelerometers over " + formatNumber(span, 4) +
                       " s at rest at the start; the mean gyro output there is removed as bias (with Earth rate)");
}

void CoarseAligner::endRest(const Sums& sums, const std::string& why) {
  if (sums.n / rate_ >= opt_.min_static_s) {
    levelStatic(sums);
  } else {
    static_start_ = false;
    rep_.notes.push_back("not at rest for " + formatNumber(opt_.min_static_s, 4) + " s at the start (" + why + ")");
  }
}

void CoarseAligner::levelQuasiStatic() {
  rp0_ = levelRollPitch(qs_u_ / qs_T_);
  sigma_tilt_ = std::hypot(opt_.accel_sigma_mps2, opt_.acc_bias_sigma_mps2) / kG;
  levelled_ = true;
  want_quasi_static_ = false;
  t_levelled_ = t_last_;
  rep_.levelling = "quasi_static";
  rep_.level_span_s = qs_T_;
  rep_.notes.push_back("not at rest at the start and no GNSS velocity to correct for the acceleration: levelled over the first " +
                       formatNumber(qs_T_, 4) + " s as if at rest (tilt sigma " + formatNumber(sigma_tilt_ * kRad2Deg, 3) +
                       " deg from an assumed acceleration of " + formatNumber(opt_.accel_sigma_mps2, 3) + " m/s^2)");
}

int CoarseAligner::levelWithVelocities(const FixRec& a, const FixRec& b) {
  const double T = b.fix.t - a.fix.t;
  if (!(T > 0.0) || T > 10.0) return 0;
  // Course at a (unless the heading is given at t0, or given later and reached:
  // then that yaw; a course levels before a later yaw arrives, the heading waits for it).
  double course = 0.0, sigma_course = 0.0;
  const Vector3d va = *a.fix.v_N;
  const bool laterYaw = !heading_ && later_yaw_seen_;
  if (!heading_ && !laterYaw) {
    const double speed = va.head<2>().norm();
    sigma_course = speed > 0.0 ? a.fix.sigma_vel_N.head<2>().maxCoeff() / speed : 1e9;
    if (sigma_course > opt_.max_course_sigma_rad) return 0;
    course = std::atan2(va.y(), va.x());
    if (!later_yaw_) {
      rep_.course_speed_mps = speed;
      rep_.course_t = a.fix.t;
    }
  }
  // C_B0toN maps the specific force integrated in B0 over (a, b] onto the
  // velocity change minus gravity (Coriolis and transport rate neglected):
  // levelling corrected for the vehicle's own acceleration.
  const Vector3d v = *b.fix.v_N - va - earth::gravity_N(b.fix.pos.lat, b.fix.pos.h) * T;
  if (u_B0_.norm() < 1e-9 || v.norm() < 1e-9) return 0;
  const Vector3d uh = u_B0_.normalized(), vh = v.normalized();
  auto yawFor = [&](double r, double p) {
    if (heading_) return yaw0_;
    if (laterYaw) return ins::wrapAngle(*opt_.yaw_rad - yawOf(quatLevel(r, p) * q_later_yaw_));
    return ins::wrapAngle(course - yawOf(quatLevel(r, p) * a.q_BtoB0));
  };
  auto resid = [&](double r, double p) {
    return Vector3d(quatZ(yawFor(r, p)) * quatLevel(r, p) * uh - vh);
  };
  double r = 0.0, p = 0.0;
  for (int it = 0; it < 30; ++it) {  // Gauss-Newton on (roll, pitch)
    const Vector3d e = resid(r, p);
    Eigen::Matrix<double, 3, 2> J;
    J.col(0) = (resid(r + 1e-6, p) - e) / 1e-6;
    J.col(1) = (resid(r, p + 1e-6) - e) / 1e-6;
    const Eigen::Vector2d step = (J.transpose() * J).ldlt().solve(-J.transpose() * e);
    r = ins::wrapAngle(r + step[0]);
    p = std::max(-1.5, std::min(1.5, p + step[1]));
    if (step.norm() < 1e-10) break;
  }
  const double sv = std::max(a.fix.sigma_vel_N.maxCoeff(), b.fix.sigma_vel_N.maxCoeff());
  double s_tilt = std::hypot(std::sqrt(2.0) * sv / (kG * T), opt_.acc_bias_sigma_mps2 / kG);
  const double yaw = yawFor(r, p);
  double s_yaw = heading_    ? sigma_yaw_
                 : laterYaw ? opt_.yaw_sigma_rad
                            : std::hypot(sigma_course, opt_.sideslip_sigma_rad);
  const Quaterniond q = quatZ(yaw) * quatLevel(r, p);
  if (!vel_first_) {  // keep it; confirm over the next interval
    vel_first_ = VelLevel{q, s_tilt, s_yaw, b.fix.t};
    return 1;
  }
  // two solutions for the same body attitude at t0: they must agree
  const double dis = Eigen::AngleAxisd(vel_first_->q_B0toN.conjugate() * q).angle();
  const double comb = std::sqrt(std::pow(std::hypot(s_tilt, s_yaw), 2) +
                                std::pow(std::hypot(vel_first_->sigma_tilt, vel_first_->sigma_yaw), 2));
  if (dis > 3.0 * comb) {
    rep_.notes.push_back("the GNSS-velocity levellings over two consecutive intervals disagree by " +
                         formatNumber(dis * kRad2Deg, 3) + " deg (3 combined sigmas: " + formatNumber(3.0 * comb * kRad2Deg, 3) +
                         " deg; sideslip or unmodelled acceleration): attitude sigmas raised to it");
    s_tilt = std::max(s_tilt, dis);
    s_yaw = std::max(s_yaw, dis);
  }
  rp0_ = Eigen::Vector2d(r, p);
  sigma_tilt_ = s_tilt;
  levelled_ = true;
  t_levelled_ = t_last_;
  rep_.levelling = "gnss_velocity";
  rep_.level_span_s = T;
  rep_.notes.push_back("moving at the start: levelled by matching the specific force over " + formatNumber(T, 4) +
                       " s to the GNSS velocity change minus gravity (checked against the interval before)");
  if (!heading_ && laterYaw) {
    yaw0_ = yaw;
    heading_ = true;
    t_heading_ = t_later_yaw_;
    rep_.heading = opt_.yaw_source;
    noteLaterYaw();
  } else if (!heading_ && !later_yaw_) {
    yaw0_ = yaw;
    heading_ = true;
    t_heading_ = a.fix.t;
    rep_.heading = "gnss_velocity_course";
  }
  if (heading_) sigma_yaw_ = s_yaw;  // a later yaw not reached yet: the heading waits for it
  return 2;
}

void CoarseAligner::tryHeading(const FixRec& r) {
  const Quaterniond qL = quatLevel(rp0_[0], rp0_[1]);
  if (r.fix.v_N) {
    // course of the IMU velocity; the lever-arm term needs the heading: iterate
    double yaw0 = 0.0;
    for (int it = 0; it < 3; ++it) {
      yaw0_ = yaw0;
      const Vector3d v = imuVelocity(r);
      const double speed = v.head<2>().norm();
      const double sc = speed > 0.0 ? r.fix.sigma_vel_N.head<2>().maxCoeff() / speed : 1e9;
      if (sc > opt_.max_course_sigma_rad) {
        yaw0_ = 0.0;
        return;
      }
      yaw0 = ins::wrapAngle(std::atan2(v.y(), v.x()) - yawOf(qL * r.q_BtoB0));
      if (it == 2) {
        yaw0_ = yaw0;
        heading_ = true;
        sigma_yaw_ = std::hypot(sc, opt_.sideslip_sigma_rad);
        t_heading_ = r.fix.t;
        rep_.heading = "gnss_velocity_course";
        rep_.course_speed_mps = speed;
        rep_.course_t = r.fix.t;
      }
    }
    return;
  }
  // chord from an earlier fix to this one (IMU positions), the most recent
  // earlier fix far enough for the course sigma; its direction is the mean of
  // the two end headings for a constant-rate turn at constant speed
  for (auto it = fixes_.rbegin(); it != fixes_.rend(); ++it) {
    const FixRec& a = *it;
    const double dt = r.fix.t - a.fix.t;
    if (!(dt > 0.0)) continue;
    const double ya = yawOf(qL * a.q_BtoB0), yb = yawOf(qL * r.q_BtoB0);
    const double ymean = ya + 0.5 * ins::wrapAngle(yb - ya);
    const double sp = std::hypot(a.fix.sigma_pos_N.head<2>().maxCoeff(), r.fix.sigma_pos_N.head<2>().maxCoeff());
    double yaw0 = 0.0, sc = 1e9, len = 0.0;
    for (int k = 0; k < 4; ++k) {  // the lever arm needs the heading: iterate
      yaw0_ = yaw0;
      const Vector3d d = imuPosition(r) - imuPosition(a);
      len = d.head<2>().norm();
      sc = len > 0.0 ? sp / len : 1e9;
      if (sc > opt_.max_course_sigma_rad) break;
      yaw0 = ins::wrapAngle(std::atan2(d.y(), d.x()) - ymean);
    }
    yaw0_ = 0.0;
    if (sc > opt_.max_course_sigma_rad) continue;
    yaw0_ = yaw0;
    heading_ = true;
    sigma_yaw_ = std::hypot(sc, opt_.sideslip_sigma_rad);
    t_heading_ = 0.5 * (a.fix.t + r.fix.t);
    rep_.heading = "gnss_chord_course";
    rep_.course_speed_mps = len / dt;
    rep_.course_t = r.fix.t;
    return;
  }
}

void CoarseAligner::applyLaterYaw() {
  // yaw(t0) = yaw(t_y) - yaw(C_level C_B(t_y)toB0): a rotation about the navigation z axis adds to the ZYX yaw
  yaw0_ = ins::wrapAngle(*opt_.yaw_rad - yawOf(quatLevel(rp0_[0], rp0_[1]) * q_later_yaw_));
  heading_ = true;
  sigma_yaw_ = opt_.yaw_sigma_rad;
  t_heading_ = t_later_yaw_;
  rep_.heading = opt_.yaw_source;
  noteLaterYaw();
}

void CoarseAligner::noteLaterYaw() {
  rep_.notes.push_back("heading from the " + opt_.yaw_source + "'s yaw at t = " + formatNumber(t_later_yaw_, 8) +
                       " s (its first attitude after the start of the IMU data), carried to the start through the "
                       "body rotation the gyros measured in between; the aligning phase waited for it");
}

void CoarseAligner::finish(const FixRec& r) {
  const Quaterniond q = (q_B0toN() * q_BtoB0_).normalized();
  // velocity at the end
  Vector3d v = Vector3d::Zero(), sv;
  std::string vnote;
  // A vehicle at constant velocity without vibration looks static to the IMU:
  // "at rest" needs the GNSS chord over the longest kept baseline to agree
  // (each axis within 3 sigma of zero), and the velocity sigma is then at least
  // what that chord can resolve.
  bool chord_static = false;
  Vector3d s_chord = Vector3d::Zero();
  if (!r.fix.v_N && !fixes_.empty()) {
    const FixRec& a = fixes_.front();
    const double dt = r.fix.t - a.fix.t;
    if (dt > 0.0) {
      const Vector3d d = (imuPosition(r) - imuPosition(a)) / dt;
      for (int i = 0; i < 3; ++i) s_chord(i) = std::hypot(a.fix.sigma_pos_N(i), r.fix.sigma_pos_N(i)) / dt;
      chord_static = (d.cwiseAbs().array() <= 3.0 * s_chord.array()).all();
    }
  }
  if (r.fix.v_N) {
    v = imuVelocity(r);
    sv = r.fix.sigma_vel_N;
    vnote = "GNSS velocity";
  } else if (static_now_ && (fixes_.empty() || chord_static)) {
    sv = s_chord.cwiseMax(opt_.static_velocity_sigma_mps);
    vnote = "at rest (static detector)";
  } else {
    const FixRec& a = fixes_.back();
    const double dt = r.fix.t - a.fix.t;
    v = (imuPosition(r) - imuPosition(a)) / dt;
    // chord mean velocity: noise of the two fixes and the change over half the chord
    for (int i = 0; i < 3; ++i)
      sv(i) = std::hypot(std::hypot(a.fix.sigma_pos_N(i), r.fix.sigma_pos_N(i)) / dt,
                         0.5 * opt_.accel_sigma_mps2 * dt);
    vnote = "mean velocity over the last " + formatNumber(dt, 4) + " s between GNSS fixes";
  }
  const Vector3d p = imuPosition(r) + v * (t_last_ - r.fix.t);
  const earth::Geodetic g = earth::nedToGeodetic(*origin_, p);
  x0_ = ins::NavState{};
  x0_.t = t_last_;
  x0_.lat = g.lat;
  x0_.lon = g.lon;
  x0_.h = g.h;
  x0_.v_N = v;
  x0_.q_BtoN = q;
  const double sg = opt_.gyro_bias_sigma_rad_s;
  // attitude carried by the gyros since levelling / the heading: bias and
  // angle random walk (per-sample at-rest sigma s_w: variance s_w^2 T / rate)
  const double arw = opt_.detector.gyro_sigma_rad_s.maxCoeff() / std::sqrt(rate_);
  const double Tl = t_last_ - t_levelled_, Th = t_last_ - t_heading_;
  const double s_tilt = std::sqrt(sigma_tilt_ * sigma_tilt_ + std::pow(sg * Tl, 2) + arw * arw * Tl);
  const double s_yaw = std::sqrt(sigma_yaw_ * sigma_yaw_ + std::pow(sg * Th, 2) + arw * arw * Th);
  P0_.setZero();
  for (int i = 0; i < 3; ++i) {
    P0_(i, i) = r.fix.sigma_pos_N(i) * r.fix.sigma_pos_N(i) + std::pow(sv(i) * (t_last_ - r.fix.t), 2);
    P0_(3 + i, 3 + i) = sv(i) * sv(i);
  }
  P0_(6, 6) = P0_(7, 7) = s_tilt * s_tilt;
  P0_(8, 8) = s_yaw * s_yaw;
  used_fix_t_ = r.fix.t;
  done_ = true;
  rep_.t_end = t_last_;
  rep_.heading_t = t_heading_;
  rep_.rpy = x0_.rollPitchYaw();
  rep_.sigma_rpy = Vector3d(s_tilt, s_tilt, s_yaw);
  rep_.static_at_end = vnote.rfind("at rest", 0) == 0;
  if (rep_.levelling == "static")
    rep_.gyro_bias_B = gyro_bias_ - (q_B0toN().conjugate() * earth::w_IE_N(g.lat));
  rep_.notes.push_back("aligned at t = " + formatNumber(t_last_, 8) + " s: roll " + formatNumber(rep_.rpy[0] * kRad2Deg, 4) +
                       ", pitch " + formatNumber(rep_.rpy[1] * kRad2Deg, 4) + ", yaw " + formatNumber(rep_.rpy[2] * kRad2Deg, 4) +
                       " deg (1-sigma " + formatNumber(s_tilt * kRad2Deg, 3) + " / " + formatNumber(s_yaw * kRad2Deg, 3) +
                       " deg), heading from " + rep_.heading + ", position from the GNSS fix at " +
                       formatNumber(r.fix.t, 8) + " s, velocity " + vnote);
}

void CoarseAligner::addImu(const ins::ImuSample& s) {
  if (done_) return;
  const Vector3d w = s.w_IB_B(), f = s.f_B();
  const bool st = det_.push(s);
  static_now_ = st;
  t_last_ = s.t;

  // 2. body rotation since t0 (after static levelling: its mean gyro output removed)
  w_last_ = w - gyro_bias_;
  q_BtoB0_ = (q_BtoB0_ * ins::quatFromRotVec(w_last_ * s.dt)).normalized();
  if (later_yaw_ && !later_yaw_seen_ && s.t >= *opt_.yaw_t_s - 0.5 / rate_) {  // the sample nearest the later yaw
    later_yaw_seen_ = true;
    t_later_yaw_ = s.t;
    q_later_yaw_ = q_BtoB0_;
  }

  // 1. levelling at rest: decisions on disjoint detector windows; a window
  // called moving is left out, two in a row end the rest (one is a false
  // alarm at the detector's level)
  if (!levelled_ && static_start_) {
    window_.add(f, w);
    if (++window_pos_ == det_.window()) {
      window_pos_ = 0;
      if (st) {
        level_.add(window_);
        flagged_ = false;
        q_rest_end_ = q_BtoB0_;
        t_rest_end_ = s.t;
      } else if (flagged_) {
        endRest(level_, "static detector");
      } else {
        flagged_ = true;
      }
      window_ = Sums{};
    }
    if (!levelled_ && static_start_ && level_.n / rate_ >= opt_.max_level_s) endRest(level_, "");
  }

  const Vector3d f_B0 = q_BtoB0_ * f;
  if (vel_a_) u_B0_ += f_B0 * s.dt;
  if (qs_T_ < opt_.level_window_s - 0.5 / rate_) {
    qs_u_ += f_B0 * s.dt;
    qs_T_ += s.dt;
  }
  if (want_quasi_static_ && !levelled_ && qs_T_ >= opt_.level_window_s - 0.5 / rate_) levelQuasiStatic();
  if (levelled_ && !heading_ && later_yaw_seen_) applyLaterYaw();
  if (s.t - t0_ > opt_.max_align_s)
    throw Error("alignment not complete after " + formatNumber(opt_.max_align_s, 6) + " s of IMU data: " + missing());
}

void CoarseAligner::addFix(const AlignmentFix& f) {
  if (done_) return;
  if (f.t < t0_ - 0.5 / rate_) {
    if (!early_fix_noted_) rep_.notes.push_back("GNSS fixes before the start of the IMU data are not used");
    early_fix_noted_ = true;
    return;
  }
  if (!origin_) origin_ = f.pos;
  FixRec r{f, earth::geodeticToNed(*origin_, f.pos), q_BtoB0_, w_last_};
  // GNSS says whether the rest at the start is real (a vehicle at constant
  // velocity without vibration looks static to the IMU alone)
  if (!levelled_ && static_start_) {
    bool moving = false;
    if (f.v_N) moving = f.v_N->norm() > 3.0 * f.sigma_vel_N.norm() + 0.02;
    if (rest_anchor_) {
      const FixRec& a = fixes_[*rest_anchor_];
      const double d = (r.p_L - a.p_L).head<2>().norm();
      moving = moving || d > 4.0 * std::hypot(a.fix.sigma_pos_N.head<2>().norm(), f.sigma_pos_N.head<2>().norm());
    }
    if (moving) {
      endRest(gnss_seen_in_rest_ ? confirmed_ : Sums{}, "GNSS shows motion");
    } else {
      if (f.v_N || rest_anchor_) {
        confirmed_ = level_;
        gnss_seen_in_rest_ = true;
      }
      if (!rest_anchor_) rest_anchor_ = fixes_.size();
    }
  }
  if (!levelled_ && !static_start_) {
    if (f.v_N) {
      const int lv = vel_a_ ? levelWithVelocities(*vel_a_, r) : 0;
      if (lv != 2) {
        // too slow for a course: level as if at rest
        if (lv == 0 && vel_a_ && !heading_ && !vel_first_) want_quasi_static_ = true;
        vel_a_ = r;
        u_B0_.setZero();
      }
    } else {
      want_quasi_static_ = true;
    }
    if (want_quasi_static_ && !levelled_ && qs_T_ >= opt_.level_window_s - 0.5 / rate_) levelQuasiStatic();
  }
  if (levelled_ && !heading_ && later_yaw_seen_) applyLaterYaw();
  if (levelled_ && !heading_ && !later_yaw_) tryHeading(r);
  if (levelled_ && heading_ && (static_now_ || f.v_N || !fixes_.empty())) {
    finish(r);
    return;
  }
  fixes_.push_back(r);
  // bounded memory that keeps long baselines (a slow vehicle needs a long
  // chord for its course): past kKeep fixes, every second older one goes
  constexpr std::size_t kKeep = 128;
  if (fixes_.size() > kKeep && levelled_) {
    std::vector<FixRec> kept;
    kept.reserve(kKeep / 2 + 2);
    for (std::size_t i = 0; i + 1 < fixes_.size(); i += 2) kept.push_back(fixes_[i]);
    kept.push_back(fixes_.back());
    fixes_.swap(kept);
    rest_anchor_.reset();
  }
}

std::string CoarseAligner::missing() const {
  std::vector<std::string> m;
  if (!levelled_)
    m.push_back(static_start_ ? "levelling (still at rest; it ends when the vehicle moves or after " +
                                    formatNumber(opt_.max_level_s, 4) + " s)"
                              : "levelling (moving at the start, waiting for GNSS fixes)");
  if (!heading_ && later_yaw_)
    m.push_back("heading (waiting for the " + opt_.yaw_source + "'s yaw at t = " + formatNumber(*opt_.yaw_t_s, 10) +
                " s)");
  else if (!heading_)
    m.push_back("heading (no GNSS course with a 1-sigma below " + formatNumber(opt_.max_course_sigma_rad * kRad2Deg, 3) +
                " deg yet: the vehicle has not moved far enough between fixes; give the initial heading)");
  if (!origin_) m.push_back("position (no GNSS fix since the start of the IMU data)");
  if (m.empty()) m.push_back("a GNSS fix with a velocity (moving, or a second fix)");
  std::string out = "missing ";
  for (std::size_t i = 0; i < m.size(); ++i) out += (i ? "; " : "") + m[i];
  return out;
}

}  // namespace navimpact::filter
