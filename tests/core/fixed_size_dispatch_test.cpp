#include "twincal/core/fixed_size_dispatch.hpp"

#include <vector>

#include <gtest/gtest.h>

namespace twincal {
namespace {

TEST(DispatchFixedSize, RunsTheInstantiationOfTheRunTimeSizeOnlyWithinTheBound) {
  for (Index n = 1; n <= 5; ++n) {
    std::vector<int> called;
    EXPECT_TRUE(dispatch_fixed_size<5>(n, [&]<int K>() { called.push_back(K); }));
    EXPECT_EQ(called, std::vector<int>{static_cast<int>(n)});
  }
  for (const Index n : {Index{0}, Index{-1}, Index{6}, Index{1000}}) {
    bool called = false;
    EXPECT_FALSE(dispatch_fixed_size<5>(n, [&]<int K>() { called = true; })) << "n = " << n;
    EXPECT_FALSE(called) << "n = " << n;
  }
}

TEST(DispatchFixedSize, TheLibraryBoundCoversTheUsualFilterSizes) {
  static_assert(max_fixed_dispatch_size >= 6);
  EXPECT_TRUE(
      dispatch_fixed_size<max_fixed_dispatch_size>(max_fixed_dispatch_size, []<int K>() {}));
  EXPECT_FALSE(
      dispatch_fixed_size<max_fixed_dispatch_size>(max_fixed_dispatch_size + 1, []<int K>() {}));
}

}  // namespace
}  // namespace twincal
