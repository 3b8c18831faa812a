#include <gtest/gtest.h>
#include <zlib.h>

#include <cmath>
#include <fstream>
#include <optional>
#include <random>
#include <sstream>

#include "navimpact/core/csv_reader.hpp"
#include "navimpact/core/error.hpp"
#include "test_support.hpp"

using namespace navimpact;

namespace {
std::string writeFile(const std::string& name, const std::string& content) {
  const auto p = test::tempDir() / name;
  std::ofstream(p) << content;
  return p.string();
}

std::string errorOf(const std::string& path, const CsvImuOptions& opt) {
  try {
    readImuCsv(path, opt);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

CsvImuOptions degG(double rate = 100.0) {
  CsvImuOptions o;
  o.rate_hz = rate;
  o.gyro_unit = "deg/s";
  o.acc_unit = "g";
  return o;
}
}  // namespace

TEST(CsvReader, ReadsAndConvertsToSi) {
  const auto f = writeFile("a.csv", "gyro_x,gyro_y,gyro_z,acc_x,acc_y,acc_z\n1,2,3,1,0,-1\n-1,0,0.5,0,0,-1\n");
  const ImuSeries s = readImuCsv(f, degG());
  ASSERT_EQ(s.size(), 2u);
  EXPECT_DOUBLE_EQ(s.rate_hz, 100.0);
  EXPECT_DOUBLE_EQ(s.channel("gyro_y").x[0], 2.0 * units::kDeg);
  EXPECT_DOUBLE_EQ(s.channel("acc_z").x[1], -units::kG0);
}

TEST(CsvReader, GzipIsTransparentAndTimeColumnGivesRate) {
  const auto p = test::tempDir() / "b.csv.gz";
  gzFile g = gzopen(p.string().c_str(), "wb");
  const std::string txt = "t,gyro_z[rad/s]\n0.0,1\n0.005,2\n0.010,3\n0.015,4\n";
  gzwrite(g, txt.data(), static_cast<unsigned>(txt.size()));
  gzclose(g);
  CsvImuOptions o;  // unit from the header, rate from t
  const ImuSeries s = readImuCsv(p.string(), o);
  EXPECT_NEAR(s.rate_hz, 200.0, 1e-9);
  EXPECT_EQ(s.channel("gyro_z").x.size(), 4u);
}

TEST(CsvReader, AxesRemapFlipsAndPermutes) {
  const auto f = writeFile("c.csv", "gyro_x,gyro_y,gyro_z\n1,2,3\n");
  CsvImuOptions o = degG();
  o.gyro_unit = "rad/s";
  o.axes = "y,-x,-z";
  const ImuSeries s = readImuCsv(f, o);
  EXPECT_DOUBLE_EQ(s.channel("gyro_x").x[0], 2.0);
  EXPECT_DOUBLE_EQ(s.channel("gyro_y").x[0], -1.0);
  EXPECT_DOUBLE_EQ(s.channel("gyro_z").x[0], -3.0);
  o.axes = "x,x,z";
  EXPECT_NE(errorOf(f, o).find("used twice"), std::string::npos);
}

// A unit both in the header and from the caller: equal units (by their SI
// factor) read; different ones are refused naming the column and both units.
// Before, the header won silently while the command recorded the flag's unit
// (a deg/s column read with --gyro-unit rad/s reported as rad/s).
TEST(CsvReader, AHeaderUnitThatContradictsTheFlagIsRefused) {
  const auto f = writeFile("hdr.csv", "gyro_x[deg/s],acc_x[g]\n1,1\n2,1\n");
  EXPECT_DOUBLE_EQ(readImuCsv(f, degG()).channel("gyro_x").x[0], units::kDeg);  // the same units: fine
  CsvImuOptions o = degG();
  o.gyro_unit = "rad/s";
  const auto m = errorOf(f, o);
  EXPECT_NE(m.find("hdr.csv:1"), std::string::npos) << m;
  EXPECT_NE(m.find("column 'gyro_x' is in deg/s by its header, but --gyro-unit says rad/s"), std::string::npos) << m;
  o = degG();
  o.acc_unit = "m/s2";
  EXPECT_NE(errorOf(f, o).find("column 'acc_x' is in g by its header"), std::string::npos);
}

// A regular clock stamped coarsely (ms stamps of a 50-500 Hz IMU, a quantum up
// to half the step: 400 Hz gives 2, 3, 2, 3 ms) reads at its true rate, as the nominal step
// of core/recording.hpp has it; before, every such file was refused as "gap or
// jitter" (found by a probe: 128, 300 and 400 Hz). A lost sample in it is
// still refused, naming its line. Rates drawn at random (seeded, printed).
TEST(CsvReader, QuantisedStampsOfARegularClockRead) {
  std::mt19937_64 g(test::envOr("NAVIMPACT_CSV_SEED", 4242));
  for (int trial = 0; trial < 6; ++trial) {
    const double rate = std::uniform_real_distribution<double>(50.0, 500.0)(g);
    const int n = 2000, lost = 700 + trial;
    std::string a = "t,gyro_x[rad/s]\n", b = a;
    for (int k = 0; k < n; ++k) {
      const std::string row = std::to_string(std::floor(1000.0 * k / rate + 1e-9) / 1000.0) + ",0.1\n";
      a += row;
      if (k != lost) b += row;
    }
    std::printf("trial %d: %.3f Hz stamped in ms\n", trial, rate);
    const ImuSeries s = readImuCsv(writeFile("q.csv", a), CsvImuOptions{});
    EXPECT_NEAR(s.rate_hz, rate, 1e-3 * rate);
    const auto m = errorOf(writeFile("q_lost.csv", b), CsvImuOptions{});
    EXPECT_NE(m.find("q_lost.csv:" + std::to_string(lost + 2) + ": time step"), std::string::npos) << m;
  }
}

TEST(CsvReader, BadInputsNameFileAndLine) {
  const CsvImuOptions o = degG();
  EXPECT_NE(errorOf(writeFile("e.csv", ""), o).find("empty"), std::string::npos);
  EXPECT_NE(errorOf(writeFile("h.csv", "a,b\n1,2\n"), o).find("no IMU column"), std::string::npos);
  {
    const auto m = errorOf(writeFile("nan.csv", "gyro_x,acc_x\n1,2\n3,nan\n"), o);
    EXPECT_NE(m.find("nan.csv:3"), std::string::npos) << m;
  }
  {
    const auto m = errorOf(writeFile("inf.csv", "gyro_x,acc_x\n1,2\n3,inf\n"), o);
    EXPECT_NE(m.find("inf.csv:3"), std::string::npos) << m;
  }
  {
    const auto m = errorOf(writeFile("miss.csv", "gyro_x,acc_x\n1,2\n3\n"), o);
    EXPECT_NE(m.find("miss.csv:3"), std::string::npos) << m;
    EXPECT_NE(m.find("missing field"), std::string::npos) << m;
  }
  {
    const auto m = errorOf(writeFile("txt.csv", "gyro_x\n1\nabc\n"), o);
    EXPECT_NE(m.find("txt.csv:3"), std::string::npos) << m;
  }
  {
    CsvImuOptions u;
    u.rate_hz = 100;
    const auto m = errorOf(writeFile("nounit.csv", "gyro_x\n1\n"), u);
    EXPECT_NE(m.find("--gyro-unit"), std::string::npos) << m;
  }
  {
    CsvImuOptions u = o;
    u.gyro_unit = "furlong/s";
    EXPECT_NE(errorOf(writeFile("badunit.csv", "gyro_x\n1\n"), u).find("furlong"), std::string::npos);
  }
  {
    CsvImuOptions t = o;
    t.rate_hz.reset();
    const auto m = errorOf(writeFile("back.csv", "t,gyro_x\n0,1\n0.01,1\n0.005,1\n"), t);
    EXPECT_NE(m.find("back.csv:4"), std::string::npos) << m;
    const auto g = errorOf(writeFile("gap.csv", "t,gyro_x\n0,1\n0.01,1\n0.02,1\n0.05,1\n0.06,1\n"), t);
    EXPECT_NE(g.find("gap.csv:5"), std::string::npos) << g;
    // a time column whose rate lies outside the IMU rates [1, 10000] Hz (a unit
    // gone wrong: steps of 1e300 s wrote tau = 2e300 s into wv.csv, of 1 ns a
    // model at 1e9 Hz that no reader loads), and times printed as numbers, not
    // as 300 digits of %f
    const auto slow = errorOf(writeFile("slow.csv", "t,gyro_x\n0,1\n1e300,1\n2e300,1\n"), t);
    EXPECT_NE(slow.find("slow.csv: time column 't' holds 2e+300 s, outside [-1e+10, 1e+10] s (is the time unit right?)"),
              std::string::npos) << slow;
    const auto slowSmall = errorOf(writeFile("slow_small.csv", "t,gyro_x\n0,1\n2,1\n4,1\n"), t);
    EXPECT_NE(slowSmall.find("slow_small.csv: the time column gives a rate of 0.5 Hz, outside [1, 10000] Hz (is the time unit right?)"),
              std::string::npos) << slowSmall;
    const auto fast = errorOf(writeFile("fast.csv", "t,gyro_x\n0,1\n1e-9,1\n2e-9,1\n"), t);
    EXPECT_NE(fast.find("fast.csv: the time column gives a rate of 1e+09 Hz"), std::string::npos) << fast;
    const auto back = errorOf(writeFile("back300.csv", "t,gyro_x\n1e300,1\n0,1\n"), t);
    EXPECT_NE(back.find("back300.csv:3: time 0 s is not after the previous 1e+300 s"), std::string::npos) << back;
  }
  {
    CsvImuOptions t = o;
    t.rate_hz.reset();
    EXPECT_NE(errorOf(writeFile("norate.csv", "gyro_x\n1\n2\n"), t).find("--rate"), std::string::npos);
  }
  EXPECT_NE(errorOf("/nonexistent/file.csv", o).find("/nonexistent/file.csv"), std::string::npos);
}

// Found by the bad-input battery: a value below the smallest double was "not a
// number" (it is that close to 0); a UTF-16 CSV was sniffed as a rawlog and a
// file with carriage returns alone for line breaks read as its header only.
TEST(CsvReader, TextTheLinesCannotBeReadFromIsNamedAndTinyValuesAreZero) {
  const CsvImuOptions o = degG();
  const ImuSeries s = readImuCsv(writeFile("tiny.csv", "gyro_x,acc_x\n1e-400,1\n-1e-400,1\n"), o);
  EXPECT_EQ(s.channels[0].x[0], 0.0);
  EXPECT_NE(errorOf(writeFile("huge.csv", "gyro_x,acc_x\n1e400,1\n"), o).find("huge.csv:2: column 1 ('gyro_x'): '1e400' is not a number"),
            std::string::npos);
  const std::string utf16("\xFF\xFEg\0y\0r\0o\0_\0x\0\n\0", 16);
  const auto u = writeFile("utf16.csv", utf16);
  EXPECT_EQ(errorOf(u, o), u + ":1: zero bytes or a UTF-16 byte-order mark in the first line: no UTF-8 text "
                               "(UTF-16 or UTF-32 text: save it as UTF-8)");
  const auto cr = writeFile("cr.csv", "gyro_x,acc_x\r1,2\r3,4\r");
  EXPECT_EQ(errorOf(cr, o), cr + ":1: line breaks are carriage returns alone (old Mac text): save it with LF or CR LF line breaks");
  EXPECT_EQ(readImuCsv(writeFile("crlf.csv", "gyro_x,acc_x\r\n1,2\r\n3,4\r\n"), o).size(), 2u);  // CR LF is fine
}

// Found by the intake probe: a bzip2, xz or zstd file was "zero bytes or a
// UTF-16 byte-order mark". Each packed format is named with its unpacker;
// a text that merely starts with "BZh" is still read as text.
TEST(CsvReader, PackedFilesAreNamedWithTheirUnpacker) {
  const CsvImuOptions o = degG();
  const struct {
    std::string bytes, format, tool;
  } packed[] = {
      {std::string("BZh91AY&SY\x12\x00\x9a", 13), "bzip2-compressed", "bunzip2 -k FILE"},
      {std::string("\xFD" "7zXZ\0\0\x04", 8), "xz-compressed", "unxz -k FILE"},
      {std::string("\x28\xB5\x2F\xFD\x24\x00", 6), "zstd-compressed", "unzstd FILE"},
      {std::string("PK\x03\x04\x14\x00", 6), "a zip archive", "unzip FILE"},
      {std::string("7z\xBC\xAF\x27\x1C\x00", 7), "a 7-Zip archive", "7z x FILE"},
      {std::string("\x04\x22\x4D\x18\x64", 5), "lz4-compressed", "unlz4 FILE"},
  };
  int k = 0;
  for (const auto& p : packed) {
    const auto f = writeFile("packed" + std::to_string(k++) + ".csv", p.bytes);
    EXPECT_EQ(errorOf(f, o), f + ":1: the file is " + p.format + ": navimpact reads plain text or gzip; unpack it first (" +
                                 p.tool + ")");
  }
  // text that starts like bzip2 ("BZh", a digit) without its block magic is read as text
  for (const char* head : {"BZh_gyro,acc_x\n1,2\n", "BZh9,acc_x\n1,2\n"}) {
    const auto text = writeFile("bzh.csv", head);
    EXPECT_EQ(errorOf(text, o).find("the file is"), std::string::npos) << errorOf(text, o);
  }
}

TEST(CsvReader, ReadsTheFullStaticRecording) {
  const ImuSeries s = readImuCsv(test::dataPath("adis16405_static_1.csv.gz"), degG());
  ASSERT_EQ(s.size(), 1000000u);
  ASSERT_EQ(s.channels.size(), 6u);
  // First row of the file: -0.05,-0.3,0.7,-0.00666,0,-1.01565
  EXPECT_DOUBLE_EQ(s.channel("gyro_x").x[0], -0.05 * units::kDeg);
  EXPECT_DOUBLE_EQ(s.channel("acc_z").x[0], -1.01565 * units::kG0);
}

// A value beyond any IMU (garbage, or a unit wrong by orders of magnitude) is an
// error at its line, never a sample: drawn at a random row, column and
// magnitude between the limit and 1e300 (seed logged).
TEST(CsvReader, ValuesBeyondAnyImuAreErrorsAtTheirLine) {
  const std::uint64_t seed = 20261124;
  std::mt19937_64 rng(seed);
  CsvImuOptions o;
  o.rate_hz = 100.0;
  o.gyro_unit = "rad/s";
  o.acc_unit = "m/s2";
  for (int k = 0; k < 8; ++k) {
    const int rows = 20 + int(rng() % 200), bad = int(rng() % rows), col = int(rng() % 6);
    const double limit = col < 3 ? 1.0e3 : 1.0e5;
    const double v = (rng() % 2 ? -1.0 : 1.0) * limit * std::pow(10.0, 0.01 + 297.0 * std::uniform_real_distribution<>(0, 1)(rng));
    std::ostringstream text;
    text << "gyro_x,gyro_y,gyro_z,acc_x,acc_y,acc_z\n";
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < 6; ++c) text << (r == bad && c == col ? v : 0.5 * c) << (c == 5 ? '\n' : ',');
    SCOPED_TRACE("seed " + std::to_string(seed) + " case " + std::to_string(k) + ": row " + std::to_string(bad) +
                 " column " + std::to_string(col + 1) + " value " + std::to_string(v));
    const auto m = errorOf(writeFile("big.csv", text.str()), o);
    EXPECT_NE(m.find("big.csv:" + std::to_string(bad + 2) + ": column " + std::to_string(col + 1)), std::string::npos) << m;
    EXPECT_NE(m.find("beyond any IMU"), std::string::npos) << m;
  }
  // The limit itself is a value (57,000 deg/s; 10,000 g).
  EXPECT_EQ(errorOf(writeFile("edge.csv", "gyro_x,acc_x\n1000,100000\n-1000,-100000\n"), o), "");
}

// --time-column NAME: the named column is the time base, the default names
// become ordinary columns; a missing name or two time columns are errors.
TEST(CsvReader, NamedTimeColumn) {
  // 't' steps unevenly (it is not a time here); 'stamp' steps 0.004 s.
  const auto f = writeFile("stamp.csv", "t,stamp,gyro_x[rad/s]\n0,10.000,1\n7,10.004,2\n8,10.008,3\n30,10.012,4\n");
  CsvImuOptions o;
  o.time_column = "stamp";
  const ImuSeries s = readImuCsv(f, o);
  EXPECT_NEAR(s.rate_hz, 250.0, 1e-9);
  EXPECT_DOUBLE_EQ(s.t0_s, 10.0);
  EXPECT_EQ(s.channel("gyro_x").x, (std::vector<double>{1, 2, 3, 4}));
  // Without the option 't' is the time column and its gap is an error.
  const std::string uneven = errorOf(f, CsvImuOptions{});
  EXPECT_NE(uneven.find("stamp.csv:"), std::string::npos) << uneven;
  EXPECT_NE(uneven.find("time step"), std::string::npos) << uneven;
  o.time_column = "time_ns";
  const std::string m = errorOf(f, o);
  EXPECT_NE(m.find("stamp.csv:1: no time column 'time_ns' (--time-column)"), std::string::npos) << m;
  const std::string two = errorOf(writeFile("two.csv", "t,time_s,gyro_x[rad/s]\n0,0,1\n0.01,0.01,2\n"), CsvImuOptions{});
  EXPECT_NE(two.find("two.csv:1: column 2 'time_s': a second time column (the first is column 1)"), std::string::npos)
      << two;
}

// A time column in s, ms, us or ns (header bracket or time_unit) gives the
// clock's rate and first stamp. Rate log-uniform over the documented [1, 1e4]
// Hz, start uniform over Unix seconds [1e9, 2e9] (seeded, printed); stamps are
// whole nanoseconds written exactly in each unit (Unix ns exceed a double's 2^53).
TEST(CsvReader, TimeStampsInAnyUnitGiveTheClocksRateAndStart) {
  std::mt19937_64 g(test::envOr("NAVIMPACT_CSV_SEED", 4242));
  const char* unitNames[] = {"s", "ms", "us", "ns"};
  const int decimals[] = {9, 6, 3, 0};  // digits after the point of whole ns in each unit
  for (int trial = 0; trial < 4; ++trial) {
    const double rate = std::exp(std::uniform_real_distribution<double>(0.0, std::log(1e4))(g));
    const long long start_ns = std::uniform_int_distribution<long long>(1000000000LL, 2000000000LL)(g) * 1000000000LL +
                               std::uniform_int_distribution<long long>(0, 999999999LL)(g);
    const int n = 1500;
    std::vector<long long> ns(n);
    for (int k = 0; k < n; ++k) ns[k] = start_ns + std::llround(1e9 * k / rate);
    const double trueRate = (n - 1) / (1e-9 * static_cast<double>(ns[n - 1] - ns[0]));
    std::printf("trial %d: %.6f Hz from Unix %lld ns\n", trial, rate, start_ns);
    for (int u = 0; u < 4; ++u)
      for (const bool inHeader : {true, false}) {
        std::string text = std::string("t") + (inHeader ? std::string("[") + unitNames[u] + "]" : "") + ",gyro_x[rad/s]\n";
        for (int k = 0; k < n; ++k) {
          const long long p10 = static_cast<long long>(std::llround(std::pow(10.0, decimals[u])));
          const std::string frac = std::to_string(p10 + ns[k] % p10).substr(1);  // zero-padded
          text += std::to_string(ns[k] / p10) + (decimals[u] ? "." + frac : "") + ",0.1\n";
        }
        CsvImuOptions o;
        if (!inHeader) o.time_unit = unitNames[u];
        const ImuSeries s = readImuCsv(writeFile("stamps.csv", text), o);
        SCOPED_TRACE(std::string(unitNames[u]) + (inHeader ? " in the header" : " as time_unit"));
        // a nanosecond over the record's span (a double's 0.24 us at 2e9 s would not do)
        EXPECT_NEAR(s.rate_hz, trueRate, 1e-9 / ((n - 1) / trueRate) * trueRate);
        EXPECT_NEAR(s.t0_s, 1e-9 * static_cast<double>(start_ns), 5e-7);  // a double's resolution at 2e9 s
        EXPECT_EQ(s.size(), static_cast<std::size_t>(n));
      }
  }
  const std::string unknown = errorOf(writeFile("min.csv", "t[min],gyro_x[rad/s]\n0,1\n1,1\n"), CsvImuOptions{});
  EXPECT_NE(unknown.find("min.csv:1: time column 't': unknown time unit 'min' (expected one of: s, ms, us, ns)"),
            std::string::npos) << unknown;
  CsvImuOptions ns;
  ns.time_unit = "ns";
  const std::string clash = errorOf(writeFile("ms.csv", "t[ms],gyro_x[rad/s]\n0,1\n10,1\n"), ns);
  EXPECT_NE(clash.find("ms.csv:1: time column 't' is in ms by its header, but --time-unit says ns"), std::string::npos)
      << clash;
  ns.rate_hz = 100.0;
  const std::string none = errorOf(writeFile("none.csv", "gyro_x[rad/s]\n1\n1\n"), ns);
  EXPECT_NE(none.find("none.csv:1: time unit 'ns' given, but the header has no time column"), std::string::npos)
      << none;
}

// Columns that are not read must not hide a channel or the stamps: a channel
// written otherwise is an error (a fit modelled it as "none", a perfect
// sensor), and so is a column of stamps not read as time (--rate would go
// unchecked: the katwijk IMU's t_s at 125 Hz read at --rate 100). t_s, the
// emulator's own IMU time column, is a default; other columns stay ignored.
TEST(CsvReader, AColumnNotReadHidesNoChannelAndNoStamps) {
  CsvImuOptions r100;
  r100.rate_hz = 100.0;
  for (const char* name : {"Gyro_X", "gyrox", "GYRO-X"}) {
    const std::string m = errorOf(writeFile("case.csv", std::string("t,") + name + "[rad/s],acc_z[m/s2]\n0,1,2\n0.01,1,2\n"),
                                  CsvImuOptions{});
    EXPECT_NE(m.find("case.csv:1: column 2 '" + std::string(name) + "' is not a channel name: write it gyro_x"),
              std::string::npos) << m;
  }
  for (const char* name : {"T", "timestamp", "time_ns", "t_imu", "gps_time", "Stamp"}) {
    const std::string m =
        errorOf(writeFile("stamps.csv", std::string(name) + ",gyro_x[rad/s]\n0,1\n0.008,1\n0.016,1\n"), r100);
    EXPECT_NE(m.find("stamps.csv:1: column '" + std::string(name) + "' looks like time stamps but is not read as time: "
                     "pass --time-column " + name),
              std::string::npos) << m;
  }
  // t_s is read (125 Hz), so a --rate that disagrees is refused
  const auto ts = writeFile("ts.csv", "t_s,gyro_x[rad/s]\n0,1\n0.008,1\n0.016,1\n");
  EXPECT_NEAR(readImuCsv(ts, CsvImuOptions{}).rate_hz, 125.0, 1e-9);
  EXPECT_NE(errorOf(ts, r100).find("--rate 100 Hz disagrees with the time column (125 Hz)"), std::string::npos);
  // other columns stay ignored
  const ImuSeries other = readImuCsv(writeFile("temp.csv", "temperature,count,gyro_x[rad/s]\n20,1,1\n21,2,2\n"), r100);
  EXPECT_EQ(other.channel("gyro_x").x, (std::vector<double>{1, 2}));
}

// Stamps beyond a file's time axis (±1e10 s) are a unit gone wrong: Unix
// milliseconds of a 1 kHz IMU under a plain 't' read as seconds were a 1 Hz
// record in range. Whole nanoseconds of a 100 Hz clock give 100 Hz exactly.
TEST(CsvReader, StampsOfTheWrongUnitAreRefusedAndExactOnesGiveTheExactRate) {
  std::string ms = "t,gyro_x[rad/s]\n", ns = "t[ns],gyro_x[rad/s]\n";
  for (long long k = 0; k < 300; ++k) {
    ms += std::to_string(1700000000123LL + k) + ",0.1\n";
    ns += std::to_string(1700000000000000000LL + 10000000LL * k) + ",0.1\n";
  }
  const std::string m = errorOf(writeFile("unix_ms.csv", ms), CsvImuOptions{});
  EXPECT_NE(m.find("unix_ms.csv: time column 't' holds 1.7e+12 s, outside [-1e+10, 1e+10] s"),
            std::string::npos) << m;
  EXPECT_NE(m.find("(is the time unit right?)"), std::string::npos) << m;
  EXPECT_EQ(readImuCsv(writeFile("unix_ns.csv", ns), CsvImuOptions{}).rate_hz, 100.0);
}

// cutWindow keeps the samples at k / rate in [start, end) and moves t0; the
// window is drawn at random (seeded, printed) over the record; a window outside
// the record names the source, the flag and the record's extent.
TEST(ImuSeriesWindow, KeepsTheSamplesInsideTheWindow) {
  std::mt19937_64 g(60221);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int r = 0; r < 200; ++r) {
    ImuSeries s;
    s.source = "rec.csv";
    s.rate_hz = 10.0 + 990.0 * u(g);
    s.t0_s = 5.0 * u(g);
    const std::size_t n = 10 + static_cast<std::size_t>(5000 * u(g));
    ImuChannel c{"gyro_x", units::Quantity::AngularRate, {}};
    for (std::size_t k = 0; k < n; ++k) c.x.push_back(static_cast<double>(k));
    s.channels = {c, c};
    s.channels[1].name = "acc_z";
    const double dur = n / s.rate_hz;
    const double a = dur * u(g) * 0.9, b = a + (dur - a) * (0.05 + 0.95 * u(g));
    const bool open_end = u(g) < 0.3;
    std::printf("record %d: %zu samples at %.6g Hz, window [%.9g, %.9g)%s\n", r, n, s.rate_hz, a, b,
                open_end ? " open" : "");
    const std::size_t k0 = static_cast<std::size_t>(std::ceil(a * s.rate_hz - 1e-6));
    const std::size_t k1 = open_end ? n : static_cast<std::size_t>(std::ceil(b * s.rate_hz - 1e-6));
    if (k1 < k0 + 2) continue;
    ImuSeries w = s;
    cutWindow(w, a, open_end ? std::nullopt : std::optional<double>(b));
    ASSERT_EQ(w.size(), k1 - k0);
    for (const auto& ch : w.channels) {
      EXPECT_EQ(ch.x.front(), static_cast<double>(k0));
      EXPECT_EQ(ch.x.back(), static_cast<double>(k1 - 1));
      // every kept sample's time lies in the window, its neighbours outside
      EXPECT_GE(ch.x.front() / s.rate_hz, a - 1e-6 / s.rate_hz);
      if (k0 > 0) { EXPECT_LT((k0 - 1) / s.rate_hz, a); }
      if (!open_end) { EXPECT_LT(ch.x.back() / s.rate_hz, b); }
    }
    EXPECT_NEAR(w.t0_s, s.t0_s + k0 / s.rate_hz, 1e-9);
  }
  ImuSeries s;
  s.source = "rec.csv";
  s.rate_hz = 100.0;
  s.channels = {{"gyro_x", units::Quantity::AngularRate, std::vector<double>(1000, 0.5)}};
  auto err = [&](double a, std::optional<double> b) {
    ImuSeries w = s;
    try {
      cutWindow(w, a, b);
    } catch (const Error& e) {
      EXPECT_EQ(w.size(), 1000u) << "a refused window must not cut";
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(err(-1, std::nullopt), "rec.csv: --start -1 s must be a finite time >= 0 (the record has 1000 samples, 0 to 10 s at 100 Hz)");
  EXPECT_EQ(err(0, std::numeric_limits<double>::infinity()),
            "rec.csv: --end inf s must be a finite time (the record has 1000 samples, 0 to 10 s at 100 Hz)");
  EXPECT_NE(err(10, std::nullopt).find("--start 10 s is not before the end of the record"), std::string::npos);
  EXPECT_NE(err(2, 1.0).find("--end 1 s must be after --start"), std::string::npos);
  EXPECT_NE(err(2, 10.5).find("--end 10.5 s is beyond the end of the record"), std::string::npos);
  EXPECT_NE(err(2, 2.005).find("leaves fewer than 2 samples"), std::string::npos);
  EXPECT_NE(err(NAN, std::nullopt).find("--start"), std::string::npos);
  EXPECT_EQ(err(0, 10.0), "");  // the whole record
}
