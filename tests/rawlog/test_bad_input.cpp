// Bad rawlogs: each reader stops with one navimpact::Error naming the file and
// the entry, in bounded memory and time. The files under tests/data/bad are
// regressions (a real MRPT rawlog with one field corrupted).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>

#include "navimpact/core/error.hpp"
#include "navimpact/rawlog/imu_reader.hpp"
#include "navimpact/rawlog/writer.hpp"
#include "test_support.hpp"

using namespace navimpact;
namespace fs = std::filesystem;

namespace {

using test::errorOf;

std::string bad(const std::string& name) { return test::sourcePath("tests/data/bad/" + name); }

void expectBoth(const std::string& path, const std::string& label, const std::vector<std::string>& parts) {
  for (int reader = 0; reader < 2; ++reader) {
    const std::string m = errorOf([&] {
      if (reader == 0) rawlog::readImuRawlog(path, label);
      else rawlog::readRawlog(path);
    });
    for (const auto& p : parts) EXPECT_NE(m.find(p), std::string::npos) << "reader " << reader << ": '" << p << "' not in: " << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
}

}  // namespace

// A string length of 0xffffffff in a 1.8 KB file: refused before allocating
// (it took 4.26 GB and 27 s before the cap).
TEST(RawlogBadInput, LengthFieldLargerThanTheFileIsRefused) {
  expectBoth(bad("huge_string_length.rawlog"), "XSENS",
             {bad("huge_string_length.rawlog"), ": entry 0: a length field asks for 4294967296 bytes",
              "more than the file can hold (1776 bytes decompressed)"});
}

TEST(RawlogBadInput, UnregisteredClassNamesTheCause) {
  expectBoth(bad("unregistered_class.rawlog"), "XSENS",
             {": entry 2: ", "stored object has class 'mrpt::poses\\xC7:CPose3D' which is not registered"});
}

// An entry of class mrpt::obs::CObservation (abstract: MRPT has no
// constructor for it and printed a line to stderr before failing; found by
// the libFuzzer corpus through the CLI): refused before MRPT sees the name,
// nothing printed.
TEST(RawlogBadInput, AbstractClassIsRefusedWithoutPrinting) {
  testing::internal::CaptureStderr();
  expectBoth(bad("abstract_class.rawlog"), "IMU",
             {bad("abstract_class.rawlog"), ": entry 0: an object of class 'mrpt::obs::CObservation'",
              "which MRPT cannot create (an abstract class)"});
  // MRPT's old object header: a 4-byte little-endian name length, the name, a 4-byte version
  const auto old = (test::tempDir() / "old_header.rawlog").string();
  const std::string name = "mrpt::obs::CObservation";
  std::string bytes(1, static_cast<char>(name.size()));
  bytes += std::string(3, '\0') + name + std::string(68, '\0');
  std::ofstream(old, std::ios::binary) << bytes;
  expectBoth(old, "IMU", {old, ": entry 0: an object of class 'mrpt::obs::CObservation'"});
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
}

TEST(RawlogBadInput, TrailingGarbageAfterTheGzipDataIsAnError) {
  const auto src = test::sourcePath("tests/data/imu_label_xsens.rawlog");  // gzip
  const auto p = (test::tempDir() / "tail.rawlog").string();
  fs::copy_file(src, p);
  std::ofstream(p, std::ios::app | std::ios::binary) << "trailing junk";
  expectBoth(p, "XSENS", {p, "13 bytes of trailing garbage after the gzip data"});
}

TEST(RawlogBadInput, CsvWithByteOrderMarkIsNotSniffedAsRawlog) {
  const auto p = (test::tempDir() / "bom.csv").string();
  std::ofstream(p, std::ios::binary) << "\xEF\xBB\xBFgyro_x,gyro_y,gyro_z,acc_x,acc_y,acc_z\n1,2,3,4,5,6\n";
  EXPECT_FALSE(rawlog::isRawlogFile(p));
}

// Found by the intake probe: an xz- or bzip2-compressed rawlog ("run.rawlog.xz"
// renamed, or unpacked by a tool that did nothing) reached MRPT, which said "class
// name has more than 120 chars". Both readers name the format and its unpacker;
// the gzip rawlog beside it still reads.
TEST(RawlogBadInput, APackedRawlogIsNamedWithItsUnpacker) {
  const auto xz = (test::tempDir() / "run_xz.rawlog").string();
  std::ofstream(xz, std::ios::binary) << std::string("\xFD" "7zXZ\0\0\x04\xE6\xD6\xB4\x46", 12);
  expectBoth(xz, "IMU", {xz + ": the file is xz-compressed: navimpact reads plain text or gzip; unpack it first (unxz -k FILE)"});
  const auto bz = (test::tempDir() / "run_bz.rawlog").string();
  std::ofstream(bz, std::ios::binary) << std::string("BZh91AY&SY\x9e\x00", 12);
  expectBoth(bz, "IMU", {bz + ": the file is bzip2-compressed"});
  // inside gzip too (a gzip of the xz file), and a packed file is never sniffed as a rawlog
  const auto gz = xz + ".gz";
  ASSERT_EQ(std::system(("gzip -c '" + xz + "' > '" + gz + "'").c_str()), 0);
  expectBoth(gz, "IMU", {gz + ": the file is xz-compressed"});
  const auto xzCsv = xz.substr(0, xz.size() - 7) + ".csv";  // run_xz.csv beside it
  fs::copy_file(xz, xzCsv);
  EXPECT_FALSE(rawlog::isRawlogFile(xzCsv));
  EXPECT_NO_THROW(rawlog::readRawlog(test::sourcePath("tests/data/imu_label_xsens.rawlog")));
}
