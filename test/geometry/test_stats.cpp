#include "mono_plane_detection/geometry/stats.h"

#include <gtest/gtest.h>

namespace mono_plane_detection {
namespace {

TEST(Stats, PercentileIsTheValueAtRankFloorQN) {
  EXPECT_EQ(percentile({}, 0.5), 0.0);
  EXPECT_EQ(percentile({3, 1, 2, 5, 4}, 0.0), 1.0);
  EXPECT_EQ(percentile({3, 1, 2, 5, 4}, 0.5), 3.0);
  EXPECT_EQ(percentile({3, 1, 2, 5, 4}, 0.95), 5.0);
  EXPECT_EQ(percentile({3, 1, 2, 5, 4}, 1.0), 5.0);
  EXPECT_EQ(percentile({3, 1, 2, 5, 4}, 7.0), 5.0);   // clamped
  EXPECT_EQ(percentile({3, 1, 2, 5, 4}, -1.0), 1.0);  // clamped
}

TEST(Stats, MedianOfAnEvenCountIsTheUpperMiddle) {
  EXPECT_EQ(median(std::vector<double>{4, 1, 3, 2}), 3.0);
  EXPECT_EQ(median(std::vector<double>{7}), 7.0);
  EXPECT_EQ(median(std::vector<float>{-1.5f, 2.5f, 0.5f}), 0.5f);
  EXPECT_EQ(median(std::vector<float>{}), 0.0f);
}

TEST(Stats, TheCallersValuesAreNotReordered) {
  // A non-const vector: a median that sorted its argument in place would reorder it.
  std::vector<double> values{5, 4, 3, 2, 1};
  EXPECT_EQ(median(values), 3.0);
  EXPECT_EQ(values, (std::vector<double>{5, 4, 3, 2, 1}));
}

}  // namespace
}  // namespace mono_plane_detection
