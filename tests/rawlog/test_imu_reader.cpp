// Rawlog IMU reader: round trip of MRPT-written rawlogs in both formats, and
// one-line errors naming the entry for truncated files and bad timestamps.
#include <gtest/gtest.h>

#include <filesystem>
#include <mrpt/core/Clock.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/io/CFileOutputStream.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CObservationComment.h>
#include <mrpt/obs/CObservationIMU.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/serialization/CArchive.h>
#include <string>

#include "navimpact/core/error.hpp"
#include "navimpact/rawlog/imu_reader.hpp"
#include "test_support.hpp"

using namespace navimpact;
namespace fs = std::filesystem;

namespace {

constexpr double kT0 = 1767225600.0;  // 2026-01-01T00:00:00Z

double value(int k, int field) { return 0.001 * k + 0.1 * field - (field >= 3 ? 9.8 * (field == 5) : 0.0); }

mrpt::obs::CObservationIMU::Ptr imuObs(const std::string& label, double t, int k) {
  using namespace mrpt::obs;
  auto o = CObservationIMU::Create();
  o->sensorLabel = label;
  o->timestamp = mrpt::Clock::fromDouble(t);
  const TIMUDataIndex idx[6] = {IMU_WX, IMU_WY, IMU_WZ, IMU_X_ACC, IMU_Y_ACC, IMU_Z_ACC};
  for (int f = 0; f < 6; ++f) o->set(idx[f], value(k, f));
  return o;
}

/// Observation-only rawlog: a comment, then IMU at 100 Hz interleaved with a "BARO" IMU.
/// times[k] overrides the time of sample k when given.
void writeObsOnly(const fs::path& p, int n, bool gzip, const std::vector<double>& times = {}) {
  auto write = [&](auto& stream) {
    auto arch = mrpt::serialization::archiveFrom(stream);
    auto c = mrpt::obs::CObservationComment::Create();
    c->sensorLabel = "SCENARIO";
    c->text = "test";
    arch << *c;
    for (int k = 0; k < n; ++k) {
      const double t = times.empty() ? kT0 + 0.01 * k : times[k];
      arch << *imuObs("IMU", t, k);
      if (k % 10 == 0) {
        auto b = mrpt::obs::CObservationIMU::Create();
        b->sensorLabel = "BARO";
        b->timestamp = mrpt::Clock::fromDouble(t);
        b->set(mrpt::obs::IMU_ALTITUDE, 500.0);
        arch << *b;
      }
    }
  };
  if (gzip) {
    mrpt::io::CFileGZOutputStream f(p.string());
    write(f);
  } else {
    mrpt::io::CFileOutputStream f(p.string());
    write(f);
  }
}

/// CSensoryFrame / CActionCollection rawlog, 5 IMU samples per frame.
void writeSfAc(const fs::path& p, int n) {
  mrpt::io::CFileGZOutputStream f(p.string());
  auto arch = mrpt::serialization::archiveFrom(f);
  for (int k0 = 0; k0 < n; k0 += 5) {
    mrpt::obs::CActionCollection acts;
    arch << acts;
    mrpt::obs::CSensoryFrame sf;
    for (int k = k0; k < std::min(n, k0 + 5); ++k) sf.insert(imuObs("IMU", kT0 + 0.01 * k, k));
    arch << sf;
  }
}

void expectError(const std::function<void()>& f, const std::vector<std::string>& parts) {
  try {
    f();
    FAIL() << "no error";
  } catch (const Error& e) {
    const std::string m = e.what();
    for (const auto& p : parts) EXPECT_NE(m.find(p), std::string::npos) << "'" << p << "' not in: " << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << "multi-line: " << m;
  }
}

void checkSeries(const ImuSeries& s, int n, const std::string& path) {
  ASSERT_EQ(s.size(), static_cast<std::size_t>(n));
  EXPECT_EQ(s.source, path);
  EXPECT_NEAR(s.rate_hz, 100.0, 1e-4);  // 100 ns timestamp ticks
  EXPECT_NEAR(s.t0_s, kT0, 1e-6);
  ASSERT_EQ(s.channels.size(), 6u);
  for (int f = 0; f < 6; ++f) {
    EXPECT_EQ(s.channels[f].name, kChannelNames[f]);
    for (int k = 0; k < n; k += 37) EXPECT_EQ(s.channels[f].x[k], value(k, f)) << f << " " << k;
  }
  EXPECT_EQ(s.channel("acc_z").quantity, units::Quantity::SpecificForce);
}

}  // namespace

TEST(RawlogImuReader, ObservationOnlyGzipRoundTrip) {
  const auto p = (test::tempDir() / "obs.rawlog").string();
  writeObsOnly(p, 500, true);
  checkSeries(rawlog::readImuRawlog(p), 500, p);
  EXPECT_TRUE(rawlog::isRawlogFile(p));
}

TEST(RawlogImuReader, PlainFileAndContentDetection) {
  const auto p = (test::tempDir() / "obs.bin").string();  // no .rawlog extension
  writeObsOnly(p, 200, false);
  EXPECT_TRUE(rawlog::isRawlogFile(p));
  checkSeries(rawlog::readImuRawlog(p), 200, p);
  const auto csv = (test::tempDir() / "x.csv").string();
  std::ofstream(csv) << "gyro_x\n1\n";
  EXPECT_FALSE(rawlog::isRawlogFile(csv));
}

TEST(RawlogImuReader, SensoryFrameFormat) {
  const auto p = (test::tempDir() / "sf.rawlog").string();
  writeSfAc(p, 333);
  checkSeries(rawlog::readImuRawlog(p), 333, p);
}

TEST(RawlogImuReader, MissingLabelListsLabelsFound) {
  const auto p = (test::tempDir() / "obs.rawlog").string();
  writeObsOnly(p, 50, true);
  expectError([&] { rawlog::readImuRawlog(p, "XSENS"); },
              {p, "no CObservationIMU with label 'XSENS'", "'IMU' (CObservationIMU)",
               "'BARO' (CObservationIMU)", "(CObservationComment)"});
}

TEST(RawlogImuReader, TruncatedFileNamesTheEntry) {
  const auto p = (test::tempDir() / "cut.rawlog").string();
  writeObsOnly(p, 300, false);
  fs::resize_file(p, fs::file_size(p) - 17);
  // 300 IMU + 30 BARO + 1 comment = 331 entries; the last one (index 330, an IMU) is cut.
  expectError([&] { rawlog::readImuRawlog(p); }, {p, "entry 330", "truncated or malformed"});
}

TEST(RawlogImuReader, TruncatedGzipIsAnError) {
  const auto p = (test::tempDir() / "cut.rawlog.gz").string();
  writeObsOnly(p, 3000, true);
  fs::resize_file(p, fs::file_size(p) / 2);
  expectError([&] { rawlog::readImuRawlog(p); }, {p, "entry", "truncated gzip data"});
}

TEST(RawlogImuReader, BackwardsAndGappyTimestamps) {
  std::vector<double> t(100);
  for (int k = 0; k < 100; ++k) t[k] = kT0 + 0.01 * k;
  auto back = t;
  back[40] = back[38];
  const auto p1 = (test::tempDir() / "back.rawlog").string();
  writeObsOnly(p1, 100, true, back);
  // entry index: comment (0), then IMU k at 1 + k + ceil(k/10) (BARO after every 10th sample).
  expectError([&] { rawlog::readImuRawlog(p1); }, {p1, "entry 45", "does not increase"});
  auto gap = t;
  for (int k = 60; k < 100; ++k) gap[k] += 0.01;  // one missing sample
  const auto p2 = (test::tempDir() / "gap.rawlog").string();
  writeObsOnly(p2, 100, true, gap);
  expectError([&] { rawlog::readImuRawlog(p2); }, {p2, "entry 67", "median step"});
}

TEST(RawlogImuReader, MissingFile) {
  expectError([] { rawlog::readImuRawlog("/nonexistent/x.rawlog"); }, {"/nonexistent/x.rawlog", "not found"});
}
