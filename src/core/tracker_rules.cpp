// The two decision rules of the tracker (paper II-C and II-D), kept apart from the
// image work so they can be tested on hand-made cases.
#include "mono_plane_detection/feature_tracker.h"

#include <limits>

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

std::vector<int> matchCornersToPoints(const std::vector<cv::Point2f>& corners,
                                      const std::vector<cv::Point2f>& points,
                                      double radius_px) {
  std::vector<int> match(corners.size(), -1);
  // For every point, the closest corner that picked it wins.
  std::vector<int> winner(points.size(), -1);
  std::vector<double> winner_distance(points.size(), std::numeric_limits<double>::max());
  const double radius2 = radius_px * radius_px;
  for (size_t c = 0; c < corners.size(); ++c) {
    int best = -1;
    double best_d2 = 0.0;
    for (size_t p = 0; p < points.size(); ++p) {
      const cv::Point2f d = corners[c] - points[p];
      const double d2 = static_cast<double>(d.x) * d.x + static_cast<double>(d.y) * d.y;
      if (d2 > radius2) continue;
      if (best < 0 || d2 < best_d2) {
        best = static_cast<int>(p);
        best_d2 = d2;
      }
    }
    if (best < 0) continue;
    match[c] = best;
    if (best_d2 < winner_distance[best]) {
      winner[best] = static_cast<int>(c);
      winner_distance[best] = best_d2;
    }
  }
  for (size_t c = 0; c < corners.size(); ++c) {
    if (match[c] >= 0 && winner[match[c]] != static_cast<int>(c)) match[c] = -1;
  }
  return match;
}

}  // namespace mono_plane_detection
