#include "mono_plane_detection/mapping/odometry_check.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <sstream>

namespace mono_plane_detection {

OdometryCheck checkOdometryMotion(const std::vector<cv::Point2d>& ref,
                                  const std::vector<cv::Point2d>& cur, const Pose& cur_from_ref,
                                  double parallax_px, double noise_px, double focal_px,
                                  const OdometryCheckParams& params) {
  OdometryCheck out;
  out.tracks = static_cast<int>(std::min(ref.size(), cur.size()));
  out.parallax_px = parallax_px;
  if (ref.size() != cur.size() || out.tracks < params.min_tracks ||
      !(parallax_px >= params.min_parallax_px) || !(noise_px > 0) || !(focal_px > 0))
    return out;
  // RANSAC at 4 of the pair's noise scales (the least median of squares needs no scale
  // but took 17.6 ms for 48 tracks, against 0.5). Normalized points: the identity camera.
  cv::Mat mask;
  const cv::Mat E = cv::findEssentialMat(ref, cur, 1.0, cv::Point2d(0, 0), cv::RANSAC, 0.999,
                                         4.0 * noise_px / focal_px, mask);
  if (E.cols != 3 || E.rows < 3) return out;
  cv::Mat R, t;
  const int in_front =
      cv::recoverPose(E.rowRange(0, 3), ref, cur, cv::Mat::eye(3, 3, CV_64F), R, t, mask);
  if (in_front < params.min_in_front_share * out.tracks) return out;
  const cv::Matx33d vision_R(R);
  // RANSAC's, not refined: 5.7 deg and 0.5 deg off on the wheeled path's pair at 0.2 px
  // of noise (refitting the direction over every inlier gave 5.3), far inside the bounds.
  const cv::Vec3d vision_t(t);  // unit length
  out.rotation_error_deg = rotationAngleDeg(cur_from_ref.R * vision_R.t());
  const double odometry_length = cv::norm(cur_from_ref.t);
  if (!(odometry_length > 0)) {
    out.direction_error_deg = 180;  // the images show translation, the odometry none
  } else {
    const double c = cur_from_ref.t.dot(vision_t) / (odometry_length * cv::norm(vision_t));
    if (!std::isfinite(c)) return out;  // (a non-finite odometry: undecided, not "agrees")
    out.direction_error_deg = std::acos(std::max(-1.0, std::min(1.0, c))) * 180.0 / CV_PI;
  }
  if (!std::isfinite(out.rotation_error_deg)) return out;
  out.decided = true;
  out.agrees = out.direction_error_deg <= params.max_direction_deg &&
               out.rotation_error_deg <= params.max_rotation_deg;
  return out;
}

void OdometryMonitor::add(const OdometryCheck& check) {
  tick(check.stamp);
  if (!check.decided) return;
  checks_.push_back(check);
  while (checks_.size() > static_cast<size_t>(std::max(1, params_.window))) checks_.pop_front();
}

void OdometryMonitor::tick(double stamp) {
  if (!checks_.empty() && stamp < checks_.back().stamp) checks_.clear();  // time went back
  while (!checks_.empty() && stamp - checks_.front().stamp > params_.max_age_s) checks_.pop_front();
}

bool OdometryMonitor::disagrees() const {
  long off = 0;
  for (const OdometryCheck& c : checks_) off += !c.agrees;
  return off >= params_.min_disagreeing;
}

std::string OdometryMonitor::summary() const {
  if (!disagrees()) return {};
  std::vector<double> direction, rotation;
  for (const OdometryCheck& c : checks_)
    if (!c.agrees) {
      direction.push_back(c.direction_error_deg);
      rotation.push_back(c.rotation_error_deg);
    }
  auto median = [](std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  std::ostringstream text;
  text.precision(0);
  text << std::fixed << "its translation " << median(direction) << " deg off the tracks' ";
  text.precision(1);
  text << "(median), its rotation " << median(rotation) << " deg, in " << direction.size()
       << " of the last " << checks_.size() << " image pairs with parallax";
  return text.str();
}

}  // namespace mono_plane_detection
