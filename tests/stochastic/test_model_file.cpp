// YAML model files: the Table 1 file, strict keys, errors naming file and key,
// exact round trip through toYaml.
#include <gtest/gtest.h>

#include <fstream>
#include <random>

#include "navimpact/core/error.hpp"
#include "navimpact/stochastic/model_file.hpp"
#include "navimpact/stochastic/model_text.hpp"
#include "test_support.hpp"

using namespace navimpact::stochastic;
namespace test = navimpact::test;

namespace {
std::string table1() { return test::sourcePath("config/models/navchip_table1.yaml"); }

std::string write(const std::string& name, const std::string& text) {
  const auto p = test::tempDir() / name;
  std::ofstream(p) << text;
  return p.string();
}

using navimpact::test::errorOf;
}  // namespace

TEST(ModelFile, Table1HasTheEightModelsAndRef) {
  const auto names = listModels(table1());
  const std::vector<std::string> expected = {"acc_model1", "acc_model2", "acc_model3", "acc_ref",
                                             "gyro_model1", "gyro_model2", "gyro_model3",
                                             "gyro_ref", "ref"};
  EXPECT_EQ(names, expected);
  const ImuModel acc = loadImuModel(table1() + ":acc_ref");
  EXPECT_EQ(acc.rate_hz, 200.0);
  EXPECT_EQ(acc.name, "acc_ref");
  EXPECT_EQ(acc.source, table1() + ":acc_ref");
  for (int i = 0; i < 3; ++i) EXPECT_TRUE(acc.axis[i].empty());  // no gyro error
  const auto& ax = acc.forChannel("acc_y");
  EXPECT_EQ(ax.rate_hz, 200.0);
  ASSERT_EQ(ax.terms.size(), 5u);
  EXPECT_EQ(ax.terms[0], Process::wn(5.521e-3));
  EXPECT_EQ(ax.terms[3], Process::gm(4.003e-4, 556));
  EXPECT_EQ(ax.terms[4], Process::dr(9.302e-10));
  const ImuModel gyro = loadImuModel(table1() + ":gyro_ref");
  EXPECT_EQ(gyro.forChannel("gyro_z").terms[3], Process::gm(7.555e-5, 2008));
  for (int i = 3; i < 6; ++i) EXPECT_TRUE(gyro.axis[i].empty());
  const ImuModel ref = loadImuModel(table1() + ":ref");
  EXPECT_EQ(ref.axis[0].terms, gyro.axis[0].terms);
  EXPECT_EQ(ref.axis[5].terms, acc.axis[5].terms);
  for (const auto& n : names) EXPECT_NO_THROW(loadImuModel(table1() + ":" + n)) << n;
  // Model 1s are white noise only; model 2 acc has WN+GM+DR
  EXPECT_EQ(loadImuModel(table1() + ":gyro_model1").axis[0].count(ProcessKind::WN), 1);
  EXPECT_EQ(loadImuModel(table1() + ":acc_model2").axis[3].count(ProcessKind::DR), 1);
}

TEST(ModelFile, UnknownModelNameListsAvailable) {
  const std::string e = errorOf([] { loadImuModel(table1() + ":acc_model4"); });
  EXPECT_NE(e.find("no model named 'acc_model4'"), std::string::npos) << e;
  EXPECT_NE(e.find("available: acc_model1, acc_model2"), std::string::npos) << e;
  EXPECT_NE(errorOf([] { loadImuModel(table1()); }).find("select one as FILE:NAME"),
            std::string::npos);
}

TEST(ModelFile, SingleModelPerAxisOverrideAndRateOverride) {
  const auto f = write("single.yaml",
                       "rate_hz: 100\n"
                       "accelerometer: \"WN(sigma=1e-2)\"\n"
                       "gyroscope: \"WN(sigma=1e-3)\"\n"
                       "gyro_z: \"WN(sigma=2e-3) + RW(gamma=1e-7)\"\n");
  const ImuModel m = loadImuModel(f);
  EXPECT_EQ(m.name, "");
  EXPECT_EQ(m.rate_hz, 100.0);
  EXPECT_EQ(m.forChannel("gyro_x").terms, std::vector<Process>{Process::wn(1e-3)});
  EXPECT_EQ(m.forChannel("gyro_z").terms.size(), 2u);
  EXPECT_EQ(m.forChannel("acc_z").terms, std::vector<Process>{Process::wn(1e-2)});
  EXPECT_TRUE(listModels(f).empty());
  EXPECT_NE(errorOf([&] { loadImuModel(f + ":x"); }).find("single model"), std::string::npos);
  EXPECT_THROW(m.forChannel("mag_x"), navimpact::Error);

  const auto g = write("multi.yaml",
                       "rate_hz: 200\n"
                       "models:\n"
                       "  a:\n"
                       "    gyroscope: \"AR1(phi=0.99, sigma2=1e-8)\"\n"
                       "  b:\n"
                       "    rate_hz: 50\n"
                       "    accelerometer: none\n"
                       "    gyroscope: \"AR1(phi=0.99, sigma2=1e-8)\"\n");
  const ImuModel a = loadImuModel(g + ":a"), b = loadImuModel(g + ":b");
  EXPECT_EQ(a.rate_hz, 200.0);
  EXPECT_EQ(b.rate_hz, 50.0);
  EXPECT_EQ(b.axis[1].rate_hz, 50.0);
  EXPECT_TRUE(b.axis[4].empty());
  // the AR1 -> GM conversion uses the model's own rate
  EXPECT_NEAR(a.axis[0].terms[0].T * 4, b.axis[0].terms[0].T, 1e-12);
}

TEST(ModelFile, ErrorsNameFileAndKey) {
  const auto typo = write("typo.yaml",
                          "rate_hz: 200\nmodels:\n  acc2:\n    gyroscop: \"WN(sigma=1)\"\n");
  std::string e = errorOf([&] { loadImuModel(typo + ":acc2"); });
  EXPECT_NE(e.find(typo), std::string::npos) << e;
  EXPECT_NE(e.find("models.acc2.gyroscop"), std::string::npos) << e;
  EXPECT_NE(e.find("unknown key (accepted: acc_x, acc_y, acc_z, accelerometer, description, gyro_x"), std::string::npos) << e;

  const auto top = write("top.yaml", "rate_hz: 200\naccelerometr: \"WN(sigma=1)\"\n");
  EXPECT_NE(errorOf([&] { loadImuModel(top); }).find("'accelerometr': unknown key"),
            std::string::npos);

  const auto norate = write("norate.yaml", "gyroscope: \"WN(sigma=1)\"\n");
  EXPECT_NE(errorOf([&] { loadImuModel(norate); }).find("'rate_hz': missing"), std::string::npos);

  const auto badrate = write("badrate.yaml", "rate_hz: fast\ngyroscope: \"WN(sigma=1)\"\n");
  EXPECT_NE(errorOf([&] { loadImuModel(badrate); }).find("key 'rate_hz': must be a number in [1, 10000] Hz, got 'fast'"),
            std::string::npos);

  const auto badmodel = write("badmodel.yaml", "rate_hz: 200\ngyroscope: \"WN(sigma=1\"\n");
  e = errorOf([&] { loadImuModel(badmodel); });
  EXPECT_NE(e.find("key 'gyroscope'"), std::string::npos) << e;
  EXPECT_NE(e.find("at position 11: expected ',' or ')'"), std::string::npos) << e;

  const auto neg = write("neg.yaml", "rate_hz: 200\nmodels:\n  m:\n    acc_x: \"WN(sigma=-1)\"\n");
  e = errorOf([&] { loadImuModel(neg); });  // single named model: FILE alone selects it
  EXPECT_NE(e.find("models.m.acc_x"), std::string::npos) << e;
  EXPECT_NE(e.find("term 1 WN(sigma=-1): sigma must be"), std::string::npos) << e;

  const auto syntax = write("syntax.yaml", "rate_hz: 200\ngyroscope: [unclosed\n");
  e = errorOf([&] { loadImuModel(syntax); });
  EXPECT_NE(e.find("YAML syntax error"), std::string::npos) << e;

  const auto dup = write("dup.yaml", "rate_hz: 200\ngyroscope: none\ngyroscope: none\n");
  EXPECT_NE(errorOf([&] { loadImuModel(dup); }).find("duplicate key"), std::string::npos);

  const auto numeric = write("numeric.yaml", "rate_hz: 200\ngyroscope: [1, 2]\n");
  EXPECT_NE(errorOf([&] { loadImuModel(numeric); }).find("expected a model string"),
            std::string::npos);

  // an empty value loaded as a perfect sensor; "none" says so on purpose
  const auto empty = write("empty.yaml", "rate_hz: 200\ngyroscope: \"WN(sigma=1)\"\naccelerometer:\n");
  EXPECT_NE(errorOf([&] { loadImuModel(empty); }).find("key 'accelerometer': is empty: write a model string"),
            std::string::npos);

  EXPECT_NE(errorOf([] { loadImuModel("/nonexistent/x.yaml"); }).find("cannot open"),
            std::string::npos);
}

TEST(ModelFile, ToYamlRoundTripIsExact) {
  std::mt19937_64 rng(31337);
  std::uniform_real_distribution<double> u(-9.0, -1.0);
  auto r = [&] { return std::pow(10.0, u(rng)); };
  for (int it = 0; it < 20; ++it) {
    ImuModel m;
    m.rate_hz = 200.0 + it / 3.0;
    for (int i = 0; i < 6; ++i) {
      m.axis[i].rate_hz = m.rate_hz;
      // some axes share, some differ, one is empty
      if (i == 2 && it % 2) continue;
      m.axis[i].terms = {Process::wn(r()), Process::gm(r(), 1.0 / r())};
      if (i >= 3 && it % 3 == 0) m.axis[i].terms = m.axis[3].terms;
      if (i == 4) m.axis[i].terms.push_back(Process::dr(-r()));
    }
    const std::string y = toYaml(m, "round trip\nsecond line");
    const auto f = write("rt.yaml", y);
    const ImuModel b = loadImuModel(f);
    EXPECT_EQ(b.rate_hz, m.rate_hz);
    for (int i = 0; i < 6; ++i) EXPECT_EQ(b.axis[i].terms, m.axis[i].terms) << y;
  }
}

TEST(ModelFile, ConvertImuModel) {
  const ImuModel m = loadImuModel(table1() + ":ref");
  const ImuModel c = convertRate(m, 100.0);
  EXPECT_EQ(c.rate_hz, 100.0);
  for (int i = 0; i < 6; ++i) {
    EXPECT_EQ(c.axis[i].rate_hz, 100.0);
    Model a = m.axis[i];
    EXPECT_EQ(c.axis[i].terms, convertRate(a, 100.0).terms);
  }
  EXPECT_NEAR(c.axis[0].terms[0].sigma, 9.788e-4 * std::sqrt(0.5), 1e-18);
  EXPECT_NEAR(c.axis[3].terms[4].omega, 2 * 9.302e-10, 1e-24);
}

// A model given as text (a rawlog scenario records its model this way) reads as
// the same file would, named by its source in errors; no file is written.
TEST(ModelFile, ParsedFromTextAsFromItsFile) {
  const ImuModel ref = loadImuModel(table1() + ":ref");
  const std::string y = toYaml(ref, "scenario model");
  const ImuModel m = parseImuModel(y, "run.rawlog (scenario imu_model_yaml)");
  EXPECT_EQ(m.rate_hz, ref.rate_hz);
  EXPECT_EQ(m.source, "run.rawlog (scenario imu_model_yaml)");
  for (int i = 0; i < 6; ++i) EXPECT_EQ(m.axis[i].terms, ref.axis[i].terms);
  const std::string e = errorOf([] { parseImuModel("rate_hz: 200\ngyroscope: none\ngyroscope: none\n", "run.rawlog"); });
  EXPECT_NE(e.find("run.rawlog: key 'gyroscope': duplicate key (line 3; first at line 2)"), std::string::npos) << e;
  const std::string n = errorOf([] { parseImuModel("rate_hz: 200\nmodels: {a: {gyroscope: none}}\n", "t", "b"); });
  EXPECT_NE(n.find("t: no model named 'b' (available: a)"), std::string::npos) << n;
}
