/**
 * @file limits.hpp
 * @brief Documented physical ranges of configuration values, and the work and
 *        memory budgets of a run: limits as validation, checked when a value is
 *        loaded (with the file and key named), not left to luck at run time.
 *
 * The ranges are wide (beyond any real sensor or mission) but finite, so that
 * no single value can make a run spin, overflow or exhaust memory. Values that
 * must be positive have a lower bound below any real sensor or mission too,
 * not 0: a sigma of 1e-300 squares to 0 and ends in "sigma must be > 0" at run
 * time with no file or key, a duration of 1e-300 s is an outage of nothing.
 * (The parameters of a stochastic model stay open at 0: a fitted white-noise
 * sigma may legitimately be tiny, and a model file GMWM writes must load.)
 *  - IMU rate 1 Hz - 10 kHz; aiding and output rates (GNSS, barometer, ground
 *    truth, records) 0.001 Hz - 10 kHz;
 *  - position and altitude sigmas [0.1 mm, 10 km]; velocity sigmas
 *    [0.1 mm/s, 1 km/s]; attitude sigmas [1e-4, 180] deg;
 *  - lever-arm components [-100, 100] m;
 *  - durations [0.1 ms, 7 days]; times on a file's axis [-1e10, 1e10] s;
 *  - origins: latitude [-89.9, 89.9] deg (NED is singular at the poles), longitude [-360, 360] deg, height
 *    [-11 km, 100 km]; smoother cut-offs [1 mHz, 10 kHz];
 *  - IMU error states per axis at most 32 (a model has a handful);
 *  - Monte Carlo runs of a study at most 10^6;
 *  - sensor effects of an emulation and the extra filter states that model
 *    them (emulation::SensorEffects): scale factors [-0.05, 0.05] (ratio,
 *    +-50 000 ppm), misalignment and non-orthogonality angles [-0.05, 0.05] rad,
 *    IMU-GNSS time offset [-0.1, 0.1] s, lever-arm error components [-10, 10] m,
 *    in-motion white-noise factor [1, 100], motion thresholds
 *    [1e-3, 10] rad/s and [0.05, 100] m/s^2; prior sigmas of the filter
 *    states that estimate them: scale factors [1e-6, 0.05], angles
 *    [1e-6, 0.05] rad, lever-arm error [0.1 mm, 10 m], time offset
 *    [100 ns, 0.1 s].
 * README ("Ranges and budgets") lists them with the budgets.
 */
#pragma once

#include <cstdint>
#include <initializer_list>
#include <string>

namespace navimpact::limits {

/// A closed or left-open range of a physical value, in SI (or the key's unit).
struct Range {
  double lo, hi;
  bool lo_open;      ///< lo itself excluded (e.g. a sigma must be > 0)
  const char* unit;  ///< unit of the key, for the message
};

inline constexpr Range kImuRateHz{1.0, 1.0e4, false, "Hz"};
inline constexpr Range kAidingRateHz{1.0e-3, 1.0e4, false, "Hz"};
/// GNSS fix rates: receivers give at most 100 Hz (import reads a faster stream
/// as a time unit gone wrong, so emulate writes none it could not read back).
inline constexpr Range kGnssRateHz{1.0e-3, 100.0, false, "Hz"};
/// Position and altitude sigmas (GNSS, barometer, replay noise, initial
/// sigmas) [m]: from 0.1 mm, a tenth of the best survey-grade fix (RTK, laser
/// tracker ~1 mm); below it the variance is no sensor's and the Kalman gain is
/// 1 to rounding (1e-300 squared is 0).
inline constexpr Range kPositionSigmaM{1.0e-4, 1.0e4, false, "m"};
/// Velocity sigmas (GNSS, replay noise, initial sigma, aids) [m/s]: from
/// 0.1 mm/s, below the best carrier-phase Doppler velocity (~1 mm/s).
inline constexpr Range kVelocitySigmaMps{1.0e-4, 1.0e3, false, "m/s"};
/// Attitude sigmas (initial roll, pitch and yaw sigmas, alignment sigmas)
/// [deg]: from 1e-4 deg (1.7 urad), below the alignment of a strategic-grade
/// INS (~1e-3 deg).
inline constexpr Range kAttitudeSigmaDeg{1.0e-4, 180.0, false, "deg"};
inline constexpr Range kLeverArmM{-100.0, 100.0, false, "m"};
/// Durations and intervals (outages, record intervals, windows, gaps, knot
/// steps) [s]: from 0.1 ms, one sample interval at the highest IMU rate
/// (10 kHz); nothing shorter can be sampled.
inline constexpr Range kDurationS{1.0e-4, 7.0 * 86400.0, false, "s"};
/// A time on a file's own axis (trajectory start_s/end_s: file time, e.g. Unix seconds) [s].
inline constexpr Range kFileTimeS{-1.0e10, 1.0e10, false, "s"};
/// Geodetic latitude, longitude and height of an origin [deg, deg, m].
/// Latitudes of positions navimpact navigates (origins, trajectory rows, a static
/// state): the NED mechanisation's transport rate holds tan(latitude), singular
/// at the poles (an emulation at 90 deg replayed to a covariance of NaN at 0.05 s).
inline constexpr Range kLatitudeDeg{-89.9, 89.9, false, "deg"};
inline constexpr Range kLongitudeDeg{-360.0, 360.0, false, "deg"};
inline constexpr Range kHeightM{-1.1e4, 1.0e5, false, "m"};
/// Cut-off frequency of a smoother [Hz]: from 1 mHz (a period of 17 min; a
/// lower cut-off smooths a vehicle's every manoeuvre into a straight line).
inline constexpr Range kCutoffHz{1.0e-3, 1.0e4, false, "Hz"};

/// Most IMU samples between two covariance propagations (filter.propagate_every, 1..1000).
inline constexpr int kMaxPropagateEvery = 1000;

// Sensor effects (emulation::SensorEffects) and the prior sigmas of the filter
// states that estimate them. Scale factors and small angles are first-order
// effects: beyond a few percent the linear models of emulation and filter
// stop agreeing to second order, so the ranges stop there.
inline constexpr Range kScaleFactor{-0.05, 0.05, false, "(ratio)"};
inline constexpr Range kMisalignmentRad{-0.05, 0.05, false, "rad"};
inline constexpr Range kTimeOffsetS{-0.1, 0.1, false, "s"};
inline constexpr Range kLeverArmErrorM{-10.0, 10.0, false, "m"};
inline constexpr Range kMotionNoiseFactor{1.0, 100.0, false, "(factor)"};
inline constexpr Range kMotionRateThresholdRadS{1.0e-3, 10.0, false, "rad/s"};
inline constexpr Range kMotionAccThresholdMps2{0.05, 100.0, false, "m/s^2"};
// Prior sigmas of the filter's extra states (filter::ExtraStates): the same
// upper bounds as the effects they estimate; a state is off by leaving it out,
// and a prior below the lower bound is no uncertainty any instrument has:
/// scale factor: from 1 ppm, the scale-factor stability of navigation-grade sensors;
inline constexpr Range kScaleFactorSigma{1.0e-6, 0.05, false, "(ratio)"};
/// misalignment: from 1 urad (0.2 arcsec), below any IMU's mounting accuracy (~10 urad);
inline constexpr Range kMisalignmentSigmaRad{1.0e-6, 0.05, false, "rad"};
/// lever-arm error: from 0.1 mm, as a position sigma;
inline constexpr Range kLeverArmErrorSigmaM{1.0e-4, 10.0, false, "m"};
/// IMU-GNSS time offset: from 100 ns, one tick of a rawlog's time stamps (MRPT's clock).
inline constexpr Range kTimeOffsetSigmaS{1.0e-7, 0.1, false, "s"};
// Sigmas of the IMU at rest (replay imu_at_rest, the static detector): below
// the per-sample noise of a navigation-grade IMU sampled at 1 Hz
// (ARW 0.001 deg/sqrt(h) = 2.9e-7 rad/s, VRW 0.002 m/s/sqrt(h) = 3.3e-5 m/s^2).
inline constexpr Range kAtRestGyroSigmaRadS{1.0e-7, 1000.0, false, "rad/s"};
inline constexpr Range kAtRestAccSigmaMps2{1.0e-6, 1.0e5, false, "m/s^2"};

/// Most Monte Carlo runs of one study (monte_carlo.runs).
inline constexpr long long kMaxMonteCarloRuns = 1000000;

/// Most GNSS outages of one run (a replay's outages_every over a long log with
/// a short period: 1e-4 s periods over 40 s made 4e5 windows).
inline constexpr long long kMaxOutagesPerRun = 1000000;

/// Most IMU error states of one sensor axis in the filter.
inline constexpr int kMaxImuStatesPerAxis = 32;
/// Most process terms of one model (one axis of a model file): a model has a
/// handful, and every term costs a simulated stream (300,000 WN terms made
/// emulate hold 2.5 GB).
inline constexpr int kMaxTermsPerModel = 32;

/// Default work budget of one covariance command, in estimated floating-point
/// operations summed over its models (analysis::estimateCovarianceBudget):
/// about an hour of one core (2.4e9 estimated operations per second measured
/// on a 2-core build machine: a 48 h static run at 200 Hz with a 24-state model
/// is 9.8e11, about 7 minutes).
inline constexpr double kDefaultWorkBudget = 1.0e13;
/// Default work budget of one run diagnosis's simulation, in IMU steps summed
/// over its realisations' emulations and filter runs: about an hour of one core
/// (0.5-2.5 us per step). The defaults on a 600 s run at 200 Hz with three
/// durations: 50 x 1.2e5 x 7 = 4.2e7.
inline constexpr double kDefaultFilterStepBudget = 2.0e9;
/// Default work budget of the model simulations of one static diagnosis, in
/// simulated samples over channels and simulations (simulation and wavelet
/// variance ~50-100 ns per sample: about half an hour of one core). The
/// defaults on a 2.8 h record at 100 Hz: 8 x 6 x 1e6 = 4.8e7.
inline constexpr double kDefaultSimulatedSampleBudget = 2.0e10;
/// Default memory budget of the results a run holds [bytes].
inline constexpr double kDefaultMemoryBudgetBytes = 2.0e9;

/**
 * One estimate of a run's work or memory, made before the run starts, with its
 * budget (README "Ranges and budgets").
 */
struct BudgetEstimate {
  std::string place;   ///< what sizes it: keyPlace(file, key) or "COMMAND: --flag VALUE"
  std::string what;    ///< what needs it: "the simulation", "the results"
  double need = 0.0;   ///< the estimate, in @ref unit
  double budget = 0.0; ///< its budget, in @ref unit
  std::string unit;    ///< "IMU steps", "MB", "floating-point operations"
  std::string how;     ///< how it is counted (may be empty): "50 realisations x 1.2e5 samples x 7 passes"
  std::string remedy;  ///< what the user can lower: "lower --realisations or --durations"
};

/**
 * The one budget check of every command: unless @p allow_large, throws for the
 * first estimate above its budget
 *   "PLACE: WHAT would need about NEED UNIT (HOW), above the budget of BUDGET UNIT: REMEDY, or pass --allow-large".
 */
void checkBudget(const std::initializer_list<BudgetEstimate>& estimates, bool allow_large);

/**
 * The one rule for "all cores" within the memory budget: as many workers as
 *   floor((kDefaultMemoryBudgetBytes / n - fixed) / per_worker)
 * bytes per sample allow, at most @p most and at least one, for a run holding
 * @p samples samples of @p fixed_bytes_per_sample shared and
 * @p worker_bytes_per_sample per worker (README "Ranges and budgets").
 */
unsigned budgetWorkers(double most, double samples, double fixed_bytes_per_sample, double worker_bytes_per_sample);

/// Fewest bootstrap resamples or replicates: a 95 % percentile interval needs
/// (B + 1) * 0.025 >= 1 so that its ends are order statistics inside the
/// resamples (Davison & Hinkley 1997, section 5.2.2: B = 39 is the smallest).
inline constexpr int kMinBootstrap = 39;

/// Text of a range, e.g. "(0, 1e+04] m".
std::string describe(const Range& r);

/// @p v if it lies in @p r; else throws keyError(file, key, "must be in RANGE, got V").
double check(const std::string& file, const std::string& key, double v, const Range& r);

}  // namespace navimpact::limits
