// Spectral line test against the null model's PSD (see lines.hpp).
#include "navimpact/detect/lines.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <string>

#include <Eigen/Dense>
#include <unsupported/Eigen/FFT>

#include "navimpact/core/error.hpp"
#include "robust.hpp"

namespace navimpact::detect {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kTwoPi = 2.0 * kPi;
using cplx = std::complex<double>;

/// Smallest 2^a 3^b 5^c 7^d >= n (fast sizes for the mixed-radix FFT).
std::size_t fastSize(std::size_t n) {
  for (std::size_t m = n;; ++m) {
    std::size_t r = m;
    for (std::size_t p : {2u, 3u, 5u, 7u})
      while (r % p == 0) r /= p;
    if (r == 1) return m;
  }
}

/// Squared magnitude of the Hann window's transform at nu bins from its centre,
/// normalised to unit integral over nu (|W| ~ sinc(nu) / (1 - nu^2)).
double hannKernel(double nu) {
  const double a = std::abs(nu);
  double s;
  if (a < 1e-9) s = 1.0;
  else if (std::abs(a - 1.0) < 1e-9) s = 0.5;
  else s = std::sin(kPi * a) / (kPi * a) / (1.0 - a * a);
  return s * s / 0.375;  // integral of (sinc/(1-nu^2))^2 = 3/8
}

/// sum_{t<n} e^{i theta t}.
cplx geomSum(double theta, std::size_t n) {
  const double h = 0.5 * theta;
  const double sh = std::sin(h);
  if (std::abs(sh) < 1e-12) return cplx(static_cast<double>(n), 0.0);
  const double nn = static_cast<double>(n);
  return std::polar(std::sin(nn * h) / sh, h * (nn - 1.0));
}

/// Hann-tapered (periodic, length n) transform sum_t w_t e^{i theta t}.
cplx hannSum(double theta, std::size_t n) {
  const double d = kTwoPi / static_cast<double>(n);
  return 0.5 * geomSum(theta, n) - 0.25 * geomSum(theta + d, n) - 0.25 * geomSum(theta - d, n);
}

/// Least-squares mean + b sin + c cos at f over x[a, b); rotation recurrence re-seeded every 1024.
void lsSinusoid(const std::vector<double>& x, std::size_t a, std::size_t b, double f, double fs,
                double* bs, double* bc) {
  // Sums in double over blocks of 1024 samples (where the phasor is re-seeded),
  // blocks added in long double.
  long double S[3][3] = {{0}}, r[3] = {0};
  const double w = kTwoPi * f / fs;
  const cplx rot(std::cos(w), std::sin(w));
  for (std::size_t k0 = a; k0 < b; k0 += 1024) {
    const std::size_t k1 = std::min(b, k0 + 1024);
    cplx ph = std::polar(1.0, w * static_cast<double>(k0));
    double s1 = 0, ss = 0, sc = 0, sss = 0, ssc = 0, scc = 0, r0 = 0, rs = 0, rc = 0;
    for (std::size_t k = k0; k < k1; ++k) {
      const double sn = ph.imag(), cs = ph.real(), xv = x[k];
      s1 += 1.0;
      ss += sn;
      sc += cs;
      sss += sn * sn;
      ssc += sn * cs;
      scc += cs * cs;
      r0 += xv;
      rs += sn * xv;
      rc += cs * xv;
      ph *= rot;
    }
    S[0][0] += s1; S[0][1] += ss; S[0][2] += sc;
    S[1][1] += sss; S[1][2] += ssc; S[2][2] += scc;
    r[0] += r0; r[1] += rs; r[2] += rc;
  }
  Eigen::Matrix3d A;
  Eigen::Vector3d y;
  for (int i = 0; i < 3; ++i) {
    y(i) = static_cast<double>(r[i]);
    for (int j = i; j < 3; ++j) A(i, j) = A(j, i) = static_cast<double>(S[i][j]);
  }
  const Eigen::Vector3d c = A.ldlt().solve(y);
  *bs = c(1);
  *bc = c(2);
}

/// Zoomed, tapered DFT power around f0: the tapered record demodulated at f0
/// and summed in blocks; the phase error inside a block is kept < 0.01 rad.
struct Zoom {
  std::vector<cplx> z;
  std::vector<double> centre;
  double fs = 1;
  Zoom(const std::vector<double>& y, double f0, double fs_, double max_delta_hz) : fs(fs_) {
    const std::size_t n = y.size();
    std::size_t B = 1;
    while (B * 2 <= n / 64 && kPi * max_delta_hz * static_cast<double>(B * 2) / fs < 0.01) B *= 2;
    const double w = kTwoPi * f0 / fs;
    const cplx rot(std::cos(w), -std::sin(w));
    for (std::size_t k0 = 0; k0 < n; k0 += B) {
      const std::size_t k1 = std::min(n, k0 + B);
      cplx ph = std::polar(1.0, -w * static_cast<double>(k0)), acc(0, 0);
      for (std::size_t k = k0; k < k1; ++k) {
        acc += y[k] * ph;
        ph *= rot;
      }
      z.push_back(acc);
      centre.push_back(0.5 * static_cast<double>(k0 + k1 - 1));
    }
  }
  double power(double delta_hz) const {
    const double w = kTwoPi * delta_hz / fs;
    cplx acc(0, 0);
    for (std::size_t k = 0; k < z.size(); ++k) acc += z[k] * std::polar(1.0, -w * centre[k]);
    return std::norm(acc);
  }
};

}  // namespace

LineTestResult detectLines(std::vector<double>& x, double fs, const PsdFunction& null_psd,
                           double alpha, const LineTestOptions& opt) {
  const std::size_t n = x.size();
  if (n < 64) throw Error("detectLines: need at least 64 samples, got " + std::to_string(n));
  if (!(fs > 0)) throw Error("detectLines: sampling rate must be > 0");
  if (!(alpha > 0 && alpha < 1)) throw Error("detectLines: alpha must be in (0, 1)");
  LineTestResult res;
  const double nd = static_cast<double>(n);
  const std::size_t nfft = fastSize(n);
  const double scale_bins = static_cast<double>(nfft) / nd;  // FFT bins per natural bin
  res.bin_hz = fs / nd;

  // Tapered, detrended copy (mean and slope removed; t centred).
  std::vector<double> y(nfft, 0.0), w(n);
  double U = 0;
  {
    const double tc = 0.5 * (nd - 1.0);
    long double m = 0, st = 0, stt = 0;
    for (std::size_t k = 0; k < n; ++k) {
      m += x[k];
      st += (static_cast<double>(k) - tc) * x[k];
      stt += (static_cast<double>(k) - tc) * (static_cast<double>(k) - tc);
    }
    const double mean = static_cast<double>(m / n), slope = static_cast<double>(st / stt);
    for (std::size_t k = 0; k < n; ++k) {
      w[k] = 0.5 * (1.0 - std::cos(kTwoPi * static_cast<double>(k) / nd));
      U += w[k] * w[k];
      y[k] = (x[k] - mean - slope * (static_cast<double>(k) - tc)) * w[k];
    }
  }
  std::vector<cplx> X;
  {
    Eigen::FFT<double> fft;
    fft.SetFlag(Eigen::FFT<double>::HalfSpectrum);
    fft.fwd(X, y);
  }
  const std::size_t nb = nfft / 2 + 1;
  const double norm = 1.0 / (fs * U);
  std::vector<double> I(nb);
  for (std::size_t k = 0; k < nb; ++k) I[k] = std::norm(X[k]) * norm;

  // Null expectation E_k: the model PSD seen through the Hann window (exact
  // convolution where the PSD may vary across the main lobe, i.e. the lowest
  // 256 natural bins; the PSD itself above).
  auto S = [&](double f) {
    f = std::abs(f);
    f = std::fmod(f, fs);
    if (f > 0.5 * fs) f = fs - f;
    f = std::max(f, 0.5 * res.bin_hz);
    const double v = null_psd(f);
    return std::isfinite(v) && v > 0 ? v : 0.0;
  };
  std::vector<double> E(nb);
  for (std::size_t k = 0; k < nb; ++k) {
    const double f = static_cast<double>(k) * fs / static_cast<double>(nfft);
    const double nu_k = static_cast<double>(k) / scale_bins;
    if (nu_k < 256.0) {
      double acc = 0, wsum = 0;
      for (int j = -64; j <= 64; ++j) {
        const double dnu = j / 8.0;
        const double kw = hannKernel(dnu);
        acc += kw * S(f + dnu * res.bin_hz);
        wsum += kw;
      }
      E[k] = acc / wsum;
    } else {
      E[k] = S(f);
    }
  }
  // Local background B_k: least-squares line of log I against log f over
  // +-W bins (the guard bins left out), evaluated at f_k, plus Euler's gamma
  // (E log Exp(1) = -gamma): follows power-law slopes (a random walk or a
  // Gauss-Markov process above its corner) that a running median would not.
  const int W = static_cast<int>(std::lround(opt.background_half_width * scale_bins));
  const int G = static_cast<int>(std::lround(opt.guard_bins * scale_bins));
  std::vector<double> B(nb, 0.0);
  {
    constexpr double kEulerGamma = 0.5772156649015329;
    // Prefix sums of 1, u = log k, v = log I, u^2, u v over bins 1..nb-1.
    std::vector<double> c0(nb + 1, 0), cu(nb + 1, 0), cv(nb + 1, 0), cuu(nb + 1, 0), cuv(nb + 1, 0);
    for (std::size_t k = 0; k < nb; ++k) {
      const bool use = k >= 1 && I[k] > 0;
      const double u = use ? std::log(static_cast<double>(k)) : 0.0;
      const double v = use ? std::log(I[k]) : 0.0;
      c0[k + 1] = c0[k] + (use ? 1.0 : 0.0);
      cu[k + 1] = cu[k] + u;
      cv[k + 1] = cv[k] + v;
      cuu[k + 1] = cuu[k] + u * u;
      cuv[k + 1] = cuv[k] + u * v;
    }
    auto range = [&](const std::vector<double>& c, long a, long b) {  // sum over [a, b]
      if (b < a) return 0.0;
      return c[b + 1] - c[a];
    };
    for (std::size_t k = 1; k < nb; ++k) {
      const long kk = static_cast<long>(k);
      const long lo = std::max<long>(1, kk - W), hi = std::min<long>(static_cast<long>(nb) - 1, kk + W);
      const long g0 = std::max(lo, kk - G), g1 = std::min(hi, kk + G);
      auto sum = [&](const std::vector<double>& c) { return range(c, lo, hi) - range(c, g0, g1); };
      const double m = sum(c0), su = sum(cu), sv = sum(cv), suu = sum(cuu), suv = sum(cuv);
      if (m < 3) continue;
      const double den = m * suu - su * su;
      const double b = den > 1e-12 * m * m ? (m * suv - su * sv) / den : 0.0;
      const double a = (sv - b * su) / m;
      B[k] = std::exp(a + b * std::log(static_cast<double>(k)) + kEulerGamma);
    }
    B[0] = B[1];
  }
  // Tested band and mask.
  const std::size_t k_lo = std::max<std::size_t>(
      2, static_cast<std::size_t>(std::ceil(opt.min_cycles * scale_bins)));
  const std::size_t k_hi = nb - 1 - static_cast<std::size_t>(std::ceil(2 * scale_bins));
  std::vector<char> tested(nb, 0);
  for (std::size_t k = k_lo; k <= k_hi && k < nb; ++k) tested[k] = 1;
  for (double fe : opt.exclude_hz) {
    const double kc = fe / fs * static_cast<double>(nfft);
    const double half = 4 * scale_bins;
    for (long k = static_cast<long>(std::floor(kc - half)); k <= static_cast<long>(std::ceil(kc + half)); ++k)
      if (k >= 0 && k < static_cast<long>(nb)) tested[k] = 0;
  }
  int K = 0;
  for (char t : tested) K += t;
  res.bins_tested = K;
  res.f_min_hz = static_cast<double>(k_lo) * fs / static_cast<double>(nfft);
  res.f_max_hz = static_cast<double>(k_hi) * fs / static_cast<double>(nfft);
  // K counts FFT bins (correlated where zero padded): a conservative Bonferroni.
  res.threshold = std::log(std::max(1, K) / alpha);
  // Against the local level B the threshold is raised for B's own noise: log B
  // is a mean of about m = 2 (W - G) log-periodogram values (variance
  // pi^2/6 each, x1.5 for the correlation of Hann-tapered neighbours), and
  // E exp(-c B/B_true) ~ exp(-c + c^2 s^2 / 2) for log-normal B.
  const double m_eff = 2.0 * (opt.background_half_width - opt.guard_bins);
  const double s2 = 1.6449 * 1.5 / std::max(1.0, m_eff);
  const double threshold_local =
      res.threshold / std::max(0.5, 1.0 - 0.5 * res.threshold * s2);

  // Plot arrays (before subtraction).
  {
    const std::size_t blk = std::max<std::size_t>(1, nb / 4000);
    for (std::size_t k0 = 1; k0 < nb; k0 += blk) {
      double mx = 0, bg = 0;
      std::size_t c = 0;
      for (std::size_t k = k0; k < std::min(nb, k0 + blk); ++k, ++c) {
        mx = std::max(mx, I[k]);
        bg += std::max(E[k], B[k]);
      }
      res.plot_freq_hz.push_back(static_cast<double>(k0) * fs / static_cast<double>(nfft));
      res.plot_psd.push_back(mx);
      res.plot_background.push_back(bg / static_cast<double>(c));
    }
  }

  const double mask_half = 3 * scale_bins;
  for (int li = 0; li < opt.max_lines; ++li) {
    std::size_t kbest = 0;
    double rbest = 0;
    for (std::size_t k = k_lo; k <= k_hi && k < nb; ++k) {
      if (!tested[k]) continue;
      // Ratio to the threshold-equivalent background: E x 1 or B x c_B / c.
      const double bg = std::max(E[k], B[k] * threshold_local / res.threshold);
      if (!(bg > 0)) continue;
      const double r = I[k] / bg;
      if (r > rbest) {
        rbest = r;
        kbest = k;
      }
    }
    if (!(rbest > res.threshold)) break;
    SpectralLine L;
    L.ratio = rbest;
    L.model_ratio = E[kbest] > 0 ? I[kbest] / E[kbest] : INFINITY;
    L.local_ratio = B[kbest] > 0 ? I[kbest] / B[kbest] : INFINITY;
    L.p_value = std::min(1.0, static_cast<double>(K) * std::exp(-rbest));
    L.background_psd = std::max(E[kbest], B[kbest] * threshold_local / res.threshold);
    // Refine: zoomed tapered DFT over +-1 natural bin, grid of 41 + parabola.
    const double f0 = static_cast<double>(kbest) * fs / static_cast<double>(nfft);
    const Zoom zm(y, f0, fs, 1.2 * res.bin_hz);
    double best_p = -1, best_d = 0;
    std::vector<double> pw(41);
    for (int i = 0; i < 41; ++i) {
      const double d = (i - 20) / 20.0 * res.bin_hz;
      pw[i] = zm.power(d);
      if (pw[i] > best_p) {
        best_p = pw[i];
        best_d = d;
      }
    }
    const int ib = static_cast<int>(std::lround(best_d / res.bin_hz * 20.0)) + 20;
    if (ib > 0 && ib < 40) {
      const double a = pw[ib - 1], b = pw[ib], c = pw[ib + 1], den = a - 2 * b + c;
      if (den < 0) best_d += std::clamp(0.5 * (a - c) / den, -0.5, 0.5) * res.bin_hz / 20.0;
    }
    const double f = std::clamp(f0 + best_d, 0.5 * res.bin_hz, 0.5 * fs - 0.5 * res.bin_hz);
    L.freq_hz = f;
    double bs = 0, bc = 0;
    lsSinusoid(x, 0, n, f, fs, &bs, &bc);
    L.amplitude = std::hypot(bs, bc);
    L.phase_rad = std::atan2(bc, bs);  // bs sin + bc cos = A sin(wt + phase)
    for (int h = 0; h < 2; ++h) {
      double hs = 0, hc = 0;
      lsSinusoid(x, h * (n / 2), h == 0 ? n / 2 : n, f, fs, &hs, &hc);
      L.amp_half[h] = std::hypot(hs, hc);
      L.phase_half[h] = std::atan2(hc, hs);
    }
    const double Sf = L.background_psd * fs;  // white-equivalent variance
    L.amp_se = std::sqrt(2.0 * Sf / nd);
    L.freq_se_hz = L.amplitude > 0
                       ? fs / kTwoPi * std::sqrt(12.0 * 2.0 * Sf / (L.amplitude * L.amplitude * nd * nd * nd))
                       : INFINITY;
    // Subtract from the record and from the spectrum (exact tapered transform).
    {
      const double wv = kTwoPi * f / fs;
      const cplx rot(std::cos(wv), std::sin(wv));
      cplx ph;
      for (std::size_t k = 0; k < n; ++k) {
        if ((k & 1023) == 0) ph = std::polar(1.0, wv * static_cast<double>(k));
        x[k] -= bs * ph.imag() + bc * ph.real();
        ph *= rot;
      }
      // A sin(wt + p) = (A / 2i) (e^{i(wt+p)} - e^{-i(wt+p)}).
      const cplx cpos = L.amplitude / 2.0 * std::polar(1.0, L.phase_rad) / cplx(0, 1);
      const cplx cneg = -L.amplitude / 2.0 * std::polar(1.0, -L.phase_rad) / cplx(0, 1);
      const double kc = f / fs * static_cast<double>(nfft);
      const long span = static_cast<long>(std::ceil(64 * scale_bins));
      for (long k = static_cast<long>(kc) - span; k <= static_cast<long>(kc) + span; ++k) {
        if (k < 0 || k >= static_cast<long>(nb)) continue;
        const double wk = kTwoPi * static_cast<double>(k) / static_cast<double>(nfft);
        X[k] -= cpos * hannSum(wv - wk, n) + cneg * hannSum(-wv - wk, n);
        I[k] = std::norm(X[k]) * norm;
      }
      for (long k = static_cast<long>(std::floor(kc - mask_half)); k <= static_cast<long>(std::ceil(kc + mask_half)); ++k)
        if (k >= 0 && k < static_cast<long>(nb)) tested[k] = 0;
    }
    res.lines.push_back(L);
  }
  // Harmonics: a line at h f0 (h = 2..max) of a lower line within 2 bins + 3 h se.
  std::vector<std::size_t> order(res.lines.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return res.lines[a].freq_hz < res.lines[b].freq_hz; });
  for (std::size_t jj = 0; jj < order.size(); ++jj) {
    auto& Lj = res.lines[order[jj]];
    for (std::size_t ii = 0; ii < jj; ++ii) {
      const auto& Li = res.lines[order[ii]];
      if (Li.harmonic_of >= 0) continue;
      const double h = std::round(Lj.freq_hz / Li.freq_hz);
      if (h < 2 || h > opt.max_harmonic) continue;
      const double tol = 2.0 * res.bin_hz + 3.0 * h * Li.freq_se_hz;
      if (std::abs(Lj.freq_hz - h * Li.freq_hz) <= tol) {
        Lj.harmonic_of = static_cast<int>(order[ii]);
        Lj.harmonic_number = static_cast<int>(h);
        break;
      }
    }
  }
  return res;
}

}  // namespace navimpact::detect
