// plane_pair: planes between two real images. SIFT (or ORB) matches, ratio test, both
// images' points undistorted with their intrinsics (image_geometry's raw model: K + D,
// the undistorted points stay in pixels of K), then segmentPlanes. Prints the planes and
// writes an overlay (image 1, points coloured by plane).
//   plane_pair [options] IMG1 IMG2 --fx F --fy F --cx C --cy C [--k1 .. --p2 ..]
#include <cstdio>
#include <opencv2/calib3d.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "cli_args.h"
#include "config_dir.h"
#include "profile.h"
#include "mono_plane_detection/planes/homography_voting.h"

using namespace mono_plane_detection;

namespace {

struct Intrinsics {
  double fx = 0, fy = 0, cx = 0, cy = 0, k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0;
  cv::Matx33d K() const { return {fx, 0, cx, 0, fy, cy, 0, 0, 1}; }
  cv::Mat D() const { return (cv::Mat_<double>(1, 5) << k1, k2, p1, p2, k3); }
};

std::vector<cv::Point2d> undistort(const std::vector<cv::Point2f>& p, const Intrinsics& in) {
  std::vector<cv::Point2f> out;
  if (!p.empty()) cv::undistortPoints(p, out, in.K(), in.D(), cv::noArray(), in.K());
  return {out.begin(), out.end()};
}

cv::Ptr<cv::Feature2D> detector(const std::string& name, int features) {
  if (name == "orb") return cv::ORB::create(features);
#if CV_VERSION_MAJOR > 4 || (CV_VERSION_MAJOR == 4 && CV_VERSION_MINOR >= 4)
  return cv::SIFT::create(features);
#else
  return nullptr;  // SIFT is in features2d from OpenCV 4.4 on (Noetic's 4.2: use --features orb)
#endif
}

}  // namespace

int main(int argc, char** argv) {
  auto profile =
      readToolProfile(argc, argv, toolConfigDir(MPD_CONFIG_DIR), "planes", planeNodeParamTable(), std::string("none"));
  PlaneParams params = profile.params.pipeline.planes;
  Intrinsics in1, in2;
  std::string img1, img2, overlay = "plane_pair.png", features = "sift", matches_file;
  int max_features = 4000;
  double ratio = 0.8;
  bool json = false, no_overlay = false;
  cli::Parser cli("plane_pair", "[options] IMG1 IMG2",
                  "  Planes between two real images: feature matches (SIFT or ORB, ratio test),\n"
                  "  undistorted with the given intrinsics (radial-tangential k1 k2 p1 p2 k3;\n"
                  "  image 2 uses image 1's unless --fx2 .. are given), then segmentPlanes\n"
                  "  with the core's defaults. Homographies map undistorted pixels of image 1\n"
                  "  to undistorted pixels of image 2.",
                  "exit codes: 0 done, 2 bad usage, an unreadable image or an unwritable output file\n");
  cli.positional("IMG1", &img1, "first image").positional("IMG2", &img2, "second image");
  cli.text("profile", &profile.name, profileHelp("planes"), "P");
  cli.number("fx", &in1.fx, 1e-6, 1e6, "focal length x, pixels (required)", "PX")
      .number("fy", &in1.fy, 1e-6, 1e6, "focal length y, pixels (required)", "PX")
      .number("cx", &in1.cx, -1e6, 1e6, "principal point x, pixels", "PX")
      .number("cy", &in1.cy, -1e6, 1e6, "principal point y, pixels", "PX")
      .number("k1", &in1.k1, -100, 100, "radial distortion").number("k2", &in1.k2, -100, 100, "radial distortion")
      .number("p1", &in1.p1, -100, 100, "tangential distortion")
      .number("p2", &in1.p2, -100, 100, "tangential distortion")
      .number("k3", &in1.k3, -100, 100, "radial distortion")
      .number("fx2", &in2.fx, 0, 1e6, "image 2: focal length x (0: image 1's)", "PX")
      .number("fy2", &in2.fy, 0, 1e6, "image 2: focal length y", "PX")
      .number("cx2", &in2.cx, -1e6, 1e6, "image 2: principal point x", "PX")
      .number("cy2", &in2.cy, -1e6, 1e6, "image 2: principal point y", "PX")
      .number("k1-2", &in2.k1, -100, 100, "image 2: k1").number("k2-2", &in2.k2, -100, 100, "image 2: k2")
      .number("p1-2", &in2.p1, -100, 100, "image 2: p1").number("p2-2", &in2.p2, -100, 100, "image 2: p2")
      .number("k3-2", &in2.k3, -100, 100, "image 2: k3")
      .choice("features", &features, {"sift", "orb"}, "feature type")
      .integer("max-features", &max_features, 10, 100000, "features per image at most")
      .number("ratio", &ratio, 0.1, 1.0, "Lowe's ratio test: best / second best distance below this")
      .number("threshold", &params.vote_threshold_px, 0.0, 1e3,
              "inlier threshold, pixels; 0 = estimated (default)", "PX")
      .choice("coplanarity-test", &params.groups.coplanarity_test, {"transfer", "cross_ratio"},
              "five-point coplanarity test")
      .flag("no-epipolar-check", &params.epipolar_check,
            "keep planes whose points are off the epipolar lines of the planes' F", false)
      .integer<unsigned>("seed", &params.groups.seed, 0, std::numeric_limits<unsigned>::max(),
                         "seed of the group choice", "S")
      .text("overlay", &overlay, "where to write the overlay image", "FILE.png")
      .flag("no-overlay", &no_overlay, "write no overlay image")
      .text("matches", &matches_file,
            "also write every undistorted match as 'x1 y1 x2 y2' lines (segment_planes' input)",
            "FILE.txt")
      .flag("json", &json, "print the planes as JSON (homography, inlier correspondences)");
  if (const auto code = cli.parse(argc, argv)) return *code;
  if (!profile.errors.empty()) return cli.fail(profile.errors.front());
  if (in1.fx <= 0 || in1.fy <= 0) return cli.fail("--fx and --fy are needed (pixels)");
  if (in2.fx <= 0) in2 = in1;
  if (in2.fy <= 0) in2.fy = in2.fx;

  const cv::Mat a = cv::imread(img1, cv::IMREAD_GRAYSCALE), b = cv::imread(img2, cv::IMREAD_GRAYSCALE);
  if (a.empty()) return cli.fail("cannot read image " + img1);
  if (b.empty()) return cli.fail("cannot read image " + img2);
  cv::Ptr<cv::Feature2D> det = detector(features, max_features);
  if (!det) return cli.fail("SIFT needs OpenCV 4.4 or newer here: use --features orb");
  std::vector<cv::KeyPoint> ka, kb;
  cv::Mat da, db;
  det->detectAndCompute(a, cv::noArray(), ka, da);
  det->detectAndCompute(b, cv::noArray(), kb, db);
  std::vector<cv::Point2f> pa, pb;
  if (!da.empty() && !db.empty()) {
    cv::BFMatcher matcher(features == "orb" ? cv::NORM_HAMMING : cv::NORM_L2);
    std::vector<std::vector<cv::DMatch>> knn;
    matcher.knnMatch(da, db, knn, 2);
    for (const auto& m : knn) {
      if (m.size() == 2 && m[0].distance < ratio * m[1].distance) {
        pa.push_back(ka[m[0].queryIdx].pt);
        pb.push_back(kb[m[0].trainIdx].pt);
      }
    }
  }
  const std::vector<cv::Point2d> ua = undistort(pa, in1), ub = undistort(pb, in2);
  if (!matches_file.empty()) {
    std::FILE* f = std::fopen(matches_file.c_str(), "w");
    if (!f) return cli.fail("cannot write " + matches_file);
    // The images' folder and name (cam0/x.png, cam1/x.png), not the whole path: the file
    // may go into a repository.
    auto tail = [](const std::string& path) {
      const size_t name = path.find_last_of('/');
      const size_t folder = name == std::string::npos || name == 0 ? std::string::npos
                                                                    : path.find_last_of('/', name - 1);
      return folder == std::string::npos ? path : path.substr(folder + 1);
    };
    std::fprintf(f, "# x1 y1 x2 y2 (undistorted pixels); plane_pair %s %s\n", tail(img1).c_str(),
                 tail(img2).c_str());
    for (size_t i = 0; i < ua.size(); ++i)
      std::fprintf(f, "%.3f %.3f %.3f %.3f\n", ua[i].x, ua[i].y, ub[i].x, ub[i].y);
    if (std::fclose(f) != 0) return cli.fail("cannot write " + matches_file);
  }
  const PlaneSegmentation result = segmentPlanes(ua, ub, params);
  if (!result.error.empty()) return cli.fail(result.error);

  if (json) {
    std::printf("{\n  \"matches\": %zu,\n  \"noise_px\": %.6f,\n  \"threshold_px\": %.6f,\n  \"planes\": [",
                ua.size(), result.noise_px, result.threshold_px);
    for (size_t k = 0; k < result.planes.size(); ++k) {
      const HomographyPlane& p = result.planes[k];
      std::printf("%s\n    {\"id\": %zu, \"support\": %zu, \"noise_px\": %.6f, \"rms_error_px\": %.6f,\n"
                  "     \"homography\": [[%.10g, %.10g, %.10g], [%.10g, %.10g, %.10g], [%.10g, %.10g, %.10g]],\n"
                  "     \"points\": [",
                  k ? "," : "", k + 1, p.inliers.size(), p.noise_px, p.rms_error_px, p.H(0, 0), p.H(0, 1),
                  p.H(0, 2), p.H(1, 0), p.H(1, 1), p.H(1, 2), p.H(2, 0), p.H(2, 1), p.H(2, 2));
      for (size_t i = 0; i < p.inliers.size(); ++i) {
        const int q = p.inliers[i];
        std::printf("%s[%.3f, %.3f, %.3f, %.3f]", i ? ", " : "", ua[q].x, ua[q].y, ub[q].x, ub[q].y);
      }
      std::printf("]}");
    }
    std::printf("\n  ]\n}\n");
  } else {
    std::printf("plane_pair: %zu matches, noise scale %.3f px, %zu planes\n", ua.size(),
                result.noise_px, result.planes.size());
    for (size_t k = 0; k < result.planes.size(); ++k) {
      const HomographyPlane& p = result.planes[k];
      std::printf("  plane %zu: %zu points (%.0f %%), noise %.3f px, rms %.3f px, H = [%.5g %.5g %.5g; %.5g %.5g %.5g; %.5g %.5g %.5g]\n",
                  k + 1, p.inliers.size(), 100 * p.score, p.noise_px, p.rms_error_px, p.H(0, 0), p.H(0, 1),
                  p.H(0, 2), p.H(1, 0), p.H(1, 1), p.H(1, 2), p.H(2, 0), p.H(2, 1), p.H(2, 2));
    }
  }

  // Overlay on image 1 (as read, distorted): each match at its raw position, coloured by
  // its plane; outliers small and grey.
  cv::Mat out;
  cv::cvtColor(a, out, cv::COLOR_GRAY2BGR);
  static const cv::Scalar colours[] = {{0, 0, 255}, {0, 200, 0}, {255, 0, 0}, {0, 200, 255},
                                       {255, 0, 255}, {255, 255, 0}, {0, 128, 255}, {128, 0, 255}};
  for (size_t i = 0; i < pa.size(); ++i) {
    const int l = result.labels[i];
    if (l == 0)
      cv::circle(out, pa[i], 2, {128, 128, 128}, 1, cv::LINE_AA);
    else
      cv::circle(out, pa[i], 4, colours[(l - 1) % 8], cv::FILLED, cv::LINE_AA);
  }
  for (size_t k = 0; k < result.planes.size(); ++k)
    cv::putText(out, cv::format("plane %zu: %zu", k + 1, result.planes[k].inliers.size()),
                {10, 20 + 20 * static_cast<int>(k)}, cv::FONT_HERSHEY_SIMPLEX, 0.55, colours[k % 8], 2,
                cv::LINE_AA);
  if (no_overlay) return 0;  // (scripts/eval_euroc without --overlays)
  if (!cv::imwrite(overlay, out)) return cli.fail("cannot write " + overlay);
  if (!json) std::printf("overlay: %s\n", overlay.c_str());
  return 0;
}
