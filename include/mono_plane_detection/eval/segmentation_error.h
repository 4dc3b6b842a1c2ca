// The judge of a plane segmentation against hand or rendered labels (the AdelaideRMF
// measure), shared by the unit tests, eval_two_view and benchmark_suite.
#pragma once

#include <vector>

namespace mono_plane_detection {

// Share of points whose label is wrong after the best one-to-one matching of found
// planes to true planes (0 is matched to 0), as in the AdelaideRMF literature (Wong et
// al., ICCV 2011). Labels: 0 = no plane, k >= 1 = plane k. 1.0 when the sizes differ.
double misclassificationError(const std::vector<int>& truth, const std::vector<int>& found);

}  // namespace mono_plane_detection
