#include "mono_plane_detection/viz/draw_tracks.h"

#include <opencv2/imgproc.hpp>
#include <string>

namespace mono_plane_detection {

cv::Mat drawTracks(const cv::Mat& image, const std::vector<TrackedPoint>& points) {
  cv::Mat canvas;
  if (image.channels() == 1) {
    cv::cvtColor(image, canvas, cv::COLOR_GRAY2BGR);
  } else {
    canvas = image.clone();
  }
  for (const auto& p : points) {
    const cv::Scalar colour = p.is_reidentified ? kReidentifiedColour
                              : p.is_new        ? kNewColour
                                                : kTrackedColour;
    cv::circle(canvas, p.uv, 3, colour, 1, cv::LINE_AA);
    cv::putText(canvas, std::to_string(p.id), p.uv + cv::Point2f(4.f, -4.f), cv::FONT_HERSHEY_PLAIN,
                0.8, colour, 1, cv::LINE_AA);
  }
  return canvas;
}

}  // namespace mono_plane_detection
