#include "mono_plane_detection/geometry/camera_model.h"

namespace mono_plane_detection {

cv::Point2d CameraModel::project(const cv::Vec3d& x) const {
  double u = x[0] / x[2], v = x[1] / x[2];
  const double r2 = u * u + v * v, scale = 1 + k1 * r2 + k2 * r2 * r2;
  u *= scale;
  v *= scale;
  return {fx * u + cx, fy * v + cy};
}

}  // namespace mono_plane_detection
