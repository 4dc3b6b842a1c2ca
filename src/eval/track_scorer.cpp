#include "mono_plane_detection/eval/track_scorer.h"

#include <algorithm>

#include "mono_plane_detection/sim/synthetic_views.h"

namespace mono_plane_detection {

void TrackScorer::observe(const std::vector<TrackedPoint>& points, const cv::Matx33d& H) {
  const cv::Matx33d Hinv = H.inv();
  for (const auto& p : points) {
    const cv::Point2d uv(p.uv.x, p.uv.y);
    auto it = texture_of_.find(p.id);
    if (it == texture_of_.end()) {
      texture_of_[p.id] = transfer(Hinv, uv);
    } else if (p.is_tracked) {
      errors_.push_back(cv::norm(transfer(H, it->second) - uv));
    }
  }
}

double TrackScorer::meanError() const {
  double sum = 0.0;
  for (double e : errors_) sum += e;
  return errors_.empty() ? 0.0 : sum / errors_.size();
}

double TrackScorer::maxError() const {
  return errors_.empty() ? 0.0 : *std::max_element(errors_.begin(), errors_.end());
}

}  // namespace mono_plane_detection
