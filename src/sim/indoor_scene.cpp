#include "mono_plane_detection/sim/indoor_scene.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/aruco.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <stdexcept>

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

// Blends `grey` into the texels of the plane-coordinate rectangle [a0, a1] x [b0, b1],
// each texel by the share of its area inside (anti-aliased edges).
void paintRect(ScenePlane& plane, double a0, double b0, double a1, double b1, double grey) {
  const double s = plane.texels_per_m;
  auto coverage = [](double lo, double hi, int c) {
    return std::max(0.0, std::min(hi, c + 0.5) - std::max(lo, c - 0.5));
  };
  const double lx = a0 * s, hx = a1 * s, ly = b0 * s, hy = b1 * s;
  for (int r = static_cast<int>(std::floor(ly)); r <= static_cast<int>(std::ceil(hy)); ++r)
    for (int c = static_cast<int>(std::floor(lx)); c <= static_cast<int>(std::ceil(hx)); ++c) {
      if (r < 0 || c < 0 || r >= plane.texture.rows || c >= plane.texture.cols) continue;
      const double share = coverage(lx, hx, c) * coverage(ly, hy, r);
      uchar& t = plane.texture.at<uchar>(r, c);
      t = cv::saturate_cast<uchar>(share * grey + (1 - share) * t);
    }
}

// Copies `image` (grey) into the texels of the rectangle from plane coordinates (a0, b0),
// `width` metres wide, keeping its aspect ratio; image row 0 goes to the largest b, so
// that it reads upright on a wall seen from the room.
void paintImage(ScenePlane& plane, const cv::Mat& image, double a0, double b0, double width) {
  const double s = plane.texels_per_m;
  const int cols = std::max(1, static_cast<int>(std::lround(width * s)));
  const int rows = std::max(1, static_cast<int>(std::lround(width * s * image.rows / image.cols)));
  cv::Mat resized;
  cv::resize(image, resized, cv::Size(cols, rows), 0, 0, cv::INTER_AREA);
  cv::flip(resized, resized, 0);
  const int c0 = static_cast<int>(std::lround(a0 * s)), r0 = static_cast<int>(std::lround(b0 * s));
  const cv::Rect into = cv::Rect(c0, r0, cols, rows) & cv::Rect(0, 0, plane.texture.cols, plane.texture.rows);
  if (into.area() == 0) return;
  resized(cv::Rect(into.x - c0, into.y - r0, into.width, into.height)).copyTo(plane.texture(into));
}

cv::Mat woodTexture(const cv::Size& size, double texels_per_m, unsigned seed) {
  cv::Mat wood(size, CV_32F);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> phase(0, 2 * CV_PI);
  const double p1 = phase(rng), p2 = phase(rng);
  for (int r = 0; r < size.height; ++r)
    for (int c = 0; c < size.width; ++c) {
      const double x = c / texels_per_m, y = r / texels_per_m;
      // Grain along x: rings bent by a slow wave, with fine streaks.
      const double ring = std::sin(2 * CV_PI * (9 * y + 0.25 * std::sin(2.3 * x + p1)) + p2);
      const double streak = std::sin(2 * CV_PI * (47 * y + 0.6 * std::sin(5.1 * x)));
      wood.at<float>(r, c) = static_cast<float>(115 + 22 * ring + 7 * streak);
    }
  cv::Mat noise(size, CV_32F);
  cv::RNG(seed).fill(noise, cv::RNG::NORMAL, 0, 4);
  wood += noise;
  cv::GaussianBlur(wood, wood, cv::Size(0, 0), 0.8);
  cv::Mat out;
  wood.convertTo(out, CV_8U);
  return out;
}

// Plain paint: one grey with a faint, slow variation (a roller's unevenness), nothing a
// corner detector can hold on to.
cv::Mat paintTexture(const cv::Size& size, double grey, unsigned seed) {
  cv::Mat small(4, 4, CV_32F);
  cv::RNG(seed).fill(small, cv::RNG::UNIFORM, grey - 4, grey + 4);
  cv::Mat out;
  cv::resize(small, out, size, 0, 0, cv::INTER_CUBIC);
  out.convertTo(out, CV_8U);
  return out;
}

// Book spines on shelf boards: vertical strips of random width and grey.
cv::Mat booksTexture(const cv::Size& size, double texels_per_m, unsigned seed) {
  cv::Mat books(size, CV_8U, cv::Scalar(60));
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> width(0.02, 0.05), grey(40, 220), top(0.22, 0.32);
  const double board = 0.36;  // shelf spacing, m
  for (double b = 0.03; b + 0.1 < size.height / texels_per_m; b += board) {
    for (double a = 0.02; a < size.width / texels_per_m - 0.02;) {
      const double w = width(rng), h = top(rng), g = grey(rng);
      cv::rectangle(books,
                    cv::Point(static_cast<int>(a * texels_per_m), static_cast<int>(b * texels_per_m)),
                    cv::Point(static_cast<int>((a + w) * texels_per_m) - 1,
                              static_cast<int>((b + h) * texels_per_m)),
                    cv::Scalar(g), cv::FILLED);
      // A label on some spines.
      if (g > 100)
        cv::rectangle(books,
                      cv::Point(static_cast<int>((a + 0.3 * w) * texels_per_m),
                                static_cast<int>((b + 0.5 * h) * texels_per_m)),
                      cv::Point(static_cast<int>((a + 0.7 * w) * texels_per_m),
                                static_cast<int>((b + 0.65 * h) * texels_per_m)),
                      cv::Scalar(g - 80), cv::FILLED);
      a += w + 0.003;
    }
  }
  cv::GaussianBlur(books, books, cv::Size(0, 0), 0.7);
  return books;
}

// Paints the start-up target centred at plane coordinates (centre_a, centre_b) and fills
// in its geometry. Sheet backgrounds: black (the paper's border), grey (a mid-grey wall
// around it), wood (a wood-grain table under it).
StartTarget paintTarget(ScenePlane& plane, int plane_index, double centre_a, double centre_b,
                        const RoomParams& params) {
  StartTarget target;
  target.type = params.target_type;
  target.plane_index = plane_index;
  const double s = plane.texels_per_m;
  if (target.type == "aruco") {
    target.width_m = target.height_m = params.aruco_size_m;
    target.border_m = 0;
  }
  const double hw = target.width_m / 2, hh = target.height_m / 2;
  if (target.type == "sheet") {
    const std::string& background = params.target_background;
    if (background == "black") {
      const double border = target.border_m;
      paintRect(plane, centre_a - hw - border, centre_b - hh - border, centre_a + hw + border,
                centre_b + hh + border, 0.0);
    } else if (background == "grey") {
      paintRect(plane, centre_a - hw - 0.3, centre_b - hh - 0.3, centre_a + hw + 0.3,
                centre_b + hh + 0.3, 128.0);
      target.border_m = 0;
    } else if (background == "wood" && plane.surface != "wood") {
      const double m = 0.35;
      const cv::Mat wood = woodTexture(
          cv::Size(static_cast<int>((2 * (hw + m)) * s), static_cast<int>((2 * (hh + m)) * s)), s,
          params.seed + 7);
      paintImage(plane, wood, centre_a - hw - m, centre_b - hh - m, 2 * (hw + m));
      target.border_m = 0;
    } else if (background == "wood") {
      target.border_m = 0;
    }
    // The white rectangle, whose corners are the ground truth: the two texels that
    // straddle each edge are set so that the renderer's bilinear reconstruction crosses
    // half-way exactly on the edge (area coverage would be off by up to 0.075 texel).
    auto blend = [&](int r, int c, double share, double grey) {
      if (r < 0 || c < 0 || r >= plane.texture.rows || c >= plane.texture.cols) return;
      uchar& t = plane.texture.at<uchar>(r, c);
      t = cv::saturate_cast<uchar>(share * grey + (1 - share) * t);
    };
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
    const cv::Point2d lo((centre_a - hw) * s, (centre_b - hh) * s),
        hi((centre_a + hw) * s, (centre_b + hh) * s);
    for (int r = static_cast<int>(std::floor(lo.y)); r <= static_cast<int>(std::floor(hi.y)) + 1;
         ++r)
      for (int c = static_cast<int>(std::floor(lo.x)); c <= static_cast<int>(std::floor(hi.x)) + 1;
           ++c)
        blend(r, c, profile(lo.x, hi.x, c) * profile(lo.y, hi.y, r), 255.0);
  } else if (target.type == "aruco") {
    // The marker drawn texel for texel (a module is several texels): its outer black
    // square spans whole texels, so the bilinear reconstruction crosses half-way half a
    // texel outside the first and last texel centres. The side is rounded to texels.
    const cv::Ptr<cv::aruco::Dictionary> dictionary =
        cv::aruco::getPredefinedDictionary(params.aruco_dictionary);
    const int modules = dictionary->markerSize + 2;
    const int per_module = std::max(1, static_cast<int>(std::lround(params.aruco_size_m * s / modules)));
    const int side = per_module * modules;
    cv::Mat marker;
    cv::aruco::drawMarker(dictionary, params.aruco_id, side, marker, 1);
    cv::flip(marker, marker, 0);  // image top at +v: upright on a wall
    const int c0 = static_cast<int>(std::lround(centre_a * s - side / 2.0));
    const int r0 = static_cast<int>(std::lround(centre_b * s - side / 2.0));
    // A white quiet zone of one module all round.
    const cv::Rect quiet = cv::Rect(c0 - per_module, r0 - per_module, side + 2 * per_module,
                                    side + 2 * per_module) &
                           cv::Rect(0, 0, plane.texture.cols, plane.texture.rows);
    plane.texture(quiet).setTo(255);
    const cv::Rect into(c0, r0, side, side);
    if ((into & cv::Rect(0, 0, plane.texture.cols, plane.texture.rows)) != into)
      throw std::invalid_argument("the marker does not fit on its plane");
    marker.copyTo(plane.texture(into));
    target.width_m = target.height_m = side / s;
    centre_a = (c0 - 0.5 + side / 2.0) / s;
    centre_b = (r0 - 0.5 + side / 2.0) / s;
    target.aruco_dictionary = params.aruco_dictionary;
    target.aruco_id = params.aruco_id;
  } else if (target.type != "none") {
    throw std::invalid_argument("target type must be none, sheet or aruco, not '" + target.type +
                                "'");
  }
  const double w2 = target.width_m / 2, h2 = target.height_m / 2;
  auto world = [&](double a, double b) {
    return plane.origin + a * plane.u_axis + b * plane.v_axis;
  };
  target.centre = world(centre_a, centre_b);
  target.corners = {world(centre_a - w2, centre_b - h2), world(centre_a + w2, centre_b - h2),
                    world(centre_a + w2, centre_b + h2), world(centre_a - w2, centre_b + h2)};
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
  if (params.layout != "bare" && params.layout != "furnished")
    throw std::invalid_argument("layout must be bare or furnished, not '" + params.layout + "'");
  const std::string& bg = params.target_background;
  if (bg != "black" && bg != "grey" && bg != "wood")
    throw std::invalid_argument("target background must be black, grey or wood, not '" + bg + "'");
  const bool furnished = params.layout == "furnished";
  IndoorScene scene;
  const double W = params.width_m, H = params.height_m, F = params.front_m, B = params.back_m;
  const double x0 = -W / 2;
  const cv::Vec3d X(1, 0, 0), Y(0, 1, 0), Z(0, 0, 1);
  // Axes are chosen so that u x v points into the room.
  auto add = [&](const std::string& name, const cv::Vec3d& origin, const cv::Vec3d& u,
                 const cv::Vec3d& v, double w, double h) -> ScenePlane& {
    scene.planes.push_back(
        makePlane(static_cast<int>(scene.planes.size()) + 1, name, origin, u, v, w, h, params));
    return scene.planes.back();
  };
  add("floor", {x0, -B, 0}, X, Y, W, F + B);
  if (params.walls >= 1) add("front_wall", {x0, F, 0}, X, Z, W, H);
  if (params.walls >= 2) add("left_wall", {x0, -B, 0}, Y, Z, F + B, H);
  if (params.walls >= 3) add("right_wall", {-x0, -B, 0}, Z, Y, H, F + B);
  if (params.walls >= 4) add("back_wall", {x0, -B, 0}, Z, X, H, W);
  if (params.ceiling) add("ceiling", {x0, -B, H}, Y, X, F + B, W);

  // The photographs (params.photos) on the floor, the front and the left wall, in that
  // order, tiled photo_tile_m wide: furnished or bare.
  int next_photo = 0;
  auto paintPhotos = [&](ScenePlane& p) {
    if (params.photos.empty()) return;
    if (p.name != "floor" && p.name != "front_wall" && p.name != "left_wall") return;
    p.surface = "photo";
    const cv::Mat& photo = params.photos[next_photo++ % params.photos.size()];
    const double tile_h = params.photo_tile_m * photo.rows / photo.cols;
    for (double b = 0; b < p.height_m; b += tile_h)
      for (double a = 0; a < p.width_m; a += params.photo_tile_m)
        paintImage(p, photo, a, b, params.photo_tile_m);
  };
  int table_top = -1;
  if (!furnished) {
    for (ScenePlane& p : scene.planes) paintPhotos(p);
  } else {
    const size_t room_planes = scene.planes.size();
    // The faces of an axis-aligned box that can be seen (`faces` of "+x-x+y-y+z-z"), each
    // a plane whose normal points out of the box.
    auto box = [&](const std::string& name, const cv::Vec3d& lo, const cv::Vec3d& hi,
                   const std::string& faces) {
      const cv::Vec3d d = hi - lo;
      auto has = [&](const char* f) { return faces.find(f) != std::string::npos; };
      if (has("+x")) add(name + "_+x", {hi[0], lo[1], lo[2]}, Y, Z, d[1], d[2]);
      if (has("-x")) add(name + "_-x", lo, Z, Y, d[2], d[1]);
      if (has("+y")) add(name + "_+y", {lo[0], hi[1], lo[2]}, Z, X, d[2], d[0]);
      if (has("-y")) add(name + "_-y", lo, X, Z, d[0], d[2]);
      if (has("+z")) add(name + "_+z", {lo[0], lo[1], hi[2]}, X, Y, d[0], d[1]);
      if (has("-z")) add(name + "_-z", lo, Y, X, d[1], d[0]);
    };
    // Sideboard against the front wall, right of the target; bookshelf against the left
    // wall; a table with a top and four legs; a door recess in the left wall.
    box("sideboard", {0.55, F - 0.45, 0}, {1.85, F, 0.8}, "+x-x-y+z");
    box("shelf", {x0, 0.3, 0}, {x0 + 0.35, 1.4, 1.9}, "+x+y-y+z");
    const double top_z = 0.74;
    box("table", {-1.6, -2.2, top_z - 0.04}, {-0.6, -1.4, top_z}, "+x-x+y-y+z-z");
    table_top = -1;
    for (size_t k = room_planes; k < scene.planes.size(); ++k)
      if (scene.planes[k].name == "table_+z") table_top = static_cast<int>(k);
    for (const cv::Vec2d& leg : {cv::Vec2d(-1.55, -2.15), cv::Vec2d(-0.7, -2.15),
                                cv::Vec2d(-1.55, -1.5), cv::Vec2d(-0.7, -1.5)})
      box("table_leg", {leg[0], leg[1], 0}, {leg[0] + 0.05, leg[1] + 0.05, top_z - 0.04},
          "+x-x+y-y");
    const double door_y0 = -2.6, door_w = 0.9, door_h = 2.05, recess = 0.12;
    if (params.walls >= 2) {
      scene.planes[2].holes.push_back(cv::Rect2d(door_y0 + B, 0, door_w, door_h));
      add("door", {x0 - recess, door_y0, 0}, Y, Z, door_w, door_h);
      add("door_jamb_near", {x0 - recess, door_y0, 0}, Z, X, door_h, recess);
      add("door_jamb_far", {x0 - recess, door_y0 + door_w, 0}, X, Z, recess, door_h);
      add("door_lintel", {x0 - recess, door_y0, door_h}, Y, X, door_w, recess);
    }
    // Surfaces: photographs (or generated texture) on the floor, the front and the left
    // wall; plain paint with posters on the right and back walls and the ceiling; wood,
    // books and paint on the furniture.
    std::mt19937 rng(params.seed * 7919u + 3u);
    for (size_t k = 0; k < scene.planes.size(); ++k) {
      ScenePlane& p = scene.planes[k];
      const cv::Size size = p.texture.size();
      const unsigned seed = params.seed * 131u + static_cast<unsigned>(k);
      const std::string& n = p.name;
      if (n == "floor" || n == "front_wall" || n == "left_wall") {
        paintPhotos(p);
      } else if (n == "right_wall" || n == "back_wall" || n == "ceiling" ||
                 n.rfind("door", 0) == 0 || n == "sideboard_+x" || n == "sideboard_-x" ||
                 n.rfind("table_leg", 0) == 0 || (n.rfind("table", 0) == 0 && n != "table_+z")) {
        p.surface = "paint";
        const double grey = n == "ceiling" ? 205 : n.rfind("door", 0) == 0 ? 150
                            : n.rfind("table", 0) == 0 ? 70 : n.rfind("sideboard", 0) == 0 ? 120 : 175;
        p.texture = paintTexture(size, grey, seed);
        // A few posters on the painted walls: the only corners there.
        if (n == "right_wall" || n == "back_wall") {
          const int posters = n == "right_wall" ? 2 : 1;
          std::uniform_real_distribution<double> along(0.3, 1.0);
          for (int q = 0; q < posters; ++q) {
            const cv::Mat art = params.photos.empty()
                                    ? makeCornerTexture(cv::Size(120, 160), seed * 17 + q)
                                    : params.photos[(next_photo + q) % params.photos.size()];
            // Wall axes: u = up (z), v = along the wall.
            const double along_wall = (q + along(rng)) * p.height_m / (posters + 1);
            cv::Mat framed;
            cv::copyMakeBorder(art, framed, 4, 4, 4, 4, cv::BORDER_CONSTANT, cv::Scalar(20));
            paintImage(p, framed, 1.0, along_wall, 0.6);
          }
        }
      } else if (n == "shelf_+x") {
        p.surface = "books";
        p.texture = booksTexture(size, p.texels_per_m, seed);
      } else if (n == "table_+z" || n.rfind("shelf", 0) == 0 || n == "sideboard_+z") {
        p.surface = "wood";
        p.texture = woodTexture(size, p.texels_per_m, seed);
      }
      // Shading: a light from above and behind the start, so that faces of one box
      // differ in brightness as they do in a room.
      const cv::Vec3d light = cv::normalize(cv::Vec3d(0.3, -0.4, 1.0));
      const double shade = 0.8 + 0.2 * std::max(-1.0, std::min(1.0, p.normal().dot(light)));
      p.texture.convertTo(p.texture, CV_8U, shade);
    }
  }

  auto index_of = [&](const std::string& name) {
    for (size_t k = 0; k < scene.planes.size(); ++k)
      if (scene.planes[k].name == name) return static_cast<int>(k);
    return -1;
  };
  if (params.target_on == "table") {
    if (table_top < 0) throw std::invalid_argument("target on the table needs --layout furnished");
    ScenePlane& top = scene.planes[table_top];
    scene.target = paintTarget(top, table_top, top.width_m / 2, top.height_m / 2, params);
  } else if (params.target_on == "floor" || params.walls < 1) {
    // 1 m ahead on the floor.
    scene.target = paintTarget(scene.planes[0], 0, W / 2, B + 1.0, params);
  } else if (params.target_on == "wall") {
    const int front = index_of("front_wall");
    scene.target =
        paintTarget(scene.planes[front], front, W / 2, params.target_centre_height_m, params);
  } else {
    throw std::invalid_argument("target must be on the wall, floor or table, not '" +
                                params.target_on + "'");
  }
  return scene;
}

bool ScenePlane::contains(double a, double b) const {
  if (a < 0 || b < 0 || a > width_m || b > height_m) return false;
  for (const cv::Rect2d& h : holes)
    if (a > h.x && a < h.x + h.width && b > h.y && b < h.y + h.height) return false;
  return true;
}

std::vector<cv::Mat> loadTexturePhotos(const std::string& folder) {
  namespace fs = std::filesystem;
  std::vector<std::string> files;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    std::string ext = entry.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
    if (ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp" || ext == ".pgm")
      files.push_back(entry.path().string());
  }
  if (ec) throw std::runtime_error("cannot read the folder " + folder + ": " + ec.message());
  std::sort(files.begin(), files.end());
  std::vector<cv::Mat> photos;
  for (const auto& f : files) {
    cv::Mat image = cv::imread(f, cv::IMREAD_GRAYSCALE);
    if (!image.empty()) photos.push_back(image);
  }
  if (photos.empty()) throw std::runtime_error("no readable image (png, jpg, bmp, pgm) in " + folder);
  return photos;
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
    if (!p.contains(a, b)) continue;
    hit.plane = static_cast<int>(k);
    hit.distance = s;
    hit.a = a;
    hit.b = b;
  }
  return hit;
}

}  // namespace mono_plane_detection
