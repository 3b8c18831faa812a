// Checks shared by the tests of the modules that write and read recordings
// (rawlog, import): what must come back to the bit.
#pragma once

#include <gtest/gtest.h>

#include <vector>

#include "navimpact/core/recording.hpp"

namespace navimpact::test {

/// The IMU records @p b are those of @p a: same count, times and rates to the bit.
inline void expectSameImu(const std::vector<ImuRecord>& b, const std::vector<ImuRecord>& a) {
  ASSERT_EQ(b.size(), a.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(b[i].t, a[i].t) << "IMU record " << i;
    EXPECT_EQ(b[i].w_IB_B, a[i].w_IB_B) << "IMU record " << i;
    EXPECT_EQ(b[i].f_B, a[i].f_B) << "IMU record " << i;
  }
}

}  // namespace navimpact::test
