// The one GNSS outage: the interval (start, end] it removes, its text form
// START:DURATION read back, and the one validation (order, overlap, span),
// on outages drawn at random over the whole documented range (seeded, logged),
// and the pattern PERIOD:DURATION of outages all along a run.
#include <gtest/gtest.h>

#include <cstdint>
#include <iostream>
#include <random>
#include <string>

#include "navimpact/core/error.hpp"
#include "navimpact/core/outage.hpp"

using navimpact::Outage;

namespace {

std::string errorOf(const std::vector<Outage>& w, double span, const std::string& after = "the data") {
  try {
    navimpact::checkOutages(w, span, after);
  } catch (const navimpact::Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Outage, CoversTheHalfOpenInterval) {
  const Outage o = Outage::fromStartDuration(200.0, 60.0);
  EXPECT_DOUBLE_EQ(o.end_s, 260.0);
  EXPECT_DOUBLE_EQ(o.duration_s(), 60.0);
  EXPECT_FALSE(o.covers(200.0));  // the fix at the start is the last one used
  EXPECT_TRUE(o.covers(200.000001));
  EXPECT_TRUE(o.covers(260.0));   // the fix at the end is not used
  EXPECT_FALSE(o.covers(260.000001));
  const Outage a = o.shifted(1000.0);
  EXPECT_DOUBLE_EQ(a.start_s, 1200.0);
  EXPECT_DOUBLE_EQ(a.end_s, 1260.0);
  EXPECT_TRUE(navimpact::inOutage(230.0, {Outage{0.0, 10.0}, o}));
  EXPECT_FALSE(navimpact::inOutage(100.0, {Outage{0.0, 10.0}, o}));
}

// An outage is named in a message by the key or flag that gave it where the
// caller has one, else "WHAT S:D"; more names than outages is a caller's error.
TEST(Outage, CheckNamesEachOutageByWhatGaveIt) {
  const std::vector<Outage> w = {{10.0, 20.0}, {15.0, 30.0}, {40.0, 50.0}};
  auto message = [&](const std::vector<std::string>& names, double span) {
    try {
      navimpact::checkOutages(w, span, "the data", "--outage", names);
    } catch (const navimpact::Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(message({"key 'a[0]'", "key 'a[1]'"}, 100.0),
            "key 'a[1]' starts before the previous outage ends at 20 s (outages in time order, no overlap)");
  EXPECT_EQ(message({"key 'a[0]'"}, 100.0),
            "--outage 15:15 starts before the previous outage ends at 20 s (outages in time order, no overlap)");
  EXPECT_EQ(message({"n0", "n1", "n2", "n3"}, 100.0), "checkOutages: 4 names for 3 outages");
}

TEST(Outage, ParsesStartColonDuration) {
  const Outage o = navimpact::parseOutage(" 200 : 60 ");
  EXPECT_DOUBLE_EQ(o.start_s, 200.0);
  EXPECT_DOUBLE_EQ(o.end_s, 260.0);
  EXPECT_EQ(navimpact::outageText(o), "200:60");
  for (const char* bad : {"200", "200-60", "abc", ":60", "200:", "200:60:1", "200:6O", ""})
    EXPECT_THROW(navimpact::parseOutage(bad), navimpact::Error) << bad;
  // outside the documented ranges: a start beyond the time axis [0, 1e10] s, a
  // duration outside [0.1 ms, 7 days] (1e300:10 used to end as "1e+300:0")
  for (const char* bad : {"-1:5", "5:0", "5:-1", "nan:5", "5:inf", "1e300:10", "1e11:10", "25:0.00001", "0:604801"}) {
    try {
      navimpact::parseOutage(bad, "--outage");
      ADD_FAILURE() << bad << " accepted";
    } catch (const navimpact::Error& e) {
      EXPECT_EQ(std::string(e.what()).rfind("--outage '" + std::string(bad) + "'", 0), 0u) << e.what();
    }
  }
}

TEST(Outage, TextReadsBackOverTheRange) {
  const std::uint64_t seed = 20261124;
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> s(0.0, 1e5), d(1e-3, 1e4);
  std::cout << "seed " << seed << ": 2000 outages, start U(0, 1e5) s, duration U(1e-3, 1e4) s\n";
  for (int i = 0; i < 2000; ++i) {
    // Round to what the text carries (6 significant digits), then read back exactly.
    const Outage o = navimpact::parseOutage(navimpact::outageText(Outage::fromStartDuration(s(g), d(g))));
    const Outage r = navimpact::parseOutage(navimpact::outageText(o));
    EXPECT_EQ(navimpact::outageText(r), navimpact::outageText(o));
    EXPECT_GT(r.end_s, r.start_s);
  }
}

TEST(Outage, OneValidation) {
  const std::vector<Outage> ok = {Outage::fromStartDuration(100, 30), Outage::fromStartDuration(130, 40)};
  EXPECT_EQ(errorOf(ok, 170.0), "");
  EXPECT_EQ(errorOf(ok, 170.0 - 0.5e-6), "");  // a microsecond of slack at the end
  EXPECT_EQ(errorOf(ok, 169.0), "outage 130:40 ends at 170 s, after the data");
  EXPECT_NE(errorOf({Outage::fromStartDuration(100, 30), Outage::fromStartDuration(120, 5)}, 200.0)
                .find("outage 120:5 starts before the previous outage ends at 130 s"),
            std::string::npos);
  EXPECT_NE(errorOf({Outage::fromStartDuration(100, 30), Outage::fromStartDuration(50, 5)}, 200.0)
                .find("starts before the previous outage"),
            std::string::npos);
  EXPECT_NE(errorOf({Outage{-1.0, 5.0}}, 200.0).find("START must be >= 0 s"), std::string::npos);
  EXPECT_NE(errorOf({Outage{5.0, 5.0}}, 200.0).find("DURATION > 0 s"), std::string::npos);
  // Random lists: valid ones pass, the same list with one outage moved past the span fails naming it.
  const std::uint64_t seed = 11;
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> gap(0.0, 50.0), len(0.01, 100.0);
  std::cout << "seed " << seed << ": 200 lists of 1-5 outages, gaps U(0, 50) s, durations U(0.01, 100) s\n";
  for (int i = 0; i < 200; ++i) {
    std::vector<Outage> w;
    double t = gap(g);
    for (int k = 0; k < 1 + int(g() % 5); ++k) {
      w.push_back(Outage::fromStartDuration(t, len(g)));
      t = w.back().end_s + gap(g);
    }
    EXPECT_EQ(errorOf(w, w.back().end_s), "");
    const double span = w.back().end_s - 1e-3;
    EXPECT_NE(errorOf(w, span).find(navimpact::outageText(w.back()) + " ends at"), std::string::npos);
  }
}

TEST(Outage, PatternClosedForm) {
  const navimpact::OutagePattern p = navimpact::parseOutagePattern("120:30");
  EXPECT_EQ(p.period_s, 120.0);
  EXPECT_EQ(p.duration_s, 30.0);
  // aided from 10 s, data to 500 s: starts 100, 220, 340 (ends 130, 250, 370);
  // the next (460..490) fits too; 580 does not.
  const auto w = navimpact::outagesEvery(p, 10.0, 500.0);
  ASSERT_EQ(w.size(), 4u);
  for (std::size_t k = 0; k < w.size(); ++k) {
    EXPECT_DOUBLE_EQ(w[k].start_s, 10.0 + (k + 1) * 120.0 - 30.0);
    EXPECT_DOUBLE_EQ(w[k].duration_s(), 30.0);
    // GNSS time before each outage = period - duration
    const double before = k == 0 ? w[k].start_s - 10.0 : w[k].start_s - w[k - 1].end_s;
    EXPECT_DOUBLE_EQ(before, 90.0);
  }
  EXPECT_TRUE(navimpact::outagesEvery(p, 0.0, 119.0).empty());
  for (const char* bad : {"30", "30:30", "20:30", "a:b", "120:0", "120:-1", ":", "1e-300:1e-301", "0.00005:0.00001",
                          "604801:30", "nan:1", "inf:1"})
    EXPECT_THROW(navimpact::parseOutagePattern(bad), navimpact::Error) << bad;
  EXPECT_NO_THROW(navimpact::parseOutagePattern("0.0002:0.0001"));  // both at the range's lower end
}

// Raw user text in a parse error is bounded and escaped (printable()): a control
// character or a megabyte argument does not reach the message as it is.
TEST(Outage, ParseErrorsEchoTheTextBoundedAndEscaped) {
  const std::string huge(1 << 20, '7');
  for (const std::string& bad : {std::string("12\n0:3\x1b[2J0"), std::string("120:0\t"), huge + ":x", "9:" + huge}) {
    for (int which = 0; which < 2; ++which) {
      try {
        if (which == 0) navimpact::parseOutagePattern(bad);
        else navimpact::parseOutage(bad, "--outage");
        ADD_FAILURE() << "accepted " << bad.size() << " bytes";
      } catch (const navimpact::Error& e) {
        const std::string m = e.what();
        EXPECT_LT(m.size(), 300u) << m;
        for (char ch : m) EXPECT_FALSE(static_cast<unsigned char>(ch) < 0x20) << m;
        const std::string head = which == 0 ? "outages every '" : "--outage '";
        EXPECT_EQ(m.rfind(head + navimpact::printable(bad, 60) + "'", 0), 0u) << m;
      }
    }
  }
}
