// The renderer against the geometry: rays, depths, pixels and plane-induced motion.
#include <gtest/gtest.h>

#include <opencv2/aruco.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "mono_plane_detection/sim/scene_renderer.h"

using namespace mono_plane_detection;

namespace {

struct Fixture {
  RoomParams room;
  IndoorScene scene = makeRoom(room);
  CameraModel camera;
  TrajectoryParams trajectory;
};

// H (view a pixel -> view b pixel) induced by a plane of the scene.
cv::Matx33d planeHomography(const CameraModel& cam, const Pose& a, const Pose& b,
                            const ScenePlane& p) {
  const Pose b_from_a = b.inverse() * a;
  const cv::Vec3d n_a = a.R.t() * p.normal();
  const double d_a = p.distance() - p.normal().dot(a.t);  // n_a . X_a = d_a
  const cv::Matx33d H = cam.K() * (b_from_a.R + b_from_a.t * n_a.t() * (1.0 / d_a)) * cam.K().inv();
  return H * (1.0 / H(2, 2));
}

}  // namespace

TEST(SceneRenderer, EveryPixelsRayHitsTheNearestPlaneAtItsDepth) {
  for (double k1 : {0.0, -0.15}) {
    Fixture f;
    f.camera.k1 = k1;
    const SceneRenderer renderer(f.scene, f.camera, RenderOptions());
    const Pose pose = trajectoryPose(f.trajectory, 3.0);
    int checked = 0;
    for (int v = 0; v < 480; v += 24) {
      for (int u = 0; u < 640; u += 32) {
        const cv::Vec3d ray_cam = renderer.ray(u, v);
        const RayHit hit = castRay(f.scene, pose.t, pose.R * ray_cam);
        ASSERT_GE(hit.plane, 0);
        const ScenePlane& p = f.scene.planes[hit.plane];
        const cv::Vec3d X = pose.t + hit.distance * (pose.R * ray_cam);
        // On that plane, inside it, and it projects back onto the pixel.
        EXPECT_NEAR(p.normal().dot(X), p.distance(), 1e-9);
        const cv::Point2d back = f.camera.project(pose.inverse().apply(X));
        EXPECT_NEAR(back.x, u, 1e-3);
        EXPECT_NEAR(back.y, v, 1e-3);
        // No other plane is hit closer along the ray.
        for (size_t k = 0; k < f.scene.planes.size(); ++k) {
          const ScenePlane& q = f.scene.planes[k];
          const double denom = q.normal().dot(pose.R * ray_cam);
          if (k == static_cast<size_t>(hit.plane) || std::abs(denom) < 1e-12) continue;
          const double s = (q.distance() - q.normal().dot(pose.t)) / denom;
          if (s <= 0 || s >= hit.distance) continue;
          const cv::Vec3d local = pose.t + s * (pose.R * ray_cam) - q.origin;
          const double a = local.dot(q.u_axis), b = local.dot(q.v_axis);
          EXPECT_TRUE(a < 0 || b < 0 || a > q.width_m || b > q.height_m) << q.name << " is closer";
        }
        ++checked;
      }
    }
    EXPECT_EQ(checked, 400);
  }
}

TEST(SceneRenderer, PixelsAreTheTextureAtTheHit) {
  Fixture f;
  const SceneRenderer renderer(f.scene, f.camera, RenderOptions());
  const Pose pose = trajectoryPose(f.trajectory, 0.0);
  const cv::Mat image = renderer.render(pose);
  ASSERT_EQ(image.type(), CV_8UC1);
  ASSERT_EQ(image.size(), cv::Size(640, 480));
  for (int v = 5; v < 480; v += 47) {
    for (int u = 5; u < 640; u += 61) {
      const RayHit hit = castRay(f.scene, pose.t, pose.R * renderer.ray(u, v));
      const ScenePlane& p = f.scene.planes[hit.plane];
      cv::Mat texel;
      cv::getRectSubPix(p.texture, {1, 1},
                        cv::Point2f(hit.a * p.texels_per_m, hit.b * p.texels_per_m), texel);
      EXPECT_NEAR(image.at<uchar>(v, u), texel.at<uchar>(0, 0), 1.5) << u << "," << v;
    }
  }
  // The start view shows the target: white at its projected centre.
  const cv::Point2d centre = f.camera.project(pose.inverse().apply(f.scene.target.centre));
  EXPECT_EQ(image.at<uchar>(cvRound(centre.y), cvRound(centre.x)), 255);
}

// A textured plane moves between two images exactly as its plane-induced homography
// says: ECC image alignment (OpenCV), started from that homography, stays within
// 0.05 px of it over the region of the plane.
TEST(SceneRenderer, PlaneMovesAsItsHomographyPredicts) {
  Fixture f;
  RenderOptions options;
  options.supersample = 4;  // anti-aliased, so that image alignment is sub-pixel exact
  const SceneRenderer renderer(f.scene, f.camera, options);
  const Pose a = trajectoryPose(f.trajectory, 1.0), b = trajectoryPose(f.trajectory, 1.2);
  const ScenePlane& wall = f.scene.planes[f.scene.target.plane_index];
  const cv::Matx33d H = planeHomography(f.camera, a, b, wall);
  cv::Mat ia, ib;
  renderer.render(a).convertTo(ia, CV_32F);
  renderer.render(b).convertTo(ib, CV_32F);
  // A region of image a that is the front wall in both images.
  const cv::Rect region(200, 60, 240, 120);
  for (const cv::Point2d corner : {cv::Point2d(200, 60), cv::Point2d(440, 180)}) {
    const RayHit hit = castRay(f.scene, a.t, a.R * renderer.ray(corner.x, corner.y));
    ASSERT_EQ(f.scene.planes[hit.plane].name, "front_wall");
  }
  // ECC's warp maps template (image b) coordinates to input (image a) coordinates.
  cv::Mat warp(cv::Matx33f(H.inv() * (1.0 / H.inv()(2, 2))));
  cv::Mat mask = cv::Mat::zeros(ib.size(), CV_8U);
  std::vector<cv::Point2f> in_b;
  for (const cv::Point2d c :
       {cv::Point2d(region.x, region.y), cv::Point2d(region.br().x, region.y),
        cv::Point2d(region.br().x, region.br().y), cv::Point2d(region.x, region.br().y)}) {
    const cv::Vec3d q = H * cv::Vec3d(c.x, c.y, 1);
    in_b.emplace_back(q[0] / q[2], q[1] / q[2]);
  }
  std::vector<cv::Point> polygon(in_b.begin(), in_b.end());
  cv::fillConvexPoly(mask, polygon, 255);
  cv::erode(mask, mask, cv::Mat(), {-1, -1}, 5);
  const cv::Mat initial = warp.clone();
  cv::findTransformECC(ib, ia, warp, cv::MOTION_HOMOGRAPHY,
                       cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-8),
                       mask, 1);
  // Compared over the plane's region in image b (a grid inside the mask).
  double worst = 0, sum = 0;
  int n = 0;
  const cv::Matx33d w0(initial), w1(warp);
  for (int y = 0; y < mask.rows; y += 8) {
    for (int x = 0; x < mask.cols; x += 8) {
      if (!mask.at<uchar>(y, x)) continue;
      const cv::Vec3d q0 = w0 * cv::Vec3d(x, y, 1), q1 = w1 * cv::Vec3d(x, y, 1);
      const double e = std::hypot(q0[0] / q0[2] - q1[0] / q1[2], q0[1] / q0[2] - q1[1] / q1[2]);
      worst = std::max(worst, e);
      sum += e;
      ++n;
    }
  }

  // Measured: 0.020 px mean, 0.054 px at worst (at the region's border, where an 8-dof
  // alignment is least certain).
  EXPECT_LT(sum / n, 0.05);
  EXPECT_LT(worst, 0.1);
  std::printf("plane-induced homography vs image alignment: %.4f px mean, %.4f px at worst\n",
              sum / n, worst);

  // And by the known texture coordinates: points of the wall projected into both views
  // obey the same homography exactly.
  int projected = 0;
  for (double wa = 1.0; wa < 5.0; wa += 0.5) {
    for (double wb = 0.3; wb < 2.0; wb += 0.4) {
      const cv::Vec3d X = wall.origin + wa * wall.u_axis + wb * wall.v_axis;
      const cv::Vec3d xa = a.inverse().apply(X), xb = b.inverse().apply(X);
      if (xa[2] <= 0 || xb[2] <= 0) continue;
      ++projected;
      const cv::Point2d pa = f.camera.project(xa), pb = f.camera.project(xb);
      const cv::Vec3d q = H * cv::Vec3d(pa.x, pa.y, 1);
      EXPECT_LT(std::hypot(q[0] / q[2] - pb.x, q[1] / q[2] - pb.y), 1e-6);
    }
  }
  EXPECT_GT(projected, 30);  // of the 40 wall points
}

TEST(SceneRenderer, SameSeedSameImageAndNoiseBlurExposureWork) {
  Fixture f;
  RenderOptions options;
  options.noise_sigma = 3;
  const SceneRenderer noisy(f.scene, f.camera, options);
  const Pose pose = trajectoryPose(f.trajectory, 0.5);
  EXPECT_EQ(cv::norm(noisy.render(pose, 7), noisy.render(pose, 7), cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(noisy.render(pose, 7), noisy.render(pose, 8), cv::NORM_L1), 0.0);
  const SceneRenderer clean(f.scene, f.camera, RenderOptions());
  cv::Mat difference;
  cv::absdiff(noisy.render(pose, 7), clean.render(pose), difference);
  cv::Scalar mean, sd;
  cv::meanStdDev(difference, mean, sd);
  EXPECT_NEAR(mean[0], 3 * std::sqrt(2 / CV_PI), 0.3);  // mean |N(0, 3)|
  // Blur: the mean of renders along the path; exposure scales intensity.
  const cv::Mat one = clean.render(pose);
  EXPECT_EQ(cv::norm(one, clean.renderBlurred({pose, pose, pose}), cv::NORM_INF), 0.0);
  const Pose later = trajectoryPose(f.trajectory, 0.6);
  const cv::Mat other = clean.render(later), blurred = clean.renderBlurred({pose, later});
  cv::Mat mean_of_two;
  cv::addWeighted(one, 0.5, other, 0.5, 0, mean_of_two, CV_32F);
  cv::Mat blurred_f;
  blurred.convertTo(blurred_f, CV_32F);
  EXPECT_LE(cv::norm(blurred_f, mean_of_two, cv::NORM_INF), 1.0);  // both poses, averaged
  EXPECT_GT(cv::norm(blurred, one, cv::NORM_L1), 0.0);
  EXPECT_GT(cv::norm(blurred, other, cv::NORM_L1), 0.0);
  RenderOptions dark;
  dark.exposure = 0.5;
  const cv::Mat half = SceneRenderer(f.scene, f.camera, dark).render(pose);
  EXPECT_NEAR(cv::mean(half)[0], cv::mean(one)[0] / 2, 1.0);
}

// The ArUco target (issue 12 part 4): OpenCV's own detector finds the rendered marker
// with its id, and its corners where the ground truth projects them.
TEST(SceneRenderer, ArucoMarkerIsFoundWhereItsCornersAre) {
  RoomParams room;
  room.target_type = "aruco";
  room.aruco_id = 7;
  const IndoorScene scene = makeRoom(room);
  ASSERT_EQ(scene.target.type, "aruco");
  EXPECT_NEAR(scene.target.width_m, 0.15, 0.01);
  const CameraModel camera;
  const SceneRenderer renderer(scene, camera, RenderOptions());
  TrajectoryParams trajectory;
  for (double t : {0.0, 1.0}) {
    const Pose world_from_camera = trajectoryPose(trajectory, t);
    const cv::Mat image = renderer.render(world_from_camera);
    std::vector<std::vector<cv::Point2f>> corners;
    std::vector<int> ids;
    // The pre-4.7 API (Noetic's OpenCV 4.2 has no ArucoDetector).
    const cv::Ptr<cv::aruco::DetectorParameters> detector = cv::aruco::DetectorParameters::create();
    detector->cornerRefinementMethod = cv::aruco::CORNER_REFINE_SUBPIX;
    cv::aruco::detectMarkers(image, cv::aruco::getPredefinedDictionary(cv::aruco::DICT_4X4_50),
                             corners, ids, detector);
    ASSERT_EQ(ids.size(), 1u) << "t = " << t;
    EXPECT_EQ(ids[0], 7);
    // OpenCV's order (top-left, top-right, bottom-right, bottom-left) is ours 3, 2, 1, 0.
    const Pose camera_from_world = world_from_camera.inverse();
    for (int k = 0; k < 4; ++k) {
      const cv::Point2d truth = camera.project(camera_from_world.apply(scene.target.corners[3 - k]));
      EXPECT_LT(cv::norm(cv::Point2d(corners[0][k]) - truth), 0.25) << "corner " << k;
    }
  }
}

TEST(SceneRenderer, SizesBeyondItsMemoryBoundAreNamed) {
  EXPECT_EQ(renderSizeError({4096, 4096}, 1), "");  // 2^24 sub-pixels: the limit itself
  EXPECT_EQ(renderSizeError({320, 240}, 8), "");
  const std::string e = renderSizeError({4096, 4096}, 2);
  EXPECT_NE(e.find("67108864 sub-pixels"), std::string::npos) << e;
  EXPECT_NE(renderSizeError({4097, 4096}, 1), "");
}
