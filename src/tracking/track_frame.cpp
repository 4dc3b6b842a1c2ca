#include "mono_plane_detection/tracking/track_frame.h"

#include <cmath>
#include <sstream>
#include <unordered_map>
#include <unordered_set>

namespace mono_plane_detection {

TrackFrame trackFrameOf(const std::vector<TrackedPoint>& points, double stamp, cv::Size size) {
  TrackFrame frame;
  frame.stamp = stamp;
  frame.size = size;
  for (const TrackedPoint& p : points) {
    frame.ids.push_back(p.id);
    frame.pixels.emplace_back(p.uv.x, p.uv.y);
    frame.target_corner.push_back(p.is_target_corner);
    frame.reidentified.push_back(p.is_reidentified);
  }
  return frame;
}

std::string validateTrackFrame(const TrackFrame& frame) {
  std::ostringstream why;
  if (frame.size.width <= 0 || frame.size.height <= 0) {
    why << "image size " << frame.size.width << "x" << frame.size.height << " is empty";
    return why.str();
  }
  if (frame.pixels.size() != frame.ids.size() || frame.target_corner.size() != frame.ids.size() ||
      (!frame.reidentified.empty() && frame.reidentified.size() != frame.ids.size())) {
    why << "array lengths differ (" << frame.ids.size() << " ids, " << frame.pixels.size()
        << " points, " << frame.target_corner.size() << " flags";
    if (!frame.reidentified.empty()) why << ", " << frame.reidentified.size() << " re-identified";
    why << ")";
    return why.str();
  }
  std::unordered_set<std::uint64_t> seen;
  seen.reserve(frame.ids.size());
  for (size_t i = 0; i < frame.ids.size(); ++i) {
    const cv::Point2d& p = frame.pixels[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) {
      why << "point " << i << " (id " << frame.ids[i] << ") has a non-finite coordinate";
      return why.str();
    }
    // OpenCV's convention: pixel centres at integers, the image spans [-0.5, size - 0.5];
    // trackers' sub-pixel refinement may end a little outside, which is tolerated.
    const double margin = kTrackBorderMarginPx + 0.5;
    if (p.x < -margin || p.y < -margin || p.x > frame.size.width - 1 + margin ||
        p.y > frame.size.height - 1 + margin) {
      why << "point " << i << " (id " << frame.ids[i] << ") at (" << p.x << ", " << p.y
          << ") is outside the " << frame.size.width << "x" << frame.size.height << " image";
      return why.str();
    }
    if (!seen.insert(frame.ids[i]).second) {
      why << "id " << frame.ids[i] << " appears twice";
      return why.str();
    }
  }
  return {};
}

TrackPairs matchById(const TrackFrame& first, const TrackFrame& second) {
  std::unordered_map<std::uint64_t, size_t> index;
  index.reserve(first.ids.size());
  for (size_t i = 0; i < first.ids.size(); ++i) index.emplace(first.ids[i], i);
  TrackPairs out;
  for (size_t j = 0; j < second.ids.size(); ++j) {
    const auto it = index.find(second.ids[j]);
    if (it == index.end()) continue;
    out.ids.push_back(second.ids[j]);
    out.first.push_back(first.pixels[it->second]);
    out.second.push_back(second.pixels[j]);
  }
  return out;
}

}  // namespace mono_plane_detection
