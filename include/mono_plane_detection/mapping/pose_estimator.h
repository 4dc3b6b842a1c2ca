// The camera's pose in the metric map over time (beyond the paper, which stops at
// image-space planes): the start-up target's corners fix pose and scale, tracks are
// triangulated into landmarks once they have seen enough parallax, and the landmarks
// place the camera (PnP) after the target has left the view. Optionally an odometry
// pose (odom -> camera) replaces the visual estimate, the target fixing map -> odom.
// Without a target the metres come from the odometry itself (the map is the odometry
// frame) or from the camera's known height above the floor (camera_height_scale.h):
// PoseParams::metric_source. ROS-free.
#pragma once

#include <cstdint>
#include <deque>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "mono_plane_detection/geometry/pose.h"
#include "mono_plane_detection/mapping/camera_height_scale.h"
#include "mono_plane_detection/mapping/local_bundle_adjustment.h"
#include "mono_plane_detection/mapping/two_view_init.h"
#include "mono_plane_detection/tracking/target_detector.h"
#include "mono_plane_detection/tracking/track_frame.h"

namespace mono_plane_detection {

struct PoseParams {
  double min_parallax_deg = 3.0;      // triangulate a track once its two rays differ this much
  double retriangulate_factor = 1.5;  // and again each time its parallax grows by this factor
  double max_reprojection_px = 2.0;   // PnP inliers and triangulation check
  int min_pnp_points = 8;             // landmarks needed to place the camera without the target
  double min_inlier_share = 0.5;      // of the landmarks in view, else the PnP pose is refused
  double max_jump_m = 0.5;            // a PnP pose further than this from the last one is refused
  double min_depth_m = 0.05;          // triangulated points must be this far in front of both views
  size_t max_landmarks = 5000;        // least recently seen are dropped beyond this
  TwoViewParams two_view;             // the metric start (two_view_init.h)
  // Where the metres come from: target | odometry | camera_height | auto (the first of
  // them that is available). Once one has started the map, the others are ignored.
  std::string metric_source = "target";
  FloorParams floor;  // camera_height (camera_height_scale.h)
  // Keyframes of the local bundle adjustment run at each new keyframe (the oldest two
  // held fixed); 0: none (local_bundle_adjustment.h). Measured (docs/mapping.md): the
  // humanoid camera_height map's worst normal 3.45 -> 2.66 deg (noise seed 0); 6
  // keyframes missed a floor, 20 took 3-5 times as long.
  int bundle_window = 10;
};

// The source that started the metric map.
enum class MetricSource { kNone, kTarget, kOdometry, kCameraHeight };
const char* toString(MetricSource source);
// Empty when `choice` is one of target, odometry, camera_height, auto; else why not.
std::string metricSourceError(const std::string& choice);

// A track's 3D point. Before triangulation only its first observation with a known
// camera pose (the anchor) is known.
struct Landmark {
  bool triangulated = false;
  bool fixed = false;              // a target corner: position known exactly
  cv::Vec3d position;              // map frame, m (when triangulated or fixed)
  Pose anchor_pose;                // map_from_camera at the anchor observation
  std::int64_t anchor_image = -1;  // that image's imageIndex() (-1: none)
  cv::Point2d anchor_normalized;   // undistorted normalised image coordinates there
  double parallax_deg = 0;         // between the two rays of the triangulation
  double last_seen = 0;            // stamp, s
  // Anchored or triangulated from a vision-only pose while the odometry of an odometry
  // map was missing: used to place the camera, not given out (landmarkPosition), and
  // started again from the odometry when it returns.
  bool provisional = false;
};

enum class PoseSource { kTarget, kLandmarks, kOdometry };
const char* toString(PoseSource source);

struct PoseEstimate {
  Pose map_from_camera;
  PoseSource source = PoseSource::kTarget;
  int points = 0;     // correspondences behind it (PnP inliers, target corners)
  double rms_px = 0;  // their reprojection error
};

class PoseEstimator {
 public:
  PoseEstimator(const cv::Matx33d& K, const cv::Mat& distortion,
                const PoseParams& params = PoseParams(),
                const TargetParams& target = TargetParams());

  // The camera's pose for this frame, nothing while it cannot be known (target not seen
  // yet, start not done: not enough motion yet, too few landmarks). Triangulates new
  // landmarks when the pose is known.
  // odom_from_camera: the robot's odometry for this frame, when it has one, in the
  // core's axis convention (y up: the ROS boundary turns a z-up odometry frame into it,
  // ros/map_frame.h). With metric_source odometry the map IS this odometry frame.
  std::optional<PoseEstimate> update(const TrackFrame& frame,
                                     const std::optional<Pose>& odom_from_camera = {});

  // True once a metric source has started: poses are in metres (for the target: once
  // it has been seen, before the two-view start).
  // camera_height: not while the start is being checked against the floor landmarks.
  bool scaleKnown() const { return metric_ != MetricSource::kNone && !floor_check_; }
  // kNone while a camera_height start is being checked (nothing metric is given out).
  MetricSource metricSource() const { return scaleKnown() ? metric_ : MetricSource::kNone; }
  // camera_height, while an up-to-scale start waits for its floor: this image's pose in
  // the start's (uncorrected) map, not given out; the plane map takes it once the check
  // has corrected the start (floorCorrectionApplied), with what the planes showed
  // meanwhile: that floor may come long after the planes seen first have left the view
  // (a humanoid: image 250 of 300). Not after a floor start: its check comes after one
  // camera height, and the planes seen before it, from the start's rougher landmarks,
  // tilted the wheeled room's front wall 1.4 -> 4.0 deg.
  const std::optional<PoseEstimate>& checkingPose() const { return checking_pose_; }
  // The similarity the last floor check applied to the map (identity before).
  const Similarity& floorCorrectionApplied() const { return correction_; }
  // camera_height: the landmarks the passed floor check fitted the floor to (ids) and
  // the imageIndex() of that image (-1 before).
  struct CheckedFloor {
    std::vector<std::uint64_t> ids;
    std::int64_t image = -1;
  };
  const CheckedFloor& checkedFloor() const { return checked_floor_; }
  // How many images update() has been given, less one: the last image's number. Images
  // are told apart by it, not by their stamps (a driver may stamp two images alike).
  std::int64_t imageIndex() const { return image_index_; }
  // What the start waits for, for people ("waiting for target", ...).
  std::string waitingFor() const;
  // True once the two-view start has placed the first landmarks (before that the pose
  // comes from the target alone and nothing is triangulated).
  bool initialised() const { return initialised_; }
  // The target start before it succeeds (not initialised, the target counting): how long
  // it has waited since the target was first seen, and since all four of its corners were
  // last tracked, s of stamps (0 otherwise). The start needs the target in two views with
  // parallax: a target that left the view makes it wait for ever (hostile try: "waiting
  // for camera motion" for 550 images while the camera travelled 3 m, status OK).
  double startWaitS() const { return start_wait_s_; }
  double startTargetUnseenS() const { return start_target_unseen_s_; }
  const std::unordered_map<std::uint64_t, Landmark>& landmarks() const { return landmarks_; }
  // Triangulated (or fixed) landmark position of a track, if any (not provisional).
  std::optional<cv::Vec3d> landmarkPosition(std::uint64_t id) const;
  // After a pause (tracking loss) the last pose is no guide to the next.
  void forgetLastPose() { last_pose_.reset(); }
  void reset();
  // The local bundle adjustment's time per run, ms (the last 1000 keyframes it ran at).
  const std::vector<double>& bundleTimesMs() const { return bundle_times_ms_; }
  // What the local bundle adjustment refused or flagged, since the start.
  struct BundleCounts {
    int refused = 0;  // runs whose input was refused (last_reason)
    std::string last_reason;
    int behind_after = 0;    // observations behind their camera after a run (outliers)
    int refused_behind = 0;  // steps refused: they put a point behind a camera
  };
  const BundleCounts& bundleCounts() const { return bundle_counts_; }

 private:
  std::optional<PoseEstimate> visualPose(const TrackFrame& frame,
                                         const std::vector<cv::Point2d>& normalized);
  void triangulate(const TrackFrame& frame, const std::vector<cv::Point2d>& normalized,
                   const Pose& map_from_camera);
  std::optional<PoseEstimate> initialise(const TrackFrame& frame,
                                         const std::vector<cv::Point2d>& normalized);
  std::optional<PoseEstimate> targetPose(const TrackFrame& frame) const;
  // unscaled: set when the map started up to scale (no floor in the image).
  std::optional<PoseEstimate> startFromFloor(const TrackFrame& frame,
                                             const std::vector<cv::Point2d>& normalized,
                                             bool& unscaled);
  // Landmarks of a two-view start; the second view is this frame.
  // The first view (ids, first) and this frame become the first keyframes.
  void placeStartLandmarks(const TrackFrame& frame, const std::vector<std::uint64_t>& ids,
                           const std::vector<cv::Point2d>& first,
                           const std::vector<cv::Point2d>& second, const std::vector<int>& points,
                           const std::vector<cv::Vec3d>& points_map, double parallax_deg,
                           const Pose& map_from_first, const Pose& map_from_second);
  // Adds this frame as a keyframe when its tracks have moved since the last one, and
  // then adjusts the window (local_bundle_adjustment.h): the keyframes' poses, their
  // landmarks and the estimate's pose.
  void bundleAdjust(const TrackFrame& frame, const std::vector<cv::Point2d>& normalized,
                    PoseEstimate& estimate);
  // Its steps (pose_estimator_window.cpp): this frame kept as a keyframe or not (true:
  // a window of at least 3 to adjust), the window's problem, and the adjusted window
  // written back (poses, landmarks; observations it disagrees with dropped or restarted).
  struct WindowProblem {
    BundleProblem problem;
    std::vector<std::uint64_t> point_ids;        // the landmark of each problem point
    size_t keyframe_observations = 0;            // the first ones: the keyframes' (then anchors')
    size_t first_in_window = 0, first_free = 0;  // keyframe indices
    std::unordered_map<std::int64_t, int> keyframe_of_image;
  };
  bool addKeyframe(const TrackFrame& frame, const std::vector<cv::Point2d>& normalized,
                   const PoseEstimate& estimate);
  size_t bundleWindow() const;
  WindowProblem windowProblem() const;
  void applyWindow(const WindowProblem& w, const BundleResult& result, PoseEstimate& estimate);
  bool allows(MetricSource source) const;
  void restartProvisional(const TrackFrame& frame, const std::vector<cv::Point2d>& normalized,
                          const Pose& map_from_camera);
  void forgetOldLandmarks();
  // camera_height: checks the start against the floor its landmarks show; true once the
  // map has been corrected (poses may be given out), false while waiting; undoes the
  // start when the floor disagrees.
  bool checkFloor(PoseEstimate& estimate, const std::optional<Pose>& odom_from_camera);
  void undoFloorStart(const std::string& why);
  // Tracks of this image with a landmark position (landmarkPosition).
  int landmarksInView(const TrackFrame& frame) const;

  struct FirstView {  // the image the two-view start measures motion from
    std::vector<std::uint64_t> ids;
    std::vector<cv::Point2d> normalized;
    // Its target corners, averaged over the later images carried back by the wall's
    // homography (two_view_init.h explains why).
    std::array<cv::Point2d, 4> corner_sum{};
    int corner_count = 0;
    double stamp = 0;
    // camera_height: how many images in a row found the same floor against this view.
    int floor_count = 0;
    cv::Vec3d floor_down{0, 0, 0};
    // The tracks' points in this view's frame (metres) by each of those images' floor.
    std::vector<std::unordered_map<std::uint64_t, cv::Vec3d>> floor_points{};
    std::vector<cv::Vec3d> floor_downs{};
    // Its orientation (map_from_camera.R) by each image's own corners, carried back by
    // the relative rotation: summed, projected onto a rotation at the start.
    cv::Matx33d rotation_sum = cv::Matx33d::zeros();
    int rotation_count = 0;
  };
  FirstView firstView(const TrackFrame& frame, const std::vector<cv::Point2d>& normalized) const;

  cv::Matx33d K_;
  cv::Mat distortion_;
  PoseParams params_;
  TargetParams target_;
  std::vector<std::uint64_t> target_ids_;  // in TargetDetection's corner order
  std::unordered_map<std::uint64_t, Landmark> landmarks_;
  std::optional<Pose> last_pose_;
  std::optional<Pose> map_from_odom_;
  bool vision_only_ = false;  // odometry map, odometry missing for this image
  bool initialised_ = false;
  double start_first_stamp_ = -1, start_target_stamp_ = -1;  // (startWaitS)
  double start_wait_s_ = 0, start_target_unseen_s_ = 0;
  std::optional<FirstView> first_view_;
  MetricSource metric_ = MetricSource::kNone;
  std::string floor_reason_;  // why the camera_height start has not happened yet
  // camera_height: earlier images the floor's motion is measured from (a new one each
  // time the tracks have moved 1 % of the focal length, at most 20), dropped when they
  // share fewer tracks than a floor needs; the oldest is tried first (most parallax).
  std::deque<FirstView> floor_views_;
  // camera_height: after the start, until the floor landmarks confirm and correct it.
  struct FloorCheck {
    std::vector<cv::Vec3d> cameras;  // positions since the start, map frame
    cv::Vec3d start_up{0, 1, 0};     // the map's up as the start set it
    // Started up to scale (unscaledStart): the floor is looked for within
    // floor_max_angle_deg of the nominal up, its scale is not bounded, and the start is
    // not undone for want of a floor.
    bool unscaled = false;
    double last_placed_s = -1;  // stamp of the newest image placed since the start
  };
  std::optional<FloorCheck> floor_check_;
  std::optional<PoseEstimate> checking_pose_;
  Similarity correction_;
  CheckedFloor checked_floor_;
  struct Keyframe {
    std::int64_t image = -2;  // imageIndex() (-2: the two-view start's first view)
    Pose map_from_camera;
    std::vector<std::uint64_t> ids;
    std::vector<cv::Point2d> normalized;
  };
  std::int64_t image_index_ = -1;   // never reset: an index is not used twice
  std::deque<Keyframe> keyframes_;  // the window (newest bundle_window) and as many before it
  std::vector<double> bundle_times_ms_;
  BundleCounts bundle_counts_;
};

}  // namespace mono_plane_detection
