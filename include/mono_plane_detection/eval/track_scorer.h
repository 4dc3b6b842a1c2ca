// Scores tracks on views made with warpView (synthetic_views.h): each id is pinned to
// the texture pixel it was first seen on, and every later tracked position is compared
// with where that view's homography sends the pixel. Shared by tests and benchmarks.
#pragma once

#include <cstdint>
#include <map>
#include <opencv2/core.hpp>
#include <vector>

#include "mono_plane_detection/geometry/stats.h"  // percentile, used with errors()
#include "mono_plane_detection/tracking/feature_tracker.h"

namespace mono_plane_detection {

class TrackScorer {
 public:
  // points: the tracker's state for the view made with H (texture pixel -> view pixel).
  void observe(const std::vector<TrackedPoint>& points, const cv::Matx33d& H);

  const std::vector<double>& errors() const { return errors_; }  // px, tracked points
  double meanError() const;
  double maxError() const;
  // Texture pixel the id was first seen on; throws std::out_of_range for unknown ids.
  const cv::Point2d& texturePixel(std::uint64_t id) const { return texture_of_.at(id); }

 private:
  std::map<std::uint64_t, cv::Point2d> texture_of_;
  std::vector<double> errors_;
};

}  // namespace mono_plane_detection
