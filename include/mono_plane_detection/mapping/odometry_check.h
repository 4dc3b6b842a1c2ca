// Does the odometry's camera motion explain the images? Between two images the tracks
// themselves fix the camera's rotation and the direction of its translation (essential
// matrix); odometry that moves the camera otherwise is wrong or misconfigured: an
// odom_frame that moves with the robot (base_link through a head's joints: its "motion"
// is the head's turning only), or images whose frame_id is not the camera's optical frame
// (camera_link: x forward read as x right). Found by hostile tries; such odometry left the
// map empty with the status "tracking (odometry)".
#pragma once

#include <cstddef>
#include <deque>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "mono_plane_detection/geometry/pose.h"

namespace mono_plane_detection {

struct OdometryCheckParams {
  // The translation directions apart beyond this (deg) disagree. Gross: wheel slip or a
  // leg's sway err by a few degrees over a keyframe's baseline; a wrong frame by 90.
  double max_direction_deg = 45.0;
  // The rotations apart beyond this (deg) disagree (a wrong frame turns the axes).
  double max_rotation_deg = 10.0;
  int min_tracks = 20;  // fewer shared tracks: not decided (and no noise scale)
  // Less rotation-free parallax: not decided (a turn on the spot fits any translation).
  // Twice the planes' keyframe parallax: at 12 px single checks of the true humanoid
  // odometry reached 54 deg at 1 px of track noise (a review); the pipeline takes the
  // oldest image within reach for the check.
  double min_parallax_px = 24.0;
  // Fewer of the tracks in front of both cameras under the tracks' motion: not decided
  // (moving things or mismatches may hold the motion RANSAC found).
  double min_in_front_share = 0.6;
  // OdometryMonitor: of the last `window` decided checks, this many disagreeing make
  // the disagreement persistent (one bad pair is not a configuration error).
  int window = 10;
  int min_disagreeing = 7;
  double max_age_s = 10.0;  // checks older than this (image stamps) are forgotten
};

struct OdometryCheck {
  double stamp = 0;      // the current image's (s)
  bool decided = false;  // enough shared tracks and parallax to tell
  bool agrees = true;
  int tracks = 0;
  double parallax_px = 0;
  // Between the odometry's and the tracks' translation directions (deg); 180 when the
  // odometry has the camera not moving at all.
  double direction_error_deg = 0;
  double rotation_error_deg = 0;  // between the two rotations (deg)
};

// ref, cur: the shared tracks' normalized image points (undistorted, z = 1) in the two
// images; cur_from_ref: the camera motion odometry gives (the current camera from the
// reference one); parallax_px: the tracks' rotation-free parallax; noise_px: the pair's
// noise scale (PlaneSegmentation::noise_px; the essential matrix's RANSAC takes tracks
// within 4 of it); both at the focal length focal_px. The tracks must determine the
// motion (not all on one plane: one plane's tracks fit two motions), which the caller
// knows from the planes it found.
OdometryCheck checkOdometryMotion(const std::vector<cv::Point2d>& ref,
                                  const std::vector<cv::Point2d>& cur, const Pose& cur_from_ref,
                                  double parallax_px, double noise_px, double focal_px,
                                  const OdometryCheckParams& params = OdometryCheckParams());

// The last decided checks: whether the odometry disagrees persistently, and how.
class OdometryMonitor {
 public:
  explicit OdometryMonitor(const OdometryCheckParams& params = OdometryCheckParams())
      : params_(params) {}
  void add(const OdometryCheck& check);
  // The newest image's stamp: checks max_age_s older are forgotten (a robot that stands
  // still decides no more checks; an old disagreement must not stay for ever).
  void tick(double stamp);
  // min_disagreeing of the last `window` decided checks (within max_age_s) disagree.
  bool disagrees() const;
  // For people: "the translation 88 deg off (median), rotation 0.4 deg, in 9 of the last
  // 10 image pairs"; "" while it agrees.
  std::string summary() const;
  void reset() { checks_.clear(); }

 private:
  OdometryCheckParams params_;
  std::deque<OdometryCheck> checks_;  // decided only, oldest first
};

}  // namespace mono_plane_detection
