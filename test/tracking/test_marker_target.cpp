// The ArUco marker target on rendered marker images with exact corners: the marker is
// drawn by OpenCV (cv::aruco) and warped by a homography from a known camera pose, so its
// corners and the camera's pose are known exactly.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "mono_plane_detection/geometry/camera_model.h"
#include "mono_plane_detection/tracking/marker_target.h"

using namespace mono_plane_detection;

namespace {

constexpr int kSide = 240;    // marker pixels in the drawn image
constexpr int kMargin = 40;   // white quiet zone around it

struct MarkerView {
  cv::Mat image;
  std::array<cv::Point2f, 4> corners;  // truth, in the map frame's order
  Pose map_from_camera;
};

// The camera at `position` (map frame: x right, y up on the printed marker, z out of it)
// looking at the marker's centre, rolled by roll_deg about its optical axis.
MarkerView view(const TargetParams& params, const cv::Vec3d& position, double roll_deg = 0,
                double noise = 0) {
  const CameraModel camera;
  const cv::Vec3d z = cv::normalize(-position);
  const cv::Vec3d up(0, 1, 0);
  cv::Vec3d x = cv::normalize((-up).cross(z));
  cv::Vec3d y = z.cross(x);
  const double r = roll_deg * CV_PI / 180;
  const cv::Vec3d xr = std::cos(r) * x + std::sin(r) * y, yr = -std::sin(r) * x + std::cos(r) * y;
  const cv::Matx33d map_R_cam(xr[0], yr[0], z[0], xr[1], yr[1], z[1], xr[2], yr[2], z[2]);
  const Pose map_from_camera{map_R_cam, position};
  const Pose camera_from_map = map_from_camera.inverse();
  // Drawn-image pixel (u, v) -> map (X, Y, 1): pixel centres, the square spans
  // [kMargin - 0.5, kMargin + kSide - 0.5].
  const double s = params.marker_size_m / kSide;
  const double o = kMargin - 0.5 + kSide / 2.0;
  const cv::Matx33d A(s, 0, -s * o, 0, -s, s * o, 0, 0, 1);
  const cv::Matx33d& R = camera_from_map.R;
  const cv::Matx33d Rt(R(0, 0), R(0, 1), camera_from_map.t[0], R(1, 0), R(1, 1),
                       camera_from_map.t[1], R(2, 0), R(2, 1), camera_from_map.t[2]);
  const cv::Matx33d H = camera.K() * Rt * A;
  MarkerView v;
  const cv::Mat drawn = drawMarkerImage(params, kSide, kMargin);
  cv::warpPerspective(drawn, v.image, cv::Mat(H), camera.size, cv::INTER_LINEAR,
                      cv::BORDER_CONSTANT, cv::Scalar(90));
  if (noise > 0) {
    cv::Mat n(v.image.size(), CV_16S);
    cv::randn(n, 0, noise);
    cv::Mat sum;
    v.image.convertTo(sum, CV_16S);
    sum += n;
    sum.convertTo(v.image, CV_8U);
  }
  const auto map = targetCornersInMap(params);
  for (int i = 0; i < 4; ++i)
    v.corners[i] = camera.project(camera_from_map.apply(cv::Vec3d(map[i].x, map[i].y, 0)));
  v.map_from_camera = map_from_camera;
  return v;
}

TargetParams marker(int id = 7) {
  TargetParams p;
  p.target_type = "aruco";
  p.dictionary = "DICT_4X4_50";
  p.marker_id = id;
  p.marker_size_m = 0.15;
  return p;
}

double worstError(const MarkerView& v, const TargetDetection& d) {
  double worst = 0;
  for (int i = 0; i < 4; ++i) worst = std::max(worst, cv::norm(d.corners[i] - v.corners[i]));
  return worst;
}

}  // namespace

TEST(MarkerTarget, CornersInTheMapOrderToSubPixel) {
  const TargetParams p = marker();
  for (const cv::Vec3d& position : {cv::Vec3d(0, 0, 0.6), cv::Vec3d(0.25, -0.2, 0.55),
                                    cv::Vec3d(-0.3, 0.1, 0.8)}) {
    const MarkerView v = view(p, position, 0, 2.0);
    const TargetDetection d = detectConfiguredTarget(v.image, p);
    ASSERT_TRUE(d.found) << d.reason;
    const double e = worstError(v, d);
    std::printf("marker from (%.2f %.2f %.2f): worst corner %.3f px\n", position[0], position[1],
                position[2], e);
    EXPECT_LT(e, 0.5);
  }
}

// The marker fixes its own orientation: a camera rolled by 90 or 180 deg sees the same
// corner first (the printed marker's bottom-left), unlike the sheet.
TEST(MarkerTarget, OrderFollowsTheMarkerNotTheImage) {
  const TargetParams p = marker();
  for (const double roll : {90.0, 180.0, -90.0}) {
    const MarkerView v = view(p, {0.1, 0.05, 0.7}, roll);
    const TargetDetection d = detectMarkerTarget(v.image, p);
    ASSERT_TRUE(d.found) << d.reason;
    EXPECT_LT(worstError(v, d), 0.5) << "roll " << roll;
  }
}

// Same map frame as the sheet: the camera's pose from the marker's corners is the pose it
// was rendered from.
TEST(MarkerTarget, PoseInTheMapFrame) {
  const TargetParams p = marker();
  const CameraModel camera;
  const cv::Vec3d position(0.2, -0.15, 0.7);
  const MarkerView v = view(p, position, 10);
  const TargetDetection d = detectMarkerTarget(v.image, p);
  ASSERT_TRUE(d.found) << d.reason;
  const auto pose = cameraPoseFromTarget(d, camera.K(), camera.distortion(), p);
  ASSERT_TRUE(pose);
  EXPECT_LT(cv::norm(pose->map_from_camera.t - position), 0.01);  // 1 cm at 0.75 m
  const cv::Matx33d dR = pose->map_from_camera.R.t() * v.map_from_camera.R;
  EXPECT_LT(rotationAngleDeg(dR), 1.0);
  const auto map = targetCornersInMap(p);
  EXPECT_DOUBLE_EQ(map[2].x - map[0].x, 0.15);
  EXPECT_DOUBLE_EQ(map[2].y - map[0].y, 0.15);
}

TEST(MarkerTarget, OtherIdsAndBadParametersSayWhy) {
  const MarkerView v = view(marker(7), {0, 0, 0.6});
  TargetDetection d = detectMarkerTarget(v.image, marker(8));
  EXPECT_FALSE(d.found);
  EXPECT_EQ(d.rejection, TargetRejection::kNoMarker);
  EXPECT_NE(d.reason.find("saw id 7"), std::string::npos) << d.reason;
  // No marker at all, and the sheet detector does not take the marker for a sheet.
  d = detectMarkerTarget(cv::Mat(480, 640, CV_8UC1, cv::Scalar(90)), marker());
  EXPECT_FALSE(d.found);
  EXPECT_FALSE(detectTarget(v.image).found);
  TargetParams bad = marker();
  bad.dictionary = "DICT_9X9_1";
  EXPECT_FALSE(markerParamsError(bad).empty());
  EXPECT_FALSE(targetParamsError(bad).empty());
  EXPECT_EQ(detectMarkerTarget(v.image, bad).rejection, TargetRejection::kBadImage);
  bad = marker(50);  // DICT_4X4_50 holds ids 0-49
  EXPECT_NE(markerParamsError(bad).find("0-49"), std::string::npos);
  bad = marker();
  bad.target_type = "checkerboard";
  EXPECT_FALSE(targetParamsError(bad).empty());
  EXPECT_TRUE(targetParamsError(marker()).empty());
  EXPECT_TRUE(drawMarkerImage(bad, 4).empty());
  EXPECT_EQ(detectMarkerTarget(cv::Mat(), marker()).rejection, TargetRejection::kBadImage);
}
