// Empirical Haar wavelet variance: exact agreement with the R package gmwm on
// the ADIS16405 recordings, and closed-form checks on small series.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iostream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "gmwm_test_util.hpp"
#include "navimpact/core/csv_reader.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/gmwm/wavelet_variance.hpp"
#include "test_support.hpp"

using namespace navimpact;
using navimpact::gmwm::WaveletVariance;

namespace {

struct RefRow {
  std::string axis;
  int j;
  double wv, lo, hi, m, eta;
};

std::string unquote(std::string s) {
  if (s.size() >= 2 && s.front() == '"' && s.back() == '"') return s.substr(1, s.size() - 2);
  return s;
}

std::vector<RefRow> readReference(const std::string& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  std::string line;
  std::getline(in, line);  // header
  std::vector<RefRow> rows;
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::stringstream ss(line);
    std::string tok;
    while (std::getline(ss, tok, ',')) f.push_back(unquote(tok));
    if (f.size() < 11) continue;
    // dataset,axis,units_of_wv,j,tau_samples,tau_s,wv,ci_low,ci_high,n_coef_Mj,eta3,...
    rows.push_back({f[1], std::stoi(f[3]), std::stod(f[6]), std::stod(f[7]), std::stod(f[8]),
                    std::stod(f[9]), std::stod(f[10])});
  }
  return rows;
}

double rel(double a, double b) { return std::fabs(a - b) / std::fabs(b); }

// Naive reference: W_{j,t} = (mean of x[t-s+1..t] - mean of x[t-2s+1..t-s]) / 2,
// s = 2^{j-1}, over all t with a full window (Percival & Walden 2000, eq. 171).
double naiveWv(const std::vector<double>& x, int j) {
  const std::size_t s = std::size_t{1} << (j - 1);
  long double acc = 0;
  std::size_t cnt = 0;
  for (std::size_t t = 2 * s - 1; t < x.size(); ++t) {
    long double a = 0, b = 0;
    for (std::size_t k = 0; k < s; ++k) {
      a += x[t - k];
      b += x[t - s - k];
    }
    const long double w = (a - b) / (2.0L * s);
    acc += w * w;
    ++cnt;
  }
  return static_cast<double>(acc / cnt);
}

// Straightforward pyramid on whole arrays (Percival & Walden 2000, eq. 177a),
// boundary coefficients dropped: the blocked library code must agree.
std::vector<double> simplePyramidWv(const std::vector<double>& x, int J) {
  std::vector<double> v = x, out;
  std::size_t first = 0;  // first index of v that is boundary-free
  for (int j = 1; j <= J; ++j) {
    const std::size_t s = std::size_t{1} << (j - 1);
    std::vector<double> nv(x.size(), 0.0);
    long double acc = 0;
    std::size_t cnt = 0;
    for (std::size_t t = first + s; t < x.size(); ++t) {
      const double w = 0.5 * (v[t] - v[t - s]);
      nv[t] = 0.5 * (v[t] + v[t - s]);
      acc += static_cast<long double>(w) * w;
      ++cnt;
    }
    first += s;
    v.swap(nv);
    out.push_back(static_cast<double>(acc / cnt));
  }
  return out;
}

}  // namespace

class WvReference : public ::testing::TestWithParam<int> {};

// Acquisition 1 is committed (tests/data); 2 and 3 come from ../shared when present.
TEST_P(WvReference, MatchesRPackageOnFullRecording) {
  const int acq = GetParam();
  const std::string file = "adis16405_static_" + std::to_string(acq) + ".csv.gz";
  if (acq != 1) NAVIMPACT_REQUIRE_SHARED("data/imu_static/" + file);
  CsvImuOptions opt;
  opt.rate_hz = 100.0;
  opt.gyro_unit = "rad/s";  // factor 1: values stay in deg/s and g as in the R reference
  opt.acc_unit = "m/s2";
  const auto series =
      readImuCsv(acq == 1 ? test::dataPath(file) : test::sharedPath("data/imu_static/" + file), opt);
  ASSERT_EQ(series.size(), 1000000u);
  const auto rows =
      readReference(test::dataPath("gmwm_r_reference/wv_adis_16405_imu" + std::to_string(acq) + ".csv"));
  ASSERT_FALSE(rows.empty());
  const auto wvs = gmwm::waveletVariances(series);
  std::map<std::string, const WaveletVariance*> byName;
  for (std::size_t c = 0; c < series.channels.size(); ++c) byName[series.channels[c].name] = &wvs[c];
  int checked = 0;
  for (const auto& r : rows) {
    ASSERT_TRUE(byName.count(r.axis)) << r.axis;
    const WaveletVariance& w = *byName[r.axis];
    ASSERT_EQ(w.scales(), 19);
    ASSERT_LE(r.j, w.scales());
    const int i = r.j - 1;
    EXPECT_EQ(w.n_coef[i], r.m) << r.axis << " j=" << r.j;
    EXPECT_LT(rel(w.eta[i], r.eta), 1e-12) << r.axis << " j=" << r.j;
    EXPECT_LT(rel(w.wv[i], r.wv), 1e-9) << r.axis << " j=" << r.j << " " << w.wv[i] << " vs " << r.wv;
    EXPECT_LT(rel(w.ci_low[i], r.lo), 1e-9) << r.axis << " j=" << r.j;
    EXPECT_LT(rel(w.ci_high[i], r.hi), 1e-9) << r.axis << " j=" << r.j;
    ++checked;
  }
  EXPECT_EQ(checked, 6 * 19);
}

INSTANTIATE_TEST_SUITE_P(Acquisitions, WvReference, ::testing::Values(1, 2, 3));

TEST(Wv, MatchesNaiveDefinitionWithLargeMean) {
  // large mean, white noise and a random walk
  const std::vector<double> x = gmwmtest::levelNoiseAndAr1(1000, 11, 1e3, 1.0, 1.0, 0.05);
  const auto w = gmwm::waveletVariance(x.data(), x.size(), 10.0);
  ASSERT_EQ(w.scales(), 9);  // floor(log2 1000)
  for (int j = 1; j <= 9; ++j) {
    EXPECT_EQ(w.tau[j - 1], std::ldexp(1.0, j));
    EXPECT_EQ(w.n_coef[j - 1], 1000.0 - std::ldexp(1.0, j) + 1.0);
    EXPECT_LT(rel(w.wv[j - 1], naiveWv(x, j)), 1e-11) << "j=" << j;
    EXPECT_LT(w.ci_low[j - 1], w.wv[j - 1]);
    EXPECT_GT(w.ci_high[j - 1], w.wv[j - 1]);
  }
  EXPECT_DOUBLE_EQ(w.tauSeconds()[0], 0.2);
}

TEST(Wv, BlockedPyramidMatchesWholeArrayPyramid) {
  // 200003 samples: several cache blocks in every stage of the blocked code.
  const std::vector<double> x = gmwmtest::levelNoiseAndAr1(200003, 5, -9.8, 0.01, 0.999, 0.1);
  const auto w = gmwm::waveletVariance(x.data(), x.size(), 100.0);
  const auto ref = simplePyramidWv(x, 17);
  ASSERT_EQ(w.scales(), 17);
  for (int j = 1; j <= 17; ++j) EXPECT_LT(rel(w.wv[j - 1], ref[j - 1]), 1e-12) << "j=" << j;
}

TEST(Wv, MaxLevelLimitsScales) {
  std::vector<double> x = {1, 3, 2, 5, 4, 4, 0, 1};
  const auto all = gmwm::waveletVariance(x.data(), x.size(), 1.0);
  EXPECT_EQ(all.scales(), 3);
  const auto two = gmwm::waveletVariance(x.data(), x.size(), 1.0, 0.05, 2);
  ASSERT_EQ(two.scales(), 2);
  EXPECT_EQ(two.wv[1], all.wv[1]);
  // j=1: W = (x_t - x_{t-1})/2 -> mean of squared half-differences.
  double s = 0;
  for (int t = 1; t < 8; ++t) s += 0.25 * (x[t] - x[t - 1]) * (x[t] - x[t - 1]);
  EXPECT_DOUBLE_EQ(all.wv[0], s / 7.0);
  EXPECT_THROW(gmwm::waveletVariance(x.data(), x.size(), 1.0, 0.05, 4), Error);
}

TEST(Wv, WhiteNoiseFollowsSigma2OverTau) {
  // Theory (gmwm_formulas.md §3): WN nu^2(tau) = sigma2 / tau. Each estimate
  // must lie within its own 99.9 % CI of the truth (fixed seed list).
  const double sigma2 = 4.0;
  for (unsigned seed : {1u, 2u, 3u}) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> nd(0.0, std::sqrt(sigma2));
    std::vector<double> x(1 << 16);
    for (auto& v : x) v = nd(rng);
    const auto w = gmwm::waveletVariance(x.data(), x.size(), 100.0, 0.001);
    for (int i = 0; i < w.scales() - 4; ++i) {
      const double truth = sigma2 / w.tau[i];
      EXPECT_LE(w.ci_low[i], truth) << "seed " << seed << " j=" << i + 1;
      EXPECT_GE(w.ci_high[i], truth) << "seed " << seed << " j=" << i + 1;
    }
  }
}

TEST(Wv, ConfidenceIntervalChiSquare) {
  double lo, hi;
  // eta = 2: chi2 quantiles are -2 ln(1-p): q(0.975) = 7.37775890822787, q(0.025) = 0.0506356159685798
  gmwm::wvConfidenceInterval(1.0, 2.0, 0.05, lo, hi);
  EXPECT_NEAR(lo, 2.0 / (-2.0 * std::log(0.025)), 1e-14);
  EXPECT_NEAR(hi, 2.0 / (-2.0 * std::log(0.975)), 1e-12);
  EXPECT_THROW(gmwm::wvConfidenceInterval(1.0, 0.0, 0.05, lo, hi), Error);
  EXPECT_THROW(gmwm::wvConfidenceInterval(1.0, 2.0, 1.5, lo, hi), Error);
}

TEST(Wv, BadInputThrows) {
  std::vector<double> three = {1, 2, 3};
  EXPECT_THROW(gmwm::waveletVariance(three.data(), three.size(), 1.0), Error);
  std::vector<double> nan = {1, 2, std::nan(""), 3, 4};
  try {
    gmwm::waveletVariance(nan.data(), nan.size(), 1.0);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("sample 2"), std::string::npos) << e.what();
  }
  std::vector<double> inf = {1, 2, 3, INFINITY};
  EXPECT_THROW(gmwm::waveletVariance(inf.data(), inf.size(), 1.0), Error);
  std::vector<double> cst(100, 0.7);
  try {
    gmwm::waveletVariance(cst.data(), cst.size(), 1.0);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("constant"), std::string::npos) << e.what();
  }
}

TEST(Wv, BatchNamesSourceAndChannel) {
  ImuSeries s = gmwmtest::seriesOf("some_file.csv", 100);
  for (int c = 0; c < 6; ++c) {
    ImuChannel ch = gmwmtest::channelOf(kChannelNames[c]);
    ch.x = {1, 2, 4, 3, 5, 1, 0, 2};
    if (c == 4) ch.x.assign(8, 9.81);
    s.channels.push_back(ch);
  }
  try {
    gmwm::waveletVariances(s);
    FAIL();
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("some_file.csv"), std::string::npos) << m;
    EXPECT_NE(m.find("acc_y"), std::string::npos) << m;
  }
  s.channels[4].x = s.channels[0].x;
  const auto w = gmwm::waveletVariances(s);
  ASSERT_EQ(w.size(), 6u);
  EXPECT_EQ(w[5].wv, w[0].wv);
}

// A result that is not finite (a sample so large that its square overflows) is
// an error naming the file, the channel and the cause, never inf in wv.csv.
TEST(Wv, NonFiniteResultIsAnErrorNamingTheCause) {
  const std::uint64_t seed = 77;
  std::mt19937_64 rng(seed);
  ImuSeries s = gmwmtest::seriesOf("big_sample.csv", 100);
  const int n = 512 + int(rng() % 512), at = int(rng() % n);
  const double big = std::pow(10.0, 160.0 + 140.0 * std::uniform_real_distribution<>(0, 1)(rng));
  SCOPED_TRACE("seed 77: n " + std::to_string(n) + " sample " + std::to_string(at) + " = " + std::to_string(big));
  ImuChannel ch = gmwmtest::channelOf("gyro_z");
  std::normal_distribution<> g(0, 1e-3);
  for (int i = 0; i < n; ++i) ch.x.push_back(g(rng));
  ch.x[at] = big;
  s.channels.push_back(ch);
  try {
    gmwm::waveletVariances(s);
    FAIL() << "accepted a non-finite wavelet variance";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("big_sample.csv: channel gyro_z: wavelet variance at tau"), std::string::npos) << m;
    EXPECT_NE(m.find("is not finite"), std::string::npos) << m;
  }
}

// The channels go over the worker pool: the wavelet variances (classical and
// robust) are the same whatever the thread count. Six channels of white noise
// plus a random walk, lengths and levels drawn at random (seeded, printed).
TEST(Wv, ChannelsGiveTheSameResultOnAnyNumberOfThreads) {
  const std::uint64_t seed = 20261125;
  std::mt19937_64 rng(seed);
  ImuSeries s = gmwmtest::seriesOf("threads.csv", 100);
  const int n = 1024 + int(rng() % 3000);
  std::cout << "seed " << seed << ": " << n << " samples per channel\n";
  for (int c = 0; c < 6; ++c) {
    ImuChannel ch = gmwmtest::channelOf(kChannelNames[c]);
    const double sigma = std::pow(10.0, std::uniform_real_distribution<>(-4, -1)(rng)), q = sigma * 1e-2;
    std::normal_distribution<> g(0, 1);
    double walk = 0.0;
    for (int i = 0; i < n; ++i) {
      walk += q * g(rng);
      ch.x.push_back(sigma * g(rng) + walk);
    }
    s.channels.push_back(ch);
  }
  for (bool robust : {false, true}) {
    gmwm::WvOptions o;
    o.robust = robust;
    o.threads = 1;
    const auto one = gmwm::waveletVariances(s, o);
    for (int threads : {2, 3, 6, 0}) {
      o.threads = threads;
      const auto many = gmwm::waveletVariances(s, o);
      ASSERT_EQ(many.size(), one.size());
      for (std::size_t c = 0; c < one.size(); ++c) {
        EXPECT_EQ(many[c].wv, one[c].wv) << "robust " << robust << ", " << threads << " threads, channel " << c;
        EXPECT_EQ(many[c].ci_low, one[c].ci_low);
        EXPECT_EQ(many[c].ci_high, one[c].ci_high);
      }
    }
  }
}
