// Datasheet figures on random models against closed forms: the ARW / VRW of
// white noise plus short-T Gauss-Markov terms, the IEEE 952 bias instability
// of WN + RW and WN + DR (exact discrete-time Allan variances), its warnings
// (minimum at the first scales, flat region not reached) and bounded work at
// extreme rates. Draws are seeded (master seed printed with every draw) and
// cover the documented ranges: rate 1 Hz - 10 kHz, WN sigma 1e-8 - 1e2 per
// sample (or vanishing, 1e-60), GM T 0.05 - 4 samples (counted) and
// 4 - 1e5 samples (not counted), ADEV minimum 20 - 1e5 samples (floor),
// 1.5 - 8 samples (first scales).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "navimpact/stochastic/datasheet.hpp"
#include "navimpact/stochastic/model_text.hpp"
#include "navimpact/stochastic/simulate.hpp"
#include "navimpact/stochastic/theoretical_wv.hpp"

using namespace navimpact::stochastic;
using navimpact::units::Quantity;

namespace {

constexpr std::uint64_t kMaster = 20240614;

double unit(std::mt19937_64& g) { return double(g() >> 11) * 0x1.0p-53; }
double logUniform(std::mt19937_64& g, double lo, double hi) {
  return std::exp(std::log(lo) + unit(g) * (std::log(hi) - std::log(lo)));
}
Model model(double rate, std::vector<Process> terms) {
  Model m;
  m.rate_hz = rate;
  m.terms = std::move(terms);
  return m;
}
/// Model Allan variance at m samples from the Haar WV (AVAR(m) = 2 nu^2(2m)).
double avar(const Model& m, double msamples) {
  double s = 0;
  for (const auto& p : m.terms) s += haarWv(p, m.rate_hz, 2.0 * msamples);
  return 2.0 * s;
}

}  // namespace

// N^2 = dt (sigma_WN^2 + sum_{GM, T < 4 samples} sigma^2 (1+phi)/(1-phi)); a
// GM beyond 4 samples does not count. Independent check on the model without
// the long GM: AVAR(m) m dt -> N^2 for m >> T (the -1/2 slope's level).
TEST(DatasheetFigures, NoiseDensityIncludesShortGaussMarkovTerms) {
  std::printf("master seed %llu\n", (unsigned long long)kMaster);
  for (int i = 0; i < 40; ++i) {
    std::mt19937_64 g(deriveSeed(kMaster, std::uint64_t(i)));
    const double rate = logUniform(g, 1.0, 1e4), dt = 1.0 / rate;
    const double sw = unit(g) < 0.25 ? 1e-60 : logUniform(g, 1e-8, 1e2);
    std::vector<Process> terms{Process::wn(sw)};
    double n2 = sw * sw;
    const int n_short = 1 + int(unit(g) * 2.0);
    for (int k = 0; k < n_short; ++k) {
      const double T = logUniform(g, 0.05, 3.99) * dt;
      const double s = sw * logUniform(g, 0.1, 10.0) + (sw < 1e-50 ? logUniform(g, 1e-6, 1.0) : 0.0);
      const double phi = std::exp(-dt / T);
      n2 += s * s * (1 + phi) / (1 - phi);
      terms.push_back(Process::gm(s, T));
    }
    const Model white = model(rate, terms);
    terms.push_back(Process::gm(logUniform(g, 1e-3, 1.0) * std::sqrt(n2), logUniform(g, 4.0, 1e5) * dt));
    const Model all = model(rate, terms);
    const auto f = datasheetFigures(all);
    ASSERT_TRUE(f.noise_density.has_value());
    const double N = std::sqrt(n2 * dt);
    EXPECT_NEAR(*f.noise_density, N, 1e-12 * N) << "draw " << i;
    EXPECT_EQ(f.noise_density_gms, n_short) << "draw " << i;
    EXPECT_NEAR(f.noise_density_gm_share, 1.0 - sw * sw / n2, 1e-12) << "draw " << i;
    const double m_big = 1e8;
    const double level = avar(white, m_big) * m_big * dt;
    EXPECT_NEAR(level, N * N, 1e-6 * N * N) << "draw " << i;
    std::printf("draw %2d rate %.4g Hz %s: N %.6g (AVAR level %.6g), %d short GMs, %.3g of N^2\n", i, rate,
                formatTerms(all.terms).c_str(), N, std::sqrt(level), n_short, f.noise_density_gm_share);
  }
  // The ADIS16405 case: WN driven to ~0, the first-scale noise in a GM with
  // T = 0.55 samples (phi = 0.162): ARW 2.47 deg/sqrt(h), not 1e-64.
  const auto adis = datasheetFigures(model(100, {Process::wn(1e-66 * 0.0174533), Process::gm(0.35 * 0.0174533, 0.0055)}));
  const std::string s = formatDatasheet(adis, Quantity::AngularRate);
  EXPECT_NE(s.find("ARW                2.47"), std::string::npos) << s;
  EXPECT_NE(s.find("incl. 1 GM with T < 4 samples, 100 % of N^2"), std::string::npos) << s;
}

// Bias instability = min ADEV / 0.664 at the exact minimum of the discrete
// WN + RW Allan variance AVAR(m) = (sigma^2 + gamma^2/6)/m + gamma^2 m/3 and of
// WN + DR, AVAR(m) = sigma^2/m + omega^2 m^2/2, with the minimum drawn over
// 20 - 1e5 samples; no warning.
TEST(DatasheetFigures, BiasInstabilityAtTheExactAllanMinimum) {
  for (int i = 0; i < 40; ++i) {
    std::mt19937_64 g(deriveSeed(kMaster, 100 + std::uint64_t(i)));
    const double rate = logUniform(g, 1.0, 1e4), dt = 1.0 / rate;
    const double sw = logUniform(g, 1e-8, 1e2);
    const double m0_target = logUniform(g, 20.0, 1e5);
    const bool rw = i % 2 == 0;
    Model m;
    double m0 = 0, amin = 0;
    if (rw) {
      // m0 = sqrt(3 (sigma^2 + gamma^2/6)) / gamma ~ sqrt(3) sigma / gamma.
      const double gamma = std::sqrt(3.0) * sw / m0_target;
      m = model(rate, {Process::wn(sw), Process::rw(gamma)});
      const double A = sw * sw + gamma * gamma / 6, B = gamma * gamma / 3;
      m0 = std::sqrt(A / B);
      amin = 2 * std::sqrt(A * B);
    } else {
      const double omega = sw / std::pow(m0_target, 1.5);
      m = model(rate, {Process::wn(sw), Process::dr(omega)});
      m0 = std::cbrt(sw * sw / (omega * omega));
      amin = sw * sw / m0 + omega * omega * m0 * m0 / 2;
    }
    const auto f = datasheetFigures(m);
    std::printf("draw %2d rate %.4g Hz %s: ADEV min %.6g at %.6g s (closed form %.6g at %.6g s)\n", i, rate,
                formatTerms(m.terms).c_str(), f.bias_instability ? *f.bias_instability * 0.664 : -1.0,
                f.bias_instability_tau_s ? *f.bias_instability_tau_s : -1.0, std::sqrt(amin), m0 * dt);
    ASSERT_TRUE(f.bias_instability.has_value()) << "draw " << i;
    EXPECT_NEAR(*f.bias_instability, std::sqrt(amin) / 0.664, 1e-9 * std::sqrt(amin)) << "draw " << i;
    EXPECT_NEAR(*f.bias_instability_tau_s, m0 * dt, 1e-3 * m0 * dt) << "draw " << i;
    EXPECT_TRUE(f.bias_instability_warning.empty()) << f.bias_instability_warning;
  }
}

// A minimum below 10 samples is reported with a warning; an ADEV that still
// falls at the longest averaging time gives no value and a warning; a dip at
// the first scales before a GM hump yields to the floor after the hump.
TEST(DatasheetFigures, BiasInstabilityWarnings) {
  for (int i = 0; i < 20; ++i) {
    std::mt19937_64 g(deriveSeed(kMaster, 200 + std::uint64_t(i)));
    const double rate = logUniform(g, 1.0, 1e4), dt = 1.0 / rate;
    const double sw = logUniform(g, 1e-8, 1e2);
    const double gamma = std::sqrt(3.0) * sw / logUniform(g, 1.5, 8.0);
    const Model m = model(rate, {Process::wn(sw), Process::rw(gamma)});
    const double A = sw * sw + gamma * gamma / 6, B = gamma * gamma / 3;
    const auto f = datasheetFigures(m);
    ASSERT_TRUE(f.bias_instability.has_value()) << "draw " << i;
    EXPECT_NEAR(*f.bias_instability * 0.664, std::sqrt(2 * std::sqrt(A * B)), 1e-9 * std::sqrt(2 * std::sqrt(A * B)));
    EXPECT_NE(f.bias_instability_warning.find("first scales"), std::string::npos) << "draw " << i;
    EXPECT_NE(formatDatasheet(f, Quantity::AngularRate).find("warning: bias instability"), std::string::npos);
    // The same model searched only up to 0.8 m0: the floor is not reached.
    const auto h = datasheetFigures(model(rate, {Process::wn(sw), Process::rw(gamma / 100)}),
                                    0.5 * std::sqrt(3.0) * sw / (gamma / 100) * dt);
    EXPECT_FALSE(h.bias_instability.has_value()) << "draw " << i;
    EXPECT_NE(h.bias_instability_warning.find("no flat region"), std::string::npos) << "draw " << i;
  }
  // WN + QN alone: the ADEV falls everywhere.
  const auto q = datasheetFigures(model(200, {Process::wn(1e-3), Process::qn(1e-3)}));
  EXPECT_FALSE(q.bias_instability.has_value());
  EXPECT_NE(formatDatasheet(q, Quantity::SpecificForce).find("no flat region"), std::string::npos);
  // Ring-laser-gyro-like: a strong GM hump at 3 samples after a dip at the first
  // scales, then white noise and a rate random walk floor near 2e5 samples.
  const Model rlg = model(100, {Process::wn(1e-4), Process::gm(3e-4, 0.03), Process::rw(1e-9)});
  double first_dip = 1e300;
  for (double mm = 1.01; mm < 10; mm *= 1.01)
    if (avar(rlg, mm) < avar(rlg, mm / 1.01) && avar(rlg, mm) <= avar(rlg, mm * 1.01))
      first_dip = std::min(first_dip, std::sqrt(avar(rlg, mm)));
  const auto r = datasheetFigures(rlg);
  ASSERT_TRUE(r.bias_instability.has_value());
  EXPECT_GT(*r.bias_instability_tau_s, 10.0 / 100);
  EXPECT_TRUE(r.bias_instability_warning.empty()) << r.bias_instability_warning;
  std::printf("RLG-like: first-scale dip %.4g, floor %.4g at %.4g s\n", first_dip, *r.bias_instability * 0.664,
              *r.bias_instability_tau_s);
}

// Bounded work and empty figures at degenerate rates (rate_hz 1e308 used to
// loop forever: the grid's upper limit 1e6 * rate overflowed).
TEST(DatasheetFigures, ExtremeRatesAreBounded) {
  const std::vector<Process> terms{Process::wn(1e-3), Process::gm(1e-4, 10.0), Process::rw(1e-7)};
  for (double rate : {1e308, 1e-300, 1e300, 1e-5}) {
    const auto f = datasheetFigures(model(rate, terms));
    EXPECT_TRUE(f.noise_density.has_value()) << rate;
    formatDatasheet(f, Quantity::AngularRate);
  }
  for (double rate : {0.0, -1.0, std::nan(""), HUGE_VAL}) {
    const auto f = datasheetFigures(model(rate, terms));
    EXPECT_FALSE(f.noise_density || f.bias_instability || f.random_walk) << rate;
  }
}
