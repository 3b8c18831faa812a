/**
 * @file pspline.hpp
 * @brief Penalised regression spline (P-spline, Eilers & Marx 1996): uniform
 *        B-splines of degree 5 with a difference penalty on the coefficients,
 *        evaluated analytically (value, 1st, 2nd derivative) at any time.
 *
 * Why this smoother: the truth of an emulation must be smooth enough to be
 * differentiated twice (specific force needs acceleration), and the recorded
 * trajectories are noisy and quantised. A degree-5 P-spline is C^4, so the
 * acceleration is C^2 and the jerk C^1: a strapdown mechanization fed with
 * its exact increments has nothing discontinuous to trip on. The penalty on
 * d-th differences makes the fit, for a sampled sinusoid of frequency f well
 * below the knot rate, a Butterworth-like low-pass of order d:
 *   gain(f) ~ 1 / (1 + (f / f_c)^(2d)),
 * with lambda = n_pk / (2 sin(pi f_c h))^(2d), n_pk the mean number of samples
 * per knot interval h (Eilers & Marx 1996, sec. 8; the Whittaker smoother
 * transfer function). The smoothing is thus chosen by a physical cutoff
 * frequency f_c [Hz]. Polynomials of degree < d are reproduced exactly (the
 * penalty's null space), so a constant attitude or a constant-acceleration
 * track is not biased at all.
 */
#pragma once

#include <array>
#include <string>
#include <cstddef>
#include <vector>

namespace navimpact::emulation {

/// Options of a P-spline fit.
/// Bounds of cutoff_hz * knot_step_s: above 1/4 the knots cannot resolve the
/// cutoff; below 2e-4 the penalty weight lambda (about (2 pi f_c h)^(-2d) times
/// the samples per knot) makes the banded normal equations numerically
/// singular (measured: 1.5e-4 still solves on the bundled UAV trajectory with
/// d = 3, 5e-5 does not).
inline constexpr double kMaxCutoffTimesKnotStep = 0.25;
inline constexpr double kMinCutoffTimesKnotStep = 2.0e-4;

/// Most knot intervals of one spline, per sample and in all (about 350 bytes
/// each: 5e6 is about 2 GB, the default memory budget).
inline constexpr double kMaxKnotIntervalsPerSample = 64.0;
inline constexpr double kMaxKnotIntervals = 5.0e6;

/// Empty when the cutoff [Hz] and knot step [s] can be used together, else why not.
std::string checkSmoothing(double cutoff_hz, double knot_step_s);

struct PSplineOptions {
  double cutoff_hz = 1.0;    ///< -6 dB frequency of the smoother [Hz], > 0
  double knot_step_s = 0.05; ///< knot spacing h [s], > 0; must resolve f_c (h <= 1/(4 f_c))
  int penalty_order = 3;     ///< d, order of the coefficient differences, 1..4
};

/**
 * Several channels fitted on the same sample times with the same smoothing,
 * stored per knot interval as degree-5 polynomials in the local coordinate.
 */
class PSpline {
 public:
  static constexpr int kDegree = 5;

  PSpline() = default;

  /**
   * Fit @p channels (each of size t.size()) sampled at times @p t.
   * @param[in] t        strictly increasing sample times [s], at least 8 samples.
   * @param[in] channels values, one vector per channel (any unit).
   * @param[in] opt      smoothing options.
   * @throws navimpact::Error on invalid options or too few samples.
   */
  PSpline(const std::vector<double>& t, const std::vector<std::vector<double>>& channels,
          const PSplineOptions& opt);

  /// Number of channels.
  std::size_t channels() const { return nch_; }
  double tBegin() const { return a_; }
  double tEnd() const { return a_ + h_ * static_cast<double>(nseg_); }
  double knotStep() const { return h_; }
  /// Smoothing parameter lambda actually used.
  double lambda() const { return lambda_; }

  /**
   * Value and derivatives of channel @p c at time @p t (clamped to the fitted span).
   * @param[out] v    value; @param[out] d1 first derivative [unit/s];
   * @param[out] d2   second derivative [unit/s^2]. Null pointers are skipped.
   */
  void eval(std::size_t c, double t, double* v, double* d1, double* d2) const;

  /// Times of the knots strictly inside (t0, t1), for splitting integrals.
  void knotsInside(double t0, double t1, std::vector<double>& out) const;

 private:
  double a_ = 0.0, h_ = 1.0, lambda_ = 0.0;
  std::size_t nseg_ = 0, nch_ = 0;
  // poly_[(c * nseg_ + s) * 6 + k]: coefficient of u^k on segment s.
  std::vector<double> poly_;
};

}  // namespace navimpact::emulation
