// report.md of `navimpact diagnose`: the scale table under a channel's findings
// shows the record the findings describe. The table is the raw record against
// the model; where cleaning (outliers, shifts, lines taken out) changed the WV,
// the cleaned WV stands beside the raw one, so that a finding's "N scales
// outside the 95 % CI" (of the cleaned record) can be read in the table.
#include <gtest/gtest.h>

#include <string>

#include "navimpact/analysis/diagnosis.hpp"
#include "navimpact/report/diagnosis_report.hpp"

namespace an = navimpact::analysis;
namespace rp = navimpact::report;

namespace {

/// One channel with one note and two scales outside the CI of the raw record.
an::Diagnosis withScales(const std::vector<double>& cleaned) {
  an::Diagnosis d;
  d.source = "x.csv";
  d.rate_hz = 100;
  an::ChannelDiagnosis c;
  c.name = "gyro_x";
  c.notes.push_back("1 outlier event taken out");
  for (int j = 0; j < 2; ++j) {
    an::ScaleCheck s;
    s.tau_s = 0.02 * (1 << j);
    s.measured = 4e-5 / (1 << j);
    s.model = 1e-5 / (1 << j);
    s.ci_low = 0.9 * s.model;
    s.ci_high = 1.1 * s.model;
    s.ratio = s.measured / s.model;
    s.outside95 = s.significant = true;
    c.scales.push_back(s);
  }
  c.wv_cleaned = cleaned;
  d.channels.push_back(c);
  return d;
}

}  // namespace

TEST(DiagnosisReport, TheScaleTableShowsTheCleanedWvBesideTheRawWhereCleaningChangedIt) {
  const std::string cleaned = rp::diagnosisReport(withScales({1.05e-5, 0.52e-5}), {});
  EXPECT_NE(cleaned.find("| tau [s] | measured WV (raw) | cleaned WV | model WV |"), std::string::npos) << cleaned;
  EXPECT_NE(cleaned.find("| 0.02 | 4e-05 | 1.05e-05 | 1e-05 |"), std::string::npos) << cleaned;
  EXPECT_NE(cleaned.find("the findings above are on the cleaned record"), std::string::npos) << cleaned;
  // nothing taken out: one WV column, no caption
  const std::string raw = rp::diagnosisReport(withScales({4e-5, 2e-5}), {});
  EXPECT_NE(raw.find("| tau [s] | measured WV | model WV |"), std::string::npos) << raw;
  EXPECT_EQ(raw.find("cleaned WV"), std::string::npos) << raw;
  EXPECT_EQ(raw.find("the findings above are on the cleaned record"), std::string::npos) << raw;
}

// An undecided finding names the two explanations the data leave open; where
// the runner-up is the same cause alone (the winner has another term beside
// it) it says so, instead of "undecided between random_walk and random_walk".
TEST(DiagnosisReport, AnUndecidedFindingNamesWhatIsUndecided) {
  an::Diagnosis d = withScales({4e-5, 2e-5});
  an::Finding f;
  f.channel = "gyro_x";
  f.cause = an::Cause::RandomWalk;
  f.decided = false;
  f.explanation = "x";
  f.runner_up = "random_walk";
  f.runner_up_detail = "RW(gamma=1e-3)";
  d.channels[0].findings.push_back(f);
  f.cause = an::Cause::Drift;
  d.channels[0].findings.push_back(f);
  const std::string r = rp::diagnosisReport(d, {});
  EXPECT_EQ(r.find("undecided between random_walk and random_walk"), std::string::npos) << r;
  EXPECT_NE(r.find("random_walk, undecided: with or without the other terms found"), std::string::npos) << r;
  EXPECT_NE(r.find("undecided between drift and random_walk"), std::string::npos) << r;
}
