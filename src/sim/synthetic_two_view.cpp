#include "mono_plane_detection/sim/synthetic_two_view.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <opencv2/calib3d.hpp>
#include <random>

#include "mono_plane_detection/geometry/homography_fit.h"
#include "mono_plane_detection/geometry/stats.h"

namespace mono_plane_detection {
namespace {

cv::Matx33d rotation(const cv::Vec3d& axis_angle) {
  cv::Matx33d R;
  cv::Rodrigues(axis_angle, R);
  return R;
}

}  // namespace

TwoViewScene makeTwoViewScene(const TwoViewSceneParams& params) {
  std::mt19937 rng(params.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, params.noise_px);
  auto between = [&](double a, double b) { return a + (b - a) * unit(rng); };

  const double w = params.image.width, h = params.image.height, f = params.focal_px;
  const cv::Matx33d K(f, 0, w / 2, 0, f, h / 2, 0, 0, 1);
  const cv::Matx33d Kinv = K.inv();
  const cv::Matx33d R =
      rotation({between(-0.05, 0.05), between(-0.08, 0.08), between(-0.03, 0.03)});
  cv::Vec3d t(1.0, between(-0.2, 0.2), between(-0.3, 0.3));
  t *= params.baseline_m / cv::norm(t);

  TwoViewScene scene;
  const int planes = std::max(1, std::min(params.planes, 6));
  const double strip = w / planes;
  // Median transfer difference of two homographies over the pixels of a strip.
  auto separation = [&](const cv::Matx33d& A, const cv::Matx33d& B, int strip_index) {
    std::vector<double> d;
    for (int i = 0; i < 5; ++i)
      for (int j = 0; j < 5; ++j) {
        const cv::Vec3d p((strip_index + (i + 0.5) / 5) * strip, (j + 0.5) * h / 5, 1.0);
        const cv::Vec3d a = A * p, b = B * p;
        d.push_back(std::hypot(a[0] / a[2] - b[0] / b[2], a[1] / a[2] - b[1] / b[2]));
      }
    return median(std::move(d));
  };
  for (int k = 0; k < planes; ++k) {
    // Plane through a point 2-6 m along the strip's central ray, tilted up to 50 deg;
    // redrawn (up to 100 times) while too close to an earlier plane.
    cv::Vec3d n;
    double d = 0.0;
    cv::Matx33d H;
    for (int attempt = 0; attempt < 100; ++attempt) {
      const cv::Vec3d centre_ray = Kinv * cv::Vec3d((k + 0.5) * strip, h / 2, 1.0);
      const cv::Vec3d centre = between(2.0, 6.0) * centre_ray;
      const double yaw = between(-0.87, 0.87), pitch = between(-0.5, 0.5);
      n = cv::Vec3d(std::sin(yaw) * std::cos(pitch), std::sin(pitch),
                    std::cos(yaw) * std::cos(pitch));
      d = n.dot(centre);
      H = K * (R + t * n.t() * (1.0 / d)) * Kinv;
      H *= 1.0 / H(2, 2);
      bool separate = true;
      for (int j = 0; j < k && separate; ++j) {
        separate = separation(H, scene.homographies[j], k) >= params.min_separation_px &&
                   separation(H, scene.homographies[j], j) >= params.min_separation_px;
      }
      if (separate) break;
    }
    scene.homographies.push_back(H);

    for (int made = 0, tries = 0;
         made < params.points_per_plane && tries < 100 * params.points_per_plane; ++tries) {
      const cv::Point2d p1(between(k * strip + 5, (k + 1) * strip - 5), between(5, h - 5));
      const cv::Vec3d ray = Kinv * cv::Vec3d(p1.x, p1.y, 1.0);
      const double depth = d / n.dot(ray);
      if (!(depth > 0.1)) continue;
      const cv::Vec3d X2 = R * (depth * ray) + t;
      if (X2[2] < 0.1) continue;
      const cv::Vec3d q = K * X2;
      const cv::Point2d p2(q[0] / q[2], q[1] / q[2]);
      if (p2.x < 0 || p2.y < 0 || p2.x >= w || p2.y >= h) continue;
      scene.view1.emplace_back(p1.x + noise(rng), p1.y + noise(rng));
      scene.view2.emplace_back(p2.x + noise(rng), p2.y + noise(rng));
      scene.labels.push_back(k + 1);
      ++made;
    }
  }
  const double inliers = static_cast<double>(scene.view1.size());
  const int outliers = params.outlier_fraction >= 1.0
                           ? 0
                           : static_cast<int>(std::lround(inliers * params.outlier_fraction /
                                                          (1.0 - params.outlier_fraction)));
  for (int i = 0; i < outliers; ++i) {
    scene.view1.emplace_back(between(0, w), between(0, h));
    scene.view2.emplace_back(between(0, w), between(0, h));
    scene.labels.push_back(0);
  }
  // Shuffle so that the order says nothing about the planes.
  std::vector<size_t> order(scene.view1.size());
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), rng);
  TwoViewScene shuffled;
  shuffled.homographies = scene.homographies;
  for (size_t i : order) {
    shuffled.view1.push_back(scene.view1[i]);
    shuffled.view2.push_back(scene.view2[i]);
    shuffled.labels.push_back(scene.labels[i]);
  }
  return shuffled;
}

std::vector<int> bestPossibleLabels(const TwoViewScene& scene, double threshold_px) {
  std::vector<int> labels(scene.view1.size(), 0);
  for (size_t i = 0; i < labels.size(); ++i) {
    double best = threshold_px;
    for (size_t k = 0; k < scene.homographies.size(); ++k) {
      const double e = transferError(scene.homographies[k], scene.view1[i], scene.view2[i]);
      if (e < best) {
        best = e;
        labels[i] = static_cast<int>(k) + 1;
      }
    }
  }
  return labels;
}

}  // namespace mono_plane_detection
