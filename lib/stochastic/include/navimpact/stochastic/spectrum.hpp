/**
 * @file spectrum.hpp
 * @brief Power spectral density (PSD) of a model, and its spectral lines.
 *
 * The PSD is that of the **sampled** process at the model's rate_hz (dt =
 * 1/rate_hz), **one-sided**, in u^2/Hz (u the signal's SI unit), defined for
 * 0 < f <= rate_hz/2: the variance of a stationary term is the integral of its
 * PSD over (0, rate_hz/2]. Per kind, with s = sin^2(pi f dt) and the two-sided
 * density per sample S(s) [u^2 per cycle/sample], PSD(f) = 2 dt S(s):
 *  - WN(sigma):    S = sigma^2                       (PSD = 2 sigma^2 dt = 2 N^2, N the noise density)
 *  - QN(Q):        S = 4 Q^2 s                       (difference of white noise of variance Q^2)
 *  - GM(sigma, T): S = sigma^2 (1 - phi^2) / ((1 - phi)^2 + 4 phi s), phi = exp(-dt/T)
 *                  (the exact AR(1) spectrum of the sampled GM)
 *  - RW(gamma):    S = gamma^2 / (4 s)               (the pseudo-spectrum of the random walk:
 *                  the limit of GM for phi -> 1 with its innovation variance gamma^2 fixed;
 *                  not integrable at f = 0, the process is not stationary)
 *  - SIN(amp, freq): no density; a **line** at freq with power amp^2/2 [u^2]
 *                  (the variance of the sinusoid), see lines().
 *  - DR(omega):    a deterministic ramp has neither density nor line: psd()
 *                  counts it as 0 and hasTrend() says the model has one. Its
 *                  periodogram leaks from the lowest bins as 1/f^2; remove the
 *                  trend before comparing a periodogram with psd().
 *
 * The Haar wavelet variance is the PSD integrated against the squared gain of
 * the Haar filter at scale tau = 2n samples, |H(f)|^2 = sin^4(pi f n dt) /
 * (n^2 sin^2(pi f dt)) (Percival & Walden 2000, §8.1):
 *     nu^2(tau) = int_0^{rate/2} |H(f)|^2 PSD(f) df + sum over lines of power |H(freq)|^2
 * for every term but DR (tests/stochastic/test_process_kinds.cpp checks it,
 * and the PSD against simulated periodograms, for every kind).
 */
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

#include "navimpact/stochastic/process.hpp"
#include "navimpact/stochastic/process_kind.hpp"

namespace navimpact::stochastic {

/// A spectral line of a model (a SIN term).
struct SpectralLine {
  double freq_hz = 0.0;   ///< frequency [Hz], 0 < freq < rate/2
  double power = 0.0;     ///< power = variance of the line [u^2] (amp^2/2)
  std::size_t term = 0;   ///< index of the term in Model::terms
};

/// How a kind shows in the spectrum (Density, Line or Trend).
SpectralForm spectralForm(ProcessKind k);

/**
 * The PSD of a model prepared once (per-term constants computed in the
 * constructor) for evaluation at many frequencies.
 */
class Spectrum {
 public:
  /// @throws navimpact::Error if the model is invalid (see validate()).
  explicit Spectrum(const Model& m);

  /// One-sided PSD [u^2/Hz] of the density terms at @p f_hz.
  /// @throws navimpact::Error unless 0 < f_hz <= rate_hz/2.
  double operator()(double f_hz) const;

  /// Two-sided density per sample [u^2 per cycle/sample] at s = sin^2(pi f dt)
  /// (0 < s <= 1): PSD(f) = 2 dt perSample(s). For quadratures in f/rate.
  double perSample(double sin2) const;

  /// The spectral lines (SIN terms), in term order.
  const std::vector<SpectralLine>& lines() const { return lines_; }
  /// True if the model has a deterministic trend (a DR term), which psd() leaves out.
  bool hasTrend() const { return trend_; }
  double rate_hz() const { return rate_hz_; }

 private:
  double rate_hz_ = 0.0;
  std::vector<std::function<double(double)>> density_;
  std::vector<SpectralLine> lines_;
  bool trend_ = false;
};

/// One-sided PSD [u^2/Hz] of @p m at @p f_hz (0 < f_hz <= rate/2): Spectrum(m)(f_hz).
double psd(const Model& m, double f_hz);

/// The spectral lines of @p m (its SIN terms).
std::vector<SpectralLine> lines(const Model& m);

}  // namespace navimpact::stochastic
