// Small order statistics used by every stage and tool (one copy, tested). ROS-free.
#pragma once

#include <vector>

namespace mono_plane_detection {

// The value at rank floor(q * n) of the n sorted values (the largest for q = 1), q in
// [0, 1]; 0 for no values. Takes a copy: the caller's order is kept.
double percentile(std::vector<double> values, double q);

// percentile(values, 0.5): for an even count the upper of the two middle values.
double median(std::vector<double> values);

// The same for floats (image motions).
float median(std::vector<float> values);

}  // namespace mono_plane_detection
