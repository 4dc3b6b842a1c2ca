// The start-up target in rendered views with exact ground truth.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "mono_plane_detection/sim/scene_renderer.h"
#include "mono_plane_detection/tracking/target_detector.h"

using namespace mono_plane_detection;

namespace {

struct View {
  IndoorScene scene;
  CameraModel camera;
  Pose world_from_camera;
  cv::Mat image;
};

View render(const std::string& target_on, const std::string& trajectory, double t, double noise = 0,
            int blur = 1) {
  RoomParams room;
  room.target_on = target_on;
  View v{makeRoom(room), CameraModel(), Pose(), cv::Mat()};
  TrajectoryParams tp;
  tp.name = trajectory;
  if (target_on == "floor") tp.pitch_down_deg = 35;
  RenderOptions options;
  options.noise_sigma = noise;
  options.supersample = 2;
  const SceneRenderer renderer(v.scene, v.camera, options);
  v.world_from_camera = trajectoryPose(tp, t);
  std::vector<Pose> path;
  for (int s = 0; s < blur; ++s) path.push_back(trajectoryPose(tp, std::max(0.0, t - 0.005 * s)));
  v.image = renderer.renderBlurred(path, 3);
  return v;
}

// Largest distance between detected corners and the true ones, in the map order.
double cornerError(const View& v, const TargetDetection& d) {
  double worst = 0;
  for (int i = 0; i < 4; ++i) {
    const cv::Point2d truth =
        v.camera.project(v.world_from_camera.inverse().apply(v.scene.target.corners[i]));
    worst = std::max(worst, cv::norm(cv::Point2d(d.corners[i]) - truth));
  }
  return worst;
}

// Position error (m) and angle error (deg) of the pose from the target.
std::pair<double, double> poseError(const View& v, const TargetPose& p) {
  const Pose truth = v.scene.target.world_from_map.inverse() * v.world_from_camera;
  const cv::Matx33d dR = truth.R.t() * p.map_from_camera.R;
  const double angle = rotationAngleDeg(dR);
  return {cv::norm(truth.t - p.map_from_camera.t), angle};
}

}  // namespace

TEST(TargetDetector, FindsTheTargetOnTheWallToSubPixel) {
  for (const std::string trajectory : {"wheeled", "humanoid"}) {
    const View v = render("wall", trajectory, 0.0);
    const TargetDetection d = detectTarget(v.image);
    ASSERT_TRUE(d.found) << trajectory << ": " << d.reason;
    EXPECT_LT(cornerError(v, d), 0.2) << trajectory;  // measured 0.10-0.11
    const auto pose = cameraPoseFromTarget(d, v.camera.K(), v.camera.distortion());
    ASSERT_TRUE(pose);
    const auto [metres, degrees] = poseError(v, *pose);
    std::printf("%s: corners %.3f px, position %.1f mm, angle %.3f deg, reprojection %.3f px\n",
                trajectory.c_str(), cornerError(v, d), 1000 * metres, degrees,
                pose->reprojection_error_px);
    (void)metres;
    // A 0.297 m target 2 m away spans ~78 px: 0.1 px at its corners fixes the range to
    // a few millimetres but its tilt only to a few degrees (a nearly frontal plane looks
    // the same tilted slightly), which moves the position sideways. Measured: range
    // 0.1-0.3 %, tilt 0.4-3.3 deg.
    const Pose truth = v.scene.target.world_from_map.inverse() * v.world_from_camera;
    EXPECT_LT(std::abs(cv::norm(pose->map_from_camera.t) - cv::norm(truth.t)) / cv::norm(truth.t),
              0.01);
    EXPECT_LT(degrees, 5.0) << trajectory;
    EXPECT_LT(metres, 0.2) << trajectory;
  }
}

TEST(TargetDetector, NoiseAndMotionBlur) {
  const View v = render("wall", "humanoid", 0.3, 3.0, 4);
  const TargetDetection d = detectTarget(v.image);
  ASSERT_TRUE(d.found) << d.reason;
  EXPECT_LT(cornerError(v, d), 0.6);
  const auto pose = cameraPoseFromTarget(d, v.camera.K(), v.camera.distortion());
  ASSERT_TRUE(pose);
  const Pose truth = v.scene.target.world_from_map.inverse() * v.world_from_camera;
  EXPECT_LT(std::abs(cv::norm(pose->map_from_camera.t) - cv::norm(truth.t)) / cv::norm(truth.t),
            0.02);
}

TEST(TargetDetector, OnTheFloorInTheSameOrder) {
  const View v = render("floor", "wheeled", 0.0);
  const TargetDetection d = detectTarget(v.image);
  ASSERT_TRUE(d.found) << d.reason;
  EXPECT_LT(cornerError(v, d), 0.3);
  // Corners 0 and 1 are the near edge: lower in the image.
  EXPECT_GT(d.corners[0].y, d.corners[3].y);
  EXPECT_LT(d.corners[0].x, d.corners[1].x);
}

// The sheet on the floor, seen obliquely (its aspect follows the focal length about 1:1):
// a camera_info a few percent off still finds it, a wrong camera does not.
TEST(TargetDetector, FocalLengthAFewPercentOffStillFindsTheSheet) {
  const View v = render("floor", "wheeled", 0.0);
  const cv::Matx33d K = v.camera.K();
  const cv::Point2d principal(K(0, 2), K(1, 2));
  for (const double off : {0.97, 1.0, 1.04}) {
    const TargetDetection d = detectTarget(v.image, TargetParams(), K(0, 0) * off, principal);
    EXPECT_TRUE(d.found) << "focal length x" << off << ": " << d.reason;
  }
  const TargetDetection wrong = detectTarget(v.image, TargetParams(), K(0, 0) * 1.3, principal);
  EXPECT_FALSE(wrong.found) << "focal length 30 % off";
}

TEST(TargetDetector, NothingWhenTheTargetIsOutOfView) {
  int checked = 0;
  for (double t = 5.0; t <= 10.0; t += 0.5) {
    const View v = render("wall", "wheeled", t, 2.0);
    bool visible = false;
    for (const auto& c : v.scene.target.corners) {
      const cv::Vec3d x = v.world_from_camera.inverse().apply(c);
      const cv::Point2d p = v.camera.project(x);
      visible = visible || (x[2] > 0 && p.x >= 0 && p.y >= 0 && p.x < 640 && p.y < 480);
    }
    if (visible) continue;
    const TargetDetection d = detectTarget(v.image);
    EXPECT_FALSE(d.found) << "false target at t = " << t;
    EXPECT_FALSE(d.reason.empty());
    ++checked;
  }
  EXPECT_GE(checked, 8);
}

TEST(TargetDetector, DegenerateImages) {
  EXPECT_FALSE(detectTarget(cv::Mat()).found);
  EXPECT_FALSE(detectTarget(cv::Mat(1, 1, CV_8UC1, cv::Scalar(9))).found);
  EXPECT_FALSE(detectTarget(cv::Mat(480, 640, CV_8UC1, cv::Scalar(0))).found);
  EXPECT_FALSE(detectTarget(cv::Mat(480, 640, CV_8UC1, cv::Scalar(255))).found);
  EXPECT_FALSE(detectTarget(cv::Mat(480, 640, CV_8UC3, cv::Scalar(0))).found);
  // Shapes that cannot be the target: a triangle, a thin bar, a disc; and the target
  // cut by the image edge. (A square can: an A4 sheet seen obliquely looks square.)
  cv::Mat shapes(480, 640, CV_8UC1, cv::Scalar(0));
  std::vector<cv::Point> triangle{{50, 300}, {150, 300}, {100, 200}};
  cv::fillConvexPoly(shapes, triangle, 255);
  shapes(cv::Rect(250, 100, 300, 30)).setTo(255);
  cv::circle(shapes, {400, 350}, 60, 255, cv::FILLED);
  EXPECT_FALSE(detectTarget(shapes).found);
  cv::Mat cut(480, 640, CV_8UC1, cv::Scalar(0));
  cut(cv::Rect(300, 400, 212, 80)).setTo(255);
  EXPECT_FALSE(detectTarget(cut).found);
  // The right shape is.
  cv::Mat a4(480, 640, CV_8UC1, cv::Scalar(0));
  a4(cv::Rect(200, 150, 212, 150)).setTo(255);
  EXPECT_TRUE(detectTarget(a4).found);
}

TEST(TargetDetector, PoseNeedsUsableIntrinsics) {
  const View v = render("wall", "wheeled", 0.0);
  const TargetDetection d = detectTarget(v.image);
  ASSERT_TRUE(d.found);
  EXPECT_FALSE(cameraPoseFromTarget(d, cv::Matx33d::zeros(), cv::Mat()));
  cv::Matx33d nan_k = v.camera.K();
  nan_k(0, 2) = std::nan("");
  EXPECT_FALSE(cameraPoseFromTarget(d, nan_k, cv::Mat()));
  EXPECT_FALSE(cameraPoseFromTarget(TargetDetection(), v.camera.K(), cv::Mat()));
  const auto map = targetCornersInMap(TargetParams());
  EXPECT_DOUBLE_EQ(map[2].x - map[0].x, 0.297);
  EXPECT_DOUBLE_EQ(map[2].y - map[0].y, 0.210);
}

// A sheet seen exactly face-on 2.5 m away, two corners 0.1 px off: IPPE's rotation gives
// NaN there (found by a sweep of frontal views; the start-up calls this with K = identity
// on normalised corners), which used to be dropped as "no pose" without a word.
TEST(TargetDetector, FrontalViewWithCornerNoiseStillGivesAPose) {
  const auto map = targetCornersInMap(TargetParams());
  const cv::Matx33d K(540, 0, 320, 0, 540, 240, 0, 0, 1);
  const cv::Vec3d camera_from_map_t(0, 0, 2.5);
  std::vector<cv::Point2d> pixels;
  cv::projectPoints(std::vector<cv::Point3d>(map.begin(), map.end()), cv::Vec3d(0, 0, 0),
                    camera_from_map_t, K, cv::Mat(), pixels);
  pixels[0] += cv::Point2d(0.1, -0.1);
  pixels[3] += cv::Point2d(0.1, 0.1);
  TargetDetection d;
  d.found = true;
  for (int i = 0; i < 4; ++i) {
    d.corners[i] = cv::Point2f((pixels[i].x - 320) / 540, (pixels[i].y - 240) / 540);
  }
  const auto pose = cameraPoseFromTarget(d, cv::Matx33d::eye(), cv::Mat());
  ASSERT_TRUE(pose);
  // Face-on, 0.1 px leaves the tilt free by a few degrees (see the first test) but fixes
  // the range.
  EXPECT_NEAR(cv::norm(pose->map_from_camera.t), 2.5, 0.0125);
  const cv::Matx33d R = pose->map_from_camera.R;
  EXPECT_GT(R(2, 2), std::cos(5 * CV_PI / 180));  // optical axis within 5 deg of the normal
  EXPECT_NEAR(cv::determinant(R), 1.0, 1e-9);
  EXPECT_LT(pose->reprojection_error_px, 1e-3);  // normalised units: 0.1 px is 2e-4
}

// ---------------------------------------------------------------------------------------
// Real photos (test/data/target_photos, README there): the sheets labelled by hand.

namespace {

struct Labelled {
  std::string file;
  TargetParams params;  // the paper's size
  std::array<cv::Point2f, 4> corners;  // in the stored file's pixels, around the sheet
};

std::vector<Labelled> readLabels() {
  std::vector<Labelled> out;
  std::ifstream in(std::string(TEST_DATA_DIR) + "/target_photos/labels.csv");
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream row(line);
    Labelled l;
    std::string paper;
    row >> l.file >> paper;
    if (paper == "letter") {
      l.params.width_m = 0.2794;
      l.params.height_m = 0.2159;
    }
    for (auto& c : l.corners) row >> c.x >> c.y;
    out.push_back(l);
  }
  return out;
}

cv::Mat loadAtWidth(const std::string& path, int width, double* scale) {
  const cv::Mat original = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (original.empty()) return original;
  *scale = static_cast<double>(width) / original.cols;
  cv::Mat out;
  cv::resize(original, out, cv::Size(), *scale, *scale,
             *scale < 1 ? cv::INTER_AREA : cv::INTER_LINEAR);
  return out;
}

// Largest corner distance (px of the stored file) for the best correspondence of two
// quadrilaterals given in order around them (either direction, any start).
double worstCornerError(const std::array<cv::Point2f, 4>& a, const std::array<cv::Point2f, 4>& b,
                        double* mean) {
  double best = 1e9;
  for (int start = 0; start < 4; ++start)
    for (int dir : {1, -1}) {
      double worst = 0, sum = 0;
      for (int i = 0; i < 4; ++i) {
        const double e = cv::norm(a[i] - b[((start + dir * i) % 4 + 4) % 4]);
        worst = std::max(worst, e);
        sum += e;
      }
      if (worst < best) {
        best = worst;
        *mean = sum / 4;
      }
    }
  return best;
}

std::vector<std::string> filesIn(const std::string& dir, const std::string& ext) {
  std::vector<std::string> out;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().extension() == ext) out.push_back(e.path().string());
  std::sort(out.begin(), out.end());
  return out;
}

// The dark-surround-only setting (docs/start_up.md): max_surround_ratio 0.45, the
// default before the light-surround rule (light wood, test4: 0.69-0.70, refused).
constexpr double kDarkOnlyRatio = 0.45;

}  // namespace

// Issue 12: every sheet whose border with the darker surface is visible all round, at 640
// and 1280 px wide, corners within 2 px (at 640 px) of the hand labels; the focal length
// of these photos is unknown (0). test4.jpg lies on light wood (surround/sheet 0.69):
// found by the light-surround rule (its corners fix its shape to 0.05 %); with the
// dark-surround-only setting refused, with that reason.
TEST(TargetDetectorRealPhotos, FoundWithinTwoPixelsOfTheLabels) {
  const auto labels = readLabels();
  ASSERT_EQ(labels.size(), 5u);
  for (const bool dark_only : {false, true}) {
    int found = 0, expected = 0;
    double worst_all = 0, sum_all = 0;
    for (const Labelled& l : labels) {
      for (const int width : {640, 1280}) {
        double scale = 1;
        const cv::Mat image =
            loadAtWidth(std::string(TEST_DATA_DIR) + "/target_photos/" + l.file, width, &scale);
        ASSERT_FALSE(image.empty()) << l.file;
        TargetParams params = l.params;
        if (dark_only) params.max_surround_ratio = kDarkOnlyRatio;
        const TargetDetection d = detectTarget(image, params);
        if (l.file == "test4.jpg" && dark_only) {
          EXPECT_FALSE(d.found) << "light wood: refused with a dark surround required";
          EXPECT_EQ(d.rejection, TargetRejection::kBrightSurround) << d.reason;
          continue;
        }
        ++expected;
        ASSERT_TRUE(d.found) << l.file << " at " << width << ": " << d.reason;
        ++found;
        std::array<cv::Point2f, 4> in_file;
        for (int i = 0; i < 4; ++i) in_file[i] = d.corners[i] / static_cast<float>(scale);
        double mean = 0;
        const double worst = worstCornerError(in_file, l.corners, &mean);
        // In pixels of the image scaled to 640 px wide.
        const double to640 = 640.0 / (image.cols / scale);
        std::printf("%-16s %4d px: mean %.2f, worst %.2f px (at 640), surround/sheet %.2f\n",
                    l.file.c_str(), width, mean * to640, worst * to640, d.surround_ratio);
        EXPECT_LT(worst * to640, 2.0) << l.file << " at " << width;
        worst_all = std::max(worst_all, worst * to640);
        sum_all += mean * to640;
      }
    }
    std::printf("%s: found %d of %d, mean %.2f px, worst %.2f px (at 640 px width)\n",
                dark_only ? "dark surround only" : "default", found, expected,
                sum_all / std::max(1, found), worst_all);
    EXPECT_EQ(found, expected);
  }
}

// What a robot's camera does to the photos (darker, dimmer, brighter, less contrast,
// defocus, motion blur, sensor noise, JPEG, a smaller view): how many of the 5 sheets are
// still found, and how far their corners are from the labels (px of the image at 640 px
// width). Measured with this detector (min_edge_snr 5; 8 before, which found 3 of 5 at
// half size and under noise sigma 12). The misses named are the sheet's own (a light
// surround that the gamma brightens past max_surround_ratio, a side at the image border).
TEST(TargetDetectorRealPhotos, FoundUnderCameraDegradations) {
  const auto labels = readLabels();
  ASSERT_EQ(labels.size(), 5u);
  auto lut = [](double gamma, double gain, double offset) {
    cv::Mat table(1, 256, CV_8U);
    for (int i = 0; i < 256; ++i)
      table.at<uchar>(i) =
          cv::saturate_cast<uchar>(gain * 255.0 * std::pow(i / 255.0, gamma) + offset);
    return [table](const cv::Mat& m) {
      cv::Mat o;
      cv::LUT(m, table, o);
      return o;
    };
  };
  auto blur = [](double sigma) {
    return [sigma](const cv::Mat& m) {
      cv::Mat o;
      cv::GaussianBlur(m, o, {0, 0}, sigma);
      return o;
    };
  };
  auto noise = [](double sigma) {
    return [sigma](const cv::Mat& m) {
      cv::Mat n(m.size(), CV_16S), o;
      cv::RNG(3).fill(n, cv::RNG::NORMAL, 0, sigma);
      m.convertTo(o, CV_16S);
      o += n;
      o.convertTo(o, CV_8U);
      return o;
    };
  };
  auto resized = [](double f) {
    return [f](const cv::Mat& m) {
      cv::Mat o;
      cv::resize(m, o, {}, f, f, cv::INTER_AREA);
      return o;
    };
  };
  struct Degradation {
    const char* name;
    std::function<cv::Mat(const cv::Mat&)> apply;
    int found;           // at least
    double worst_px;     // corner error at most (at 640 px width)
  };
  const std::vector<Degradation> degradations = {
      {"as is", [](const cv::Mat& m) { return m.clone(); }, 5, 2.0},
      // test4's bottom-left corner lies 5.6 px from the image border: with the surround
      // darkened its refinement has too little of it (6.6 px off; 0.7 px as is).
      {"dark (gamma 2)", lut(2.0, 1, 0), 5, 7.0},
      {"dim (x0.4)", lut(1.0, 0.4, 0), 5, 2.0},
      {"bright (gamma 0.5)", lut(0.5, 1, 0), 3, 2.0},
      {"low contrast (x0.5 + 60)", lut(1.0, 0.5, 60), 4, 2.0},
      {"defocus (sigma 1.5)", blur(1.5), 5, 3.0},
      {"defocus (sigma 3)", blur(3.0), 4, 6.0},
      {"motion blur (9 px)",
       [](const cv::Mat& m) {
         cv::Mat k = cv::Mat::zeros(9, 9, CV_32F), o;
         k.row(4).setTo(1.0 / 9);
         cv::filter2D(m, o, -1, k);
         return o;
       },
       5, 3.0},
      {"noise (sigma 6)", noise(6), 5, 4.0},
      {"noise (sigma 12)", noise(12), 4, 2.0},
      {"jpeg 20",
       [](const cv::Mat& m) {
         std::vector<uchar> buf;
         cv::imencode(".jpg", m, buf, {cv::IMWRITE_JPEG_QUALITY, 20});
         return cv::imdecode(buf, cv::IMREAD_GRAYSCALE);
       },
       5, 2.0},
      {"half size", resized(0.5), 4, 3.0},
      {"quarter size", resized(0.25), 3, 4.0},
  };
  for (const Degradation& deg : degradations) {
    int found = 0;
    double worst_all = 0;
    std::string missed;
    for (const Labelled& l : labels) {
      double scale = 1;
      const cv::Mat clean =
          loadAtWidth(std::string(TEST_DATA_DIR) + "/target_photos/" + l.file, 640, &scale);
      ASSERT_FALSE(clean.empty()) << l.file;
      const cv::Mat image = deg.apply(clean);
      const double shrink = static_cast<double>(image.cols) / clean.cols;
      const TargetDetection d = detectTarget(image, l.params);
      if (!d.found) {
        missed += " " + l.file + " (" + d.reason + ")";
        continue;
      }
      ++found;
      std::array<cv::Point2f, 4> in_file;
      for (int i = 0; i < 4; ++i) in_file[i] = d.corners[i] / static_cast<float>(scale * shrink);
      double mean = 0;
      const double worst = worstCornerError(in_file, l.corners, &mean) * scale;  // px at 640
      if (worst > 2) std::printf("    %s: worst corner %.2f px\n", l.file.c_str(), worst);
      worst_all = std::max(worst_all, worst);
    }
    std::printf("%-26s found %d of 5, worst %.2f px (at 640)%s%s\n", deg.name, found, worst_all,
                missed.empty() ? "" : "; missed:", missed.c_str());
    EXPECT_GE(found, deg.found) << deg.name << ":" << missed;
    EXPECT_LE(worst_all, deg.worst_px) << deg.name;
  }
}

// Issue 12: never invented on real office frames (TUM RGB-D; the old detector took the
// black-and-white striped pole of 1341847989.802890 for the sheet, and stripes of it in
// 1341847991.814748 at 1280 px and 1341847996.874766 at 640 px with the focal length
// given), with the camera's focal length and without, at three sizes; nor on flat page
// scans (no surround). With the default, the dark-surround-only setting and no limit on
// the surround at all (the light-surround rule alone).
TEST(TargetDetectorRealPhotos, NoFalseTargets) {
  int checked = 0;
  std::vector<std::string> tum = filesIn(std::string(TEST_DATA_DIR) + "/tum_office", ".jpg");
  for (const auto& p : filesIn(std::string(TEST_DATA_DIR) + "/tum_office", ".png")) tum.push_back(p);
  ASSERT_GE(tum.size(), 8u);
  for (const double ratio : {TargetParams().max_surround_ratio, kDarkOnlyRatio, 1.0}) {
    TargetParams params;
    params.max_surround_ratio = ratio;
    for (const std::string& path : tum) {
      for (const int width : {320, 640, 1280}) {
        double scale = 1;
        const cv::Mat image = loadAtWidth(path, width, &scale);
        ASSERT_FALSE(image.empty()) << path;
        for (const double focal : {0.0, 535.4 * scale}) {
          const TargetDetection d = detectTarget(image, params, focal);
          EXPECT_FALSE(d.found) << path << " at " << width << " px, focal " << focal
                                << ", max_surround_ratio " << ratio;
          EXPECT_FALSE(d.reason.empty());
          ++checked;
        }
      }
    }
    for (const std::string name : {"result.jpg", "scanned_img.jpg"}) {
      for (const int width : {640, 1280}) {
        double scale = 1;
        const cv::Mat image =
            loadAtWidth(std::string(TEST_DATA_DIR) + "/target_photos/" + name, width, &scale);
        ASSERT_FALSE(image.empty()) << name;
        for (const bool letter : {false, true}) {
          TargetParams p = params;
          if (letter) p.width_m = 0.2794, p.height_m = 0.2159;
          EXPECT_FALSE(detectTarget(image, p).found) << name << " at " << width;
          ++checked;
        }
      }
    }
  }
  std::printf("%d negative images checked\n", checked);
}

// Rendered views: every view of the room in which the sheet is not in view gives no
// target; every view in which all of it (with its border) is in view and it is at least
// 40 px wide gives it, to sub-pixel. Both trajectories and the in-place rotation, the
// target on the wall and on the floor, with noise; on the wall also straight on mid-grey
// paint (no dark border), in the bare and in the furnished room (every other view).
TEST(TargetDetector, RenderedViewsWithAndWithoutTheSheet) {
  int negatives = 0, false_targets = 0, positives = 0, found = 0;
  double worst = 0, sum = 0;
  for (const std::string target_on : {"wall", "floor", "wall-2", "grey-wall", "grey-furnished"}) {
    RoomParams room;
    room.target_on = target_on == "floor" ? "floor" : "wall";
    room.seed = target_on == "wall-2" ? 2 : 1;  // other textures
    // The sheet straight on a mid-grey wall (surround/sheet 0.5: the light-surround rule),
    // in the bare room and in the furnished one with photographs and posters.
    if (target_on.rfind("grey", 0) == 0) room.target_background = "grey";
    if (target_on == "grey-furnished") {
      room.layout = "furnished";
      room.photos = loadTexturePhotos(std::string(TEST_DATA_DIR) + "/textures");
    }
    const IndoorScene scene = makeRoom(room);
    const CameraModel camera;
    RenderOptions options;
    options.noise_sigma = 2.0;
    const SceneRenderer renderer(scene, camera, options);
    for (const std::string trajectory : {"wheeled", "humanoid", "rotation"}) {
      TrajectoryParams tp;
      tp.name = trajectory;
      if (target_on == "floor") tp.pitch_down_deg = 35;
      const double step = target_on.rfind("grey", 0) == 0 ? 0.5 : 0.25;
      for (double t = 0; t <= 10.0; t += step) {
        const Pose world_from_camera = trajectoryPose(tp, t);
        int in_view = 0;
        double min_x = 1e9, max_x = -1e9;
        for (const auto& c : scene.target.corners) {
          const cv::Vec3d x = world_from_camera.inverse().apply(c);
          const cv::Point2d p = camera.project(x);
          const bool inside = x[2] > 0 && p.x >= 20 && p.y >= 20 && p.x < 620 && p.y < 460;
          in_view += inside ? 1 : 0;
          min_x = std::min(min_x, p.x);
          max_x = std::max(max_x, p.x);
          // Any corner in the image at all: not a clean negative.
          if (x[2] > 0 && p.x >= -50 && p.y >= -50 && p.x < 690 && p.y < 530) in_view += 10;
        }
        const cv::Mat image = renderer.render(world_from_camera, static_cast<unsigned>(t * 100));
        const TargetDetection d = detectTarget(image, TargetParams(), camera.fx);
        if (in_view == 0) {
          ++negatives;
          if (d.found) ++false_targets;
          EXPECT_FALSE(d.found) << target_on << " " << trajectory << " t = " << t;
        } else if (in_view == 44 && max_x - min_x > 40) {
          ++positives;
          if (!d.found) continue;
          ++found;
          double w = 0;
          for (int i = 0; i < 4; ++i) {
            const cv::Point2d truth =
                camera.project(world_from_camera.inverse().apply(scene.target.corners[i]));
            w = std::max(w, cv::norm(cv::Point2d(d.corners[i]) - truth));
          }
          worst = std::max(worst, w);
          sum += w;
          EXPECT_LT(w, 1.0) << target_on << " " << trajectory << " t = " << t;
        }
      }
    }
  }
  std::printf("rendered: %d false targets in %d views without the sheet; found %d of %d "
              "views with it, worst corner %.2f px (mean of worst %.2f)\n",
              false_targets, negatives, found, positives, worst, sum / std::max(1, found));
  EXPECT_EQ(false_targets, 0);
  EXPECT_GE(negatives, 100);
  EXPECT_GE(positives, 40);
  EXPECT_GE(found, positives * 95 / 100);
}

TEST(TargetDetector, RectifiedAspectOfAKnownView) {
  // A 0.297 x 0.210 sheet 1 m away, tilted 50 deg about the horizontal axis: in the image
  // its aspect is far from 1.41, rectified with the focal length it is 1.41.
  const CameraModel camera;
  const double tilt = 50 * CV_PI / 180;
  const cv::Matx33d R(1, 0, 0, 0, std::cos(tilt), -std::sin(tilt), 0, std::sin(tilt),
                      std::cos(tilt));
  std::array<cv::Point2f, 4> quad;
  const auto map = targetCornersInMap(TargetParams());
  for (int i = 0; i < 4; ++i) {
    const cv::Vec3d x = R * cv::Vec3d(map[i].x, map[i].y, 0) + cv::Vec3d(0, 0, 1);
    quad[i] = camera.project(x);
  }
  const auto aspect = rectifiedAspect(quad, {640, 480}, camera.fx);
  ASSERT_TRUE(aspect);
  EXPECT_NEAR(*aspect, 0.297 / 0.210, 0.01);
  const double in_image = cv::norm(quad[1] - quad[0]) / cv::norm(quad[2] - quad[1]);
  EXPECT_GT(std::abs(in_image - 0.297 / 0.210), 0.3);
  // With the focal length estimated from the quadrilateral (Zhang & He): possible when
  // both pairs of sides converge (tilted about two axes), so turn it 30 deg about y too.
  const double pan = 30 * CV_PI / 180;
  const cv::Matx33d Ry(std::cos(pan), 0, std::sin(pan), 0, 1, 0, -std::sin(pan), 0, std::cos(pan));
  for (int i = 0; i < 4; ++i) {
    const cv::Vec3d x = Ry * R * cv::Vec3d(map[i].x, map[i].y, 0) + cv::Vec3d(0, 0, 1);
    quad[i] = camera.project(x);
  }
  const auto estimated = rectifiedAspect(quad, {640, 480}, 0);
  ASSERT_TRUE(estimated);
  EXPECT_NEAR(*estimated, 0.297 / 0.210, 0.02);
  // A camera whose principal point is far from the image centre (camera_info's cx, cy):
  // given, the aspect is right; assumed at the centre, it is not.
  CameraModel off;
  off.cx = 200;
  off.cy = 330;
  for (int i = 0; i < 4; ++i) {
    const cv::Vec3d x = Ry * R * cv::Vec3d(map[i].x, map[i].y, 0) + cv::Vec3d(0, 0, 1);
    quad[i] = off.project(x);
  }
  const auto with_pp = rectifiedAspect(quad, {640, 480}, off.fx, {off.cx, off.cy});
  const auto centred = rectifiedAspect(quad, {640, 480}, off.fx);
  ASSERT_TRUE(with_pp && centred);
  EXPECT_NEAR(*with_pp, 0.297 / 0.210, 0.01);
  EXPECT_GT(std::abs(*centred - 0.297 / 0.210), 0.03) << *centred;
}

// Head-on, width/height = w/h with each corner moving one of its sides' lengths by half
// its shift: relative sigma = s sqrt(1/w^2 + 1/h^2). Proportional to the corner sigma,
// larger when seen obliquely, infinite without a rectangle.
TEST(TargetDetector, RectifiedAspectSigmaOfAKnownView) {
  const std::array<cv::Point2f, 4> frontal = {cv::Point2f(270, 190), cv::Point2f(370, 190),
                                              cv::Point2f(370, 260), cv::Point2f(270, 260)};
  const double expected = 0.25 * std::sqrt(1.0 / (100 * 100) + 1.0 / (70 * 70));
  // (Within 5 %: a corner's shift also reads as a little perspective, measured 3 %.)
  const double sigma = rectifiedAspectSigma(frontal, {640, 480}, 0.25, 525);
  EXPECT_NEAR(sigma, expected, 0.05 * expected);
  EXPECT_NEAR(rectifiedAspectSigma(frontal, {640, 480}, 0.5, 525), 2 * sigma, 1e-9);
  // The same width, its far side shortened by perspective.
  const std::array<cv::Point2f, 4> oblique = {cv::Point2f(270, 190), cv::Point2f(370, 200),
                                              cv::Point2f(370, 250), cv::Point2f(270, 260)};
  EXPECT_GT(rectifiedAspectSigma(oblique, {640, 480}, 0.25, 525), 1.5 * expected);
  const std::array<cv::Point2f, 4> line = {cv::Point2f(0, 0), cv::Point2f(10, 0),
                                           cv::Point2f(20, 0), cv::Point2f(30, 0)};
  EXPECT_TRUE(std::isinf(rectifiedAspectSigma(line, {640, 480}, 0.25, 525)));
}

TEST(TargetDetector, RejectionsSayWhy) {
  // A white sheet on a surface nearly as light: a quadrilateral, refused for its bright
  // surround.
  cv::Mat light(480, 640, CV_8UC1, cv::Scalar(200));
  light(cv::Rect(200, 150, 212, 150)).setTo(240);
  TargetDetection d = detectTarget(light);
  EXPECT_FALSE(d.found);
  EXPECT_EQ(d.rejection, TargetRejection::kBrightSurround) << d.reason;
  EXPECT_NE(d.reason.find("surround"), std::string::npos);
  EXPECT_GT(d.rejected[static_cast<int>(TargetRejection::kBrightSurround)], 0);
  // On light grey (170 / 240): found head-on, 212 px wide; only on a dark surround
  // when the light-surround rule is switched off (max_surround_ratio 0.45).
  light.setTo(170);
  light(cv::Rect(200, 150, 212, 150)).setTo(240);
  d = detectTarget(light, TargetParams(), 525);
  EXPECT_TRUE(d.found) << d.reason;
  EXPECT_NEAR(d.surround_ratio, 170.0 / 240, 0.01);
  EXPECT_LT(d.aspect_sigma, 0.005);
  TargetParams dark_only;
  dark_only.max_surround_ratio = 0.45;
  EXPECT_EQ(detectTarget(light, dark_only, 525).rejection, TargetRejection::kBrightSurround);
  // The sheet 2 m away on a wall turned 70 deg from the camera, on light grey: its
  // shape cannot be told (refused, and the reason says why); on a dark surface the
  // surround vouches for it.
  const double f = 525;
  std::vector<cv::Point> oblique;
  for (const cv::Vec2d c : {cv::Vec2d(-1, -1), cv::Vec2d(1, -1), cv::Vec2d(1, 1), cv::Vec2d(-1, 1)}) {
    const double a = 70 * CV_PI / 180;
    const cv::Vec3d x(0.1485 * c[0] * std::cos(a), 0.105 * c[1], 2.0 + 0.1485 * c[0] * std::sin(a));
    oblique.emplace_back(cvRound(320 + f * x[0] / x[2]), cvRound(240 + f * x[1] / x[2]));
  }
  for (const int surround : {170, 40}) {
    cv::Mat wall(480, 640, CV_8UC1, cv::Scalar(surround));
    cv::fillConvexPoly(wall, oblique, cv::Scalar(240), cv::LINE_AA);
    d = detectTarget(wall, TargetParams(), f);
    std::printf("oblique sheet on %d: %s, %s, aspect sigma %.3f\n", surround,
                d.found ? "found" : "refused", d.reason.c_str(), d.aspect_sigma);
    if (surround == 170) {
      EXPECT_FALSE(d.found);
      EXPECT_EQ(d.rejection, TargetRejection::kShapeUncertain) << d.reason;
      EXPECT_NE(d.reason.find("too small or too oblique"), std::string::npos) << d.reason;
    } else {
      EXPECT_TRUE(d.found) << d.reason;
      EXPECT_GT(d.aspect_sigma, 0.02);
    }
  }
  EXPECT_STREQ(toString(TargetRejection::kShapeUncertain), "shape uncertain");
  // A white band across a dark post on a darker wall (a striped pole): a bright
  // quadrilateral of the sheet's shape with a dark surround all round, but its left and
  // right sides go on past its corners as the post's edges: refused, and the reason
  // says so.
  cv::Mat pole(480, 640, CV_8UC1, cv::Scalar(90));
  pole(cv::Rect(200, 0, 212, 480)).setTo(20);
  pole(cv::Rect(200, 150, 212, 150)).setTo(240);
  d = detectTarget(pole);
  EXPECT_FALSE(d.found);
  EXPECT_EQ(d.rejection, TargetRejection::kEdgeContinues) << d.reason;
  EXPECT_NE(d.reason.find("past the corner at ("), std::string::npos) << d.reason;
  EXPECT_GT(d.rejected[static_cast<int>(TargetRejection::kEdgeContinues)], 0);
  // The same band on a dark card that leaves a margin round it (a sheet on a card on the
  // wall): its sides end at its corners: found.
  cv::Mat card(480, 640, CV_8UC1, cv::Scalar(90));
  card(cv::Rect(150, 100, 312, 250)).setTo(20);
  card(cv::Rect(200, 150, 212, 150)).setTo(240);
  d = detectTarget(card);
  EXPECT_TRUE(d.found) << d.reason;
  // A square: refused for its aspect ratio (seen head-on with the focal length given).
  cv::Mat square(480, 640, CV_8UC1, cv::Scalar(20));
  square(cv::Rect(220, 140, 200, 200)).setTo(230);
  d = detectTarget(square, TargetParams(), 525);
  EXPECT_FALSE(d.found);
  EXPECT_EQ(d.rejection, TargetRejection::kAspect) << d.reason;
  EXPECT_STREQ(toString(TargetRejection::kAspect), "aspect ratio");
  // Nothing at all (the image's own frame is the only quadrilateral).
  d = detectTarget(cv::Mat(480, 640, CV_8UC1, cv::Scalar(90)));
  EXPECT_FALSE(d.found);
  EXPECT_NE(d.rejection, TargetRejection::kNone);
  EXPECT_FALSE(d.reason.empty());
  d = detectTarget(cv::Mat());
  EXPECT_EQ(d.rejection, TargetRejection::kBadImage);
}

// make fuzz found a 40x30 image where the fitted sides met 0.3 px past the border: a
// found target must have every corner inside the image (tracks outside are refused).
TEST(TargetDetector, FoundCornersAreInsideTheImage) {
  std::ifstream in(std::string(TEST_DATA_DIR) + "/../fuzz/corpus/target_detector/crash_corner_outside_image",
                   std::ios::binary);
  const std::vector<unsigned char> data((std::istreambuf_iterator<char>(in)), {});
  ASSERT_GT(data.size(), 2u);
  const int cols = 1 + data[0] % 96, rows = 1 + data[1] % 96;  // as fuzz_target_detector
  cv::Mat image(rows, cols, CV_8UC1, cv::Scalar(0));
  for (size_t i = 2; i < data.size() && i - 2 < image.total(); ++i) image.data[i - 2] = data[i];
  TargetParams params;
  params.min_area_px = 20;
  const TargetDetection d = detectTarget(image, params);
  if (d.found)
    for (const auto& c : d.corners) {
      EXPECT_GE(c.x, 0);
      EXPECT_GE(c.y, 0);
      EXPECT_LE(c.x, cols - 1);
      EXPECT_LE(c.y, rows - 1);
    }
  else
    EXPECT_EQ(d.rejection, TargetRejection::kAtImageEdge) << d.reason;
}
