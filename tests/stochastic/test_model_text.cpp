// Text form of models and structures: round trips and every kind of error.
#include <gtest/gtest.h>

#include <random>

#include "navimpact/core/error.hpp"
#include "navimpact/stochastic/model_text.hpp"
#include "test_support.hpp"

using namespace navimpact::stochastic;

namespace {
using navimpact::test::errorOf;
std::string parseError(const std::string& text) {
  return errorOf([&] { parseTerms(text, 200.0); });
}
}  // namespace

TEST(ModelText, ParsesTheExample) {
  const auto t = parseTerms("WN(sigma=5.521e-3) + GM(sigma=4.811e-4, T=3.22) + DR(omega=9.302e-10)",
                            200.0);
  ASSERT_EQ(t.size(), 3u);
  EXPECT_EQ(t[0], Process::wn(5.521e-3));
  EXPECT_EQ(t[1], Process::gm(4.811e-4, 3.22));
  EXPECT_EQ(t[2], Process::dr(9.302e-10));
  EXPECT_EQ(formatTerms(t), "WN(sigma=0.005521) + GM(sigma=0.0004811, T=3.22) + DR(omega=9.302e-10)");
}

TEST(ModelText, AllKindsKeyOrderAndWhitespace) {
  const auto t = parseTerms(
      "  QN( Q = 1e-4 )+RW(gamma=2e-7)+GM(T=10,sigma=1)+SIN(freq=3.5, amp=0.2)+wn(sigma=1)", 100.0);
  ASSERT_EQ(t.size(), 5u);
  EXPECT_EQ(t[0], Process::qn(1e-4));
  EXPECT_EQ(t[1], Process::rw(2e-7));
  EXPECT_EQ(t[2], Process::gm(1.0, 10.0));
  EXPECT_EQ(t[3], Process::sin(0.2, 3.5));
  EXPECT_EQ(t[4], Process::wn(1.0));
}

TEST(ModelText, ParseModelGivesTheTermsAtTheRate) {
  const Model m = parseModel("WN(sigma=1e-3) + AR1(phi=0.5, sigma2=1)", 50.0);
  EXPECT_EQ(m.rate_hz, 50.0);
  ASSERT_EQ(m.terms.size(), 2u);
  EXPECT_EQ(formatTerms(m.terms, 17), formatTerms(parseTerms("WN(sigma=1e-3) + AR1(phi=0.5, sigma2=1)", 50.0), 17));
  EXPECT_NE(errorOf([] { parseModel("WN(sigma=)", 50.0); }).find("expected a number"), std::string::npos);
}

// At most limits::kMaxTermsPerModel terms: 32 load, 33 are refused before the
// 33rd is parsed (300,000 WN terms made emulate hold 2.5 GB).
TEST(ModelText, AtMostThirtyTwoTerms) {
  auto terms = [](int n) {
    std::string t = "WN(sigma=1e-3)";
    for (int i = 1; i < n; ++i) t += " + GM(sigma=1e-4, T=" + std::to_string(i) + ")";
    return t;
  };
  EXPECT_EQ(parseTerms(terms(32), 200.0).size(), 32u);
  const std::string e = parseError(terms(33));
  EXPECT_NE(e.find("expected at most 32 terms in one model"), std::string::npos) << e;
  EXPECT_LE(e.size(), 300u) << e;
}

TEST(ModelText, NoneIsEmpty) {
  EXPECT_TRUE(parseTerms("none", 200.0).empty());
  EXPECT_TRUE(parseTerms("  none ", 200.0).empty());
  EXPECT_EQ(formatTerms({}), "none");
}

TEST(ModelText, Ar1BecomesGm) {
  // R's AR1(phi, sigma2 innovation) at 200 Hz: T = -dt/ln(phi), sigma^2 = sigma2/(1-phi^2)
  const double phi = 0.9984487, s2 = 1.2e-9;
  const auto t = parseTerms("AR1(phi=0.9984487, sigma2=1.2e-9)", 200.0);
  ASSERT_EQ(t.size(), 1u);
  EXPECT_EQ(t[0].kind, ProcessKind::GM);
  EXPECT_NEAR(t[0].T, -0.005 / std::log(phi), 1e-9);
  EXPECT_NEAR(t[0].sigma, std::sqrt(s2 / (1 - phi * phi)), 1e-15);
  EXPECT_NE(parseError("AR1(phi=1.0, sigma2=1)").find("phi in (0, 1)"), std::string::npos);
  EXPECT_NE(errorOf([] { parseTerms("AR1(phi=0.5, sigma2=1)", 0.0); }).find("rate"),
            std::string::npos);
}

TEST(ModelText, RoundTripWith17DigitsIsExact) {
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<double> u(-30.0, 5.0);
  for (int i = 0; i < 300; ++i) {
    std::vector<Process> t = {Process::wn(std::pow(10.0, u(rng))),
                              Process::gm(std::pow(10.0, u(rng)), std::pow(10.0, u(rng) / 3)),
                              Process::qn(std::pow(10.0, u(rng))),
                              Process::rw(std::pow(10.0, u(rng))),
                              Process::dr(-std::pow(10.0, u(rng))),
                              Process::sin(std::pow(10.0, u(rng)), 1.0 / 3.0)};
    const std::string s = formatTerms(t, 17);
    const auto back = parseTerms(s, 200.0);
    ASSERT_EQ(back.size(), t.size());
    for (std::size_t k = 0; k < t.size(); ++k) EXPECT_EQ(back[k], t[k]) << s;
  }
}

TEST(ModelText, ErrorsNamePositionExpectedAndFound) {
  // unknown process
  EXPECT_EQ(parseError("WN(sigma=1) + XX(a=1)"),
            "model 'WN(sigma=1) + XX(a=1)': at position 15: expected a process name "
            "(WN, QN, RW, DR, GM, AR1, SIN), found 'XX'");
  // missing key
  EXPECT_EQ(parseError("GM(sigma=1)"),
            "model 'GM(sigma=1)': at position 11: expected key 'T' of GM(sigma, T), found ')'");
  // unknown key
  EXPECT_EQ(parseError("WN(sigm=1)"),
            "model 'WN(sigm=1)': at position 4: expected a key of WN (sigma), found unknown key "
            "'sigm'");
  // duplicate key
  EXPECT_EQ(parseError("GM(T=1, T=2, sigma=1)"),
            "model 'GM(T=1, T=2, sigma=1)': at position 9: expected each key once (sigma, T), "
            "found duplicate key 'T'");
  // bad number
  EXPECT_EQ(parseError("WN(sigma=1.2.3)"),
            "model 'WN(sigma=1.2.3)': at position 10: expected a number, found '1.2.3'");
  EXPECT_EQ(parseError("WN(sigma=)"),
            "model 'WN(sigma=)': at position 10: expected a number, found ')'");
  EXPECT_NE(parseError("WN(sigma=inf)").find("expected a finite number"), std::string::npos);
  // decimal only: strtod took hex, so sigma=0x10 loaded as 16
  EXPECT_EQ(parseError("WN(sigma=0x10)"), "model 'WN(sigma=0x10)': at position 10: expected a number, found '0x10'");
  // missing parentheses
  EXPECT_EQ(parseError("WN sigma=1"),
            "model 'WN sigma=1': at position 4: expected '(' after WN, found 'sigma'");
  EXPECT_EQ(parseError("WN(sigma=1"),
            "model 'WN(sigma=1': at position 11: expected ',' or ')', found end of text");
  // trailing garbage
  EXPECT_EQ(parseError("WN(sigma=1) foo"),
            "model 'WN(sigma=1) foo': at position 13: expected '+' or end of text, found 'foo'");
  EXPECT_EQ(parseError("WN(sigma=1) +"),
            "model 'WN(sigma=1) +': at position 14: expected a process name (WN, QN, RW, DR, "
            "GM, AR1, SIN), found end of text");
  // empty text, missing '=', trailing comma, garbage after none
  EXPECT_NE(parseError("").find("at position 1: expected 'none' or a process term"),
            std::string::npos);
  EXPECT_NE(parseError("WN(sigma 1)").find("expected '=' after sigma"), std::string::npos);
  EXPECT_NE(parseError("WN(sigma=1,)").find("at position 12: expected a key"),
            std::string::npos);
  EXPECT_NE(parseError("none + WN(sigma=1)").find("expected end of text after 'none'"),
            std::string::npos);
}

TEST(ModelText, ValidateNamesTheTerm) {
  Model m;
  m.rate_hz = 200.0;
  m.terms = parseTerms("WN(sigma=1e-3) + GM(sigma=-2e-4, T=3)", 200.0);  // parses fine
  const std::string e = errorOf([&] { validate(m); });
  EXPECT_NE(e.find("term 2 GM(sigma=-0.0002, T=3): sigma must be a finite number > 0"),
            std::string::npos)
      << e;
  m.terms = parseTerms("GM(sigma=2e-4, T=0)", 200.0);
  EXPECT_NE(errorOf([&] { validate(m); }).find("T must be"), std::string::npos);
  m.terms = parseTerms("SIN(amp=1, freq=100)", 200.0);  // at Nyquist
  EXPECT_NE(errorOf([&] { validate(m); }).find("Nyquist"), std::string::npos);
  m.terms = parseTerms("WN(sigma=1) + DR(omega=-1e-9) + SIN(amp=1, freq=99)", 200.0);
  EXPECT_NO_THROW(validate(m));  // negative drift slope is allowed
  m.rate_hz = 0.0;
  EXPECT_THROW(validate(m), navimpact::Error);
}

// An amplitude beyond the largest sample any reader accepts (1e5 in SI) is no
// IMU's: a WN sigma of 1e308 printed an ARW of inf with exit 0. The lower end
// stays open (a fitted WN sigma of 1e-66 loads) and so does GM T.
TEST(ModelText, AmplitudesBeyondAnyImuAreRefused) {
  Model m;
  m.rate_hz = 200.0;
  for (const char* bad : {"WN(sigma=1e308)", "GM(sigma=2e5, T=10)", "RW(gamma=1e6)", "DR(omega=-1e300)",
                          "QN(Q=1e6)", "SIN(amp=1e9, freq=1)"}) {
    m.terms = parseTerms(bad, 200.0);
    const std::string e = errorOf([&] { validate(m); });
    EXPECT_NE(e.find("is beyond any IMU (|"), std::string::npos) << bad << ": " << e;
  }
  m.terms = parseTerms("WN(sigma=7.2e-66) + GM(sigma=1e5, T=1e12) + RW(gamma=1e-300) + SIN(amp=1e5, freq=1)", 200.0);
  EXPECT_NO_THROW(validate(m));
}

TEST(ModelStructure, ParsesRepetitionAndAliases) {
  using K = ProcessKind;
  EXPECT_EQ(parseStructure("WN+GM+GM+DR"), (std::vector<K>{K::WN, K::GM, K::GM, K::DR}));
  EXPECT_EQ(parseStructure(" WN + 3GM + DR "),
            (std::vector<K>{K::WN, K::GM, K::GM, K::GM, K::DR}));
  EXPECT_EQ(parseStructure("2*AR1+QN+RW+SIN"),
            (std::vector<K>{K::GM, K::GM, K::QN, K::RW, K::SIN}));
  EXPECT_EQ(parseStructure("WN()+AR1()"), (std::vector<K>{K::WN, K::GM}));
  EXPECT_EQ(formatStructure(parseStructure("WN+2GM+DR")), "WN+GM+GM+DR");
  EXPECT_EQ(errorOf([] { parseStructure("WN+XY"); }),
            "structure 'WN+XY': at position 4: expected a process name (WN, QN, RW, DR, GM, AR1, "
            "SIN), found 'XY'");
  EXPECT_NE(errorOf([] { parseStructure("WN GM"); }).find("expected '+' or end of text"),
            std::string::npos);
  EXPECT_NE(errorOf([] { parseStructure("0GM"); }).find("repetition count"), std::string::npos);
  EXPECT_THROW(parseStructure(""), navimpact::Error);
  EXPECT_THROW(parseStructure("WN+"), navimpact::Error);
}
