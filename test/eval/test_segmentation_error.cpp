// The AdelaideRMF measure: labels judged after the best one-to-one matching of planes.
#include "mono_plane_detection/eval/segmentation_error.h"

#include <gtest/gtest.h>

using namespace mono_plane_detection;

TEST(MisclassificationError, BestMatchingOfLabels) {
  EXPECT_DOUBLE_EQ(misclassificationError({0, 1, 1, 2, 2}, {0, 2, 2, 1, 1}), 0.0);  // renamed
  EXPECT_DOUBLE_EQ(misclassificationError({0, 1, 1, 2, 2}, {0, 1, 1, 1, 1}), 0.4);  // merged
  EXPECT_DOUBLE_EQ(misclassificationError({0, 0, 1, 1}, {1, 1, 0, 0}), 1.0);  // 0 only matches 0
  EXPECT_DOUBLE_EQ(misclassificationError({1, 1, 1, 1}, {1, 1, 2, 3}), 0.5);
}

TEST(MisclassificationError, SizesThatDifferAreAllWrong) {
  EXPECT_DOUBLE_EQ(misclassificationError({0, 1, 1}, {0, 1}), 1.0);
  EXPECT_DOUBLE_EQ(misclassificationError({}, {}), 0.0);
}
