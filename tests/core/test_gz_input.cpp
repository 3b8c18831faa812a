// Strict streaming input: plain and gzip files, multi-member gzip, and each way
// a file can be wrong (corrupt, truncated, trailing garbage), each an error
// naming the file; lines capped in length; the byte-order mark skipped.
#include <gtest/gtest.h>
#include <zlib.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "navimpact/core/alloc_limit.hpp"
#include "navimpact/core/csv_reader.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/gz_input.hpp"
#include "test_support.hpp"

using namespace navimpact;
namespace fs = std::filesystem;

namespace {

std::string gz(const std::string& text, int level = 6) { return test::gzipBytes(text, level); }

std::string write(const std::string& name, const std::string& bytes) {
  const auto p = (test::tempDir() / name).string();
  std::ofstream(p, std::ios::binary) << bytes;
  return p;
}

std::string readAll(const std::string& path) {
  GzInput in(path);
  std::string out;
  char buf[777];  // odd size: reads straddle the internal buffers
  for (std::size_t n; (n = in.read(buf, sizeof buf)) > 0;) out.append(buf, n);
  return out;
}

using test::errorOf;

std::string randomText(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::string s(n, ' ');
  for (auto& c : s) c = static_cast<char>('0' + rng() % 40);
  return s;
}

}  // namespace

TEST(GzInput, PlainGzipAndMultiMemberGiveTheSameBytes) {
  const std::string text = randomText(3 << 20, 1);  // 3 MiB: several buffers
  EXPECT_EQ(readAll(write("p.txt", text)), text);
  EXPECT_EQ(readAll(write("g.gz", gz(text))), text);
  EXPECT_EQ(readAll(write("stored.gz", gz(text, 0))), text);
  const std::string a = text.substr(0, 1000000), b = text.substr(1000000);
  EXPECT_EQ(readAll(write("multi.gz", gz(a) + gz(b))), text);
  GzInput in(write("g2.gz", gz(text)));
  EXPECT_TRUE(in.compressed());
  EXPECT_EQ(in.statedSize(), text.size());  // from the gzip trailer
  EXPECT_EQ(readAll(write("empty", "")), "");
}

TEST(GzInput, TrailingGarbageIsAnError) {
  const std::string text = randomText(5000, 2);
  const auto p = write("tail.gz", gz(text) + "garbage!");
  const std::string m = errorOf([&] { readAll(p); });
  EXPECT_NE(m.find(p), std::string::npos) << m;
  EXPECT_NE(m.find("8 bytes of trailing garbage after the gzip data"), std::string::npos) << m;
  EXPECT_NE(errorOf([&] { readAll(write("tail1.gz", gz(text) + "x")); }).find("trailing garbage"), std::string::npos);
}

TEST(GzInput, TruncatedAndCorruptGzipAreErrors) {
  const std::string text = randomText(200000, 3);
  const std::string z = gz(text);
  // Cut at random places: always "truncated", never a silent short read.
  std::mt19937_64 rng(4);
  for (int k = 0; k < 20; ++k) {
    const std::size_t cut = 2 + rng() % (z.size() - 2);
    const auto p = write("cut" + std::to_string(k) + ".gz", z.substr(0, cut));
    const std::string m = errorOf([&] { readAll(p); });
    EXPECT_TRUE(m.find("truncated gzip data") != std::string::npos || m.find("corrupt gzip data") != std::string::npos)
        << "cut at " << cut << ": " << m;
  }
  // A flipped byte in the deflate data or the CRC: corrupt.
  std::string bad = z;
  bad[bad.size() - 6] ^= 0x55;  // inside the CRC-32 of the trailer
  EXPECT_NE(errorOf([&] { readAll(write("crc.gz", bad)); }).find("corrupt gzip data"), std::string::npos);
}

TEST(LineReader, CapsTheLineLengthAndNamesTheLine) {
  const std::string longLine(5000, 'x');
  const auto p = write("long.csv", "a,b\n1,2\n" + longLine + "\n3,4\n");
  LineReader r(p, 4096);
  std::string_view l;
  ASSERT_TRUE(r.next(l));
  EXPECT_EQ(l, "a,b");
  ASSERT_TRUE(r.next(l));
  EXPECT_EQ(l, "1,2");
  const std::string m = errorOf([&] { r.next(l); });
  EXPECT_NE(m.find(p + ":3: line longer than 4096 bytes"), std::string::npos) << m;
}

TEST(LineReader, ByteOrderMarkCrLfAndLastLineWithoutNewline) {
  const auto p = write("bom.csv", "\xEF\xBB\xBFgyro_x\r\n1\r\n2");
  LineReader r(p);
  std::string_view l;
  std::vector<std::string> got;
  while (r.next(l)) got.emplace_back(l);
  EXPECT_EQ(got, (std::vector<std::string>{"gyro_x", "1", "2"}));
}

TEST(CsvReader, OneLineFileOfManyMegabytesIsRefusedWithinTheLineCap) {
  // 8 MiB without a line end: refused after 1 MiB, the message is short.
  const auto p = write("oneline.csv", "gyro_x,gyro_y,gyro_z,acc_x,acc_y,acc_z\n" + std::string(8 << 20, '1'));
  CsvImuOptions o;
  o.rate_hz = 100.0;
  o.gyro_unit = "rad/s";
  o.acc_unit = "m/s2";
  const std::string m = errorOf([&] { readImuCsv(p, o); });
  EXPECT_NE(m.find(":2: line longer than 1048576 bytes"), std::string::npos) << m;
  EXPECT_LT(m.size(), 300u);
}

TEST(CsvReader, ByteOrderMarkIsReadAsCsv) {
  std::string text = "\xEF\xBB\xBFgyro_x,gyro_y,gyro_z,acc_x,acc_y,acc_z\n";
  for (int i = 0; i < 64; ++i) text += "0.1,0.2,0.3,0.4,0.5,9.8\n";
  CsvImuOptions o;
  o.rate_hz = 100.0;
  o.gyro_unit = "rad/s";
  o.acc_unit = "m/s2";
  const ImuSeries s = readImuCsv(write("bom.csv", text), o);
  ASSERT_EQ(s.channels.size(), 6u);
  EXPECT_EQ(s.channels[0].name, "gyro_x");
  EXPECT_EQ(s.size(), 64u);
}

TEST(AllocationLimit, RefusesOneLargeRequestOnItsThreadOnly) {
  AllocationLimit::takeRefused();
  {
    AllocationLimit lim(1 << 20);
    std::vector<char> small(1000);
    EXPECT_THROW(std::string(std::size_t(1) << 30, 'x'), std::bad_alloc);
    EXPECT_GE(AllocationLimit::takeRefused(), std::size_t(1) << 30);  // the string asks for one byte more
    {
      AllocationLimit inner(1 << 10);
      EXPECT_THROW(std::vector<char>(2048), std::bad_alloc);
    }
    EXPECT_NO_THROW(std::vector<char>(2048));  // back to the outer limit
    {
      AllocationLimit looser(1 << 30);  // a nested limit never loosens the one in force
      EXPECT_EQ(AllocationLimit::current(), std::size_t(1) << 20);
      EXPECT_THROW(std::vector<char>(std::size_t(2) << 20), std::bad_alloc);
    }
  }
  EXPECT_EQ(AllocationLimit::current(), 0u);
  EXPECT_NO_THROW(std::vector<char>(std::size_t(8) << 20));
}

// The gzip trailer's ISIZE is the file's claim, not a fact: a claim above the
// deflate bound of 1032:1 (RFC 1951) is cut to that bound, a true one is kept.
TEST(GzInput, StatedSizeIsBoundedByTheDeflateRatio) {
  const std::string text = randomText(4096, 77);
  std::string z = gz(text);
  const auto honest = write("honest.gz", z);
  EXPECT_EQ(GzInput(honest).statedSize(), text.size());
  for (int k = 1; k <= 4; ++k) z[z.size() - k] = static_cast<char>(0xff);  // ISIZE = 4 GiB - 1
  const auto liar = write("liar.gz", z);
  EXPECT_EQ(GzInput(liar).statedSize(), std::uint64_t(1032) * z.size());
}
