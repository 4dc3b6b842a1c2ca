// Local bundle adjustment (beyond the paper; as PTAM's and ORB-SLAM's local mapping):
// the camera poses of the last few keyframes and the landmarks they see are refined
// together by minimising the reprojection error, so that the drift of one frame-to-frame
// pose (PnP on landmarks triangulated from two views) does not pass into every later
// landmark. Levenberg-Marquardt on the normal equations with the points eliminated
// (Schur complement onto the poses: a dense 6n x 6n system, n the free poses), Huber
// weights in units of the observations' own noise (measured from the residuals). The
// views marked fixed (the oldest keyframes, the views landmarks were first seen from)
// fix the gauge: position, orientation and, with two of them apart, the scale. ROS-free.
#pragma once

#include <string>
#include <vector>

#include "mono_plane_detection/geometry/pose.h"

namespace mono_plane_detection {

struct BundleOptions {
  int max_iterations = 10;     // Levenberg-Marquardt steps tried per round (two rounds)
  double huber_sigmas = 2.45;  // Huber threshold, in sigmas of the residual (chi2 95 %, 2 dof)
  double min_sigma_px = 0.1;   // the residuals' noise is taken as at least this
  double focal_px = 500;       // residuals in pixels: normalised error times the focal length
};

struct BundleView {
  Pose map_from_camera;
  bool fixed = false;
};

struct BundlePoint {
  cv::Vec3d position;  // map frame
  bool fixed = false;
};

struct BundleObservation {
  int view = 0;
  int point = 0;
  cv::Point2d normalized;  // undistorted normalised image coordinates
};

struct BundleProblem {
  std::vector<BundleView> views;
  std::vector<BundlePoint> points;
  std::vector<BundleObservation> observations;
};

struct BundleResult {
  bool ok = false;
  std::string reason;         // why not, when !ok
  int iterations = 0;         // steps tried (taken or not), both rounds
  double sigma_px = 0;        // the residuals' noise, measured after the first round
  // Reprojection rms of the inliers before (Huber threshold of the noise measured as
  // given) and after (of the noise measured after the first round).
  double initial_rms_px = 0;
  double final_rms_px = 0;
  // Per observation: its residual after the adjustment is beyond the Huber threshold.
  std::vector<bool> outlier;
  // Per observation: its residual after the adjustment, px (infinite: behind the camera).
  std::vector<double> residual_px;
  // Observations whose point is behind their camera as given, and after the adjustment.
  // They have no say in it (a point behind projects as its mirror image); those behind
  // after are outliers with an infinite residual: the landmark or the observation is
  // wrong, and the caller starts the landmark again or drops the observation.
  int behind_given = 0;
  int behind_after = 0;
  int refused_behind = 0;  // steps refused: they put a point behind a camera it was in front of
};

// Refines the free views and points of `problem` in place. Every free point should have
// two observations (with one it only slides along its ray under the damping: the caller
// holds such points fixed) and every free view some. An observation whose point is
// behind its camera as a round starts is left out of that round, and no step may put a
// point behind a camera it is in front of. Nothing is changed when no step lowers the
// cost, nor when the input is refused (!ok: a name out of range, a value not finite,
// options out of range, fewer than 6 observations in front).
BundleResult adjustBundle(BundleProblem& problem, const BundleOptions& options);

}  // namespace mono_plane_detection
