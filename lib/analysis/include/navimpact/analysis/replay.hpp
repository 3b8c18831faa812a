/**
 * @file replay.hpp
 * @brief Replay of a rawlog (labels IMU, GNSS, BARO, GT; see rawlog/writer.hpp)
 *        through the error-state EKF with GNSS outages injected, and its report:
 *        solution.csv, summary.json and figures in the style of Khaghani et al.
 *        (2019) Figures 8 and 9 (error and +-1 sigma envelope, outage shaded).
 *
 * The navigation loop is analysis::runNav() (shared with the emulation study).
 * Time zero of a replay (for outages and outputs) is the start of the IMU data:
 * the beginning of the first IMU interval, i.e. the first IMU timestamp minus
 * one IMU period. An outage START:DURATION drops the GNSS fixes with
 * START < t <= START + DURATION; the barometer keeps working.
 *
 * Configuration (YAML, every key optional; relative paths against its folder):
 * @code
 * rawlog: ../../datasets/uav_flight_260s_ref.rawlog
 * imu_label: XSENS      # of a rawlog navimpact did not write; default: the only IMU label
 * gnss_label: GPS       # likewise (--imu-label / --gnss-label override them)
 * model: ../models/navchip_table1.yaml:ref   # filter's IMU model; default: the rawlog's scenario model
 * outages: [{start_s: 200, duration_s: 60}]  # [s] from time zero
 * filter: {propagate_every: 10, use_gnss_velocity: true, gate_probability: 0, gate_readmit_after: 3,
 *          max_imu_gap_s: 0,
 *          extra_states: {scale_factor: {gyro_sigma: 0.005, acc_sigma: 0.005},
 *                         misalignment: {gyro_sigma_rad: 0.003, acc_sigma_rad: 0.003},
 *                         lever_arm: {sigma_m: 0.5}, time_offset: {sigma_s: 0.05}}}
 * initial_sigma: {pos_h_m: 1, pos_v_m: 1, vel_mps: 0.1, roll_pitch_deg: 0.1, yaw_deg: 0.5}
 * noise: {sigma_pos_h_m: 2, sigma_pos_v_m: 4, sigma_vel_h_mps: 0.05, sigma_vel_v_mps: 0.1, sigma_baro_m: 0.5}
 * gnss_lever_arm_B_m: [0, 0, 0]              # default: the scenario's
 * @endcode
 * IMU gaps: an IMU interval longer than kImuGapSteps times the nominal interval
 * is an error naming the rawlog and the time, unless `filter.max_imu_gap_s`
 * (or --max-imu-gap) allows gaps up to that length [s] (0 to kMaxImuGapS);
 * then the filter propagates across each gap in nominal-length sub-steps with
 * the rates interpolated between the samples around it and their uncertainty
 * added (a Brownian bridge, README "No silent acceptance"), unless that
 * uncertainty is above filter::kSmallErrorAttitudeSigmaRad in attitude (an error naming
 * the gap: the rates change too fast around it to bridge it), and a notice in
 * summary.json says how many gaps and the longest. Duplicated records (two of
 * one sensor at the same time) are refused by the rawlog reader.
 *
 * Without `noise`, the covariances recorded with each GNSS fix and the
 * scenario's barometer sigma are used.
 *
 * outages_every: {period_s: 120, duration_s: 30}  # or --outages-every 120:30
 * reference_sigma: {horizontal_m: 0.05, vertical_m: 0.1}   # the reference's own 1-sigma
 * reference_lever_arm_B_m: [0, 0, 0]        # the reference's point (e.g. the antenna) from the IMU
 * alignment: {yaw_deg: 40, yaw_sigma_deg: 2, max_align_s: 600, max_course_sigma_deg: 3,
 *             yaw_from_reference: true}
 * imu_at_rest: {gyro_sigma_rad_s: 1e-3, acc_sigma_mps2: 1e-2, window_s: 0.5, false_alarm: 0.01}
 * aids: {zupt: {sigma_mps: 0.02, interval_s: 0.1},
 *        nhc: {sigma_lateral_mps: 0.1, sigma_vertical_mps: 0.1, interval_s: 0.1,
 *              min_speed_mps: 0.5, point_B_m: [0, 0, 0]}}   # each present = on
 *
 * Rawlogs without ground truth (label GT absent, e.g. a real run): an
 * aligning phase (filter/alignment.hpp: static or GNSS-velocity levelling,
 * heading from `alignment.yaw_deg` / `initial_attitude_deg`'s yaw, else from
 * the reference's attitude (unless `yaw_from_reference: false`): at time zero
 * when it has one there, else at its first attitude epoch read ahead, which
 * the phase then waits for (within alignment.max_align_s; the yaw then is
 * carried to the start through the gyros), else from the GNSS course once
 * moving) runs from time zero until it has an attitude, a
 * position and a velocity; the filter starts there (no fix is needed at the
 * first IMU sample) and the phase is reported. The estimate and the
 * predicted sigmas are recorded every `record_interval_s` (default 0.1 s);
 * errors and NEES are empty in solution.csv and absent from summary.json.
 *
 * With ground truth the run is scored (analysis/scoring.hpp), counting the
 * reference's own sigma; `outages_every` outages are laid from the filter start.
 */
#pragma once

#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "navimpact/analysis/nav_run.hpp"
#include "navimpact/analysis/scoring.hpp"
#include "navimpact/core/config.hpp"
#include "navimpact/core/recording.hpp"
#include "navimpact/filter/alignment.hpp"
#include "navimpact/stochastic/model_file.hpp"

namespace navimpact::rawlog {
struct RawlogRecords;  // rawlog/reader.hpp: a rawlog's records in memory
}  // namespace navimpact::rawlog

namespace navimpact::analysis {

/// IMU samples read ahead before the filter starts: their median interval is
/// the nominal step (gaps are measured against it), and the reference (GT)
/// entries among them tell whether the filter can start from the reference
/// (complete entries, one at time zero) or needs an aligning phase.
constexpr std::size_t kReplayLookaheadImu = 16384;
/// An IMU interval longer than this many nominal (median) steps is a gap.
constexpr double kImuGapSteps = 1.5;
/// Largest accepted filter.max_imu_gap_s [s]: across longer gaps the attitude
/// uncertainty outgrows the linearised filter (a probe: after a 5 s gap of the
/// UAV run roll was 5.3 deg off with sigma 0.04 deg; 10-15 s diverged; up to
/// 2 s the errors stayed within 4 sigma).
constexpr double kMaxImuGapS = 2.0;

/// Replay options (see the file comment for the YAML form).
struct ReplayConfig {
  std::string config_file;
  std::string rawlog;
  std::string imu_label, gnss_label;            ///< of a rawlog navimpact did not write; "" = the only one
  std::string model_spec;                       ///< "" = the rawlog scenario's model
  std::vector<Outage> outages;                  ///< GNSS outages from time zero [s] (navimpact::parseOutage)
  /// How each outage is named in messages, when it came from a file or flag
  /// ("FILE:L:C: key 'outages[1]': outage 200:60", "--outage 200:60"); one per outage or empty.
  std::vector<std::string> outage_names;
  /// Replace the outages and their names together (none: each named "outage S:D").
  void setOutages(std::vector<Outage> o, std::vector<std::string> names = {}) {
    outages = std::move(o);
    outage_names = std::move(names);
  }
  int propagate_every = 10;                     ///< covariance propagation every k IMU samples
  bool use_gnss_velocity = true;
  double gate_probability = 0.0;
  int gate_readmit_after = 3;                   ///< filter::EkfConfig::gate_readmit_after (0..1000, 0 = never)
  filter::ExtraStates extra_states;             ///< filter.extra_states (filter/state_layout.hpp); all off by default
  double p0_pos_h_m = 1.0, p0_pos_v_m = 1.0, p0_vel_mps = 0.1;
  double p0_roll_pitch_deg = 0.1, p0_yaw_deg = 0.5;
  std::optional<double> sigma_pos_h_m, sigma_pos_v_m, sigma_vel_h_mps, sigma_vel_v_mps, sigma_baro_m;
  std::optional<Eigen::Vector3d> lever_arm_B;
  std::optional<Eigen::Vector3d> initial_attitude_deg;  ///< roll, pitch, yaw [deg]; used without GT
  double record_interval_s = 0.1;               ///< record interval without GT [s], > 0
  double max_imu_gap_s = 0.0;                   ///< longest IMU gap propagated across [s]; 0 = gaps are errors
  std::optional<OutagePattern> outages_every;   ///< more outages all along the run (after the explicit ones)
  double reference_sigma_h_m = 0.0;             ///< the reference's own 1-sigma per horizontal axis [m]
  double reference_sigma_v_m = 0.0;             ///< its vertical 1-sigma [m]
  Eigen::Vector3d reference_lever_arm_B = Eigen::Vector3d::Zero();  ///< the reference's point from the IMU, body FRD [m]
  filter::AlignmentOptions alignment;           ///< the aligning phase without GT (lever arm and yaw set by the replay)
  /// Heading of the aligning phase from the reference's attitude (when it has
  /// one and no yaw is configured): at time zero, or at its first attitude
  /// epoch when that comes later (the phase waits for it); false: from the GNSS course.
  bool alignment_yaw_from_reference = true;
  NavRunOptions aids;                           ///< only its zupt* / nhc* fields are used (ground-vehicle aids)
  /// false: the rawlog's reference (GT) is ignored, as for a rawlog without
  /// one (aligning phase, estimate recorded every record_interval_s); used to
  /// get the GNSS-aided solution densely when the reference is sparse.
  bool use_reference = true;
  /// A filter model given in memory (e.g. an extension under test); takes
  /// precedence over model_spec, whose text then only names it.
  std::optional<stochastic::ImuModel> model;

  /// Read the keys of a replay configuration (see the file comment), with the
  /// ranges of core/limits.hpp; paths relative to the configuration's folder,
  /// their files checked (ConfigNode::inputFile). Keys in @p given_by_flags
  /// ("rawlog", "model") are replaced by a command-line flag: read as text, their files not checked.
  void loadFrom(const ConfigNode& root, const std::vector<std::string>& given_by_flags = {});
};

/// Read a replay configuration. @throws navimpact::Error naming file and key.
ReplayConfig loadReplayConfig(const std::string& path, const std::vector<std::string>& given_by_flags = {});

/// Everything a replay computed.
struct ReplayResult {
  ReplayConfig cfg;
  std::string model_source;                 ///< the filter's IMU model
  std::string scenario_yaml;                ///< the rawlog's comment
  double t_zero = 0.0;                      ///< rawlog time of replay time zero [s]
  double imu_rate_hz = 0.0;
  NavRunResult run;                         ///< errors, sigmas, NEES at the GT epochs (run.has_truth)
  std::vector<ins::NavState> truth;         ///< truth at the epochs (empty without GT)
  std::vector<ins::NavState> estimate;      ///< estimate at the epochs
  double read_s = 0.0;                      ///< wall-clock time spent reading the rawlog [s]
  std::size_t imu_gaps = 0;                 ///< IMU gaps propagated across (allowed by max_imu_gap_s)
  std::vector<std::string> notices;
  /// The aligning phase (rawlogs without GT): from time zero to report.t_end the
  /// filter does not run; absent when the filter started from GT.
  std::optional<filter::AlignmentReport> alignment;
  double aided_from_s = 0.0;                ///< filter start, from time zero [s]
  std::optional<RunScore> score;            ///< scored against the reference (GT) when there is one
  NavRunOptions nav;                        ///< the filter options the run used (outages, P0, lever arm, aids)
  std::vector<GnssFix> gnss;                ///< the GNSS fixes given to the filter (covariances as applied)
  std::vector<BaroSample> baro;             ///< the barometer samples given to the filter
};

/**
 * What a replay that keeps nothing per epoch hands on as it goes (the report
 * layer writes solution.csv row by row and keeps bounded figure series).
 */
class ReplayObserver {
 public:
  virtual ~ReplayObserver() = default;
  /// Once, before the first epoch: @p r has its configuration, time zero,
  /// IMU rate, filter model and alignment (notices, score and run come at the end).
  virtual void begin(const ReplayResult& r) = 0;
  /// One recorded epoch and the reference state at it (nullptr without one).
  /// @p windows: the outages so far in filter time (NavRunResult::outages
  /// order), r.cfg.outages the same from time zero; both hold every outage
  /// that contains the epoch or started before it.
  virtual void epoch(const ReplayResult& r, const NavEpoch& e, const ins::NavState* truth,
                     const std::vector<Outage>& windows) = 0;
};

/**
 * Run a replay: the rawlog is read record by record while the EKF runs over
 * it, with a bounded read-ahead (kReplayLookaheadImu IMU samples at the
 * start; during the run up to half an IMU step, and before each outage of
 * `outages_every` to its end: windows are laid from the filter start and an
 * outage exists only when the data reach its end). Explicit outages are
 * checked against the data's end when it is reached (an error then, after
 * the run: nothing is written).
 * Everything per epoch is kept in the result (run.epochs, estimate, truth,
 * gnss, baro): memory grows with the run's length.
 * @throws navimpact::Error for a rawlog without IMU, without GT and without a
 *         GNSS fix at time zero, an outage outside the data, a missing model.
 */
ReplayResult runReplay(const ReplayConfig& cfg);

/**
 * The same replay from the rawlog's records read into memory once
 * (rawlog::readRawlogRecords of cfg.rawlog with cfg's labels; cfg.rawlog names
 * it in messages), for a run replayed many times (diagnose --run): the same
 * result as runReplay(cfg) except read_s = 0.
 * With @p stop_after_s the filter stops at the first IMU sample later than
 * that time from time zero; the rest of the data is still read, so what
 * depends on the whole data (the reference's content and sigma, the data's
 * end) is as in the full replay. Epochs, and outages that end by then, are
 * those of the full replay; later epochs and outages are absent, or cut for
 * an outage not over by then (so use only outages ending by stop_after_s).
 */
ReplayResult runReplay(const ReplayConfig& cfg, const rawlog::RawlogRecords& data,
                       double stop_after_s = std::numeric_limits<double>::infinity());

/**
 * The same replay in bounded memory: each epoch goes to @p observer and is not
 * kept (the result's run.epochs, estimate, truth, gnss and baro stay empty;
 * run.outages keep their end epochs, the score is complete). Memory is the
 * read-ahead, the outage summaries, the gate events and the GNSS innovations
 * (one per fix), independent of the IMU rate and of the number of epochs.
 */
ReplayResult runReplay(const ReplayConfig& cfg, ReplayObserver& observer);

}  // namespace navimpact::analysis
