#include "mono_plane_detection/sim/indoor_scene.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "mono_plane_detection/sim/synthetic_views.h"

namespace mono_plane_detection {
namespace {

ScenePlane makePlane(int id, const std::string& name, const cv::Vec3d& origin, const cv::Vec3d& u,
                     const cv::Vec3d& v, double width, double height, const RoomParams& params) {
  ScenePlane p;
  p.id = id;
  p.name = name;
  p.origin = origin;
  p.u_axis = u;
  p.v_axis = v;
  p.width_m = width;
  p.height_m = height;
  p.texels_per_m = params.texels_per_m;
  const cv::Size size(static_cast<int>(std::ceil(width * params.texels_per_m)) + 2,
                      static_cast<int>(std::ceil(height * params.texels_per_m)) + 2);
  p.texture = makeCornerTexture(size, params.seed * 101 + static_cast<unsigned>(id));
  return p;
}

// Paints the target (black border, white rectangle) into the plane's texture and
// fills in its geometry.
StartTarget paintTarget(ScenePlane& plane, int plane_index, double centre_a, double centre_b) {
  StartTarget target;
  target.plane_index = plane_index;
  const double s = plane.texels_per_m;
  auto texel = [&](double a, double b) { return cv::Point2d(a * s, b * s); };
  const double hw = target.width_m / 2, hh = target.height_m / 2, border = target.border_m;
  // Texel (col, row) holds the colour at plane coordinates (col, row) / s.
  // The black border: each texel painted with the share of its area inside.
  auto coverage = [](double lo, double hi, int c) {
    return std::max(0.0, std::min(hi, c + 0.5) - std::max(lo, c - 0.5));
  };
  auto blend = [&](int r, int c, double share, double grey) {
    if (r < 0 || c < 0 || r >= plane.texture.rows || c >= plane.texture.cols) return;
    uchar& t = plane.texture.at<uchar>(r, c);
    t = cv::saturate_cast<uchar>(share * grey + (1 - share) * t);
  };
  {
    const cv::Point2d lo = texel(centre_a - hw - border, centre_b - hh - border);
    const cv::Point2d hi = texel(centre_a + hw + border, centre_b + hh + border);
    for (int r = static_cast<int>(std::floor(lo.y)); r <= static_cast<int>(std::ceil(hi.y)); ++r)
      for (int c = static_cast<int>(std::floor(lo.x)); c <= static_cast<int>(std::ceil(hi.x)); ++c)
        blend(r, c, coverage(lo.x, hi.x, c) * coverage(lo.y, hi.y, r), 0.0);
  }
  // The white rectangle, whose corners are the ground truth: the two texels that
  // straddle each edge are set so that the renderer's bilinear reconstruction crosses
  // half-way exactly on the edge (area coverage would be off by up to 0.075 texel).
  auto profile = [](double lo, double hi, int c) {
    const int c0 = static_cast<int>(std::floor(lo)), c1 = static_cast<int>(std::floor(hi));
    const double f = lo - c0, g = hi - c1;
    if (c < c0 || c > c1 + 1) return 0.0;
    if (c == c0) return f >= 0.5 ? 0.0 : (0.5 - f) / (1 - f);
    if (c == c0 + 1 && f >= 0.5) return 0.5 / f;
    if (c == c1 + 1) return g <= 0.5 ? 0.0 : (g - 0.5) / g;
    if (c == c1 && g <= 0.5) return 0.5 / (1 - g);
    return 1.0;
  };
  {
    const cv::Point2d lo = texel(centre_a - hw, centre_b - hh),
                      hi = texel(centre_a + hw, centre_b + hh);
    for (int r = static_cast<int>(std::floor(lo.y)); r <= static_cast<int>(std::floor(hi.y)) + 1;
         ++r)
      for (int c = static_cast<int>(std::floor(lo.x)); c <= static_cast<int>(std::floor(hi.x)) + 1;
           ++c)
        blend(r, c, profile(lo.x, hi.x, c) * profile(lo.y, hi.y, r), 255.0);
  }

  auto world = [&](double a, double b) {
    return plane.origin + a * plane.u_axis + b * plane.v_axis;
  };
  target.centre = world(centre_a, centre_b);
  target.corners = {world(centre_a - hw, centre_b - hh), world(centre_a + hw, centre_b - hh),
                    world(centre_a + hw, centre_b + hh), world(centre_a - hw, centre_b + hh)};
  const cv::Vec3d z = plane.normal();
  target.world_from_map.R =
      cv::Matx33d(plane.u_axis[0], plane.v_axis[0], z[0], plane.u_axis[1], plane.v_axis[1], z[1],
                  plane.u_axis[2], plane.v_axis[2], z[2]);
  target.world_from_map.t = target.centre;
  return target;
}

}  // namespace

std::array<cv::Vec3d, 4> ScenePlane::corners() const {
  return {origin, origin + width_m * u_axis, origin + width_m * u_axis + height_m * v_axis,
          origin + height_m * v_axis};
}

IndoorScene makeRoom(const RoomParams& params) {
  IndoorScene scene;
  const double W = params.width_m, H = params.height_m, F = params.front_m, B = params.back_m;
  const double x0 = -W / 2;
  const cv::Vec3d X(1, 0, 0), Y(0, 1, 0), Z(0, 0, 1);
  // Axes are chosen so that u x v points into the room.
  auto add = [&](const std::string& name, const cv::Vec3d& origin, const cv::Vec3d& u,
                 const cv::Vec3d& v, double w, double h) {
    scene.planes.push_back(
        makePlane(static_cast<int>(scene.planes.size()) + 1, name, origin, u, v, w, h, params));
  };
  add("floor", {x0, -B, 0}, X, Y, W, F + B);
  if (params.walls >= 1) add("front_wall", {x0, F, 0}, X, Z, W, H);
  if (params.walls >= 2) add("left_wall", {x0, -B, 0}, Y, Z, F + B, H);
  if (params.walls >= 3) add("right_wall", {-x0, -B, 0}, Z, Y, H, F + B);
  if (params.walls >= 4) add("back_wall", {x0, -B, 0}, Z, X, H, W);
  if (params.ceiling) add("ceiling", {x0, -B, H}, Y, X, F + B, W);

  if (params.target_on == "floor" || params.walls < 1) {
    scene.target = paintTarget(scene.planes[0], 0, W / 2, B + 1.0);  // 1 m ahead on the floor
  } else {
    scene.target = paintTarget(scene.planes[1], 1, W / 2, params.target_centre_height_m);
  }
  return scene;
}

RayHit castRay(const IndoorScene& scene, const cv::Vec3d& origin, const cv::Vec3d& direction) {
  RayHit hit;
  for (size_t k = 0; k < scene.planes.size(); ++k) {
    const ScenePlane& p = scene.planes[k];
    const cv::Vec3d n = p.normal();
    const double denom = n.dot(direction);
    if (std::abs(denom) < 1e-12) continue;
    const double s = (p.distance() - n.dot(origin)) / denom;
    if (!(s > 1e-9) || s >= hit.distance) continue;
    const cv::Vec3d local = origin + s * direction - p.origin;
    const double a = local.dot(p.u_axis), b = local.dot(p.v_axis);
    if (a < 0 || b < 0 || a > p.width_m || b > p.height_m) continue;
    hit.plane = static_cast<int>(k);
    hit.distance = s;
    hit.a = a;
    hit.b = b;
  }
  return hit;
}

}  // namespace mono_plane_detection
