// The two decision rules of the tracker (paper II-C and II-D), kept apart from the
// image work so they can be tested on hand-made cases.
#include "mono_plane_detection/tracking/feature_tracker.h"

namespace mono_plane_detection {

bool shouldSearch(int found_at_last_search, int alive, int frames_since_search,
                  const TrackerParams& params) {
  if (alive <= 0) return true;
  if (params.redetect_every > 0 && frames_since_search >= params.redetect_every) return true;
  if (found_at_last_search <= 0) return false;
  const int lost = found_at_last_search - alive;
  // Compared in integers of thirds would tie to the paper exactly; the product keeps
  // any configured fraction (a small epsilon absorbs 2/3 not being exact in binary).
  return lost >= params.redetect_lost_fraction * found_at_last_search - 1e-9;
}

std::vector<int> closestClaimWins(const std::vector<int>& claim, const std::vector<double>& cost,
                                  size_t targets) {
  std::vector<int> winner(targets, -1);
  for (size_t c = 0; c < claim.size(); ++c) {
    if (claim[c] < 0) continue;
    int& w = winner[claim[c]];
    if (w < 0 || cost[c] < cost[w]) w = static_cast<int>(c);
  }
  std::vector<int> result(claim.size(), -1);
  for (size_t c = 0; c < claim.size(); ++c) {
    if (claim[c] >= 0 && winner[claim[c]] == static_cast<int>(c)) result[c] = claim[c];
  }
  return result;
}

std::vector<int> matchCornersToPoints(const std::vector<cv::Point2f>& corners,
                                      const std::vector<cv::Point2f>& points, double radius_px) {
  std::vector<int> nearest(corners.size(), -1);
  std::vector<double> distance2(corners.size(), 0.0);
  const double radius2 = radius_px * radius_px;
  for (size_t c = 0; c < corners.size(); ++c) {
    for (size_t p = 0; p < points.size(); ++p) {
      const cv::Point2f d = corners[c] - points[p];
      const double d2 = static_cast<double>(d.x) * d.x + static_cast<double>(d.y) * d.y;
      if (d2 <= radius2 && (nearest[c] < 0 || d2 < distance2[c])) {
        nearest[c] = static_cast<int>(p);
        distance2[c] = d2;
      }
    }
  }
  return closestClaimWins(nearest, distance2, points.size());
}

}  // namespace mono_plane_detection
