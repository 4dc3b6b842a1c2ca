// ParamCheck: an invalid parameter is replaced by its default, a valid one is kept.
#include <gtest/gtest.h>

#include <limits>

#include "../../src/nodelets/param_check.h"

using mono_plane_detection::ParamCheck;

TEST(ParamCheck, InvalidValueIsReplacedByTheDefault) {
  const ParamCheck fix("test");
  int max_features = -3;
  fix(max_features < 1, "max_features", max_features, 50);
  EXPECT_EQ(max_features, 50);
  double threshold = std::numeric_limits<double>::quiet_NaN();
  fix(!(threshold > 0), "vote_threshold_px", threshold, 2.0);
  EXPECT_EQ(threshold, 2.0);
}

TEST(ParamCheck, ValidValueIsKept) {
  const ParamCheck fix("test");
  int max_features = 150;
  fix(max_features < 1, "max_features", max_features, 50);
  EXPECT_EQ(max_features, 150);
  double threshold = 0.5;
  fix(!(threshold > 0), "vote_threshold_px", threshold, 2.0);
  EXPECT_EQ(threshold, 0.5);
}
