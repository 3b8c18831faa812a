// Welch periodogram and narrow-band line detection: what the Haar WV smears out.
#include <algorithm>
#include <cmath>
#include <complex>

#include <boost/math/distributions/chi_squared.hpp>
#include <Eigen/Dense>
#include <unsupported/Eigen/FFT>

#include "navimpact/analysis/diagnosis.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/units.hpp"

namespace navimpact::analysis {

namespace {

constexpr double kTwoPi = 2.0 * units::kPi;
constexpr double kPi() { return units::kPi; }

/// Least-squares a + b sin + c cos at f; returns amplitude, subtracts b sin + c cos if asked.
/// sin/cos by a rotation recurrence, re-seeded exactly every 1024 samples.
double fitSinusoid(std::vector<double>& x, double f, double fs, bool subtract) {
  const std::size_t n = x.size();
  // Normal equations of [1, sin, cos] (3x3), accumulated in long double.
  long double S[3][3] = {{0}}, r[3] = {0};
  const double w = kTwoPi * f / fs;
  const std::complex<double> rot(std::cos(w), std::sin(w));
  auto phasor = [&](std::size_t k) {
    const double a = w * static_cast<double>(k);
    return std::complex<double>(std::cos(a), std::sin(a));
  };
  std::complex<double> ph(1.0, 0.0);
  for (std::size_t k = 0; k < n; ++k) {
    if ((k & 1023) == 0) ph = phasor(k);
    const double v[3] = {1.0, ph.imag(), ph.real()};
    for (int i = 0; i < 3; ++i) {
      r[i] += v[i] * x[k];
      for (int j = i; j < 3; ++j) S[i][j] += v[i] * v[j];
    }
    ph *= rot;
  }
  Eigen::Matrix3d A;
  Eigen::Vector3d b;
  for (int i = 0; i < 3; ++i) {
    b(i) = static_cast<double>(r[i]);
    for (int j = i; j < 3; ++j) A(i, j) = A(j, i) = static_cast<double>(S[i][j]);
  }
  const Eigen::Vector3d c = A.ldlt().solve(b);
  if (subtract) {
    ph = std::complex<double>(1.0, 0.0);
    for (std::size_t k = 0; k < n; ++k) {
      if ((k & 1023) == 0) ph = phasor(k);
      x[k] -= c(1) * ph.imag() + c(2) * ph.real();
      ph *= rot;
    }
  }
  return std::hypot(c(1), c(2));
}

/// Zoomed DFT around f0: the record demodulated at f0 once and summed in
/// blocks of B samples (z_k, block centre c_k), so that the power at
/// f0 + delta is |sum_k z_k e^{-i 2 pi delta c_k / fs}|^2 up to a phase error
/// of at most pi |delta| B / fs inside a block (kept below 0.01 rad by the caller).
struct Demodulated {
  std::vector<std::complex<double>> z;
  std::vector<double> centre;  ///< sample index of each block centre
};

Demodulated demodulate(const std::vector<double>& x, double mean, double f0, double fs, std::size_t B) {
  Demodulated d;
  const std::size_t n = x.size();
  const double w = kTwoPi * f0 / fs;
  const std::complex<double> rot(std::cos(w), -std::sin(w));
  for (std::size_t k0 = 0; k0 < n; k0 += B) {
    const std::size_t k1 = std::min(n, k0 + B);
    const double a = w * static_cast<double>(k0);
    std::complex<double> ph(std::cos(a), -std::sin(a)), acc(0.0, 0.0);
    for (std::size_t k = k0; k < k1; ++k) {
      acc += (x[k] - mean) * ph;
      ph *= rot;
    }
    d.z.push_back(acc);
    d.centre.push_back(0.5 * static_cast<double>(k0 + k1 - 1));
  }
  return d;
}

double zoomPower(const Demodulated& d, double delta, double fs) {
  const double w = kTwoPi * delta / fs;
  std::complex<double> acc(0.0, 0.0);
  for (std::size_t k = 0; k < d.z.size(); ++k) {
    const double a = w * d.centre[k];
    acc += d.z[k] * std::complex<double>(std::cos(a), -std::sin(a));
  }
  return std::norm(acc);
}

/// Equivalent dof of a Welch estimate with K Hann segments at 50 % overlap
/// (Percival & Walden 1993, eq. 292b; squared window overlap 0.167^2).
double welchDof(int K) {
  if (K <= 1) return 2.0;
  const double rho2 = 0.167 * 0.167;
  return 2.0 * K / (1.0 + 2.0 * rho2 * (K - 1.0) / K);
}

}  // namespace

SpectrumCheck welch(const std::vector<double>& x, double rate_hz, int segment_length) {
  SpectrumCheck sp;
  const std::size_t n = x.size();
  const int L = segment_length;
  if (L < 16 || static_cast<std::size_t>(L) > n)
    throw Error("welch: segment length " + std::to_string(L) + " invalid for " +
                std::to_string(n) + " samples");
  const std::size_t hop = static_cast<std::size_t>(L) / 2;
  const int K = static_cast<int>((n - L) / hop + 1);
  std::vector<double> w(L);
  double U = 0;
  for (int i = 0; i < L; ++i) {
    w[i] = 0.5 * (1.0 - std::cos(kTwoPi * i / L));  // periodic Hann
    U += w[i] * w[i];
  }
  // Linear detrend design: t centred, so intercept and slope decouple.
  const double tc = 0.5 * (L - 1);
  double stt = 0;
  for (int i = 0; i < L; ++i) stt += (i - tc) * (i - tc);
  const int nb = L / 2 + 1;
  std::vector<double> acc(nb, 0.0);
  Eigen::FFT<double> fft;
  std::vector<double> seg(L);
  std::vector<std::complex<double>> spec;
  for (int s = 0; s < K; ++s) {
    const double* p = x.data() + s * hop;
    double m = 0, st = 0;
    for (int i = 0; i < L; ++i) {
      m += p[i];
      st += (i - tc) * p[i];
    }
    m /= L;
    const double slope = st / stt;
    for (int i = 0; i < L; ++i) seg[i] = (p[i] - m - slope * (i - tc)) * w[i];
    fft.fwd(spec, seg);
    for (int k = 0; k < nb; ++k) acc[k] += std::norm(spec[k]);
  }
  sp.freq_hz.resize(nb);
  sp.psd.resize(nb);
  for (int k = 0; k < nb; ++k) {
    const double one_sided = (k == 0 || k == L / 2) ? 1.0 : 2.0;
    sp.freq_hz[k] = k * rate_hz / L;
    sp.psd[k] = one_sided * acc[k] / (K * rate_hz * U);
  }
  sp.segments = K;
  sp.segment_length = L;
  sp.dof = welchDof(K);
  return sp;
}

std::vector<LineResult> detectLines(const std::vector<double>& x_in, double rate_hz,
                                    SpectrumCheck& spec, double alpha) {
  std::vector<LineResult> lines;
  const int L = spec.segment_length;
  const int nb = static_cast<int>(spec.psd.size());
  const double nu = spec.dof;
  // Background: running median over +-W bins, divided by the median of
  // chi2_nu / nu (Wilson-Hilferty: (1 - 2/(9 nu))^3) to estimate the mean.
  const int W = 25;
  const double med_factor = std::pow(1.0 - 2.0 / (9.0 * nu), 3.0);
  spec.background.assign(nb, 0.0);
  std::vector<double> win;
  for (int k = 0; k < nb; ++k) {
    const int lo = std::max(1, k - W), hi = std::min(nb - 1, k + W);
    win.assign(spec.psd.begin() + lo, spec.psd.begin() + hi + 1);
    auto mid = win.begin() + static_cast<std::ptrdiff_t>(win.size() / 2);
    std::nth_element(win.begin(), mid, win.end());
    spec.background[k] = *mid / med_factor;
  }
  spec.first_tested_bin = W + 1;
  spec.last_tested_bin = nb - 2;
  const int tested = std::max(1, spec.last_tested_bin - spec.first_tested_bin + 1);
  // Threshold on psd/background: chi2_nu / nu upper quantile at alpha / bins
  // (Bonferroni), widened for the noise of the median background (relative
  // sd ~ 1.25 sqrt(2/nu) / sqrt(W), counting adjacent Hann bins as half
  // independent), by four of its standard deviations.
  const double p = alpha / tested;
  const double q = boost::math::quantile(boost::math::complement(
                       boost::math::chi_squared(nu), p)) / nu;
  const double sd_bg = 1.25 * std::sqrt(2.0 / nu) / std::sqrt(static_cast<double>(W));
  spec.threshold_ratio = q * (1.0 + 4.0 * sd_bg);
  (void)x_in;
  (void)rate_hz;
  // Peaks: exceeding bins, each a local maximum of the ratio over +-3 bins.
  for (int k = spec.first_tested_bin; k <= spec.last_tested_bin; ++k) {
    const double r = spec.psd[k] / spec.background[k];
    if (!(r > spec.threshold_ratio)) continue;
    bool peak = true;
    for (int d = -3; d <= 3 && peak; ++d) {
      const int kk = k + d;
      if (d == 0 || kk < 1 || kk >= nb) continue;
      if (spec.psd[kk] > spec.psd[k]) peak = false;
    }
    if (!peak) continue;
    // Gaussian interpolation of the Hann main lobe on log power.
    double delta = 0;
    if (k > 0 && k + 1 < nb) {
      const double a = std::log(spec.psd[k - 1]), b = std::log(spec.psd[k]),
                   c = std::log(spec.psd[k + 1]);
      const double den = a - 2 * b + c;
      if (den < 0) delta = std::clamp(0.5 * (a - c) / den, -0.5, 0.5);
    }
    LineResult lr;
    lr.freq_hz = (k + delta) * rate_hz / L;
    lr.ratio = r;
    lines.push_back(lr);
  }
  return lines;
}

/// Refine a line on the whole record (zoomed DFT within +-0.15 Welch bins),
/// fit its amplitude by least squares and subtract it from @p x.
/// Declared in diagnosis_internal.hpp.
LineResult refineAndRemoveLine(std::vector<double>& x, double rate_hz, int segment_length,
                               const LineResult& coarse) {
  const std::size_t n = x.size();
  double mean = 0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(n);
  const double bin = rate_hz / segment_length;
  const double fine = rate_hz / (3.0 * static_cast<double>(n));
  const int D = std::max(2, static_cast<int>(std::ceil(0.15 * bin / fine)));
  double best_f = coarse.freq_hz, best_p = -1;
  std::vector<double> pw(2 * D + 1);
  // Block length: the phase error pi |delta| B / fs over the zoom range
  // |delta| <= D fine stays below 0.01 rad.
  const double dmax = (D + 1) * fine;
  std::size_t B = 1;
  while (B * 2 <= n / 64 && kPi() * dmax * static_cast<double>(B * 2) / rate_hz < 0.01) B *= 2;
  const Demodulated dm = demodulate(x, mean, coarse.freq_hz, rate_hz, B);
  for (int d = -D; d <= D; ++d) {
    const double f = coarse.freq_hz + d * fine;
    if (f <= 0 || f >= rate_hz / 2) {
      pw[d + D] = 0;
      continue;
    }
    pw[d + D] = zoomPower(dm, d * fine, rate_hz);
    if (pw[d + D] > best_p) {
      best_p = pw[d + D];
      best_f = f;
    }
  }
  // Parabolic interpolation around the fine maximum.
  const int i = static_cast<int>(std::lround((best_f - coarse.freq_hz) / fine)) + D;
  if (i > 0 && i < 2 * D) {
    const double a = pw[i - 1], b = pw[i], c = pw[i + 1];
    const double den = a - 2 * b + c;
    if (den < 0) best_f += std::clamp(0.5 * (a - c) / den, -0.5, 0.5) * fine;
  }
  LineResult out = coarse;
  out.freq_hz = best_f;
  out.amplitude = fitSinusoid(x, best_f, rate_hz, true);
  return out;
}

}  // namespace navimpact::analysis
