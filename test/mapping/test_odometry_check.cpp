// checkOdometryMotion / OdometryMonitor: odometry that moves the camera otherwise than its
// tracks show is found; right odometry (with a real robot's errors) is not.
#include <gtest/gtest.h>

#include <unordered_map>

#include "mono_plane_detection/mapping/odometry_check.h"
#include "support/synthetic_tracks.h"

using namespace mono_plane_detection;

namespace {

constexpr double kFocal = 525;  // the synthetic camera's
constexpr double kNoise = 0.2;  // px, the tracks' noise (as PlaneSegmentation estimates it)

// The shared tracks of the wheeled path's images at t0 and t1 (s), normalized, and the
// true motion between them (the current camera from the reference one).
struct TrackPair {
  std::vector<cv::Point2d> ref, cur;
  Pose cur_from_ref;
};

TrackPair wheeledPair(double t0, double t1, double noise_px = 0.2) {
  const SyntheticTracks world("wheeled");
  const TrackFrame a = world.frame(t0, noise_px), b = world.frame(t1, noise_px);
  std::unordered_map<std::uint64_t, size_t> in_b;
  for (size_t i = 0; i < b.ids.size(); ++i) in_b.emplace(b.ids[i], i);
  const CameraModel& c = world.camera;
  auto normalized = [&](const cv::Point2d& p) {
    return cv::Point2d((p.x - c.cx) / c.fx, (p.y - c.cy) / c.fy);
  };
  TrackPair out;
  for (size_t i = 0; i < a.ids.size(); ++i) {
    const auto it = in_b.find(a.ids[i]);
    if (it == in_b.end()) continue;
    out.ref.push_back(normalized(a.pixels[i]));
    out.cur.push_back(normalized(b.pixels[it->second]));
  }
  out.cur_from_ref = world.truthMapFromCamera(t1).inverse() * world.truthMapFromCamera(t0);
  return out;
}

cv::Matx33d about(const cv::Vec3d& axis, double deg) {
  cv::Matx33d R;
  cv::Rodrigues(axis * (deg * CV_PI / 180 / cv::norm(axis)), R);
  return R;
}

}  // namespace

TEST(OdometryCheck, TheTrueMotionAgrees) {
  const TrackPair pair = wheeledPair(2.0, 2.5);
  ASSERT_GE(pair.ref.size(), 40u);
  const OdometryCheck check =
      checkOdometryMotion(pair.ref, pair.cur, pair.cur_from_ref, 30.0, kNoise, kFocal);
  ASSERT_TRUE(check.decided);
  EXPECT_TRUE(check.agrees);
  std::printf("true motion: translation %.2f deg, rotation %.2f deg off\n",
              check.direction_error_deg, check.rotation_error_deg);
  // Measured 5.7 and 0.5 deg (RANSAC's essential matrix, 0.2 px noise, 0.5 s of the
  // wheeled path): far inside the bounds of 45 and 10 deg.
  EXPECT_LT(check.direction_error_deg, 10.0);
  EXPECT_LT(check.rotation_error_deg, 1.0);
}

// A robot's odometry errs: its scale by 10 %, its direction by 8 deg, its turn by 1 deg.
TEST(OdometryCheck, OdometryWithARobotsErrorsAgrees) {
  const TrackPair pair = wheeledPair(2.0, 2.5);
  Pose odometry = pair.cur_from_ref;
  odometry.t = 1.1 * (about({0, 1, 0}, 8.0) * odometry.t);
  odometry.R = about({0, 1, 0}, 1.0) * odometry.R;
  const OdometryCheck check =
      checkOdometryMotion(pair.ref, pair.cur, odometry, 30.0, kNoise, kFocal);
  ASSERT_TRUE(check.decided);
  EXPECT_TRUE(check.agrees) << check.direction_error_deg << " / " << check.rotation_error_deg;
}

// odom_frame:=base_link on a humanoid (the head on joints): its "odometry" is the head's
// turn only, no travel, or a few millimetres sideways from the pan axis.
TEST(OdometryCheck, AFrameThatMovesWithTheRobotDisagrees) {
  const TrackPair pair = wheeledPair(2.0, 2.5);
  Pose still = pair.cur_from_ref;
  still.t = cv::Vec3d(0, 0, 0);
  const OdometryCheck none = checkOdometryMotion(pair.ref, pair.cur, still, 30.0, kNoise, kFocal);
  ASSERT_TRUE(none.decided);
  EXPECT_FALSE(none.agrees);
  EXPECT_EQ(none.direction_error_deg, 180.0);
  Pose head = still;
  head.t = cv::Vec3d(0.004, 0, 0.001);
  const OdometryCheck pan = checkOdometryMotion(pair.ref, pair.cur, head, 30.0, kNoise, kFocal);
  ASSERT_TRUE(pan.decided);
  EXPECT_FALSE(pan.agrees);
  EXPECT_GT(pan.direction_error_deg, 45.0);
}

// Images stamped with camera_link (x forward, y left, z up) where the optical frame (z
// forward, x right, y down) is meant: tf's motion of that frame, read as the optical one's.
TEST(OdometryCheck, MotionInTheWrongAxesDisagrees) {
  const TrackPair pair = wheeledPair(2.0, 2.5);
  const cv::Matx33d link_from_optical(0, 0, 1, -1, 0, 0, 0, -1, 0);
  const Pose axes{link_from_optical, {0, 0, 0}};
  const Pose wrong = axes * pair.cur_from_ref * axes.inverse();
  const OdometryCheck check = checkOdometryMotion(pair.ref, pair.cur, wrong, 30.0, kNoise, kFocal);
  ASSERT_TRUE(check.decided);
  EXPECT_FALSE(check.agrees);
  EXPECT_GT(check.direction_error_deg, 45.0);
}

TEST(OdometryCheck, TooFewTracksOrTooLittleParallaxIsNotDecided) {
  const TrackPair pair = wheeledPair(2.0, 2.5);
  Pose still = pair.cur_from_ref;
  still.t = cv::Vec3d(0, 0, 0);
  EXPECT_FALSE(
      checkOdometryMotion(pair.ref, pair.cur, still, 20.0, kNoise, kFocal).decided);  // under 24 px
  const std::vector<cv::Point2d> few_ref(pair.ref.begin(), pair.ref.begin() + 15),
      few_cur(pair.cur.begin(), pair.cur.begin() + 15);
  EXPECT_FALSE(checkOdometryMotion(few_ref, few_cur, still, 30.0, kNoise, kFocal).decided);
  EXPECT_FALSE(
      checkOdometryMotion(pair.ref, few_cur, still, 30.0, kNoise, kFocal).decided);  // sizes differ
  EXPECT_FALSE(
      checkOdometryMotion(pair.ref, pair.cur, still, 30.0, 0.0, kFocal).decided);  // no scale
}

TEST(OdometryMonitor, APersistentDisagreementOnly) {
  OdometryCheck good, bad, undecided;
  good.decided = bad.decided = true;
  bad.agrees = false;
  bad.direction_error_deg = 88;
  bad.rotation_error_deg = 0.4;
  OdometryMonitor monitor;  // 7 of the last 10
  for (int k = 0; k < 4; ++k) monitor.add(good);
  for (int k = 0; k < 6; ++k) monitor.add(bad);
  for (int k = 0; k < 20; ++k) monitor.add(undecided);  // not counted
  EXPECT_FALSE(monitor.disagrees());
  EXPECT_EQ(monitor.summary(), "");
  monitor.add(bad);  // 7 of 10
  EXPECT_TRUE(monitor.disagrees());
  EXPECT_EQ(monitor.summary(),
            "its translation 88 deg off the tracks' (median), its rotation 0.4 deg, in 7 of "
            "the last 10 image pairs with parallax");
  for (int k = 0; k < 4; ++k) monitor.add(good);  // 3 of the last 10: it agrees again
  EXPECT_FALSE(monitor.disagrees());
  monitor.add(bad);
  monitor.reset();
  EXPECT_FALSE(monitor.disagrees());
}

// A disagreement is forgotten 10 s (image stamps) after its checks: a robot standing still
// decides no more checks, and the ERROR must not stay for ever (a review).
TEST(OdometryMonitor, OldChecksAreForgotten) {
  OdometryMonitor monitor;
  OdometryCheck bad;
  bad.decided = true;
  bad.agrees = false;
  for (int k = 0; k < 10; ++k) {
    bad.stamp = 100 + 0.2 * k;
    monitor.add(bad);
  }
  EXPECT_TRUE(monitor.disagrees());
  OdometryCheck undecided;  // images go on, nothing decided
  undecided.stamp = 105;
  monitor.add(undecided);
  EXPECT_TRUE(monitor.disagrees());
  monitor.tick(111.5);  // the first seven are over 10 s old
  EXPECT_FALSE(monitor.disagrees());
  bad.stamp = 112;
  monitor.add(bad);
  monitor.tick(50);  // time went back (a bag loop): a new stream
  EXPECT_FALSE(monitor.disagrees());
}
