#include "mono_plane_detection/mapping/plane_map.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "mono_plane_detection/geometry/plane_fit.h"
#include "mono_plane_detection/mapping/structure_fit.h"

namespace mono_plane_detection {
namespace {

double meanAbsResidual(const cv::Vec3d& normal, double distance,
                       const std::vector<cv::Vec3d>& points) {
  double sum = 0;
  for (const auto& p : points) sum += std::abs(normal.dot(p) - distance);
  return points.empty() ? 0 : sum / static_cast<double>(points.size());
}

std::vector<cv::Vec3d> positions(const MapPlane& plane) {
  std::vector<cv::Vec3d> out;
  out.reserve(plane.points.size());
  for (const auto& [id, entry] : plane.points) out.push_back(entry.first);
  return out;
}

// The points' centroid and the eigen decomposition of their scatter per point (variances
// along the eigenvectors, largest first): the least-squares plane's normal is the last
// eigenvector, its residuals' mean square the last value, the points' spread across their
// long in-plane axis the middle one.
struct Spread {
  cv::Vec3d centroid{0, 0, 0};
  cv::Vec3d variances{0, 0, 0};
  cv::Vec3d normal{0, 0, 1};
};

Spread spreadOf(const std::vector<cv::Vec3d>& points) {
  Spread out;
  for (const auto& p : points) out.centroid += p;
  out.centroid *= 1.0 / static_cast<double>(points.size());
  cv::Matx33d scatter = cv::Matx33d::zeros();
  for (const auto& p : points) {
    const cv::Vec3d d = p - out.centroid;
    scatter += d * d.t();
  }
  cv::Mat values, vectors;
  cv::eigen(cv::Mat(scatter * (1.0 / static_cast<double>(points.size()))), values, vectors);
  out.variances = cv::Vec3d(values.at<double>(0), values.at<double>(1), values.at<double>(2));
  out.normal = cv::Vec3d(vectors.at<double>(2, 0), vectors.at<double>(2, 1), vectors.at<double>(2, 2));
  return out;
}

// The tolerance for a plane's points from its rms (or for one point from its sigma across
// the plane): coplanar_sigmas x that, in [min_residual_m, max_residual_m] (min/max, not
// std::clamp: min_residual_m may exceed max_residual_m), never 0 (it divides).
double planeTolerance(const MapParams& params, double sigma_m) {
  return std::max(1e-9,
                  std::min(params.max_residual_m,
                           std::max(params.min_residual_m, params.coplanar_sigmas * sigma_m)));
}

// Least-squares plane through points.
bool leastSquares(const std::vector<cv::Vec3d>& points, cv::Vec3d& normal, double& distance) {
  if (points.size() < 3) return false;
  const Spread spread = spreadOf(points);
  normal = spread.normal;
  distance = normal.dot(spread.centroid);
  return std::isfinite(distance);
}

// How well the points fix the normal: the tilt about the points' long in-plane axis
// that moves them by their rms, shrunk by sqrt(points). A strip of points (one seen edge
// on, or a narrow band of a larger surface) leaves the plane free to turn about it.
double normalSigmaDeg(const Spread& spread, size_t points, double rms_m, double floor_m) {
  if (points < 3) return 180;
  const double minor = std::sqrt(std::max(1e-12, spread.variances[1]));
  const double sigma = std::max(rms_m, floor_m) / std::sqrt(static_cast<double>(points));
  return std::atan2(sigma, minor) * 180 / CV_PI;
}

double normalSigmaDeg(const std::vector<cv::Vec3d>& points, double rms_m, double floor_m) {
  return points.size() < 3 ? 180 : normalSigmaDeg(spreadOf(points), points.size(), rms_m, floor_m);
}

// Two groups of points on parallel surfaces (a shelf front and the wall beside it),
// each seen as a narrow strip, always lie on one plane: a tilted one through both. Such
// a plane's points fall into two groups with a gap between them along some direction
// in the plane, and at least one group, fitted alone, is not that plane (or is a strip
// that cannot say). True when the points do that: the plane is not taken.
// A group can say when its own points fix its normal as well as a plane's must to be
// confirmed (max_normal_sigma_deg, from its spread across its long axis against its own
// residuals): a fixed width (20 cm) called the sparse landmarks of a real wall or floor
// strips at 1280x960, whose finer pixels fix them better, and lost the furnished room's
// left wall there.
bool looksLikeTwoSurfaces(const std::vector<cv::Vec3d>& points, const cv::Vec3d& normal,
                          double min_gap_m, double min_residual_m, double max_normal_sigma_deg) {
  if (points.size() < 8) return false;
  cv::Vec3d u, v;
  planeAxes(normal, u, v);
  for (int step = 0; step < 8; ++step) {  // directions every 22.5 deg in the plane
    const double a = step * CV_PI / 8;
    const cv::Vec3d dir = std::cos(a) * u + std::sin(a) * v;
    std::vector<std::pair<double, size_t>> along;
    for (size_t i = 0; i < points.size(); ++i) along.emplace_back(dir.dot(points[i]), i);
    std::sort(along.begin(), along.end());
    const size_t quarter = points.size() / 4;
    for (size_t k = quarter; k + quarter < points.size(); ++k) {
      if (along[k].first - along[k - 1].first < min_gap_m) continue;
      // A gap with at least a quarter of the points on each side: fit each side alone.
      for (int side = 0; side < 2; ++side) {
        std::vector<cv::Vec3d> group;
        for (size_t j = side == 0 ? 0 : k; j < (side == 0 ? k : points.size()); ++j)
          group.push_back(points[along[j].second]);
        if (group.size() < 3) return true;
        const Spread spread = spreadOf(group);
        if (!std::isfinite(spread.normal.dot(spread.centroid))) return true;
        // A strip (its normal free to turn about its long axis) cannot confirm the plane.
        const double rms = std::sqrt(std::max(0.0, spread.variances[2]));
        const bool strip = normalSigmaDeg(spread, group.size(), rms, min_residual_m) >
                           max_normal_sigma_deg;
        const double angle = normalAngleDeg(spread.normal, normal);
        if (strip || std::min(angle, 180 - angle) > 10) return true;
      }
    }
  }
  return false;
}

}  // namespace

std::vector<double> PlaneMap::tolerances(const PlaneObservation& obs,
                                         const cv::Vec3d& normal) const {
  std::vector<double> tol(obs.points.size(), params_.max_residual_m);
  if (obs.sigma_m.size() != obs.points.size()) return tol;
  for (size_t i = 0; i < obs.points.size(); ++i) {
    // The depth error moves the point along its ray: across the plane by |n . ray|.
    cv::Vec3d ray = obs.points[i] - obs.viewpoint;
    const double length = cv::norm(ray);
    const double across = length > 0 ? std::abs(normal.dot(ray)) / length : 1.0;
    if (obs.sigma_m[i] * across > params_.max_point_sigma_m) {
      tol[i] = -1;  // too uncertain across this plane to test it
      continue;
    }
    const double sigma = std::hypot(obs.sigma_m[i] * across, params_.min_residual_m / 3);
    tol[i] = planeTolerance(params_, sigma);
  }
  return tol;
}

PlaneFit PlaneMap::fitObservation(const PlaneObservation& obs, int needed) const {
  if (obs.sigma_m.size() != obs.points.size())
    return fitPlane(obs.points, params_.max_residual_m, needed);
  // RANSAC on triples with each point's own tolerance: well-triangulated points of two
  // surfaces a few centimetres apart (a shelf before its wall) are not one plane.
  PlaneFit best;
  const int n = static_cast<int>(obs.points.size());
  if (n < std::max(3, needed)) return best;
  std::mt19937 rng(12345);  // deterministic for given points
  std::uniform_int_distribution<int> pick(0, n - 1);
  size_t best_count = 0;
  double best_cost = 0;
  cv::Vec3d best_normal;
  double best_distance = 0;
  auto score = [&](const cv::Vec3d& normal, double distance, std::vector<int>* inliers) {
    const std::vector<double> tol = tolerances(obs, normal);
    size_t count = 0;
    double cost = 0;
    for (int i = 0; i < n; ++i) {
      if (tol[i] < 0) continue;
      const double r = std::abs(normal.dot(obs.points[i]) - distance) / tol[i];
      if (r <= 1) {
        ++count;
        cost += r * r;
        if (inliers) inliers->push_back(i);
      }
    }
    return std::make_pair(count, cost);
  };
  for (int it = 0; it < 300; ++it) {
    const int a = pick(rng), b = pick(rng), c = pick(rng);
    if (a == b || b == c || a == c) continue;
    cv::Vec3d normal = (obs.points[b] - obs.points[a]).cross(obs.points[c] - obs.points[a]);
    const double length = cv::norm(normal);
    if (length < 1e-9) continue;
    normal /= length;
    const double distance = normal.dot(obs.points[a]);
    const auto [count, cost] = score(normal, distance, nullptr);
    if (count > best_count || (count == best_count && cost < best_cost)) {
      best_count = count;
      best_cost = cost;
      best_normal = normal;
      best_distance = distance;
    }
  }
  if (static_cast<int>(best_count) < needed) return best;
  // Refine: least squares on the inliers, inliers again (twice).
  std::vector<int> inliers;
  for (int round = 0; round < 3; ++round) {
    inliers.clear();
    score(best_normal, best_distance, &inliers);
    if (static_cast<int>(inliers.size()) < needed) return best;
    if (round == 2) break;
    std::vector<cv::Vec3d> in;
    for (int i : inliers) in.push_back(obs.points[i]);
    if (!leastSquares(in, best_normal, best_distance)) return best;
  }
  // The spread check and the final least squares of fitPlane on the inliers.
  std::vector<cv::Vec3d> in;
  for (int i : inliers) in.push_back(obs.points[i]);
  if (looksLikeTwoSurfaces(in, best_normal, params_.min_gap_m, params_.min_residual_m,
                           params_.max_normal_sigma_deg)) return best;
  const PlaneFit check = fitPlane(in, params_.max_residual_m, needed);
  if (!check.ok) return best;
  best.ok = true;
  best.normal = best_normal;
  best.distance = best_distance;
  best.inliers = inliers;
  double sum = 0;
  for (int i : inliers) sum += std::pow(best_normal.dot(obs.points[i]) - best_distance, 2);
  best.rms_m = std::sqrt(sum / inliers.size());
  return best;
}

void PlaneMap::reset() {
  planes_.clear();
  // next_id_ goes on: a plane's id is never reused (PlaneEstimate.msg), so a node keyed
  // on ids does not take a plane of the map before a bag loop for one after it.
  vertical_.reset();
}

std::vector<int> PlaneMap::update(const std::vector<PlaneObservation>& observations, double stamp) {
  std::vector<int> ids(observations.size(), -1);
  cv::Vec3d viewpoint(0, 0, 0);
  for (size_t k = 0; k < observations.size(); ++k) {
    const PlaneObservation& obs = observations[k];
    viewpoint = obs.viewpoint;
    const int needed = std::max(params_.min_points,
                                static_cast<int>(std::ceil(params_.min_share * obs.points.size())));
    PlaneObservation rest = obs;
    const bool with_sigma = obs.sigma_m.size() == obs.points.size();
    size_t largest = 0;
    // An image plane whose 3D points are not one plane (a mixture: under little
    // parallax several surfaces share a homography) is split into the planes its points
    // support at their own uncertainty; points on none of them are not mapped.
    while (static_cast<int>(rest.points.size()) >= needed) {
      PlaneFit fit = fitObservation(rest, needed);
      if (!fit.ok) break;
      orientTowards(fit, obs.viewpoint);
      PlaneObservation kept, others;
      kept.viewpoint = others.viewpoint = obs.viewpoint;
      std::vector<bool> in(rest.points.size(), false);
      for (int i : fit.inliers) in[i] = true;
      for (size_t i = 0; i < rest.points.size(); ++i) {
        PlaneObservation& to = in[i] ? kept : others;
        to.ids.push_back(rest.ids[i]);
        to.points.push_back(rest.points[i]);
        if (with_sigma) to.sigma_m.push_back(rest.sigma_m[i]);
      }
      if (kept.points.size() == obs.points.size()) {  // a plane from motion, whole
        kept.measured_from = obs.measured_from;
        kept.normal_sigma_deg = obs.normal_sigma_deg;
      }
      const int id = fuse(kept, fit.normal, fit.distance, stamp);
      if (id >= 0 && kept.points.size() > largest) {
        largest = kept.points.size();
        ids[k] = id;
      }
      rest = std::move(others);
    }
  }
  mergeDuplicates(viewpoint);
  dropExplained();
  fadeAndBound(stamp);
  // A merge may have renamed a plane an observation went to, or a mixture gone.
  for (int& id : ids) {
    if (id < 0) continue;
    const bool alive =
        std::any_of(planes_.begin(), planes_.end(), [&](const MapPlane& p) { return p.id == id; });
    if (!alive) id = -1;
  }
  return ids;
}

int PlaneMap::addKnownPlane(const PlaneObservation& obs, double stamp) {
  PlaneFit fit = fitPlane(obs.points, params_.max_residual_m, params_.min_points);
  if (!fit.ok) return -1;
  orientTowards(fit, obs.viewpoint);
  PlaneObservation kept;
  kept.viewpoint = obs.viewpoint;
  for (int i : fit.inliers) {
    kept.ids.push_back(obs.ids[i]);
    kept.points.push_back(obs.points[i]);
  }
  const int id = fuse(kept, fit.normal, fit.distance, stamp);
  mergeDuplicates(obs.viewpoint);
  dropExplained();
  fadeAndBound(stamp);
  const bool alive =
      std::any_of(planes_.begin(), planes_.end(), [&](const MapPlane& p) { return p.id == id; });
  return alive ? id : -1;
}

int PlaneMap::fuse(const PlaneObservation& kept, const cv::Vec3d& normal, double distance,
                   double stamp) {
  const int match = associate(normal, distance, kept);
  MapPlane* plane;
  if (match < 0) {
    planes_.emplace_back();
    plane = &planes_.back();
    plane->id = next_id_++;
    plane->first_seen = stamp;
    plane->normal = normal;
    plane->distance = distance;
  } else {
    plane = &planes_[match];
  }
  for (size_t i = 0; i < kept.ids.size(); ++i) plane->points[kept.ids[i]] = {kept.points[i], stamp};
  if (kept.normal_sigma_deg >= 0)
    plane->motion_sigma_deg = std::min(plane->motion_sigma_deg, kept.normal_sigma_deg);
  if (!refit(*plane, kept.viewpoint)) {
    if (match < 0) {
      planes_.pop_back();
      --next_id_;
    }
    return -1;
  }
  // Count the observation only from a new viewpoint: images from one spot repeat the
  // same evidence (and the same mixture, if it is one).
  const double range =
      std::max(0.3, std::abs(plane->own_normal.dot(kept.viewpoint) - plane->own_distance));
  std::vector<cv::Vec3d> seen_from = kept.measured_from;
  seen_from.push_back(kept.viewpoint);
  for (const cv::Vec3d& from : seen_from) {
    const bool new_view = std::all_of(plane->views.begin(), plane->views.end(), [&](const cv::Vec3d& v) {
      return cv::norm(v - from) >= params_.view_spacing * range;
    });
    if (!new_view) continue;
    plane->observations += 1;
    plane->views.push_back(from);
    if (plane->views.size() > 16) plane->views.erase(plane->views.begin() + 1);  // bounded
  }
  plane->last_seen = stamp;
  return plane->id;
}

int PlaneMap::associate(const cv::Vec3d& normal, double distance,
                        const PlaneObservation& obs) const {
  int best = -1;
  double best_score = 0;
  for (size_t k = 0; k < planes_.size(); ++k) {
    const MapPlane& plane = planes_[k];
    // Tracks already on a plane are strong evidence; geometry decides otherwise.
    size_t shared = 0;
    for (auto id : obs.ids) shared += plane.points.count(id);
    const double share = obs.ids.empty() ? 0 : double(shared) / double(obs.ids.size());
    double score = 0;
    const bool parallel = normalAngleDeg(normal, plane.normal) <= params_.max_angle_deg;
    const double offset = meanAbsResidual(plane.normal, plane.distance, obs.points);
    if (share >= params_.min_shared_ids && parallel)
      score = 1 + share;
    // Both ways, each plane against the other's points (as the merge rule): comparing
    // the two distances would depend on where the map's origin is (within max_angle_deg
    // they differ by up to sin(12 deg) x the origin's distance along the plane).
    else if (parallel && offset <= params_.max_offset_m &&
             meanAbsResidual(normal, distance, positions(plane)) <= 2 * params_.max_offset_m)
      score = 1 - offset / params_.max_offset_m;
    if (score > best_score) {
      best_score = score;
      best = static_cast<int>(k);
    }
  }
  return best;
}

// A point of another surface beyond the line where it meets this one can lie within
// max_residual_m of this plane tilted towards it: the furnished room painted with TUM
// photographs had 4 floor points 0.7-1.2 m beyond a shelf's end, 11-14 cm before its front
// but within 5 cm of its tilted extension, and with their lever they turned the shelf
// front 3.6 deg (its own points 1.3 deg). Such a point is the crossing plane's: a confirmed
// plane more than 45 deg from this one holds it within its tolerance (coplanar_sigmas x
// rms, in [min_residual_m, max_residual_m], as dropExplained weighs them), and the plane
// of this plane's other points does not hold it within theirs. Points where the two meet
// lie on both and stay (a floor seen along a wall's foot keeps them). Nothing is judged
// when the other points fit no plane (too few, a line) or `with` (all of them) failed, and
// nothing goes unless the candidates (join points too) turn the plane beyond what its
// other points allow (a lever, not noise: on the furnished room's humanoid path,
// releasing every such point moved its floor 2.9 -> 3.1 % at noise seed 0). True when
// points left.
bool PlaneMap::releaseToCrossingPlanes(MapPlane& plane, int merged, const PlaneFit& with) const {
  if (!with.ok) return false;
  std::vector<std::pair<const MapPlane*, double>> crossing;  // with its tolerance
  for (const MapPlane& other : planes_) {
    if (other.id == plane.id || other.id == merged || !other.confirmed(params_)) continue;
    const double angle = normalAngleDeg(other.own_normal, plane.normal);
    if (std::min(angle, 180 - angle) > 45)
      crossing.emplace_back(&other, planeTolerance(params_, other.rms_m));
  }
  if (crossing.empty()) return false;
  std::vector<std::uint64_t> candidates;
  std::vector<cv::Vec3d> others;
  for (const auto& [id, entry] : plane.points) {
    const cv::Vec3d& x = entry.first;
    const bool on_crossing = std::any_of(crossing.begin(), crossing.end(), [&](const auto& c) {
      return std::abs(c.first->own_normal.dot(x) - c.first->own_distance) <= c.second;
    });
    if (on_crossing)
      candidates.push_back(id);
    else
      others.push_back(x);
  }
  if (candidates.empty()) return false;
  const PlaneFit own = fitPlane(others, params_.max_residual_m, params_.min_points);
  if (!own.ok) return false;
  // They turn it beyond coplanar_sigmas x the normal sigma of its other points?
  std::vector<cv::Vec3d> own_points;
  for (int i : own.inliers) own_points.push_back(others[i]);
  const double sigma = normalSigmaDeg(own_points, own.rms_m, params_.min_residual_m);
  const double turn = normalAngleDeg(with.normal, own.normal);
  if (std::min(turn, 180 - turn) <= params_.coplanar_sigmas * sigma) return false;
  const double own_tolerance = planeTolerance(params_, own.rms_m);
  bool released = false;
  for (std::uint64_t id : candidates) {
    const cv::Vec3d& x = plane.points.at(id).first;
    if (std::abs(own.normal.dot(x) - own.distance) <= own_tolerance) continue;
    plane.points.erase(id);
    released = true;
  }
  return released;
}

bool PlaneMap::refit(MapPlane& plane, const cv::Vec3d& viewpoint, int merged) const {
  // Bound the memory: keep the most recently seen points.
  if (plane.points.size() > params_.max_points_per_plane) {
    std::vector<std::pair<double, std::uint64_t>> by_age;
    for (const auto& [id, entry] : plane.points) by_age.emplace_back(entry.second, id);
    std::sort(by_age.begin(), by_age.end());
    for (size_t k = 0; plane.points.size() > params_.max_points_per_plane; ++k)
      plane.points.erase(by_age[k].second);
  }
  std::vector<cv::Vec3d> all = positions(plane);
  PlaneFit fit = fitPlane(all, params_.max_residual_m, params_.min_points);
  if (releaseToCrossingPlanes(plane, merged, fit)) {
    all = positions(plane);
    fit = fitPlane(all, params_.max_residual_m, params_.min_points);
  }
  if (!fit.ok) return false;
  orientTowards(fit, viewpoint);
  if (normalAngleDeg(fit.normal, plane.normal) > 90) {  // keep the side first seen
    fit.normal = -fit.normal;
    fit.distance = -fit.distance;
  }
  // Points the refit does not explain were put on this plane by mistake.
  std::vector<bool> keep(all.size(), false);
  for (int i : fit.inliers) keep[i] = true;
  size_t index = 0;
  std::vector<cv::Vec3d> inliers;
  for (auto it = plane.points.begin(); it != plane.points.end(); ++index) {
    if (keep[index]) {
      inliers.push_back(it->second.first);
      ++it;
    } else {
      it = plane.points.erase(it);
    }
  }
  // How well its own points fix the normal decides confirmation, whatever the structure
  // below adds: a strip is not confirmed by being at right angles to a wall.
  const double points_sigma_deg = normalSigmaDeg(inliers, fit.rms_m, params_.min_residual_m);
  plane.normal_sigma_deg = std::min(plane.motion_sigma_deg, points_sigma_deg);
  plane.own_normal = fit.normal;
  plane.own_distance = fit.distance;
  // Held only once its own points fix its normal to a map's bound: a loose plane (a few
  // points, a strip) would swing to a reference by degrees, and out of its observations'
  // association gate. The references' own planes, not their held ones: none is pulled back
  // by its own earlier pull through another.
  std::vector<ReferencePlane> references;
  const bool holdable = points_sigma_deg <= params_.max_normal_sigma_deg;
  if (holdable)
    for (const MapPlane& other : planes_)
      if (other.id != plane.id && other.id != merged && other.confirmed(params_) &&
          other.normal_sigma_deg < plane.normal_sigma_deg)
        references.push_back({other.own_normal, other.normal_sigma_deg});
  // The room's vertical, as a horizontal plane known to up_sigma_deg, offered as the planes
  // are (to one known worse): a floor level, a wall upright.
  if (holdable && vertical_ && params_.upCanHold() &&
      params_.up_sigma_deg < plane.normal_sigma_deg)
    references.push_back({*vertical_, params_.up_sigma_deg});
  if (!references.empty()) {
    const StructuredPlane held = structuredPlane(inliers, fit.normal, references,
                                                 params_.structure_sigmas, params_.min_residual_m);
    fit.normal = held.normal;
    fit.distance = held.distance;
  }
  plane.normal = fit.normal;
  plane.distance = fit.distance;
  plane.rms_m = fit.rms_m;
  plane.polygon = planePolygon(fit.normal, fit.distance, inliers);
  return true;
}

void PlaneMap::mergeDuplicates(const cv::Vec3d& viewpoint) {
  for (size_t i = 0; i < planes_.size(); ++i) {
    for (size_t j = i + 1; j < planes_.size();) {
      MapPlane& a = planes_[i];
      const MapPlane& b = planes_[j];
      const bool same =
          normalAngleDeg(a.normal, b.normal) <= params_.max_angle_deg &&
          meanAbsResidual(a.normal, a.distance, positions(b)) <= params_.max_offset_m &&
          meanAbsResidual(b.normal, b.distance, positions(a)) <= params_.max_offset_m;
      if (!same) {
        ++j;
        continue;
      }
      // The older plane (smaller id) keeps its id: ids stay stable for users.
      MapPlane merged = a;
      for (const auto& [id, entry] : b.points) merged.points.emplace(id, entry);
      merged.observations += b.observations;
      merged.motion_sigma_deg = std::min(a.motion_sigma_deg, b.motion_sigma_deg);
      merged.views.insert(merged.views.end(), b.views.begin(), b.views.end());
      if (merged.views.size() > 16) merged.views.resize(16);
      merged.first_seen = std::min(a.first_seen, b.first_seen);
      merged.last_seen = std::max(a.last_seen, b.last_seen);
      if (refit(merged, viewpoint, b.id)) {
        a = merged;
        planes_.erase(planes_.begin() + static_cast<long>(j));
      } else {
        ++j;
      }
    }
  }
}

// A plane of points that larger confirmed planes explain adds no surface of its own. It
// goes when
// - fewer than min_points of its points are on no larger confirmed plane and at least
//   kStrip are on each of two of them within 45 deg of it: a mixture of two surfaces
//   nearly parallel to it (a wall and the shelf before it) that one image's vote put
//   together and a tilted plane fits (two parallel strips always lie on one plane); what
//   is left would not be taken as a plane;
// - or most of its points are one larger confirmed plane's own (the same tracks, there
//   within its tolerance) and that plane is within 45 deg of it: its points seen leaning
//   (at 320x240 a strip of a shelf front's landmarks, their depth errors shared, fitted
//   17 deg off with a few of the wall below, beside the shelf's own plane: a confirmed
//   plane matching no surface). The same tracks, not only the same place: landmarks
//   bunch at joins (a door's hinge and frame, the foot of a ramp, an obtuse corner), and
//   a true face there has most of its points within a neighbour's tolerance but its own.
// A true face keeps most of its points off the others (only its edges are on them), and
// the surfaces its edges touch are across it: a floor along one wall's foot or into a
// corner, a ceiling along two corridor walls, a table top between two walls stay. Each
// point goes to the plane it is nearest to in units of that plane's tolerance
// (coplanar_sigmas x rms, in [min_residual_m, max_residual_m]). Largest first, so that a
// plane's fate is decided before it explains smaller ones. A plane that goes takes its
// points with it (the larger plane has the shared ones).
void PlaneMap::dropExplained() {
  constexpr int kStrip = 3;                // points: the fewest that show a strip's line
  constexpr double kNearParallelDeg = 45;  // nearer parallel than at right angles
  struct Explainer {
    const MapPlane* plane;  // its points' own plane (own_normal, own_distance) explains
    double tolerance;
    bool near_parallel;  // to the plane tested
  };
  std::vector<size_t> order(planes_.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return planes_[a].points.size() > planes_[b].points.size();
  });
  std::vector<bool> dropped(planes_.size(), false);
  std::vector<Explainer> explainers;
  std::vector<int> on;      // per explainer: the tested plane's points on it
  std::vector<int> shared;  // of those, its own tracks too
  for (size_t k = 0; k < order.size(); ++k) {
    const MapPlane& plane = planes_[order[k]];
    explainers.clear();
    int near_parallel = 0;
    for (size_t j = 0; j < k; ++j) {
      const MapPlane& other = planes_[order[j]];
      if (dropped[order[j]] || !other.confirmed(params_) ||
          other.points.size() <= plane.points.size())
        continue;
      const double angle = normalAngleDeg(plane.own_normal, other.own_normal);
      const bool parallel = std::min(angle, 180 - angle) < kNearParallelDeg;
      near_parallel += parallel;
      explainers.push_back({&other, planeTolerance(params_, other.rms_m), parallel});
    }
    if (near_parallel == 0) continue;
    on.assign(explainers.size(), 0);
    shared.assign(explainers.size(), 0);
    int own = 0;
    const int size = static_cast<int>(plane.points.size());
    for (const auto& [id, entry] : plane.points) {
      // Kept whatever the rest is: min_points of its own, and no majority left for another.
      if (own >= params_.min_points && 2 * own >= size) break;
      int nearest = -1;
      double nearest_ratio = 1;
      for (size_t e = 0; e < explainers.size(); ++e) {
        const MapPlane& by = *explainers[e].plane;
        const double ratio = std::abs(by.own_normal.dot(entry.first) - by.own_distance) /
                             explainers[e].tolerance;
        if (ratio <= nearest_ratio) {
          nearest = static_cast<int>(e);
          nearest_ratio = ratio;
        }
      }
      if (nearest < 0) {
        ++own;
      } else {
        ++on[nearest];
        shared[nearest] += explainers[nearest].plane->points.count(id) > 0;
      }
    }
    int strips = 0;
    bool leaning_copy = false;
    for (size_t e = 0; e < explainers.size(); ++e) {
      if (!explainers[e].near_parallel) continue;
      strips += on[e] >= kStrip;
      leaning_copy |= 2 * shared[e] > size;
    }
    dropped[order[k]] = (own < params_.min_points && strips >= 2) || leaning_copy;
  }
  for (size_t i = planes_.size(); i-- > 0;)
    if (dropped[i]) planes_.erase(planes_.begin() + static_cast<long>(i));
}

void PlaneMap::fadeAndBound(double stamp) {
  for (auto& p : planes_) {
    const double unseen = std::max(0.0, stamp - p.last_seen);
    p.confidence = (1 - std::exp(-double(p.observations) / params_.confirm_observations)) *
                   std::exp(-unseen / params_.fade_time_s);
  }
  planes_.erase(std::remove_if(planes_.begin(), planes_.end(),
                               [&](const MapPlane& p) {
                                 // Seen from too few views; one seen from enough but
                                 // with a loose normal stays (more points may fix it).
                                 return p.observations < params_.confirm_observations &&
                                        stamp - p.last_seen > params_.tentative_timeout_s;
                               }),
                planes_.end());
  while (planes_.size() > params_.max_planes) {
    const auto weakest = std::min_element(
        planes_.begin(), planes_.end(),
        [](const MapPlane& a, const MapPlane& b) { return a.confidence < b.confidence; });
    planes_.erase(weakest);
  }
}

}  // namespace mono_plane_detection
