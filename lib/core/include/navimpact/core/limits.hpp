/**
 * @file limits.hpp
 * @brief Documented physical ranges of configuration values, and the work and
 *        memory budgets of a run: limits as validation, checked when a value is
 *        loaded (with the file and key named), not left to luck at run time.
 *
 * The ranges are wide (beyond any real sensor or mission) but finite, so that
 * no single value can make a run spin, overflow or exhaust memory:
 *  - IMU rate 1 Hz - 10 kHz; aiding and output rates (GNSS, barometer, ground
 *    truth, records) 0.001 Hz - 10 kHz;
 *  - position and altitude sigmas (0, 10 km]; velocity sigmas (0, 1 km/s];
 *  - lever-arm components [-100, 100] m;
 *  - durations (0, 7 days]; times on a file's axis [-1e10, 1e10] s;
 *  - origins: latitude [-90, 90] deg, longitude [-360, 360] deg, height
 *    [-11 km, 100 km]; smoother cut-offs (0, 10 kHz];
 *  - IMU error states per axis at most 32 (a model has a handful);
 *  - Monte Carlo runs of a study at most 10^6;
 *  - sensor effects of an emulation and the extra filter states that model
 *    them (emulation::SensorEffects): scale factors [-0.05, 0.05] (ratio,
 *    +-50 000 ppm), misalignment and non-orthogonality angles [-0.05, 0.05] rad,
 *    IMU-GNSS time offset [-0.1, 0.1] s, lever-arm error components [-10, 10] m,
 *    in-motion white-noise factor [1, 100], motion thresholds
 *    [1e-3, 10] rad/s and [0.05, 100] m/s^2.
 * README ("Ranges and budgets") lists them with the budgets.
 */
#pragma once

#include <cstdint>
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
inline constexpr Range kPositionSigmaM{0.0, 1.0e4, true, "m"};
inline constexpr Range kVelocitySigmaMps{0.0, 1.0e3, true, "m/s"};
inline constexpr Range kLeverArmM{-100.0, 100.0, false, "m"};
inline constexpr Range kDurationS{0.0, 7.0 * 86400.0, true, "s"};
/// A time on a file's own axis (trajectory start_s/end_s: file time, e.g. Unix seconds) [s].
inline constexpr Range kFileTimeS{-1.0e10, 1.0e10, false, "s"};
/// Geodetic latitude, longitude and height of an origin [deg, deg, m].
inline constexpr Range kLatitudeDeg{-90.0, 90.0, false, "deg"};
inline constexpr Range kLongitudeDeg{-360.0, 360.0, false, "deg"};
inline constexpr Range kHeightM{-1.1e4, 1.0e5, false, "m"};
/// Cut-off frequency of a smoother [Hz].
inline constexpr Range kCutoffHz{0.0, 1.0e4, true, "Hz"};

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
// bounds as the effects they estimate, open at 0 (a state is off by leaving it out).
inline constexpr Range kScaleFactorSigma{0.0, 0.05, true, "(ratio)"};
inline constexpr Range kMisalignmentSigmaRad{0.0, 0.05, true, "rad"};
inline constexpr Range kLeverArmErrorSigmaM{0.0, 10.0, true, "m"};
inline constexpr Range kTimeOffsetSigmaS{0.0, 0.1, true, "s"};

/// Most Monte Carlo runs of one study (monte_carlo.runs).
inline constexpr long long kMaxMonteCarloRuns = 1000000;

/// Most IMU error states of one sensor axis in the filter.
inline constexpr int kMaxImuStatesPerAxis = 32;

/// Default work budget of one covariance command, in estimated floating-point
/// operations summed over its models (analysis::estimateCovarianceBudget):
/// about an hour of one core (2.4e9 estimated operations per second measured
/// on a 2-core build machine: a 48 h static run at 200 Hz with a 24-state model
/// is 9.8e11, about 7 minutes).
inline constexpr double kDefaultWorkBudget = 1.0e13;
/// Default memory budget of the results a run holds [bytes].
inline constexpr double kDefaultMemoryBudgetBytes = 2.0e9;

/// Text of a range, e.g. "(0, 1e+04] m".
std::string describe(const Range& r);

/// @p v if it lies in @p r; else throws keyError(file, key, "must be in RANGE, got V").
double check(const std::string& file, const std::string& key, double v, const Range& r);

}  // namespace navimpact::limits
