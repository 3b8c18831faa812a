/**
 * @file alignment.hpp
 * @brief The start of a navigation run as users have it: a static detector,
 *        coarse levelling from the accelerometers and a coarse aligner that
 *        takes the heading from a given value or, once moving, from the GNSS
 *        course, and reports its "aligning" phase instead of refusing.
 *
 * Conventions (README): body FRD, navigation frame NED, attitude C_BtoN
 * with ZYX roll, pitch, yaw; SI units.
 *
 * Levelling (Groves 2013 eq. 5.101): at rest the accelerometers measure
 * f_B = -C_NtoB g_N, so roll = atan2(-f_y, -f_z) and
 * pitch = atan2(f_x, sqrt(f_y^2 + f_z^2)), whatever the heading. An
 * accelerometer bias b tilts the result by b/g to first order
 * (d roll = -b_y/g, d pitch = b_x/g at level).
 *
 * Static detector: the moving-variance test of Skog et al. (2010, "Zero-velocity
 * detection - an algorithm evaluation", the MV detector with the angular-rate
 * energy bounded) over a window of W samples ending at the current one,
 *   T = sum_k sum_a (w_a,k - mean w_a)^2 / s_w,a^2 + (f_a,k - mean f_a)^2 / s_f,a^2,
 * which is chi-square with 6 (W - 1) degrees of freedom when the IMU is at rest
 * and its output is white noise of per-axis standard deviations s_w, s_f (the
 * at-rest levels, vibration included). "Static" when T <= the (1 - false_alarm)
 * quantile and |mean w| <= max_mean_rate_rad_s (a steady turn without vibration
 * has a small variance but not a small rate); the decision applies to the
 * window's last sample (causal).
 *
 * Coarse aligner: fed the IMU samples and GNSS fixes in time order from the
 * start of the IMU data t0, it
 *  1. levels: over the static span at the start (when the detector finds at
 *     least min_static_s of rest; the mean gyro output there is taken as bias
 *     plus Earth rate and removed while it integrates the body rotation
 *     afterwards), else, with GNSS velocities, by matching the specific force
 *     integrated over a GNSS velocity interval to the velocity change
 *     minus gravity (levelling corrected for the vehicle's own acceleration),
 *     solved over two consecutive intervals: when the two attitudes of the
 *     body at t0 disagree by more than 3 combined sigmas (sideslip at a launch,
 *     unmodelled acceleration) the sigmas are raised to the disagreement,
 *     else over the first level_window_s as if at rest (sigma inflated by the
 *     assumed acceleration);
 *  2. takes the heading from AlignmentOptions::yaw (configuration or a
 *     reference): the body's yaw at t0, or at a later time yaw_t_s (a
 *     reference whose attitude starts after the IMU data): the yaw of the
 *     body then, carried back to t0 through the rotation the gyros measured
 *     in between, yaw(t0) = yaw(t_y) - yaw(C_level C_B(t_y)toB0) (ZYX: a
 *     rotation about the navigation z axis adds to the yaw); the aligner
 *     waits for it instead of taking a GNSS course (a course still levels a
 *     moving start with GNSS velocity before it arrives); or else from the
 *     GNSS course once moving: the course of a
 *     GNSS velocity, or of the chord between two position fixes (IMU positions:
 *     lever arm removed), accepted when its standard deviation
 *     (sigma_v,h / speed, or sqrt(2) sigma_p,h / chord) is below
 *     max_course_sigma_rad; no sideslip assumed (its allowance sideslip_sigma_rad
 *     enters the yaw sigma);
 *  3. ends at the first IMU sample at or after the GNSS fix that completes it
 *     (position is always taken from a fix at or after t0): the initial state,
 *     its 9x9 covariance and a report of what was used.
 * Between t0 and the end the filter does not run: that is the reported
 * "aligning" phase.
 */
#pragma once

#include <deque>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "navimpact/core/earth.hpp"
#include "navimpact/filter/error_model.hpp"
#include "navimpact/ins/nav_state.hpp"

namespace navimpact::filter {

/// Roll and pitch [rad] of a body at rest from its mean specific force @p f_B [m/s^2]
/// (Groves 2013 eq. 5.101). @throws navimpact::Error when |f_B| is below 1 m/s^2.
Eigen::Vector2d levelRollPitch(const Eigen::Vector3d& f_B);

/// Options of the static detector (see the file comment).
struct StaticDetectorOptions {
  double window_s = 0.5;                 ///< window length [s], >= 2 samples
  /// At-rest standard deviation of each gyro axis [rad/s] and accelerometer
  /// axis [m/s^2] per sample (sensor noise and any vibration present at rest), > 0.
  Eigen::Vector3d gyro_sigma_rad_s = Eigen::Vector3d::Constant(1e-3);
  Eigen::Vector3d acc_sigma_mps2 = Eigen::Vector3d::Constant(1e-2);
  double false_alarm = 0.01;             ///< probability to call a window at rest "moving", in (0, 0.5)
  double max_mean_rate_rad_s = 0.05;     ///< |mean angular rate| above this is "moving" [rad/s], > 0
};

/**
 * Streaming static detector: push() every IMU sample in order; O(1) per sample
 * (running sums, recomputed from the window every W samples against rounding).
 */
class StaticDetector {
 public:
  /// @throws navimpact::Error for options outside their ranges or a rate <= 0.
  StaticDetector(const StaticDetectorOptions& opt, double imu_rate_hz);
  /// Add one sample; returns the decision for the window ending at it
  /// (false until the window is full).
  bool push(const ins::ImuSample& s);
  bool isStatic() const { return static_; }
  bool full() const { return n_ == w_; }
  double statistic() const { return stat_; }   ///< T of the last full window
  double threshold() const { return thr_; }    ///< chi-square quantile, 6 (W - 1) dof
  int window() const { return w_; }            ///< W [samples]
  int dof() const { return 6 * (w_ - 1); }
  /// Mean angular rate over the last full window [rad/s].
  Eigen::Vector3d meanRate() const;

 private:
  void recompute();
  StaticDetectorOptions opt_;
  int w_ = 0, n_ = 0, since_recompute_ = 0;
  double thr_ = 0.0, stat_ = 0.0;
  bool static_ = false;
  std::deque<Eigen::Matrix<double, 6, 1>> buf_;
  Eigen::Matrix<double, 6, 1> ref_, sum_, sum2_, inv_var_;
};

/// Options of the coarse aligner (see the file comment).
struct AlignmentOptions {
  std::optional<double> yaw_rad;            ///< heading at the start [rad] (or at yaw_t_s): no course needed
  /// Time of yaw_rad [s, the IMU's clock]: the body's yaw then (e.g. a
  /// reference's first attitude epoch after the start); empty or <= t0: at t0.
  /// At most max_align_s after t0.
  std::optional<double> yaw_t_s;
  std::string yaw_source = "configuration"; ///< where yaw_rad came from, for the report
  double yaw_sigma_rad = 0.035;             ///< 1-sigma of a given heading [rad], > 0
  StaticDetectorOptions detector;           ///< finds the static span at the start
  double min_static_s = 1.0;                ///< rest needed at the start for static levelling [s]
  double max_level_s = 60.0;                ///< static levelling stops after [s]
  double level_window_s = 1.0;              ///< quasi-static levelling window when moving [s]
  double max_course_sigma_rad = 0.05;       ///< accept a GNSS course when its sigma is below [rad]
  double sideslip_sigma_rad = 0.05;         ///< heading minus course of travel, 1-sigma [rad]
  double accel_sigma_mps2 = 0.5;            ///< unknown vehicle acceleration, 1-sigma [m/s^2]
  double acc_bias_sigma_mps2 = 0.0;         ///< accelerometer bias 1-sigma (tilts the levelling by b/g) [m/s^2]
  double gyro_bias_sigma_rad_s = 0.0;       ///< gyro bias 1-sigma (attitude drift while aligning) [rad/s]
  double static_velocity_sigma_mps = 0.01;  ///< velocity 1-sigma when the alignment ends at rest [m/s]
  double max_align_s = 600.0;               ///< give up after this long [s]
  Eigen::Vector3d lever_arm_B = Eigen::Vector3d::Zero();  ///< GNSS antenna from the IMU, body FRD [m]
};

/// What the aligning phase did.
struct AlignmentReport {
  double t_start = 0.0;            ///< start of the IMU data [s]
  double t_end = 0.0;              ///< the filter starts here [s]
  std::string levelling;           ///< "static", "gnss_velocity" or "quasi_static"
  double level_span_s = 0.0;       ///< data used for the levelling [s]
  std::string heading;             ///< "configuration", "reference", "gnss_velocity_course", "gnss_chord_course"
  double course_speed_mps = 0.0;   ///< speed of the accepted course (0 for a given heading)
  double course_t = 0.0;           ///< time of the accepted course [s]
  double heading_t = 0.0;          ///< time the heading was measured [s] (t0 for a heading given at the start)
  Eigen::Vector3d rpy = Eigen::Vector3d::Zero();        ///< attitude at t_end [rad]
  Eigen::Vector3d sigma_rpy = Eigen::Vector3d::Zero();  ///< its 1-sigma [rad]
  Eigen::Vector3d gyro_bias_B = Eigen::Vector3d::Zero();///< mean at-rest gyro output minus Earth rate [rad/s] (static levelling)
  bool static_at_end = false;      ///< the detector said "at rest" at t_end
  std::vector<std::string> notes;  ///< plain-words account
};

/// One GNSS fix as the aligner needs it (antenna).
struct AlignmentFix {
  double t = 0.0;                                 ///< [s]
  earth::Geodetic pos;                            ///< antenna position
  Eigen::Vector3d sigma_pos_N = Eigen::Vector3d::Ones();  ///< 1-sigma N, E, D [m]
  std::optional<Eigen::Vector3d> v_N;             ///< antenna velocity [m/s]
  Eigen::Vector3d sigma_vel_N = Eigen::Vector3d::Constant(0.1);  ///< its 1-sigma [m/s]
};

/**
 * Streaming coarse aligner. Feed addImu() for every sample in order and
 * addFix() for each GNSS fix once the IMU has reached its time (fix.t <= the
 * last sample's t); done() turns true at the IMU sample that completes the
 * alignment: then state(), P0() and report() are valid and the filter starts
 * there with the next sample.
 */
class CoarseAligner {
 public:
  /// @param[in] t0  start of the IMU data [s]; @param[in] imu_rate_hz nominal rate.
  CoarseAligner(const AlignmentOptions& opt, double t0, double imu_rate_hz);
  /// @throws navimpact::Error when the alignment has not ended after max_align_s.
  void addImu(const ins::ImuSample& s);
  void addFix(const AlignmentFix& f);
  bool done() const { return done_; }
  const ins::NavState& state() const { return x0_; }
  const Matrix9d& P0() const { return P0_; }
  const AlignmentReport& report() const { return rep_; }
  /// What is still missing, in plain words (for an error when the data end first).
  std::string missing() const;
  /// The fix used for the initial position (not to be applied again by the filter).
  double usedFixTime() const { return used_fix_t_; }

 private:
  // sums over the windows the detector called static
  struct Sums {
    long n = 0;
    Eigen::Vector3d f = Eigen::Vector3d::Zero(), w = Eigen::Vector3d::Zero(), f2 = Eigen::Vector3d::Zero();
    void add(const Eigen::Vector3d& fi, const Eigen::Vector3d& wi) {
      ++n;
      f += fi;
      w += wi;
      f2 += fi.cwiseAbs2();
    }
    void add(const Sums& o) {
      n += o.n;
      f += o.f;
      w += o.w;
      f2 += o.f2;
    }
  };
  struct FixRec {
    AlignmentFix fix;
    Eigen::Vector3d p_L;            // antenna in the tangent frame at the first fix [m]
    Eigen::Quaterniond q_BtoB0;     // body at the fix w.r.t. the body at t0
    Eigen::Vector3d w_B;            // bias-corrected angular rate at the fix [rad/s]
  };
  Eigen::Quaterniond q_B0toN() const;
  Eigen::Vector3d imuPosition(const FixRec& r) const;
  Eigen::Vector3d imuVelocity(const FixRec& r) const;
  void levelStatic(const Sums& sums);
  void levelQuasiStatic();
  /// 0: not possible over (a, b]; 1: first solution kept, confirm over the next
  /// interval; 2: confirmed (levelled, heading set unless given).
  int levelWithVelocities(const FixRec& a, const FixRec& b);
  void tryHeading(const FixRec& r);
  /// The heading from the yaw given at yaw_t_s, once the IMU reached it and the attitude is levelled.
  void applyLaterYaw();
  void noteLaterYaw();
  void finish(const FixRec& r);

  AlignmentOptions opt_;
  double t0_, rate_;
  StaticDetector det_;
  double t_last_ = 0.0;
  bool static_now_ = false;
  bool levelled_ = false, static_start_ = true, want_quasi_static_ = false;
  double t_levelled_ = 0.0;
  Sums level_, window_, confirmed_;      // static windows; the current window; at the last GNSS confirmation of rest
  bool gnss_seen_in_rest_ = false;
  int window_pos_ = 0;
  bool flagged_ = false;                 // the previous window was called moving
  Eigen::Quaterniond q_rest_end_ = Eigen::Quaterniond::Identity();  // body rotation at the end of the last static window
  double t_rest_end_ = 0.0;
  std::optional<std::size_t> rest_anchor_;  // index in fixes_ of the first fix during the rest
  void endRest(const Sums& sums, const std::string& why);
  Eigen::Vector3d qs_u_ = Eigen::Vector3d::Zero();  // specific force integrated in B0 over the first window
  double qs_T_ = 0.0;
  Eigen::Vector3d gyro_bias_ = Eigen::Vector3d::Zero();   // removed while integrating
  Eigen::Vector2d rp0_ = Eigen::Vector2d::Zero();          // roll, pitch of the body at t0
  double sigma_tilt_ = 0.0;
  Eigen::Quaterniond q_BtoB0_ = Eigen::Quaterniond::Identity();
  Eigen::Vector3d w_last_ = Eigen::Vector3d::Zero();
  // levelling with GNSS velocities: specific force integrated in B0 since fix a
  std::optional<FixRec> vel_a_;
  // first GNSS-velocity solution, awaiting its confirmation over the next interval
  struct VelLevel {
    Eigen::Quaterniond q_B0toN;   // attitude of the body at t0
    double sigma_tilt = 0.0, sigma_yaw = 0.0, t = 0.0;
  };
  std::optional<VelLevel> vel_first_;
  Eigen::Vector3d u_B0_ = Eigen::Vector3d::Zero();
  // heading: yaw of the body at t0
  bool heading_ = false;
  double yaw0_ = 0.0, sigma_yaw_ = 0.0, t_heading_ = 0.0;
  // a yaw given at a later time (yaw_t_s): awaited; once the IMU reached it, the body rotation then
  bool later_yaw_ = false, later_yaw_seen_ = false;
  double t_later_yaw_ = 0.0;                                    // the IMU sample nearest yaw_t_s [s]
  Eigen::Quaterniond q_later_yaw_ = Eigen::Quaterniond::Identity();  // body at it w.r.t. B0
  // fixes
  std::optional<earth::Geodetic> origin_;
  std::vector<FixRec> fixes_;
  bool early_fix_noted_ = false;
  // result
  bool done_ = false;
  double used_fix_t_ = -1e300;
  ins::NavState x0_;
  Matrix9d P0_ = Matrix9d::Zero();
  AlignmentReport rep_;
};

}  // namespace navimpact::filter
