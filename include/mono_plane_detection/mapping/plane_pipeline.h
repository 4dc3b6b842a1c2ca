// The plane stage as one object: each image's tracks are compared with an earlier
// image's (paper III: five-point groups, invariants, homography votes; here every
// dominant plane), the camera is placed in the metric map (PoseEstimator) and the
// planes are fused into the map (PlaneMap). The plane nodelet and the offline tools
// only feed it frames. ROS-free.
#pragma once

#include <deque>
#include <map>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "mono_plane_detection/mapping/odometry_check.h"
#include "mono_plane_detection/mapping/plane_map.h"
#include "mono_plane_detection/mapping/pose_estimator.h"
#include "mono_plane_detection/planes/homography_voting.h"
#include "mono_plane_detection/tracking/stream_gaps.h"
#include "mono_plane_detection/tracking/target_detector.h"
#include "mono_plane_detection/tracking/track_frame.h"

namespace mono_plane_detection {

struct PipelineParams {
  PlaneParams planes;
  PoseParams pose;
  MapParams map;
  TargetParams target;
  // Without intrinsics (or no image sharing enough tracks): compare with the image this
  // many images before.
  int frame_gap = 5;
  double max_gap_s = 1.0;  // a longer pause (and over 3 stream periods) is a tracking loss
  // With intrinsics, the image to compare with (a keyframe) is chosen by its parallax:
  // the median image motion of the tracks that the best-fitting rotation between the two
  // images leaves (pixels at the focal length). Under rotation alone every plane moves
  // with the same homography and the planes cannot be told apart. Without intrinsics:
  // frame_gap images back.
  double keyframe_parallax_px = 12.0;  // the most recent image with this much is taken
  double min_parallax_px = 4.0;        // below this (the best within reach): no planes
  int max_keyframe_age = 45;           // images kept to choose from (1.5 s at 30 Hz)
  double min_keyframe_shared = 0.5;    // of the current tracks the keyframe must still hold
  // Planes before landmarks (issue 18, the wheeled sideboard front with odometry): with
  // poses from odometry, an image plane whose tracks have fewer than map.min_points
  // landmarks gets a plane from its tracks' image motion and those poses (planeFromMotion:
  // each track from its earliest image within reach placed by odometry; poses from the
  // landmarks are not used: their errors over baselines of centimetres tilted the
  // furnished room's left wall by 7 deg), fused over the images it is returned in
  // (weights 1/sigma^2), from the tracks that were its members in at least half of them:
  // a track of another surface joins the vote's plane for 1-4 images and bends a fit of
  // 10 tracks by degrees while fitting within noise itself. After this many fits, once
  // the fused normal's sigma is within map.max_normal_sigma_deg, its tracks go to the
  // map as points on that plane (landmarks where they have one), the camera centres the
  // fit took them from counted as views. Furnished room, 10 noise seeds, images 4-25:
  // single fits of the sideboard 2.9 deg off (median, 90 % 15 deg), fused from the
  // stayed tracks 0.5-2.2 deg and 0.1-2.2 % (docs/mapping.md). 0 (the default): off.
  // Off because the room's odometry was the true pose: a robot's wheel or leg odometry
  // errs by millimetres to centimetres over the few centimetres these fits span, which
  // tilted them by degrees when the landmarks' poses were used, and the fused sigma counts
  // images that share their tracks as independent (1.5 times too small). On (5) for
  // odometry known to be right at the centimetre scale (motion capture, a good VIO).
  int motion_plane_images = 0;
};

// Empty when K and the distortion describe a usable camera, else why not.
std::string cameraIntrinsicsError(const cv::Matx33d& K, const cv::Mat& distortion);

// A plane found in this image (image space).
struct ImagePlane {
  int id = 0;     // stable while the plane keeps most of its tracks
  cv::Matx33d H;  // reference image pixel -> this image pixel
  std::vector<std::uint64_t> inlier_ids;
  double rms_error_px = 0;
  int map_id = -1;  // the map plane it was fused into, -1 when none
};

enum class PipelineState { kNoCamera, kWaitingForTarget, kInitialising, kLost, kTracking };

struct PipelineResult {
  PipelineState state = PipelineState::kNoCamera;
  std::string status;      // for people: "waiting for target", ...
  bool was_reset = false;  // time went backwards: everything started again
  // ...or the tracker started over: its ids (never reused by one tracker) began again
  // below those seen, none of the last image's left (a reloaded or respawned tracker
  // nodelet: its ids 1, 2, ... met the old map's landmarks, "lost" for good).
  bool tracker_restarted = false;
  bool tracking_loss = false;  // the pause since the last image exceeded max_gap_s
  double pause_s = 0;          // with tracking_loss: that pause, s
  // Images missing from the stream just before this one, by the stamps' gaps (GapCounter):
  // dropped by the tracker, or frames this stage's caller never got.
  long missing_images = 0;
  // kInitialising (the target start): how long it has waited, and since the target's four
  // corners were last tracked, s of stamps (PoseEstimator::startWaitS).
  double start_wait_s = 0;
  double start_target_unseen_s = 0;
  std::optional<PoseEstimate> pose;  // this image's camera in the map
  std::vector<ImagePlane> planes;    // largest first
  double reference_stamp = -1;       // image the homographies start from, -1 none
  // Rotation-free parallax to the reference (px at the focal length), -1 when not
  // measured (no intrinsics: the reference is frame_gap images back).
  double parallax_px = -1;
  // The motion since the images within reach is (nearly) a pure rotation: no planes
  // were segmented (status says so).
  bool pure_rotation = false;
  // With odometry poses here and at the reference: whether they explain the tracks.
  OdometryCheck odometry_check;
  TrackPairs pairs;                // reference/current pixels the planes were found in
  PlaneSegmentation segmentation;  // over `pairs`
};

class PlanePipeline {
 public:
  explicit PlanePipeline(const PipelineParams& params = PipelineParams());

  // Sets the intrinsics when cameraIntrinsicsError accepts them (else returns its
  // reason and changes nothing); a change of calibration (K, or the distortion's values
  // or number) restarts everything that depends on it: pose, map, image history.
  std::string setCamera(const cv::Matx33d& K, const cv::Mat& distortion);
  bool hasCamera() const { return pose_.has_value(); }

  // Frames must be valid (validateTrackFrame). odom_from_camera: robot odometry, if any.
  PipelineResult process(const TrackFrame& frame, const std::optional<Pose>& odom_from_camera = {});

  const PlaneMap& map() const { return map_; }
  // Whether the map's vertical (PlaneMap::vertical) has been decided for this map: at its
  // first placed image with metres.
  bool verticalDecided() const { return vertical_decided_; }
  const PoseEstimator* poseEstimator() const { return pose_ ? &*pose_ : nullptr; }
  // The odometry's recent checks against the tracks (PipelineResult::odometry_check).
  const OdometryMonitor& odometryMonitor() const { return odometry_monitor_; }
  const PipelineParams& params() const { return params_; }
  // The parameters read anew on every image (planes/..., frame_gap, max_gap_s): the next
  // image uses them (dynamic_reconfigure); the others need a new pipeline.
  void setPerImageParams(const PlaneParams& planes, int frame_gap, double max_gap_s);
  void reset();

 private:
  // newest: the frame's largest id (0 when it has none).
  bool trackerStartedOver(const TrackFrame& frame, std::uint64_t newest) const;
  void assignImageIds(std::vector<ImagePlane>& planes);
  // motion_plane_images: replaces the observation of each image plane with too few
  // landmarks by its tracks on the fused plane from motion, once that is known well.
  void addMotionPlanes(const std::vector<ImagePlane>& planes, const Pose& map_from_camera,
                       const TrackFrame& frame, const std::vector<cv::Point2d>& normalized,
                       std::vector<PlaneObservation>& observations);

  PipelineParams params_;
  std::optional<PoseEstimator> pose_;
  cv::Matx33d K_;
  cv::Mat distortion_;
  PlaneMap map_;
  bool vertical_decided_ = false;  // the map's vertical set (PlaneMap::setVertical) for this map
  struct PastFrame {
    TrackFrame frame;
    std::optional<Pose> map_from_camera;
    std::vector<cv::Point2d> normalized;  // undistorted, per track (with intrinsics)
    bool odometry = false;                // its pose came from odometry
  };
  // The reference for `frame`: index into history_, its parallax (-1: not measured),
  // -1 index when every image within reach is a rotation away.
  std::pair<int, double> chooseReference(const TrackFrame& frame, const std::optional<Pose>& pose,
                                         const std::vector<cv::Point2d>& normalized) const;
  std::vector<cv::Point2d> normalize(const std::vector<cv::Point2d>& pixels) const;
  // The map's observations of these image planes from this pose (landmarks with sigmas).
  std::vector<PlaneObservation> observationsOf(const std::vector<ImagePlane>& planes,
                                               const PoseEstimate& pose) const;
  // camera_height: images seen while the start was checked (PoseEstimator::checkingPose).
  struct PendingView {
    double stamp;
    PoseEstimate pose;
    std::vector<ImagePlane> planes;
  };
  std::deque<PendingView> pending_;  // the oldest dropped first

  std::deque<PastFrame> history_;
  std::uint64_t newest_id_ = 0;  // the largest track id seen since the last reset
  std::uint32_t tracker_run_ = 0;  // TrackFrame::tracker_run since the last reset (0: none)
  GapCounter stream_;            // the tracks' rhythm: what counts as a pause
  std::vector<ImagePlane> previous_planes_;
  int next_image_id_ = 1;
  // motion_plane_images: per image plane id, the images each track was a member in and
  // the fits so far (information-weighted, map frame).
  struct MotionPlaneState {
    std::unordered_map<std::uint64_t, int> member_images;
    int images = 0, fits = 0;
    long last_image = 0;
    cv::Vec3d normal_sum{0, 0, 0};
    double normal_weight = 0, distance_sum = 0, distance_weight = 0;
  };
  std::map<int, MotionPlaneState> motion_planes_;
  OdometryMonitor odometry_monitor_;
  long image_count_ = 0;
};

}  // namespace mono_plane_detection
