#include "mono_plane_detection/viz/draw_planes.h"

#include <opencv2/imgproc.hpp>
#include <string>

namespace mono_plane_detection {

namespace {
// The id users see: the map plane's when it has one (as in the rviz markers).
int shownId(const ImagePlane& p) { return p.map_id >= 0 ? p.map_id : p.id; }
}  // namespace

cv::Scalar planeColour(int id) {
  // Golden-angle hue steps: neighbouring ids get clearly different colours.
  const int hue = static_cast<int>((id * 137.508)) % 180;
  cv::Mat hsv(1, 1, CV_8UC3, cv::Scalar(hue, 220, 255)), bgr;
  cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
  const cv::Vec3b c = bgr.at<cv::Vec3b>(0, 0);
  return {double(c[0]), double(c[1]), double(c[2])};
}

cv::Mat drawPlanes(const cv::Mat& image, const PipelineResult& result, int max_groups) {
  cv::Mat out;
  if (image.channels() == 1)
    cv::cvtColor(image, out, cv::COLOR_GRAY2BGR);
  else
    out = image.clone();
  const auto& current = result.pairs.second;
  // Accepted groups as thin grey pentagons (paper figure 7).
  const auto& groups = result.segmentation.accepted_groups;
  for (size_t g = 0; g < groups.size() && static_cast<int>(g) < max_groups; ++g) {
    std::vector<cv::Point> corners;
    for (int i : groups[g])
      if (i >= 0 && static_cast<size_t>(i) < current.size())
        corners.emplace_back(cvRound(current[i].x), cvRound(current[i].y));
    cv::polylines(out, corners, true, cv::Scalar(160, 160, 160), 1, cv::LINE_AA);
  }
  // Every point: grey when on no plane, else its plane's colour, with its motion.
  const auto& labels = result.segmentation.labels;
  for (size_t i = 0; i < current.size(); ++i) {
    const int label = i < labels.size() ? labels[i] : 0;
    const cv::Scalar colour = label > 0 && static_cast<size_t>(label) <= result.planes.size()
                                  ? planeColour(shownId(result.planes[label - 1]))
                                  : cv::Scalar(128, 128, 128);
    cv::line(out, result.pairs.first[i], current[i], colour, 1, cv::LINE_AA);
    cv::circle(out, current[i], 3, colour, cv::FILLED, cv::LINE_AA);
    if (label == 1) cv::circle(out, current[i], 6, colour, 1, cv::LINE_AA);  // dominant's voters
  }
  std::string text = result.status + ", " + std::to_string(result.planes.size()) + " plane(s)";
  cv::putText(out, text, {8, 20}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0), 3,
              cv::LINE_AA);
  cv::putText(out, text, {8, 20}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(255, 255, 255), 1,
              cv::LINE_AA);
  for (size_t k = 0; k < result.planes.size(); ++k) {
    const ImagePlane& p = result.planes[k];
    const std::string label =
        "plane " + std::to_string(shownId(p)) + ": " + std::to_string(p.inlier_ids.size()) + " pts";
    cv::putText(out, label, {8, 40 + 18 * static_cast<int>(k)}, cv::FONT_HERSHEY_SIMPLEX, 0.5,
                planeColour(shownId(p)), 1, cv::LINE_AA);
  }
  return out;
}

}  // namespace mono_plane_detection
