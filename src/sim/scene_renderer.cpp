#include "mono_plane_detection/sim/scene_renderer.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

namespace mono_plane_detection {
namespace {

// OpenCV's default 5 iterations leave 0.02 px of error at the image corners with
// k1 = -0.15; the ground truth must be exact.
const cv::TermCriteria kUndistortCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100,
                                          1e-14);

float bilinear(const cv::Mat& texture, double x, double y) {
  x = std::min(std::max(x, 0.0), texture.cols - 1.001);
  y = std::min(std::max(y, 0.0), texture.rows - 1.001);
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const float fx = static_cast<float>(x - x0), fy = static_cast<float>(y - y0);
  const uchar* r0 = texture.ptr<uchar>(y0);
  const uchar* r1 = texture.ptr<uchar>(y0 + 1);
  return (1 - fy) * ((1 - fx) * r0[x0] + fx * r0[x0 + 1]) +
         fy * ((1 - fx) * r1[x0] + fx * r1[x0 + 1]);
}

}  // namespace

std::string renderSizeError(const cv::Size& size, int supersample) {
  const long long subpixels =
      static_cast<long long>(size.width) * size.height * supersample * supersample;
  if (subpixels <= kMaxRenderSubpixels) return "";
  return "width x height x supersample^2 = " + std::to_string(subpixels) +
         " sub-pixels, more than the renderer's limit " + std::to_string(kMaxRenderSubpixels);
}

SceneRenderer::SceneRenderer(const IndoorScene& scene, const CameraModel& camera,
                             const RenderOptions& options)
    : scene_(scene), camera_(camera), options_(options) {
  options_.supersample = std::max(1, options_.supersample);
  const int ss = options_.supersample;
  std::vector<cv::Point2f> pixels;
  pixels.reserve(static_cast<size_t>(camera.size.area()) * ss * ss);
  // Sub-pixel centres: pixel (u, v) covers [u - 0.5, u + 0.5].
  for (int r = 0; r < camera.size.height * ss; ++r)
    for (int c = 0; c < camera.size.width * ss; ++c)
      pixels.emplace_back((c + 0.5f) / ss - 0.5f, (r + 0.5f) / ss - 0.5f);
  std::vector<cv::Point2f> normalised;
  cv::undistortPoints(pixels, normalised, cv::Mat(camera.K()), camera.distortion(), cv::noArray(),
                      cv::noArray(), kUndistortCriteria);
  rays_.reserve(normalised.size());
  for (const auto& n : normalised) {
    const cv::Vec3f d(n.x, n.y, 1.f);
    rays_.push_back(d / static_cast<float>(cv::norm(d)));
  }
}

cv::Vec3d SceneRenderer::ray(double u, double v) const {
  std::vector<cv::Point2d> in{{u, v}}, out;
  cv::undistortPoints(in, out, cv::Mat(camera_.K()), camera_.distortion(), cv::noArray(),
                      cv::noArray(), kUndistortCriteria);
  const cv::Vec3d d(out[0].x, out[0].y, 1.0);
  return d / cv::norm(d);
}

cv::Mat SceneRenderer::renderFloat(const Pose& pose) const {
  const int ss = options_.supersample;
  cv::Mat image(camera_.size.height * ss, camera_.size.width * ss, CV_32F);
  // Per plane, everything of the ray-plane test that does not depend on the ray.
  struct Prepared {
    cv::Vec3d n_cam, u_cam, v_cam;  // axes in the camera frame
    double offset;                  // distance - normal . camera centre
    cv::Vec3d origin_cam;           // plane origin relative to the camera, camera frame
  };
  std::vector<Prepared> planes;
  const cv::Matx33d Rt = pose.R.t();
  for (const auto& p : scene_.planes) {
    planes.push_back({Rt * p.normal(), Rt * p.u_axis, Rt * p.v_axis,
                      p.distance() - p.normal().dot(pose.t), Rt * (p.origin - pose.t)});
  }
  const float background = static_cast<float>(options_.background[0]);
  for (int r = 0; r < image.rows; ++r) {
    float* out = image.ptr<float>(r);
    for (int c = 0; c < image.cols; ++c) {
      const cv::Vec3f& rf = rays_[static_cast<size_t>(r) * image.cols + c];
      const cv::Vec3d d(rf[0], rf[1], rf[2]);
      double best = std::numeric_limits<double>::infinity();
      int hit = -1;
      double ha = 0, hb = 0;
      for (size_t k = 0; k < planes.size(); ++k) {
        const Prepared& p = planes[k];
        const double denom = p.n_cam.dot(d);
        if (std::abs(denom) < 1e-12) continue;
        const double s = p.offset / denom;
        if (!(s > 1e-9) || s >= best) continue;
        const cv::Vec3d local = s * d - p.origin_cam;
        const double a = local.dot(p.u_cam), b = local.dot(p.v_cam);
        const ScenePlane& sp = scene_.planes[k];
        if (a < 0 || b < 0 || a > sp.width_m || b > sp.height_m) continue;
        if (!sp.holes.empty() && !sp.contains(a, b)) continue;
        best = s;
        hit = static_cast<int>(k);
        ha = a;
        hb = b;
      }
      if (hit < 0) {
        out[c] = background;
      } else {
        const ScenePlane& sp = scene_.planes[hit];
        out[c] = bilinear(sp.texture, ha * sp.texels_per_m, hb * sp.texels_per_m);
      }
    }
  }
  if (ss > 1) cv::resize(image, image, camera_.size, 0, 0, cv::INTER_AREA);
  return image;
}

cv::Mat SceneRenderer::finish(cv::Mat image, unsigned noise_seed, double gain) const {
  image *= options_.exposure * gain;
  if (options_.noise_sigma > 0) {
    cv::Mat noise(image.size(), CV_32F);
    cv::RNG rng(noise_seed + 1);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, options_.noise_sigma);
    image += noise;
  }
  cv::Mat out;
  image.convertTo(out, CV_8U);  // rounds and saturates
  return out;
}

cv::Mat SceneRenderer::render(const Pose& pose, unsigned noise_seed, double gain) const {
  return finish(renderFloat(pose), noise_seed, gain);
}

cv::Mat SceneRenderer::renderBlurred(const std::vector<Pose>& poses, unsigned noise_seed,
                                     double gain) const {
  if (poses.empty()) return cv::Mat::zeros(camera_.size, CV_8U);
  cv::Mat sum = cv::Mat::zeros(camera_.size, CV_32F);
  for (const auto& p : poses) sum += renderFloat(p);
  return finish(sum / static_cast<double>(poses.size()), noise_seed, gain);
}

}  // namespace mono_plane_detection
