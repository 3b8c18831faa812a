#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "navimpact/core/error.hpp"
#include "navimpact/core/output.hpp"
#include "test_support.hpp"

using namespace navimpact;
namespace fs = std::filesystem;

TEST(OutputSet, NothingAppearsUntilCommit) {
  const fs::path dir = test::tempDir() / "out";
  {
    OutputSet out(dir);
    out.writeText("a.json", "{}");
    EXPECT_FALSE(fs::exists(dir / "a.json"));
    // destroyed without commit: a failed job leaves nothing behind
  }
  EXPECT_FALSE(fs::exists(dir / "a.json"));
  for (const auto& e : fs::directory_iterator(dir.parent_path()))
    EXPECT_EQ(e.path().filename().string().find(".navimpact-staging"), std::string::npos);
  {
    OutputSet out(dir);
    out.writeText("a.json", "{}");
    out.writeText("sub/b.csv", "x\n");
    out.commit();
  }
  EXPECT_TRUE(fs::exists(dir / "a.json"));
  EXPECT_TRUE(fs::exists(dir / "sub/b.csv"));
}
