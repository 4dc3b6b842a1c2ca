#include "mono_plane_detection/sim/synthetic_views.h"

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>

namespace mono_plane_detection {

cv::Mat makeCornerTexture(const cv::Size& size, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  cv::Mat texture(size, CV_8UC1, cv::Scalar(128));
  cv::Mat noise(size, CV_8UC1);
  cv::theRNG().state = seed;
  cv::randn(noise, 0, 12);
  texture += noise;
  const int shapes = size.area() / 900;
  for (int i = 0; i < shapes; ++i) {
    const cv::Point c(static_cast<int>(unit(rng) * size.width),
                      static_cast<int>(unit(rng) * size.height));
    const int w = 6 + static_cast<int>(unit(rng) * 40);
    const int h = 6 + static_cast<int>(unit(rng) * 40);
    const cv::Scalar grey(20 + unit(rng) * 215);
    if (unit(rng) < 0.7) {
      cv::rectangle(texture, cv::Rect(c.x, c.y, w, h), grey, cv::FILLED);
    } else {
      std::vector<cv::Point> tri{c, c + cv::Point(w, h / 3), c + cv::Point(w / 4, h)};
      cv::fillConvexPoly(texture, tri, grey);
    }
  }
  cv::GaussianBlur(texture, texture, cv::Size(3, 3), 0.8);
  return texture;
}

cv::Mat warpView(const cv::Mat& texture, const cv::Matx33d& H, const cv::Size& view_size) {
  cv::Mat view;
  cv::warpPerspective(texture, view, cv::Mat(H), view_size, cv::INTER_LINEAR, cv::BORDER_CONSTANT,
                      cv::Scalar(0));
  return view;
}

cv::Point2d transfer(const cv::Matx33d& H, const cv::Point2d& p) {
  const cv::Vec3d q = H * cv::Vec3d(p.x, p.y, 1.0);
  return {q[0] / q[2], q[1] / q[2]};
}

cv::Matx33d similarity(double angle_rad, const cv::Point2d& center, const cv::Point2d& shift,
                       double scale) {
  const double c = std::cos(angle_rad) * scale, s = std::sin(angle_rad) * scale;
  const cv::Matx33d to_origin(1, 0, -center.x, 0, 1, -center.y, 0, 0, 1);
  const cv::Matx33d rotate(c, -s, 0, s, c, 0, 0, 0, 1);
  const cv::Matx33d back(1, 0, center.x + shift.x, 0, 1, center.y + shift.y, 0, 0, 1);
  return back * rotate * to_origin;
}

}  // namespace mono_plane_detection
