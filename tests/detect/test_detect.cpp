// Calibration and power of the detectors (lib/detect), on records drawn from
// random null models: every parameter (noise model, record length, effect
// size as a multiple of the stated detection limit, frequency, position,
// phase) is drawn at random from a seeded stream whose seed and draws are
// printed. Null false-alarm rates must stay within alpha plus three Monte
// Carlo standard errors; power at 5x the detection limit must be >= 0.9, and
// the parameters of detected effects must be right in >= 90 % of the cases.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include "detect_test_util.hpp"
#include "navimpact/detect/change_points.hpp"
#include "navimpact/detect/lines.hpp"
#include "navimpact/detect/null_model.hpp"
#include "navimpact/detect/outliers.hpp"
#include "navimpact/stochastic/simulate.hpp"
#include "test_support.hpp"

namespace nd = navimpact::detect;
namespace ns = navimpact::stochastic;

namespace {

constexpr double kPi = 3.14159265358979323846;

int runs(int dflt) {
  return std::max(10, static_cast<int>(navimpact::test::envOr("NAVIMPACT_DETECT_RUNS", static_cast<std::uint64_t>(dflt))));
}

std::uint64_t rootSeed() { return navimpact::test::envOr("NAVIMPACT_DETECT_SEED", 20261124); }

/// A random null model: white noise plus, with equal odds, nothing, a GM
/// (T from 2 samples to n/5) or a random walk, with random strengths.
struct Drawn {
  ns::Model model;
  std::size_t n = 0;
  std::string text;
};

Drawn drawNull(std::mt19937_64& rng) {
  auto logU = [&](double a, double b) { return detecttest::logUniform(rng, a, b); };
  const detecttest::WhiteRecord w = detecttest::drawWhiteRecord(rng, 8192, 65536);
  Drawn d{w.model, w.n, ""};
  const double sw = w.sigma;
  const int kind = static_cast<int>(rng() % 3);
  const double record = d.n / d.model.rate_hz;
  if (kind == 1) {
    const double T = logU(2.0 / d.model.rate_hz, record / 5.0);
    d.model.terms.push_back(ns::Process::gm(sw * logU(0.05, 2.0), T));
  } else if (kind == 2) {
    d.model.terms.push_back(ns::Process::rw(sw * logU(1e-4, 1e-2)));
  }
  d.text = "n=" + std::to_string(d.n) + " rate=" + std::to_string(d.model.rate_hz) + " terms=" +
           std::to_string(d.model.terms.size()) + " wn=" + std::to_string(sw);
  if (d.model.terms.size() > 1) {
    const auto& p = d.model.terms[1];
    d.text += p.kind == ns::ProcessKind::GM
                  ? " gm(sigma=" + std::to_string(p.sigma) + ",T=" + std::to_string(p.T) + ")"
                  : " rw(gamma=" + std::to_string(p.gamma) + ")";
  }
  return d;
}

using navimpact::test::plausibleMaxCount;

/// Stated detection limit of a line (lines.hpp): amplitude at which the Hann
/// peak reaches the threshold with the worst scalloping (0.72 in power).
double lineLimit(double S_two_sided, double fs, std::size_t n, double threshold) {
  return std::sqrt(6.0 * threshold * S_two_sided * fs / (0.72 * static_cast<double>(n)));
}

}  // namespace

TEST(Lines, NullFalseAlarmsAtAlpha) {
  const double alpha = 0.05;
  const int R = runs(200);
  std::mt19937_64 rng(rootSeed());
  int alarms = 0;
  for (int r = 0; r < R; ++r) {
    const Drawn d = drawNull(rng);
    auto x = ns::simulate(d.model, d.n, rng());
    const auto res = nd::detectLines(x, d.model.rate_hz, nd::psdOf(d.model), alpha);
    if (!res.lines.empty()) {
      ++alarms;
      std::cout << "  false line: " << d.text << " f=" << res.lines[0].freq_hz
                << " ratio=" << res.lines[0].ratio << " thr=" << res.threshold << "\n";
    }
  }
  std::cout << "lines null: " << alarms << "/" << R << " false alarms at alpha " << alpha
            << " (seed " << rootSeed() << ")\n";
  EXPECT_LE(alarms, plausibleMaxCount(R, alpha));
}

TEST(Lines, PowerAtFiveTimesTheLimitAndParameters) {
  const int R = runs(120);
  std::mt19937_64 rng(rootSeed() + 1);
  std::uniform_real_distribution<double> U(0, 1);
  int found = 0, right = 0;
  for (int r = 0; r < R; ++r) {
    const Drawn d = drawNull(rng);
    const double fs = d.model.rate_hz, record = d.n / fs;
    // Frequency log-uniform from 5 cycles per record to 0.45 fs.
    const double f = 5.0 / record * std::pow(0.45 * fs / (5.0 / record), U(rng));
    const double thr = std::log(0.5 * d.n / 0.01);
    const double A = 5.0 * lineLimit(nd::psdOf(d.model)(f), fs, d.n, thr);
    const double ph = 2 * kPi * U(rng);
    auto x = ns::simulate(d.model, d.n, rng());
    for (std::size_t k = 0; k < d.n; ++k) x[k] += A * std::sin(2 * kPi * f * k / fs + ph);
    const auto res = nd::detectLines(x, fs, nd::psdOf(d.model), 0.01);
    bool hit = false, ok = false;
    for (const auto& L : res.lines) {
      if (std::abs(L.freq_hz - f) <= 2.0 * res.bin_hz) {
        hit = true;
        ok = std::abs(L.amplitude - A) <= 0.3 * A && L.harmonic_of < 0;
      }
    }
    found += hit;
    right += ok;
    if (!ok)
      std::cout << "  line " << (hit ? "off" : "missed") << ": " << d.text << " f=" << f << " A=" << A
                << " lines=" << res.lines.size()
                << (res.lines.empty() ? std::string() : " first f=" + std::to_string(res.lines[0].freq_hz) +
                                                            " A=" + std::to_string(res.lines[0].amplitude))
                << "\n";
  }
  std::cout << "lines at 5x limit: found " << found << "/" << R << ", right parameters " << right
            << "/" << found << "\n";
  EXPECT_GE(found, 0.9 * R);
  EXPECT_GE(right, 0.9 * found);
}

TEST(Lines, HarmonicsAreOneFinding) {
  std::mt19937_64 rng(rootSeed() + 2);
  std::uniform_real_distribution<double> U(0, 1);
  int ok = 0;
  const int R = runs(20);
  for (int r = 0; r < R; ++r) {
    ns::Model m;
    m.rate_hz = 100;
    m.terms = {ns::Process::wn(1.0)};
    const std::size_t n = 32768;
    auto x = ns::simulate(m, n, rng());
    const double f0 = 0.2 + 3.0 * U(rng);
    for (int h = 1; h <= 3; ++h)
      for (std::size_t k = 0; k < n; ++k) x[k] += (0.3 / h) * std::sin(2 * kPi * h * f0 * k / 100.0 + h);
    const auto res = nd::detectLines(x, 100.0, nd::psdOf(m), 0.01);
    int fund = 0, harm = 0;
    for (const auto& L : res.lines) (L.harmonic_of < 0 ? fund : harm) += 1;
    if (fund == 1 && harm == 2) ++ok;
    else std::cout << "  harmonics f0=" << f0 << ": " << fund << " fundamental(s), " << harm << " harmonic(s)\n";
  }
  EXPECT_GE(ok, 0.9 * R);
}

TEST(Lines, BroadbandMisfitIsNotALine) {
  // A Gauss-Markov process missing from the model (up to 20x the white-noise
  // PSD) must not be called a line: its spectrum is smooth.
  const int R = runs(100);
  std::mt19937_64 rng(rootSeed() + 3);
  std::uniform_real_distribution<double> U(0, 1);
  int alarms = 0;
  for (int r = 0; r < R; ++r) {
    ns::Model null_m, truth;
    null_m.rate_hz = truth.rate_hz = 100;
    null_m.terms = {ns::Process::wn(1.0)};
    const std::size_t n = 32768;
    const double T = 0.02 * std::pow(n / 100.0 / 5.0 / 0.02, U(rng));
    truth.terms = {ns::Process::wn(1.0), ns::Process::gm(std::pow(10.0, -1 + 2 * U(rng)), T)};
    auto x = ns::simulate(truth, n, rng());
    const auto res = nd::detectLines(x, 100.0, nd::psdOf(null_m), 0.05);
    if (!res.lines.empty()) ++alarms;
  }
  std::cout << "GM misfit called a line: " << alarms << "/" << R << "\n";
  EXPECT_LE(alarms, plausibleMaxCount(R, 0.05));
}

TEST(ChangePoints, NullFalseAlarmsAtAlpha) {
  const double alpha = 0.05;
  const int R = runs(200);
  std::mt19937_64 rng(rootSeed() + 10);
  int alarms = 0;
  for (int r = 0; r < R; ++r) {
    const Drawn d = drawNull(rng);
    auto x = ns::simulate(d.model, d.n, rng());
    const auto res = nd::detectChangePoints(x, nd::haarWvOf(d.model), alpha);
    if (!res.changes.empty()) {
      ++alarms;
      std::cout << "  false change: " << d.text << " at " << res.changes[0].index << " z="
                << res.changes[0].z << " thr=" << res.changes[0].threshold << " m="
                << res.changes[0].half_width << "\n";
    }
  }
  std::cout << "change points null: " << alarms << "/" << R << " at alpha " << alpha << "\n";
  EXPECT_LE(alarms, plausibleMaxCount(R, alpha));
}

TEST(ChangePoints, PowerAtFiveTimesTheLimitAndLocation) {
  // Detection limit of a step at k (change_points.hpp): the smallest
  // threshold x null sd over the windows that fit on both sides of it.
  const int R = runs(120);
  std::mt19937_64 rng(rootSeed() + 11);
  std::uniform_real_distribution<double> U(0, 1);
  int found = 0, right = 0;
  for (int r = 0; r < R; ++r) {
    const Drawn d = drawNull(rng);
    const std::size_t n = d.n;
    const std::size_t k0 = static_cast<std::size_t>((0.1 + 0.8 * U(rng)) * n);
    const auto wv = nd::haarWvOf(d.model);
    double limit = INFINITY;
    {
      // Same grid and thresholds as the detector.
      std::vector<std::size_t> ms;
      for (double mf = 8; 2 * std::floor(mf) <= n; mf *= std::sqrt(2.0))
        if (ms.empty() || ms.back() != std::size_t(mf)) ms.push_back(std::size_t(mf));
      for (std::size_t m : ms) {
        if (m > std::min(k0, n - k0)) continue;
        const std::size_t P = (n - 2 * m) / std::max<std::size_t>(1, m / 8) + 1;
        const double p = 0.01 / (ms.size() * double(P));
        // two-sided normal quantile by bisection on erfc
        double lo = 0, hi = 40;
        for (int it = 0; it < 200; ++it) {
          const double mid = 0.5 * (lo + hi);
          (std::erfc(mid / std::sqrt(2.0)) > p ? lo : hi) = mid;
        }
        limit = std::min(limit, lo * 2.0 * std::sqrt(wv(2.0 * m)));
      }
    }
    const double S = (U(rng) < 0.5 ? -1 : 1) * 5.0 * limit;
    auto x = ns::simulate(d.model, n, rng());
    for (std::size_t k = k0; k < n; ++k) x[k] += S;
    const auto res = nd::detectChangePoints(x, wv, 0.01);
    bool hit = false, ok = false;
    for (const auto& c : res.changes)
      if (std::abs(double(c.index) - double(k0)) <= 0.02 * n) {
        hit = true;
        ok = std::abs(c.size - S) <= 0.3 * std::abs(S) && res.changes.size() == 1;
      }
    found += hit;
    right += ok;
    if (!ok)
      std::cout << "  step " << (hit ? "off" : "missed") << ": " << d.text << " k0=" << k0 << " S=" << S
                << " changes=" << res.changes.size()
                << (res.changes.empty() ? std::string()
                                        : " first at " + std::to_string(res.changes[0].index) +
                                              " size " + std::to_string(res.changes[0].size))
                << "\n";
  }
  std::cout << "steps at 5x limit: found " << found << "/" << R << ", right " << right << "/" << found << "\n";
  EXPECT_GE(found, 0.9 * R);
  EXPECT_GE(right, 0.9 * found);
}

TEST(ChangePoints, KnocksAreTransientsJudgedAtTheirOwnScale) {
  // A knock: the level leaves and comes back (a box) after L samples, L
  // log-uniform from 2 to one second of the record's rate, anywhere in the
  // middle 80 %, amplitude log-uniform 3-100x its limit (change_points.hpp
  // testTransient: threshold x 2 nu(2m) x m / min(L, m), m = max(8, L)). It
  // must come out as one transient starting within max(3, L / 10) samples of
  // the truth, significant under the model at its own scale, and no change
  // (alpha 1 %, as for the steps). Null records (alpha 5 %): a transient
  // accepted by testTransient in at most alpha + 3 MC se of them.
  const double alpha = 0.05, alpha_knock = 0.01;
  const int R = runs(100);
  std::mt19937_64 rng(rootSeed() + 12);
  std::uniform_real_distribution<double> U(0, 1);
  int right = 0, null_alarms = 0;
  for (int r = 0; r < R; ++r) {
    const Drawn d = drawNull(rng);
    const std::size_t n = d.n;
    const auto wv = nd::haarWvOf(d.model);
    nd::ChangePointOptions o;
    o.max_transient = static_cast<std::size_t>(d.model.rate_hz);
    const std::size_t L = std::max<std::size_t>(
        2, static_cast<std::size_t>(2.0 * std::pow(std::min(d.model.rate_hz, 0.05 * n) / 2.0, U(rng))));
    const std::size_t k0 = static_cast<std::size_t>((0.1 + 0.8 * U(rng)) * (n - L));
    const auto t0 = nd::testTransient(std::vector<double>(n, 0.0), k0, k0 + L, wv, alpha_knock, o);
    const double m = static_cast<double>(t0.half_width);
    const double limit = t0.threshold * 2.0 * std::sqrt(wv(2.0 * m)) * m / std::min(static_cast<double>(L), m);
    const double snr = 3.0 * std::pow(100.0 / 3.0, U(rng));
    const double A = (U(rng) < 0.5 ? -1 : 1) * snr * limit;
    auto x = ns::simulate(d.model, n, rng());
    {
      auto xs = x;
      const auto res = nd::detectChangePoints(xs, wv, alpha, o);
      bool alarm = false;
      for (const auto& t : res.transients)
        alarm = alarm || nd::testTransient(x, t.first, t.last, wv, alpha, o).significant();
      null_alarms += alarm;
    }
    for (std::size_t k = k0; k < k0 + L; ++k) x[k] += A;
    auto xs = x;
    const auto res = nd::detectChangePoints(xs, wv, alpha_knock, o);
    bool ok = res.transients.size() == 1 && res.changes.empty();
    if (ok) {
      const auto& t = res.transients[0];
      ok = std::abs(static_cast<double>(t.first) - static_cast<double>(k0)) <= std::max(3.0, 0.1 * L) &&
           nd::testTransient(x, t.first, t.last, wv, alpha_knock, o).significant();
    }
    right += ok;
    if (!ok)
      std::cout << "  knock wrong: " << d.text << " k0=" << k0 << " L=" << L << " A=" << A << " (" << snr
                << "x limit): " << res.transients.size() << " transient(s)"
                << (res.transients.empty() ? std::string() : " first at " + std::to_string(res.transients[0].first) +
                                                                 ".." + std::to_string(res.transients[0].last))
                << ", " << res.changes.size() << " change(s)\n";
  }
  std::cout << "knocks at 3-100x limit: right " << right << "/" << R << "; null records with a transient " << null_alarms
            << "/" << R << " at alpha " << alpha << "\n";
  EXPECT_GE(right, 0.9 * R);
  EXPECT_LE(null_alarms, plausibleMaxCount(R, alpha));
}

TEST(Outliers, NullFalseAlarmsAtAlpha) {
  const double alpha = 0.05;
  const int R = runs(200);
  std::mt19937_64 rng(rootSeed() + 20);
  int alarms = 0;
  for (int r = 0; r < R; ++r) {
    const Drawn d = drawNull(rng);
    auto x = ns::simulate(d.model, d.n, rng());
    const auto res = nd::detectOutliers(x, nd::secondDifferenceSd(d.model), alpha);
    if (!res.events.empty()) ++alarms;
  }
  std::cout << "outliers null: " << alarms << "/" << R << " at alpha " << alpha << "\n";
  EXPECT_LE(alarms, plausibleMaxCount(R, alpha));
}

TEST(Outliers, SpikesAndBurstsAreEventsAtFiveTimesTheLimit) {
  // Isolated spikes and bursts (2-30 consecutive samples of alternating sign,
  // a knock) at 5x the threshold: each must be exactly one event.
  const int R = runs(100);
  std::mt19937_64 rng(rootSeed() + 21);
  std::uniform_real_distribution<double> U(0, 1);
  int right = 0;
  for (int r = 0; r < R; ++r) {
    const Drawn d = drawNull(rng);
    const std::size_t n = d.n;
    auto x = ns::simulate(d.model, n, rng());
    const double s = nd::secondDifferenceSd(d.model);
    const double z = std::sqrt(2.0) * 6.0;  // about the threshold for these n at 1 %
    const int count = 1 + static_cast<int>(rng() % 10);
    std::vector<std::size_t> at;
    for (int i = 0; i < count; ++i) {
      std::size_t k;
      bool okpos;
      do {
        k = 50 + rng() % (n - 100);
        okpos = true;
        for (auto a : at) okpos = okpos && (k > a + 80 || a > k + 80);
      } while (!okpos);
      at.push_back(k);
      const int len = U(rng) < 0.5 ? 1 : 2 + static_cast<int>(rng() % 29);
      for (int j = 0; j < len; ++j) x[k + j] += (j % 2 ? -1 : 1) * 5.0 * z * s;
    }
    const auto res = nd::detectOutliers(x, s, 0.01);
    const bool ok = static_cast<int>(res.events.size()) == count;
    right += ok;
    if (!ok) std::cout << "  outliers: " << d.text << " hidden " << count << " found " << res.events.size() << "\n";
  }
  std::cout << "outlier events right: " << right << "/" << R << "\n";
  EXPECT_GE(right, 0.9 * R);
}

TEST(Outliers, CleaningTakesASpikeOutAnywhereInTheRecordEndsIncluded) {
  // One spike or short burst at 5x the threshold, at a position drawn over the
  // whole record: with even odds uniformly, or within three samples of the
  // first or the last sample (where the second difference is not defined and
  // a spike shows only next to it). After detection and cleaning (both fill
  // modes), every hidden sample must be within half the spike of the record
  // without it, and a lone spike must be reported at its sample with its size
  // (within half).
  const int R = runs(100);
  std::mt19937_64 rng(rootSeed() + 22);
  std::uniform_real_distribution<double> U(0, 1);
  int right = 0;
  for (int r = 0; r < R; ++r) {
    const Drawn d = drawNull(rng);
    const std::size_t n = d.n;
    const auto base = ns::simulate(d.model, n, rng());
    const double s = nd::secondDifferenceSd(d.model);
    const double A = 5.0 * std::sqrt(2.0) * 6.0 * s;
    const std::size_t len = U(rng) < 0.5 ? 1 : 2 + rng() % 4;
    const double where = U(rng);
    const std::size_t k = where < 0.5    ? static_cast<std::size_t>(U(rng) * static_cast<double>(n - len))
                          : where < 0.75 ? rng() % 3
                                         : n - len - rng() % 3;
    auto x = base;
    for (std::size_t j = 0; j < len; ++j) x[k + j] += (j % 2 ? -1.0 : 1.0) * A;
    nd::OutlierOptions o;
    o.local_fill = U(rng) < 0.5;
    const auto res = nd::detectOutliers(x, s, 0.01, o);
    // A lone spike is reported where it is, with its size from the local level.
    bool placed = len > 1;
    for (const auto& e : res.events)
      placed = placed || (e.peak == k && std::abs(std::abs(e.peak_value) - A) < 0.5 * A);
    nd::cleanOutliers(x, res.events, o);
    double worst = 0;
    for (std::size_t j = k; j < k + len; ++j) worst = std::max(worst, std::abs(x[j] - base[j]));
    const bool ok = worst < 0.5 * A && placed;
    right += ok;
    if (!ok)
      std::cout << "  spike left: " << d.text << " at " << k << " len " << len << " local_fill " << o.local_fill
                << " events " << res.events.size() << " placed " << placed << " residual " << worst / A
                << " of the spike\n";
  }
  std::cout << "spikes cleaned: " << right << "/" << R << "\n";
  EXPECT_GE(right, 0.95 * R);
}
