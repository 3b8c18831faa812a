#include "navimpact/emulation/pspline.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"

namespace navimpact::emulation {

namespace {

constexpr int P = PSpline::kDegree;
using Poly = std::array<double, P + 1>;  // coefficients of u^0..u^P

/// Pieces of the cardinal B-spline of degree P on [k, k+1), k = 0..P, as
/// polynomials in u = x - k (Cox-de Boor recursion on integer knots).
std::array<Poly, P + 1> cardinalPieces() {
  std::array<Poly, P + 1> prev{}, cur{};
  prev[0][0] = 1.0;  // M_0 = 1 on [0,1)
  for (int q = 1; q <= P; ++q) {
    for (auto& c : cur) c.fill(0.0);
    for (int k = 0; k <= q; ++k) {
      // (k+u)/q * piece_k(M_{q-1})
      if (k <= q - 1)
        for (int m = 0; m < P; ++m) {
          cur[k][m] += prev[k][m] * k / q;
          cur[k][m + 1] += prev[k][m] / q;
        }
      // (q+1-k-u)/q * piece_{k-1}(M_{q-1})
      if (k >= 1)
        for (int m = 0; m < P; ++m) {
          cur[k][m] += prev[k - 1][m] * (q + 1 - k) / q;
          cur[k][m + 1] -= prev[k - 1][m] / q;
        }
    }
    prev = cur;
  }
  return prev;
}

/// Local basis N_j(u), j = 0..P, on one knot interval: N_j = piece_{P-j}.
const std::array<Poly, P + 1>& localBasis() {
  static const std::array<Poly, P + 1> basis = [] {
    const auto pieces = cardinalPieces();
    std::array<Poly, P + 1> b{};
    for (int j = 0; j <= P; ++j) b[j] = pieces[P - j];
    return b;
  }();
  return basis;
}

double horner(const Poly& c, double u) {
  double r = c[P];
  for (int k = P - 1; k >= 0; --k) r = r * u + c[k];
  return r;
}

}  // namespace

std::string checkSmoothing(double cutoff_hz, double knot_step_s) {
  if (!(cutoff_hz > 0.0) || !(knot_step_s > 0.0)) return "cutoff_hz and knot_step_s must be > 0";
  const double fh = cutoff_hz * knot_step_s;
  if (fh > kMaxCutoffTimesKnotStep)
    return "knot step " + formatNumber(knot_step_s, 6) + " s cannot resolve the cutoff " + formatNumber(cutoff_hz, 6) +
           " Hz (need knot_step_s <= 1/(4 cutoff_hz))";
  if (fh < kMinCutoffTimesKnotStep)
    return "cutoff " + formatNumber(cutoff_hz, 6) + " Hz times knot step " + formatNumber(knot_step_s, 6) + " s is " +
           formatNumber(fh, 3) + ", below " + formatNumber(kMinCutoffTimesKnotStep, 3) +
           ": the penalty (lambda ~ (2 pi f_c h)^(-2d)) makes the normal equations numerically singular; "
           "raise the cutoff or the knot step";
  return {};
}

PSpline::PSpline(const std::vector<double>& t, const std::vector<std::vector<double>>& channels,
                 const PSplineOptions& opt) {
  const std::size_t n = t.size();
  if (n < 8) throw Error("smoothing spline: needs at least 8 samples, got " + std::to_string(n));
  if (!(opt.cutoff_hz > 0.0) || !(opt.knot_step_s > 0.0))
    throw Error("smoothing spline: cutoff_hz and knot_step_s must be > 0");
  const std::string why = checkSmoothing(opt.cutoff_hz, opt.knot_step_s);
  if (!why.empty()) throw Error("smoothing spline: " + why);
  if (opt.penalty_order < 1 || opt.penalty_order > 4)
    throw Error("smoothing spline: penalty_order must be 1..4");
  nch_ = channels.size();
  for (const auto& ch : channels)
    if (ch.size() != n) throw Error("smoothing spline: channel size differs from time size");

  a_ = t.front();
  h_ = opt.knot_step_s;
  const double span = t.back() - t.front();
  // Bounded memory whatever the knot step (about 350 bytes per knot interval
  // measured): knots far finer than the samples add nothing but memory.
  const double segments = std::max(1.0, std::ceil(span / h_ - 1e-9));
  if (!(segments <= kMaxKnotIntervalsPerSample * static_cast<double>(n) && segments <= kMaxKnotIntervals))
    throw Error("smoothing spline: knot step " + formatNumber(h_, 6) + " s gives " + formatNumber(segments, 6) +
                " knot intervals for " + std::to_string(n) + " samples (at most " +
                formatNumber(kMaxKnotIntervalsPerSample, 3) + " per sample and " + formatNumber(kMaxKnotIntervals, 3) +
                " in all: use a larger knot step)");
  nseg_ = static_cast<std::size_t>(segments);
  const std::size_t K = nseg_ + P;  // number of coefficients
  const auto& basis = localBasis();

  // Normal equations, lower band: A[i*(P+1) + k] = A(i, i-k).
  std::vector<double> A(K * (P + 1), 0.0);
  std::vector<double> rhs(K * nch_, 0.0);
  auto band = [&](std::size_t i, std::size_t j) -> double& { return A[i * (P + 1) + (i - j)]; };
  // Remove each channel's chord (line through its first and last sample) before
  // fitting and add it back exactly afterwards: a line is in the penalty's null
  // space, and the smaller dynamic range keeps the banded solve accurate.
  std::vector<double> c0(nch_), c1(nch_);
  for (std::size_t c = 0; c < nch_; ++c) {
    c0[c] = channels[c].front();
    c1[c] = span > 0.0 ? (channels[c].back() - channels[c].front()) / span : 0.0;
  }
  for (std::size_t i = 0; i < n; ++i) {
    double x = (t[i] - a_) / h_;
    std::size_t s = static_cast<std::size_t>(std::clamp(std::floor(x), 0.0, double(nseg_ - 1)));
    const double u = x - double(s);
    double b[P + 1];
    for (int j = 0; j <= P; ++j) b[j] = horner(basis[j], u);
    for (int j = 0; j <= P; ++j) {
      for (int k = 0; k <= j; ++k) band(s + j, s + k) += b[j] * b[k];
      for (std::size_t c = 0; c < nch_; ++c) rhs[c * K + s + j] += b[j] * (channels[c][i] - c0[c] - c1[c] * (t[i] - a_));
    }
  }
  // Difference penalty lambda * D'D (Eilers & Marx 1996 eq. 8), lambda from the cutoff.
  const int d = opt.penalty_order;
  const double npk = double(n) / double(nseg_);
  lambda_ = npk / std::pow(2.0 * std::sin(M_PI * opt.cutoff_hz * h_), 2 * d);
  std::vector<double> w(d + 1);
  for (int m = 0; m <= d; ++m) {
    double binom = 1.0;
    for (int r = 0; r < m; ++r) binom = binom * (d - r) / (r + 1);
    w[m] = ((d - m) % 2 ? -1.0 : 1.0) * binom;
  }
  for (std::size_t r = 0; r + d < K; ++r)
    for (int j = 0; j <= d; ++j)
      for (int k = 0; k <= j; ++k) band(r + j, r + k) += lambda_ * w[j] * w[k];

  // Banded Cholesky A = L L' in place.
  for (std::size_t i = 0; i < K; ++i) {
    const std::size_t j0 = i >= std::size_t(P) ? i - P : 0;
    for (std::size_t j = j0; j <= i; ++j) {
      double sum = band(i, j);
      const std::size_t k0 = std::max(j0, j >= std::size_t(P) ? j - P : 0);
      for (std::size_t k = k0; k < j; ++k) sum -= band(i, k) * band(j, k);
      if (j == i) {
        if (!(sum > 0.0)) throw Error("smoothing spline: normal equations not positive definite");
        band(i, i) = std::sqrt(sum);
      } else {
        band(i, j) = sum / band(j, j);
      }
    }
  }
  std::vector<double> coef(K);
  poly_.assign(nch_ * nseg_ * (P + 1), 0.0);
  for (std::size_t c = 0; c < nch_; ++c) {
    double* y = &rhs[c * K];
    for (std::size_t i = 0; i < K; ++i) {  // forward L z = y
      const std::size_t j0 = i >= std::size_t(P) ? i - P : 0;
      double sum = y[i];
      for (std::size_t j = j0; j < i; ++j) sum -= band(i, j) * y[j];
      y[i] = sum / band(i, i);
    }
    for (std::size_t ii = K; ii-- > 0;) {  // backward L' x = z
      double sum = y[ii];
      for (std::size_t j = ii + 1; j < std::min(K, ii + P + 1); ++j) sum -= band(j, ii) * coef[j];
      coef[ii] = sum / band(ii, ii);
    }
    for (std::size_t s = 0; s < nseg_; ++s) {
      double* out = &poly_[(c * nseg_ + s) * (P + 1)];
      for (int j = 0; j <= P; ++j)
        for (int k = 0; k <= P; ++k) out[k] += coef[s + j] * basis[j][k];
      out[0] += c0[c] + c1[c] * h_ * double(s);
      out[1] += c1[c] * h_;
    }
  }
}

void PSpline::eval(std::size_t c, double t, double* v, double* d1, double* d2) const {
  double x = (t - a_) / h_;
  x = std::clamp(x, 0.0, double(nseg_));
  std::size_t s = std::min(static_cast<std::size_t>(x), nseg_ - 1);
  const double u = x - double(s);
  const double* p = &poly_[(c * nseg_ + s) * (P + 1)];
  if (v) {
    double r = p[P];
    for (int k = P - 1; k >= 0; --k) r = r * u + p[k];
    *v = r;
  }
  if (d1) {
    double r = P * p[P];
    for (int k = P - 1; k >= 1; --k) r = r * u + k * p[k];
    *d1 = r / h_;
  }
  if (d2) {
    double r = P * (P - 1) * p[P];
    for (int k = P - 1; k >= 2; --k) r = r * u + k * (k - 1) * p[k];
    *d2 = r / (h_ * h_);
  }
}

void PSpline::knotsInside(double t0, double t1, std::vector<double>& out) const {
  out.clear();
  const double tol = 1e-9;
  double k = std::floor((t0 - a_) / h_) + 1.0;
  for (;; k += 1.0) {
    const double tk = a_ + k * h_;
    if (tk >= t1 - tol) break;
    if (tk > t0 + tol && k > 0.0 && k < double(nseg_)) out.push_back(tk);
  }
}

}  // namespace navimpact::emulation
