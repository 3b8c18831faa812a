// run_diagnosis.json and report.md of `navimpact diagnose --run` say what the
// cause comparison decided: a named cause, or two causes the held-out outages
// do not tell apart.
#include <gtest/gtest.h>

#include <string>

#include <nlohmann/json.hpp>

#include "navimpact/analysis/run_diagnosis.hpp"
#include "navimpact/report/run_diagnosis_report.hpp"

namespace an = navimpact::analysis;
namespace rp = navimpact::report;

namespace {

/// Two significant causes; the top one added to the runner-up's extension gains @p gain_given at @p p_given.
an::RunDiagnosis twoCauses(double gain_given, double p_given, bool adds) {
  an::RunDiagnosis d;
  d.alpha = 0.05;
  d.folds = 3;
  an::CauseResult top, second;
  top.cause = "bias_instability";
  top.gain = 10.8;
  top.p_value = 0.0014;
  top.significant = true;
  top.given = "misalignment";
  top.gain_given = gain_given;
  top.p_given = p_given;
  top.adds = adds;
  second.cause = "misalignment";
  second.gain = 9.7;
  second.p_value = 0.0084;
  d.causes = {top, second};
  if (adds) {
    d.best = 0;
    an::RunFinding f;
    f.cause = top.cause;
    f.channel = "acc_z";
    f.params = {{"rw_density", 1e-3}};
    d.findings.push_back(f);
  }
  return d;
}

}  // namespace

TEST(RunDiagnosisReport, UndecidedBetweenTheTopCauseAndTheRunnerUp) {
  const an::RunDiagnosis d = twoCauses(-0.77, 0.98, false);
  const std::string md = rp::runDiagnosisMarkdown(d);
  EXPECT_NE(md.find("**Undecided between bias_instability and misalignment**"), std::string::npos) << md;
  EXPECT_EQ(md.find("No cause has a significant held-out gain"), std::string::npos) << md;
  EXPECT_EQ(md.find("**Cause:"), std::string::npos) << md;
  const auto js = nlohmann::json::parse(rp::runDiagnosisJson(d, "{}"));
  EXPECT_TRUE(js["findings"].empty());
  EXPECT_NE(js["gain"]["note"].get<std::string>().find("undecided between bias_instability and misalignment"),
            std::string::npos);
  EXPECT_EQ(js["causes"][0]["on_top_of_runner_up"]["runner_up_cause"], "misalignment");
  EXPECT_EQ(js["causes"][0]["on_top_of_runner_up"]["named"], false);
  EXPECT_FALSE(js["causes"][0].contains("on_top_of_best"));
}

TEST(RunDiagnosisReport, ATopCauseThatExplainsMoreThanTheRunnerUpIsNamed) {
  const an::RunDiagnosis d = twoCauses(75.9, 1.5e-4, true);
  const std::string md = rp::runDiagnosisMarkdown(d);
  EXPECT_NE(md.find("**Cause: bias_instability**"), std::string::npos) << md;
  EXPECT_EQ(md.find("Undecided"), std::string::npos) << md;
  const auto js = nlohmann::json::parse(rp::runDiagnosisJson(d, "{}"));
  ASSERT_EQ(js["findings"].size(), 1u);
  EXPECT_EQ(js["findings"][0]["cause"], "bias_instability");
  EXPECT_EQ(js["causes"][0]["on_top_of_runner_up"]["named"], true);
}

TEST(RunDiagnosisReport, ATopCauseTheRunnerUpAddsNothingToIsNamedAndSaysWhy) {
  // bias_instability adds 0.5 (not significant) on top of misalignment,
  // misalignment adds nothing (-1) on top of bias_instability
  an::RunDiagnosis d = twoCauses(0.5, 0.3, true);
  d.causes[1].given = "bias_instability";
  d.causes[1].gain_given = -1.0;
  d.causes[1].p_given = 0.99;
  const std::string md = rp::runDiagnosisMarkdown(d);
  EXPECT_NE(md.find("not significant, but misalignment adds nothing on top of bias_instability (below): "
                    "bias_instability named"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("misalignment added to the extension of bias_instability: held-out gain -1"), std::string::npos)
      << md;
  EXPECT_NE(md.find("**Cause: bias_instability**"), std::string::npos) << md;
}
