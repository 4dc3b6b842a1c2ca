// A map plane held at right angles to, or parallel to, better-known planes when its own
// points cannot tell it from that: indoor floors, walls, ceilings and furniture faces meet
// at right angles, and a plane seen as a narrow strip (a floor along a wall, a wall seen
// late from a few views) is free to turn about the strip while its points barely notice.
// A model selection, not an assumption: the relation is taken only while the points'
// residuals do not reject it at the points' own noise scale, so a ramp or a slanted ceiling
// keeps its own normal once its points say so; and a soft one: a reference is trusted as
// far as its own sigma says, so a plane known worse than the one held pulls it little. ROS-free.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace mono_plane_detection {

struct ReferencePlane {
  cv::Vec3d normal;          // (made unit here)
  double normal_sigma_deg;   // how well it is known (1 sigma)
};

struct StructuredPlane {
  cv::Vec3d normal;          // unit, on the side of the free fit's normal
  double distance = 0;       // {x : normal . x = distance}
  int perpendicular = 0;     // references it was held at right angles to
  int parallel = 0;          // and parallel to
};

// The plane through `points` whose normal fuses the points' own information (their
// scatter over the free fit's residual variance, at least floor_m^2: exact points are not
// infinitely sure) with, for each reference, the nearer of a right angle to it or the
// parallel: a Gaussian prior on the normal, (n . m)^2 or |n x m|^2 over the reference's
// sigma^2. References are taken best-known first; each is kept while the points'
// residual sum of squares under the fused normal grows by at most sigmas^2 (in units of
// their residual variance) per degree of freedom the kept relations take (a right angle
// 1, the parallel 2, at most 2 in all), so a relation the points deny (a turn about an
// axis they fix) is left out without the others. `free_normal` must be the
// least-squares normal of `points`; with no relation taken (sigmas <= 0, fewer than 4
// points, no reference) it is returned with its distance through the points' centroid.
StructuredPlane structuredPlane(const std::vector<cv::Vec3d>& points,
                                const cv::Vec3d& free_normal,
                                const std::vector<ReferencePlane>& references, double sigmas,
                                double floor_m);

}  // namespace mono_plane_detection
