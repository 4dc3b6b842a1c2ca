// Renders an IndoorScene through a CameraModel by exact ray casting: every (sub)pixel's
// ray meets the nearest plane, whose texture is sampled bilinearly. ROS-free.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "mono_plane_detection/sim/camera_trajectory.h"
#include "mono_plane_detection/sim/indoor_scene.h"

namespace mono_plane_detection {

// Rays precomputed per sub-pixel (3 floats each, and the image's floats) bound the
// renderer's memory: at most this many sub-pixels (width x height x supersample^2), 4096 x
// 4096 at supersample 1. The tools refuse more.
constexpr long long kMaxRenderSubpixels = 1LL << 24;
// Why an image of this size cannot be rendered at this supersampling (more sub-pixels than
// kMaxRenderSubpixels), or "" when it can.
std::string renderSizeError(const cv::Size& size, int supersample);

struct RenderOptions {
  int supersample = 1;        // rays per pixel side (anti-aliasing): 2 = 4 rays per pixel
  int blur_subframes = 1;     // motion blur: average of this many poses (renderBlurred)
  double noise_sigma = 0;     // Gaussian image noise, grey levels
  double exposure = 1.0;      // intensity gain
  cv::Scalar background = 0;  // where no plane is hit
};

class SceneRenderer {
 public:
  // Precomputes each (sub)pixel's unit ray in the camera frame, undistorting when the
  // camera has radial distortion.
  SceneRenderer(const IndoorScene& scene, const CameraModel& camera, const RenderOptions& options);

  // The CV_8UC1 image seen from world_from_camera. noise_seed makes the noise repeatable;
  // gain multiplies options.exposure for this image (exposure changing over a sequence).
  cv::Mat render(const Pose& world_from_camera, unsigned noise_seed = 0, double gain = 1.0) const;
  // Motion blur: the mean of the renders at the given poses (one exposure's path).
  cv::Mat renderBlurred(const std::vector<Pose>& poses, unsigned noise_seed = 0,
                        double gain = 1.0) const;

  // The unit ray of pixel (u, v) in the camera frame (used by tests).
  cv::Vec3d ray(double u, double v) const;

 private:
  cv::Mat renderFloat(const Pose& world_from_camera) const;  // CV_32F, full resolution
  cv::Mat finish(cv::Mat image, unsigned noise_seed, double gain) const;

  const IndoorScene& scene_;
  CameraModel camera_;
  RenderOptions options_;
  std::vector<cv::Vec3f> rays_;  // supersampled grid, row-major
};

}  // namespace mono_plane_detection
