/**
 * @file scoring.hpp
 * @brief A navigation run scored against a reference: errors along the run
 *        over the GNSS-aided time, and per GNSS outage the error at its end,
 *        the maximum drift, the predicted sigma and the position NEES with its
 *        chi-square band; the distribution over many outages (median, 95th
 *        percentile, coverage of the 1/2/3-sigma predictions).
 *
 * Data only (the report layer writes): reusable from code, e.g. by a run
 * diagnosis that compares predicted and measured outage errors.
 *
 * Conventions: errors are estimate minus reference, position in metres N, E,
 * D; times in seconds from replay time zero unless named otherwise.
 *
 * The reference's own uncertainty (1-sigma horizontal per axis, vertical) is
 * counted where the filter's prediction is compared with the measured error:
 * the measured error is e = e_filter - e_ref, so with independent errors its
 * covariance is P_pos + R_ref, R_ref = diag(s_h^2, s_h^2, s_v^2).
 *  - position NEES at an outage end: e' (P_pos + R_ref)^-1 e, chi-square with
 *    3 dof when the prediction is right (Bar-Shalom et al. 2001 §5.4); its
 *    two-sided 95 % band [chi2_3(0.025), chi2_3(0.975)] = [0.216, 9.35];
 *    the mean over K outages is chi2_3K / K: band [chi2_3K(0.025), chi2_3K(0.975)] / K;
 *  - coverage: the 3K per-axis normalised end errors e_i / sqrt(P_ii + R_ii)
 *    inside +-1, 2, 3 sigma, against 68.27, 95.45, 99.73 % for a Gaussian.
 */
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "navimpact/analysis/nav_run.hpp"

namespace navimpact::analysis {

/// What is known about the reference.
struct ReferenceInfo {
  double sigma_h_m = 0.0;       ///< its own 1-sigma per horizontal axis [m], >= 0
  double sigma_v_m = 0.0;       ///< its own vertical 1-sigma [m], >= 0
  bool has_velocity = true;     ///< velocity errors are meaningful
  bool has_attitude = true;     ///< attitude errors are meaningful
};

/// One outage scored at its end.
struct OutageScore {
  double start_s = 0.0, duration_s = 0.0;  ///< the outage, from time zero [s]
  double end_s = 0.0;                      ///< reference epoch used as its end [s] (the last one <= end)
  Eigen::Vector3d err_N = Eigen::Vector3d::Zero();    ///< position error at the end, N E D [m]
  Eigen::Vector3d sigma_N = Eigen::Vector3d::Zero();  ///< filter's predicted 1-sigma, N E D [m]
  double horizontal_error_m = 0.0;         ///< |err_N, err_E| at the end [m]
  double vertical_error_m = 0.0;           ///< |err_D| at the end [m]
  double horizontal_sigma_m = 0.0;         ///< sqrt(P_NN + P_EE), the filter's [m]
  double vertical_sigma_m = 0.0;           ///< sqrt(P_DD) [m]
  double max_drift_h_m = 0.0;              ///< max horizontal error inside the outage [m]
  double max_drift_v_m = 0.0;              ///< max |vertical error| inside the outage [m]
  double nees = 0.0;                       ///< position NEES at the end (reference sigma counted), 3 dof
  bool nees_in_band = false;               ///< inside the two-sided 95 % chi-square(3) band
};

/// Distribution over the scored outages.
struct OutageDistribution {
  std::size_t count = 0;
  double median_h_m = 0.0, p95_h_m = 0.0;  ///< horizontal error at the end [m]
  double median_v_m = 0.0, p95_v_m = 0.0;  ///< vertical error at the end [m]
  std::array<double, 3> coverage{};        ///< fraction of per-axis normalised errors within 1, 2, 3 sigma
  std::array<double, 3> coverage_expected{};  ///< Gaussian: 0.6827, 0.9545, 0.9973
  double mean_nees = 0.0;                  ///< mean position NEES
  double mean_nees_lo = 0.0, mean_nees_hi = 0.0;  ///< its 95 % band chi2_3K / K
  std::size_t nees_in_band = 0;            ///< outages whose NEES is in the per-outage band
  double nees_band_lo = 0.0, nees_band_hi = 0.0;  ///< the per-outage band (chi-square 3 dof, 95 %)
};

/// A run scored against its reference.
struct RunScore {
  ReferenceInfo reference;
  std::size_t aided_epochs = 0;            ///< reference epochs with GNSS (outside outages, after aided_from)
  double horizontal_rms_m = 0.0, vertical_rms_m = 0.0;  ///< position error RMS over them [m]
  double velocity_rms_mps = 0.0;           ///< 3-D velocity error RMS [m/s] (NaN without reference velocity)
  Eigen::Vector3d attitude_rms_rad = Eigen::Vector3d::Zero();  ///< psi N, E, D RMS [rad] (NaN without reference attitude)
  std::vector<OutageScore> outages;        ///< one per outage with a reference epoch inside
  std::vector<std::size_t> unscored;       ///< indices of outages without a reference epoch inside
  OutageDistribution distribution;
};

/// Linear-interpolated percentile (Hyndman & Fan type 7) of @p v, q in [0, 1]; NaN when empty.
double percentile(std::vector<double> v, double q);

/**
 * Score a run that has a reference (run.has_truth).
 * @param[in] run          the run (epochs with errors and position covariance).
 * @param[in] t_zero       filter time of replay time zero [s] (scores are reported from it).
 * @param[in] aided_from   filter time from which the GNSS-aided statistics count [s]
 *                         (the end of an aligning phase).
 * @param[in] ref          the reference's uncertainty and content.
 * @throws navimpact::Error when the run has no reference or a reference sigma is negative.
 */
RunScore scoreRun(const NavRunResult& run, double t_zero, double aided_from, const ReferenceInfo& ref);

/// scoreRun() fed epoch by epoch, for a run whose epochs are not kept
/// (NavRunner::keep_epochs false): the same numbers in the same order.
class RunScorer {
 public:
  /// @param aided_from  as scoreRun().
  explicit RunScorer(double aided_from) : aided_from_(aided_from) {}
  /// One epoch, with the outages known so far (every outage containing it).
  void add(const NavEpoch& e, const std::vector<Outage>& outages);
  /// The score (outages from run.outages: OutageSummary::end and the drifts) with
  /// the reference's uncertainty and content @p ref (known once it was all read).
  /// @throws navimpact::Error as scoreRun().
  RunScore finish(const NavRunResult& run, double t_zero, const ReferenceInfo& ref) const;

 private:
  double aided_from_;
  std::size_t aided_epochs_ = 0;
  double sh_ = 0.0, sv_ = 0.0, svel_ = 0.0;
  Eigen::Vector3d satt_ = Eigen::Vector3d::Zero();
};

}  // namespace navimpact::analysis
