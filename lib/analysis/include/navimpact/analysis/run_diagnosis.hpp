/**
 * @file run_diagnosis.hpp
 * @brief What the simulation gets wrong on a real run: measured outage errors
 *        of a replayed rawlog against the distribution the simulation with
 *        the IMU model predicts for the same trajectory, filter and outages.
 *
 * Data only (lib/report writes run_diagnosis.json, report.md and figures).
 *
 * Measured: for each outage duration D the rawlog is replayed (analysis/replay.hpp)
 * with outages laid all along the run as `replay --outages-every P:D` does,
 * P = D + reconverge_s (reconverge_s of GNSS before each outage), and scored
 * against the reference (analysis/scoring.hpp): per outage the error at its end
 * (the last reference epoch <= end), the filter's predicted sigma, the NEES.
 *
 * Simulated: the trajectory of the run, smoothed as the emulation does
 * (emulation::SmoothTrajectory, P-splines), is
 *  - the reference itself when it has velocity and attitude at most 0.25 s apart;
 *  - else the GNSS-aided filter solution of the run without outages, recorded
 *    every 0.1 s (a position-only reference such as an RTK track carries no
 *    attitude); its position is the RTK-aided estimate.
 * Each realisation r = 0..R-1 (seed deriveSeed(seed, r), the same for every
 * duration) adds to the perfect IMU increments of that trajectory the model's
 * simulated errors (emulation::modelImuErrors) or a window of the --static
 * recording (emulation::staticImuErrors, window start from the seed), GNSS fixes
 * at the run's own fix times with the run's own covariances (and velocity where
 * the run's fixes have one), barometer samples likewise, an initial error drawn
 * from the filter's initial covariance; and runs the SAME filter (the replay's
 * NavRunOptions: propagation, gate, aids, lever arm) over the same outages.
 *
 * Comparison per quantity (horizontal position, vertical position; velocity
 * and attitude when the reference has them) and duration, at the outage ends:
 *   ratio = sqrt(mean measured e^2 / mean predicted e^2), the predicted mean
 *   square including the reference's own variance (2 s_h^2 horizontal, s_v^2
 *   vertical). With Gaussian zero-mean errors the statistic
 *   F = (SS_m / (d K)) / (SS_p / (d M)) follows F(d K, d M) when the
 *   simulation is right (d components per outage: 2 horizontal, 1 vertical,
 *   3 velocity, 3 attitude; K measured outages, M = R x outages simulated);
 *   the two-sided p-value and the (1 - alpha/m) interval of the ratio,
 *   sqrt(F / F_{1-a/2}), sqrt(F / F_{a/2}), a = alpha / m, come from it.
 *   Caveat: outages of one run share the trajectory and the bias, so they are
 *   not independent; the interval counts them as if they were.
 * Measured NEES: mean position NEES over the K outages against the
 * chi-square(3K)/K band at the same level a.
 * Verdict: "inadequate" when any of the m tests (all comparisons and all NEES
 * bands) rejects at level a = alpha / m (Bonferroni), so the family-wise
 * false-alarm rate is at most alpha; else "adequate".
 */
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "navimpact/analysis/replay.hpp"
#include "navimpact/core/csv_reader.hpp"

namespace navimpact::analysis {

/// Options of a run diagnosis.
struct RunDiagnosisOptions {
  ReplayConfig replay;                        ///< rawlog, model and filter settings (as `replay --config`)
  std::vector<double> durations_s{10.0, 30.0, 60.0};  ///< outage durations [s], each > 0
  double reconverge_s = 30.0;                 ///< GNSS time before each outage [s], > 0
  int realisations = 50;                      ///< simulated realisations, >= 2
  std::uint64_t seed = 20261124;              ///< root seed of the simulation
  double alpha = 0.05;                        ///< family-wise false-alarm rate of the verdict, (0, 0.5)
  std::string static_file;                    ///< "" = the model's simulated errors; else a static recording (CSV)
  CsvImuOptions static_csv;                   ///< units, rate, axes of that recording
  int threads = 0;                            ///< worker threads (0 = hardware)
  /// Progress (fraction done 0..1, stage); may be empty.
  std::function<void(double, const std::string&)> progress;
};

/// Measured against predicted, one quantity at one outage duration.
struct QuantityComparison {
  std::string quantity;        ///< "horizontal_position", "vertical_position", "velocity", "attitude"
  std::string unit;            ///< "m", "m/s", "rad"
  double duration_s = 0.0;     ///< outage duration [s]
  int dof = 1;                 ///< error components per outage
  std::vector<double> measured;    ///< per measured outage: error magnitude at the end [unit]
  std::vector<double> predicted;   ///< per simulated outage (all realisations): magnitude [unit]
  double measured_rms = 0.0;       ///< sqrt(mean e^2) of the measured [unit]
  double predicted_rms = 0.0;      ///< the same of the simulated, reference variance added [unit]
  double predicted_p05 = 0.0, predicted_p50 = 0.0, predicted_p95 = 0.0;  ///< percentiles of the simulated magnitudes
  double ratio = 0.0;              ///< measured_rms / predicted_rms
  double ratio_lo = 0.0, ratio_hi = 0.0;  ///< its (1 - alpha/m) interval (F distribution)
  double p_value = 1.0;            ///< two-sided F test of equal variances
  bool rejects = false;            ///< p_value < alpha/m
};

/// One outage duration: the measured outages and the NEES test.
struct DurationDiagnosis {
  double duration_s = 0.0;
  double period_s = 0.0;                   ///< outage every period_s (duration + reconverge)
  std::vector<OutageScore> measured;       ///< the scored outages of the real run
  OutageDistribution distribution;         ///< their distribution (coverage, NEES)
  double anees = 0.0;                      ///< measured mean position NEES
  double anees_lo = 0.0, anees_hi = 0.0;   ///< its band chi2(3K)/K at level alpha/m
  bool anees_rejects = false;              ///< outside the band
  double predicted_anees = 0.0;            ///< mean position NEES of the simulated outages
  std::size_t simulated_outages = 0;       ///< realisations x outages
};

/// Everything a run diagnosis computed.
struct RunDiagnosis {
  std::string rawlog;
  std::string model_source;
  std::string errors_source;               ///< "model" description or the static recording
  std::string trajectory_source;           ///< how the emulated trajectory was made
  double imu_rate_hz = 0.0;
  double aided_from_s = 0.0;               ///< filter start of the real run, from time zero [s]
  double run_end_s = 0.0;                  ///< end of the IMU data, from time zero [s]
  ReferenceInfo reference;
  int realisations = 0;
  std::uint64_t seed = 0;
  double alpha = 0.0;
  double reconverge_s = 0.0;
  std::size_t tests = 0;                   ///< m, the tests of the verdict
  double test_level = 0.0;                 ///< alpha / m
  std::vector<DurationDiagnosis> durations;
  std::vector<QuantityComparison> comparisons;
  std::string verdict;                     ///< "adequate" or "inadequate"
  std::vector<std::string> reasons;        ///< the tests that rejected, in words
  std::vector<std::string> notices;
  double wall_s = 0.0;                     ///< wall-clock time [s]
};

/**
 * Diagnose a real run (see the file comment).
 * @throws navimpact::Error for a rawlog without reference, a duration that fits
 *         no outage in the run, invalid options, or errors of the replay.
 */
RunDiagnosis diagnoseRun(const RunDiagnosisOptions& opt);

}  // namespace navimpact::analysis
