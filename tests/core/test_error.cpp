// Error messages as the CLI prints them: one line, printable, bounded; and the
// input named when an exception that is not navimpact::Error leaves a reader.
#include <gtest/gtest.h>

#include <new>
#include <random>

#include "navimpact/core/error.hpp"

using namespace navimpact;

namespace {

bool isOneSafeLine(const std::string& s) {
  for (unsigned char c : s)
    if (c < 0x20 || c == 0x7F) return false;
  return true;
}

}  // namespace

TEST(Printable, EscapesControlBytesAndInvalidUtf8KeepsValidUtf8) {
  EXPECT_EQ(printable("abc"), "abc");
  EXPECT_EQ(printable(std::string("a\x01" "b\n\t\\", 6)), "a\\x01b\\n\\t\\\\");
  EXPECT_EQ(printable("\xC3\xA9t\xC3\xA9"), "\xC3\xA9t\xC3\xA9");          // "été" stays
  EXPECT_EQ(printable("\xC3("), "\\xC3(");                                  // truncated sequence
  EXPECT_EQ(printable("\xED\xA0\x80"), "\\xED\\xA0\\x80");                  // surrogate
  EXPECT_EQ(printable(std::string("\0", 1)), "\\x00");
}

TEST(Printable, CutsLongInputAndSaysHowLong) {
  const std::string s(5000, 'x');
  const std::string p = printable(s, 40);
  EXPECT_EQ(p, std::string(40, 'x') + "...(5000 bytes)");
}

TEST(OneLine, RandomBytesGiveOneBoundedPrintableLine) {
  std::mt19937_64 rng(20261124);
  for (int trial = 0; trial < 500; ++trial) {
    std::string msg(static_cast<std::size_t>(rng() % 3000), '\0');
    for (auto& c : msg) c = static_cast<char>(rng() & 0xFF);
    const std::string out = oneLine("file.csv:3: " + msg + " (expected a number)");
    EXPECT_TRUE(isOneSafeLine(out)) << "trial " << trial;
    EXPECT_LE(out.size(), 300u) << "trial " << trial;
    EXPECT_EQ(out.rfind("file.csv:3:", 0), 0u) << "the place comes first";
  }
}

TEST(OneLine, KeepsPlaceAndWhatIsAcceptedWhenCut) {
  const std::string out = oneLine("f.yaml: key 'a': " + std::string(1000, 'v') + " (accepted: 1..10)");
  EXPECT_LE(out.size(), 300u);
  EXPECT_EQ(out.rfind("f.yaml: key 'a': ", 0), 0u);
  EXPECT_NE(out.find("..."), std::string::npos);
  EXPECT_EQ(out.substr(out.size() - 17), "(accepted: 1..10)");
  EXPECT_EQ(oneLine("first\n  second\r\nthird\n"), "first; second; third");
  EXPECT_EQ(oneLine("short"), "short");
}

TEST(InputScope, NamesTheInnermostInputAnExceptionLeft) {
  InputScope::clearFailedInput();
  try {
    InputScope outer("config.yaml");
    {
      InputScope done("model.yaml");  // left normally: not named
    }
    InputScope inner("data.csv");
    throw std::bad_alloc();
  } catch (const std::bad_alloc&) {
  }
  EXPECT_EQ(InputScope::failedInput(), "data.csv");
  InputScope::clearFailedInput();
  {
    InputScope ok("x");
  }
  EXPECT_EQ(InputScope::failedInput(), "");
}

TEST(KeyError, EscapesTheKey) {
  const std::string m = keyError("c.yaml", std::string("a\x02") + std::string(500, 'k'), "unknown key").what();
  EXPECT_TRUE(isOneSafeLine(m));
  EXPECT_LT(m.size(), 200u);
}

TEST(OneLine, ALongPathIsShortenedAndTheCauseKept) {
  // a 3000-character path printed only its start (found by a probe: the cause
  // "output folder exists and is not empty (...)" was lost)
  std::string path;
  for (int k = 0; k < 15; ++k) path += "/" + std::string(199, 'd');
  const std::string cause = "output folder exists and is not empty (pass --overwrite to replace it whole)";
  for (const std::string& msg : {path + ": " + cause, "wv: " + path + "/x.csv: " + cause,
                                 path + ": " + std::string(4000, 'w') + " " + cause}) {
    const std::string out = oneLine(msg);
    EXPECT_LE(out.size(), 300u) << out;
    EXPECT_TRUE(isOneSafeLine(out)) << out;
    EXPECT_EQ(out.substr(out.size() - cause.size()), cause) << out;
    EXPECT_EQ(out.rfind(msg.substr(0, 20), 0), 0u) << out;
  }
}
