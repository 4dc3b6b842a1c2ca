#include "mono_plane_detection/mapping/plane_from_motion.h"

#include <algorithm>
#include <cmath>

namespace mono_plane_detection {
namespace {

// Where the track's first ray meets the plane m, seen from the current camera.
bool transfer(const MotionCorrespondence& c, const cv::Vec3d& m, cv::Point2d& out) {
  const double along = m.dot(c.ray);
  if (std::abs(along) < 1e-12) return false;
  const cv::Vec3d x = c.centre + ((1 - m.dot(c.centre)) / along) * c.ray;
  if (x[2] <= 1e-9) return false;
  out = {x[0] / x[2], x[1] / x[2]};
  return true;
}

}  // namespace

MotionPlane planeFromMotion(const std::vector<MotionCorrespondence>& tracks, double focal_px) {
  MotionPlane result;
  if (tracks.size() < 4 || !(focal_px > 0)) return result;
  // Linear: z x [r + c (r . m) - r (c . m)] = 0, three rows per track (rank 2).
  cv::Mat A(static_cast<int>(3 * tracks.size()), 3, CV_64F);
  cv::Mat b(static_cast<int>(3 * tracks.size()), 1, CV_64F);
  for (size_t k = 0; k < tracks.size(); ++k) {
    const MotionCorrespondence& t = tracks[k];
    const cv::Vec3d z(t.now.x, t.now.y, 1);
    const cv::Matx33d Z(0, -z[2], z[1], z[2], 0, -z[0], -z[1], z[0], 0);
    const cv::Matx33d M = Z * (t.centre * t.ray.t() - t.ray * t.centre.t());
    const cv::Vec3d rhs = -(Z * t.ray);
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) A.at<double>(static_cast<int>(3 * k) + r, c) = M(r, c);
      b.at<double>(static_cast<int>(3 * k) + r) = rhs[r];
    }
  }
  cv::Mat x;
  if (!cv::solve(A, b, x, cv::DECOMP_SVD)) return result;
  cv::Vec3d m(x.at<double>(0), x.at<double>(1), x.at<double>(2));
  if (!(cv::norm(m) > 1e-9)) return result;

  // Gauss-Newton on the transfer error (pixels), numerical Jacobian: 3 unknowns.
  cv::Matx33d JtJ;
  double ssr = 0;
  for (int iteration = 0; iteration < 20; ++iteration) {
    JtJ = cv::Matx33d::zeros();
    cv::Vec3d Jtr(0, 0, 0);
    ssr = 0;
    for (const MotionCorrespondence& t : tracks) {
      cv::Point2d p;
      if (!transfer(t, m, p)) return result;
      const cv::Vec2d r(focal_px * (p.x - t.now.x), focal_px * (p.y - t.now.y));
      ssr += r.dot(r);
      cv::Matx<double, 2, 3> J;
      const double h = 1e-6 * std::max(1.0, cv::norm(m));
      for (int a = 0; a < 3; ++a) {
        cv::Vec3d dm(0, 0, 0);
        dm[a] = h;
        cv::Point2d q;
        if (!transfer(t, m + dm, q)) return result;
        J(0, a) = focal_px * (q.x - p.x) / h;
        J(1, a) = focal_px * (q.y - p.y) / h;
      }
      JtJ += J.t() * J;
      Jtr += J.t() * r;
    }
    const cv::Vec3d step = JtJ.solve(-Jtr, cv::DECOMP_SVD);
    m += step;
    if (cv::norm(step) < 1e-10 * cv::norm(m)) break;
  }
  ssr = 0;
  for (const MotionCorrespondence& t : tracks) {
    cv::Point2d p;
    if (!transfer(t, m, p)) return result;
    ssr += focal_px * focal_px * ((p.x - t.now.x) * (p.x - t.now.x) + (p.y - t.now.y) * (p.y - t.now.y));
  }
  const double length = cv::norm(m);
  if (!std::isfinite(length) || length < 1e-9) return result;
  // Covariance of m from the residuals (dof 2N - 3), its spread across and along n.
  const double s2 = ssr / std::max(1.0, 2.0 * tracks.size() - 3);
  const cv::Matx33d cov = s2 * JtJ.inv(cv::DECOMP_SVD);
  const cv::Vec3d n = m / length;
  cv::Vec3d e1 = n.cross(std::abs(n[0]) < 0.9 ? cv::Vec3d(1, 0, 0) : cv::Vec3d(0, 1, 0));
  e1 /= cv::norm(e1);
  const cv::Vec3d e2 = n.cross(e1);
  const double a = e1.dot(cov * e1), c = e2.dot(cov * e2), off = e1.dot(cov * e2);
  const double largest = 0.5 * (a + c) + std::sqrt(0.25 * (a - c) * (a - c) + off * off);
  result.ok = std::isfinite(largest);
  result.normal = n;
  result.distance = 1 / length;
  result.normal_sigma_deg = std::sqrt(std::max(0.0, largest)) / length * 180 / CV_PI;
  result.distance_sigma = std::sqrt(std::max(0.0, n.dot(cov * n))) / length;
  result.rms_px = std::sqrt(ssr / (2.0 * tracks.size()));
  return result;
}

}  // namespace mono_plane_detection
