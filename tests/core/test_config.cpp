// The one configuration reader: every failure names the file and the dotted
// key in one format; unknown and duplicate keys are errors; values are checked
// for type, unit (the range names it) and range.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "navimpact/core/config.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/limits.hpp"
#include "test_support.hpp"

using navimpact::ConfigNode;
using navimpact::Error;
namespace limits = navimpact::limits;

namespace {

using navimpact::test::errorOf;

ConfigNode doc(const std::string& text) { return ConfigNode::parse(text, "cfg.yaml"); }

}  // namespace

TEST(Config, ReadsTypedValuesAndKeepsDefaultsWhenAbsent) {
  const ConfigNode c = doc(
      "rate_hz: 200\nname: uav\nflag: yes\nseed: 18446744073709551615\n"
      "filter: {propagate_every: 10}\nlever_arm_B_m: [0.5, -0.25, 1]\ntimes_s: [1, 10]\n"
      "labels: [a, b]\nlist: [{x: 1}, {x: 2}]\n");
  double rate = 1, absent = 7;
  EXPECT_TRUE(c.read("rate_hz", rate, limits::kImuRateHz));
  EXPECT_FALSE(c.read("absent_hz", absent, limits::kImuRateHz));
  EXPECT_EQ(rate, 200.0);
  EXPECT_EQ(absent, 7.0);
  EXPECT_EQ(c.text("name"), "uav");
  bool flag = false;
  c.read("flag", flag);
  EXPECT_TRUE(flag);
  std::uint64_t seed = 0;
  c.readSeed("seed", seed);
  EXPECT_EQ(seed, 18446744073709551615ull);
  int k = 1;
  c.map("filter").read("propagate_every", k, 1, 1000);
  EXPECT_EQ(k, 10);
  Eigen::Vector3d l = Eigen::Vector3d::Zero();
  c.read("lever_arm_B_m", l, limits::kLeverArmM);
  EXPECT_EQ(l, Eigen::Vector3d(0.5, -0.25, 1));
  std::vector<double> ts;
  c.read("times_s", ts, limits::kDurationS);
  EXPECT_EQ(ts, (std::vector<double>{1, 10}));
  std::vector<std::string> labels;
  c.read("labels", labels);
  EXPECT_EQ(labels, (std::vector<std::string>{"a", "b"}));
  const auto items = c.list("list");
  ASSERT_EQ(items.size(), 2u);
  EXPECT_EQ(items[1].path(), "list[1]");
  EXPECT_EQ(items[1].number("x", limits::kDurationS), 2.0);
  EXPECT_EQ(c.keys(), (std::vector<std::string>{"rate_hz", "name", "flag", "seed", "filter", "lever_arm_B_m",
                                                "times_s", "labels", "list"}));
}

TEST(Config, UnknownKeyNamesTheFileTheDottedKeyAndTheAcceptedKeys) {
  const ConfigNode c = doc("gnss: {rate_hz: 1, seeed: 4}\nimu: {rate_hz: 200}\n");
  EXPECT_NO_THROW(c.allowKeys({"imu", "gnss"}));
  EXPECT_EQ(errorOf([&] { c.map("gnss").allowKeys({"seed", "rate_hz"}); }),
            "cfg.yaml: key 'gnss.seeed': unknown key (accepted: rate_hz, seed)");
  EXPECT_EQ(errorOf([&] { c.allowKeys({"gnss"}); }), "cfg.yaml: key 'imu': unknown key (accepted: gnss)");
  // nested deeper, inside a list
  const ConfigNode d = doc("sweep:\n  gnss:\n    - {name: a, rate: 1}\n");
  EXPECT_EQ(errorOf([&] { d.map("sweep").list("gnss")[0].allowKeys({"name", "rate_hz"}); }),
            "cfg.yaml: key 'sweep.gnss[0].rate': unknown key (accepted: name, rate_hz)");
}

TEST(Config, DuplicateKeysAreErrorsEvenWhereNothingReadsThem) {
  // yaml-cpp alone would keep one of the two values silently.
  EXPECT_EQ(errorOf([] { doc("gnss: {rate_hz: 1}\nbaro: {}\ngnss: {rate_hz: 5}\n"); }),
            "cfg.yaml: key 'gnss': duplicate key (line 3; first at line 1)");
  EXPECT_EQ(errorOf([] { doc("a:\n  b:\n    - {c: 1, c: 2}\n"); }),
            "cfg.yaml: key 'a.b[0].c': duplicate key (line 3; first at line 3)");
  EXPECT_EQ(errorOf([] { doc("filter:\n  propagate_every: 10\n  propagate_every: 20\n"); }),
            "cfg.yaml: key 'filter.propagate_every': duplicate key (line 3; first at line 2)");
  const std::string complex = errorOf([] { doc("? [1, 2]\n: 3\n"); });
  EXPECT_NE(complex.find("cfg.yaml:1:3: key '?': a key must be a plain name"), std::string::npos) << complex;
}

TEST(Config, AliasesAreReadAsTheirValueAndMergeKeysAreRefused) {
  // One rule: an alias (*NAME) stands for its whole value and is checked like
  // it; a merge key (<<: *NAME) is refused, so no key can come both from a
  // merge and directly (yaml-cpp would not merge it, and which one wins would
  // be a second rule).
  const ConfigNode c = doc("base: &b {rate_hz: 5, sigma_m: 2}\ngnss: *b\n");
  double rate = 0;
  EXPECT_TRUE(c.map("gnss").read("rate_hz", rate, limits::kImuRateHz));
  EXPECT_EQ(rate, 5.0);
  EXPECT_EQ(errorOf([] { doc("base: &b {rate_hz: 5}\ngnss:\n  <<: *b\n  rate_hz: 1\n"); }),
            "cfg.yaml: key 'gnss.<<': merge keys (<<: *NAME) are not supported: write the keys out "
            "(a whole value may be an alias *NAME)");
  EXPECT_EQ(errorOf([] { doc("a: &b {x: 1}\nc: [{<<: *b}]\n"); }).rfind("cfg.yaml: key 'c[0].<<': merge keys", 0), 0u);
  // a duplicate inside an anchored map is reported where the map is written
  EXPECT_EQ(errorOf([] { doc("base: &b {x: 1, x: 2}\n"); }), "cfg.yaml: key 'base.x': duplicate key (line 1; first at line 1)");
}

TEST(Config, NestedAliasesCannotExpandWithoutBound) {
  // Ten levels of ten aliases stand for 10^10 nodes in about 400 bytes
  // ("billion laughs"): refused after a bounded walk, naming the file.
  std::string text = "l0: &l0 [x, x, x, x, x, x, x, x, x, x]\n";
  for (int i = 1; i <= 10; ++i) {
    text += "l" + std::to_string(i) + ": &l" + std::to_string(i) + " [";
    for (int j = 0; j < 10; ++j) text += (j ? ", *l" : "*l") + std::to_string(i - 1);
    text += "]\n";
  }
  const std::string e = errorOf([&] { doc(text); });
  EXPECT_EQ(e.rfind("cfg.yaml: aliases (*NAME) expand the document to more than 1000000 nodes", 0), 0u) << e;
  // aliases nested a little are read
  std::string small = "l0: &l0 [1, 2]\nl1: &l1 [*l0, *l0]\nl2: [*l1, *l1, *l1]\n";
  EXPECT_EQ(errorOf([&] { doc(small); }), "(no error)");
}

// Found by the bad-input battery: texts yaml-cpp accepts and misreads. An
// alias inside its own anchor is a node that contains itself (the key check
// recursed until the stack overflowed: a segfault in every command); a second
// document after '---' was ignored, a NUL byte dropped; nesting beyond
// yaml-cpp's depth limit said "bad file".
TEST(Config, TextsYamlCppMisreadsAreRefusedNamingFileAndPlace) {
  for (const char* text : {"a: &x [*x]\n", "a: &x {b: *x}\n", "ok: 1\nlist: [1, &x [2, *x]]\n"}) {
    const std::string e = errorOf([&] { doc(text); });
    EXPECT_EQ(e.rfind("cfg.yaml: key '", 0), 0u) << text << e;
    EXPECT_NE(e.find("nested deeper than 1200 levels (an alias *NAME inside its own anchor?)"), std::string::npos) << e;
  }
  EXPECT_EQ(errorOf([] { doc("a: 1\n---\na: 2\n"); }),
            "cfg.yaml:3: a second YAML document (after '---'): a file holds one document");
  EXPECT_EQ(errorOf([] { doc("---\na: 1\n...\n"); }), "(no error)");  // one document, its markers
  EXPECT_EQ(errorOf([] { doc("a: 1\n---\n"); }), "(no error)");       // an empty second one says nothing
  EXPECT_EQ(errorOf([] { doc(std::string("a: /x\0/y\n", 10)); }),
            "cfg.yaml:1:6: control character \\x00 (YAML text holds printable characters, tabs and line breaks)");
  EXPECT_EQ(errorOf([] { doc("a: 1\r\n\tb: 2\x7f\n"); }).rfind("cfg.yaml:2:6: control character \\x7F", 0), 0u);
  EXPECT_EQ(errorOf([] { doc("a: 1\r\nb: [1,\t2]\r\n"); }), "(no error)");  // CRLF and tabs are YAML
  // UTF-16 (with its byte-order mark) is YAML, decoded by yaml-cpp: its zero bytes are no NUL characters
  const std::string utf16("\xFF\xFE" "a\0:\0 \0" "1\0\n\0", 12);
  EXPECT_EQ(doc(utf16).number("a", limits::kImuRateHz), 1.0);
  const std::string deep = errorOf([] { doc("a: " + std::string(5000, '[') + "\n"); });
  EXPECT_EQ(deep.rfind("cfg.yaml:", 0), 0u) << deep;
  EXPECT_NE(deep.find(": YAML syntax error: nested deeper than "), std::string::npos) << deep;
}

// Found by the libFuzzer run (tests/fuzz/regressions/covariance_config): on a
// ',' where a document starts yaml-cpp 0.7 builds nodes without end (a 61-byte
// configuration took 3.6 GB in 9 s, and the fuzzing harness hung in its
// out-of-memory handler). Refused after a bounded parse, naming file and place.
TEST(Config, TextOnWhichYamlCppDoesNotEndIsRefusedNamingFileAndPlace) {
  const std::string e = errorOf([] { doc(","); });
  EXPECT_EQ(e.rfind("cfg.yaml:1:1: YAML syntax error: the YAML parser (yaml-cpp) does not come to an end", 0), 0u) << e;
  const std::string f = errorOf([] { doc("# a comment\n# another\n  , nor@th(4t\n"); });
  EXPECT_EQ(f.rfind("cfg.yaml:3:3: YAML syntax error: the YAML parser (yaml-cpp) does not come to an end", 0), 0u) << f;
  // what YAML allows with few bytes per node stays within the bound
  EXPECT_EQ(errorOf([] { doc("a: [" + std::string(20000, ',') + "]\nb: " + std::string(2000, '[') + "\n"); })
                .find("does not come to an end"),
            std::string::npos);
  std::string many = "a: &a 1\nb: [";
  for (int i = 0; i < 20000; ++i) many += "*a,";
  EXPECT_EQ(errorOf([&] { doc(many + "]\nc:\n" + std::string(100, '-') + "\n"); }), "(no error)");
}

TEST(Config, WrongTypeSaysWhatWasExpectedAndWhatCame) {
  const ConfigNode c = doc("flag: perhaps\nn: [1, 2]\nseed: -5\nv: [1, 2]\nmode: fast\nk: 2.5\n"
                           "text: {a: 1}\nsigma_m: two\nlong: " + std::string(300, 'x') + "\n");
  bool b = false;
  EXPECT_EQ(errorOf([&] { c.read("flag", b); }), "cfg.yaml: key 'flag': must be true or false, got 'perhaps'");
  double x = 0;
  EXPECT_EQ(errorOf([&] { c.read("n", x, limits::kDurationS); }),
            "cfg.yaml: key 'n': must be a number in [0.0001, 604800] s, got a list");
  EXPECT_EQ(errorOf([&] { c.read("sigma_m", x, limits::kPositionSigmaM); }),
            "cfg.yaml: key 'sigma_m': must be a number in [0.0001, 10000] m, got 'two'");
  std::uint64_t s = 0;
  EXPECT_EQ(errorOf([&] { c.readSeed("seed", s); }),
            "cfg.yaml: key 'seed': must be an integer seed in 0..18446744073709551615, got '-5'");
  Eigen::Vector3d v;
  EXPECT_EQ(errorOf([&] { c.read("v", v, limits::kLeverArmM); }),
            "cfg.yaml: key 'v': must be a list of 3 numbers in [-100, 100] m, got 2 items");
  std::string m;
  EXPECT_EQ(errorOf([&] { c.readChoice("mode", m, {"series", "vanloan"}); }),
            "cfg.yaml: key 'mode': must be one of series, vanloan, got 'fast'");
  int k = 0;
  EXPECT_EQ(errorOf([&] { c.read("k", k, 1, 10); }), "cfg.yaml: key 'k': must be an integer in 1..10, got '2.5'");
  EXPECT_EQ(errorOf([&] { c.read("text", m); }), "cfg.yaml: key 'text': must be a text, got a map");
  EXPECT_EQ(errorOf([&] { c.map("flag"); }), "cfg.yaml: key 'flag': must be a map of keys, got 'perhaps'");
  // a long value is echoed bounded
  const std::string e = errorOf([&] { c.read("long", k, 1, 10); });
  EXPECT_LT(e.size(), 120u) << e;
  EXPECT_NE(e.find("...(300 bytes)"), std::string::npos) << e;
}

// The range states the unit of the key; both ends are enforced, an open end
// excluded, non-finite values refused.
TEST(Config, RangeAndUnitOfEveryNumber) {
  const ConfigNode c = doc(
      "rate_hz: 0.5\nhigh_hz: 10000\nsigma_m: 0\ntiny_m: 1e-300\nnan_m: .nan\ninf_m: .inf\n"
      "lever: [0, 100.5, 0]\nruns: 1000001\n");
  double x = 0;
  EXPECT_EQ(errorOf([&] { c.read("rate_hz", x, limits::kImuRateHz); }),
            "cfg.yaml: key 'rate_hz': must be in [1, 10000] Hz, got 0.5");
  EXPECT_NO_THROW(c.read("high_hz", x, limits::kImuRateHz));
  EXPECT_EQ(x, 1e4);
  EXPECT_EQ(errorOf([&] { c.read("sigma_m", x, limits::kPositionSigmaM); }),
            "cfg.yaml: key 'sigma_m': must be in [0.0001, 10000] m, got 0");
  // a positive value has a realistic lower bound, not 0 (1e-300 squared is 0)
  EXPECT_EQ(errorOf([&] { c.read("tiny_m", x, limits::kPositionSigmaM); }),
            "cfg.yaml: key 'tiny_m': must be in [0.0001, 10000] m, got 1e-300");
  EXPECT_EQ(errorOf([&] { c.read("tiny_m", x, limits::Range{0.0, 1.0, true, "m"}); }), "(no error)");  // an open end excludes only 0
  EXPECT_EQ(errorOf([&] { c.read("sigma_m", x, limits::Range{0.0, 1.0, true, "m"}); }),
            "cfg.yaml: key 'sigma_m': must be in (0, 1] m, got 0");
  EXPECT_NE(errorOf([&] { c.read("nan_m", x, limits::kPositionSigmaM); }).find("key 'nan_m': must be in [0.0001, 10000] m"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { c.read("inf_m", x, limits::kPositionSigmaM); }).find("key 'inf_m': must be in [0.0001, 10000] m"),
            std::string::npos);
  Eigen::Vector3d v;
  EXPECT_EQ(errorOf([&] { c.read("lever", v, limits::kLeverArmM); }),
            "cfg.yaml: key 'lever[1]': must be in [-100, 100] m, got 100.5");
  long long runs = 0;
  EXPECT_EQ(errorOf([&] { c.read("runs", runs, 1, limits::kMaxMonteCarloRuns); }),
            "cfg.yaml: key 'runs': must be an integer in 1..1000000, got 1000001");
  EXPECT_EQ(errorOf([&] { c.number("absent_s", limits::kDurationS, "the outage"); }),
            "cfg.yaml: key 'absent_s': missing (a number in [0.0001, 604800] s: the outage)");
}

TEST(Config, FilesAreNamedInEveryMessageAndPathsAreRelativeToTheirFolder) {
  const auto dir = navimpact::test::tempDir();
  std::filesystem::create_directories(dir / "sub");
  std::ofstream(dir / "sub" / "x.csv") << "t\n";
  std::ofstream(dir / "m.yaml") << "rate_hz: 100\n";
  std::ofstream(dir / "a:b.yaml") << "rate_hz: 100\n";
  const auto f = (dir / "c.yaml").string();
  std::ofstream(f) << "data: sub/../sub/x.csv\nabs: " << (dir / "sub" / "x.csv").string()
                   << "\nmodel: m.yaml:ref\nwhole: a:b.yaml\nfilter: {propagate_every: 0}\n";
  const ConfigNode c = ConfigNode::load(f);
  EXPECT_EQ(c.inputFile("data", "a CSV"), (dir / "sub" / "x.csv").string());
  EXPECT_EQ(c.inputFile("abs", "a CSV"), (dir / "sub" / "x.csv").string());
  EXPECT_EQ(errorOf([&] { c.inputFile("none", "the IMU CSV"); }), f + ": key 'none': missing (the IMU CSV)");
  EXPECT_EQ(c.modelRef("model"), (dir / "m.yaml").string() + ":ref");
  EXPECT_EQ(c.modelRef("whole"), (dir / "a:b.yaml").string());
  EXPECT_EQ(c.modelRef("none"), "");
  int k = 1;
  EXPECT_EQ(errorOf([&] { c.map("filter").read("propagate_every", k, 1, 1000); }),
            f + ": key 'filter.propagate_every': must be an integer in 1..1000, got 0");
  EXPECT_EQ(errorOf([] { ConfigNode::load("/nonexistent/c.yaml"); }),
            "/nonexistent/c.yaml: cannot open (No such file or directory)");
  const auto bad = (dir / "bad.yaml").string();
  std::ofstream(bad) << "a: 1\nb: [unclosed\n";
  EXPECT_NE(errorOf([&] { ConfigNode::load(bad); }).find(bad + ":3:1: YAML syntax error: "), std::string::npos)
      << errorOf([&] { ConfigNode::load(bad); });
  const auto lst = (dir / "list.yaml").string();
  std::ofstream(lst) << "- 1\n- 2\n";
  EXPECT_EQ(errorOf([&] { ConfigNode::load(lst); }), lst + ": expected a map of keys at the top level, got a list");
  EXPECT_TRUE(ConfigNode::parse("", "empty.yaml").keys().empty());
}

// A file named by a key that cannot be read is named with the configuration,
// the key and the path it was resolved to, with the system's reason, whatever
// the key (an input file or the FILE of a model reference).
TEST(Config, AnInputFileThatCannotBeReadNamesTheConfigurationAndTheKey) {
  const auto dir = navimpact::test::tempDir();
  std::filesystem::create_directories(dir / "folder");
  ASSERT_EQ(::mkfifo((dir / "fifo").c_str(), 0600), 0);
  const auto f = (dir / "c.yaml").string();
  std::ofstream(f) << "imu: {file: x.csv}\nfolder: folder\nfifo: fifo\nempty: ''\nlist: [a]\n"
                      "model: nope.yaml:ref\nmodel_folder: folder:ref\nmodel_empty: ''\n";
  const ConfigNode c = ConfigNode::load(f);
  const std::string d = dir.string() + "/";
  EXPECT_EQ(errorOf([&] { c.map("imu").inputFile("file", "the IMU CSV"); }),
            f + ": key 'imu.file': cannot open '" + d + "x.csv' (No such file or directory)");
  EXPECT_EQ(errorOf([&] { c.inputFile("folder", "a CSV"); }),
            f + ": key 'folder': cannot open '" + d + "folder' (Is a directory)");
  EXPECT_EQ(errorOf([&] { c.inputFile("fifo", "a CSV"); }),  // (opening a FIFO would block)
            f + ": key 'fifo': cannot open '" + d + "fifo' (not a regular file)");
  EXPECT_EQ(errorOf([&] { c.inputFile("empty", "the rawlog"); }),
            f + ": key 'empty': must be a non-empty path (the rawlog)");
  EXPECT_EQ(errorOf([&] { c.inputFile("list", "the rawlog"); }), f + ": key 'list': must be a text, got a list");
  EXPECT_EQ(errorOf([&] { c.modelRef("model"); }),
            f + ": key 'model': cannot open '" + d + "nope.yaml' (No such file or directory)");
  EXPECT_EQ(errorOf([&] { c.modelRef("model_folder"); }),
            f + ": key 'model_folder': cannot open '" + d + "folder' (Is a directory)");
  EXPECT_EQ(errorOf([&] { c.modelRef("model_empty"); }),  // (it meant "the default model" silently)
            f + ": key 'model_empty': must be a model FILE[:NAME], got ''");
  // a configuration itself: a FIFO is refused before it is opened (reading it would block)
  EXPECT_EQ(errorOf([&] { ConfigNode::load(d + "fifo"); }), d + "fifo: cannot open (not a regular file)");
  EXPECT_EQ(errorOf([&] { ConfigNode::readText(d + "folder"); }), d + "folder: cannot open (Is a directory)");
}

// A value just outside its range is printed with the digits that make it
// outside (0.1000001 was "got 0.1" beside "[-0.1, 0.1]"); others as %g.
TEST(Config, AValueOutOfRangeIsPrintedAsItIs) {
  EXPECT_EQ(errorOf([] { limits::check("f.yaml", "offset_s", 0.1000001, limits::kTimeOffsetS); }),
            "f.yaml: key 'offset_s': must be in " + limits::describe(limits::kTimeOffsetS) + ", got 0.1000001");
  EXPECT_NE(errorOf([] { limits::check("f.yaml", "rate_hz", 1e9, limits::kImuRateHz); }).find(", got 1e+09"),
            std::string::npos);
}
