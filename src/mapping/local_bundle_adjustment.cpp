#include "mono_plane_detection/mapping/local_bundle_adjustment.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/core/eigen.hpp>
#include <optional>
#include <string>

#include "mono_plane_detection/geometry/stats.h"

namespace mono_plane_detection {
namespace {

using Mat26 = Eigen::Matrix<double, 2, 6>;
using Mat23 = Eigen::Matrix<double, 2, 3>;
using Mat63 = Eigen::Matrix<double, 6, 3>;
using Mat66 = Eigen::Matrix<double, 6, 6>;
using Vec6 = Eigen::Matrix<double, 6, 1>;

// camera_from_map, the form the projection needs.
struct Camera {
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
};

Camera cameraOf(const Pose& map_from_camera) {
  const Pose c = map_from_camera.inverse();
  Camera cam;
  cv::cv2eigen(c.R, cam.R);
  cv::cv2eigen(c.t, cam.t);
  return cam;
}

Pose poseOf(const Camera& cam) {
  Pose c;
  cv::eigen2cv(cam.R, c.R);
  cv::eigen2cv(cam.t, c.t);
  return c.inverse();
}

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d s;
  s << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return s;
}

// Every camera and point, the fixed ones too (their observations are read).
struct State {
  std::vector<Camera> cameras;
  std::vector<Eigen::Vector3d> points;
};

State stateOf(const BundleProblem& problem) {
  State state;
  for (const BundleView& v : problem.views) state.cameras.push_back(cameraOf(v.map_from_camera));
  for (const BundlePoint& p : problem.points)
    state.points.emplace_back(p.position[0], p.position[1], p.position[2]);
  return state;
}

// Which views and points move, numbered among the free ones (-1: fixed), and each point's
// observations: the Schur complement walks them point by point.
struct Layout {
  std::vector<int> view_index, point_index;
  int free_views = 0, free_points = 0;
  std::vector<std::vector<int>> of_point;
};

Layout layoutOf(const BundleProblem& problem) {
  Layout l;
  l.view_index.assign(problem.views.size(), -1);
  l.point_index.assign(problem.points.size(), -1);
  for (size_t i = 0; i < problem.views.size(); ++i)
    if (!problem.views[i].fixed) l.view_index[i] = l.free_views++;
  for (size_t j = 0; j < problem.points.size(); ++j)
    if (!problem.points[j].fixed) l.point_index[j] = l.free_points++;
  l.of_point.resize(problem.points.size());
  for (size_t k = 0; k < problem.observations.size(); ++k)
    l.of_point[problem.observations[k].point].push_back(static_cast<int>(k));
  return l;
}

bool finite(const cv::Matx33d& m) { return cv::checkRange(m); }
bool finite(const cv::Vec3d& v) { return cv::checkRange(v); }

// Why the adjustment cannot run on these; empty when it can. A NaN would reach the
// noise's median (std::nth_element has no order with NaN) and every cost.
std::string whyNot(const BundleProblem& problem, const BundleOptions& options) {
  const auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  if (!positive(options.focal_px) || !positive(options.huber_sigmas) ||
      !positive(options.min_sigma_px) || options.max_iterations < 0)
    return "options out of range (focal_px, huber_sigmas, min_sigma_px > 0, max_iterations >= 0)";
  const int views = static_cast<int>(problem.views.size());
  const int points = static_cast<int>(problem.points.size());
  for (const BundleObservation& o : problem.observations) {
    if (o.view < 0 || o.view >= views || o.point < 0 || o.point >= points)
      return "an observation names no view or point";
    if (!std::isfinite(o.normalized.x) || !std::isfinite(o.normalized.y))
      return "an observation is not finite";
  }
  for (const BundleView& v : problem.views)
    if (!finite(v.map_from_camera.R) || !finite(v.map_from_camera.t)) return "a view is not finite";
  for (const BundlePoint& p : problem.points)
    if (!finite(p.position)) return "a point is not finite";
  return {};
}

Eigen::Vector3d inCamera(const State& s, const BundleObservation& o) {
  const Camera& c = s.cameras[o.view];
  return c.R * s.points[o.point] + c.t;
}

bool inFront(const Eigen::Vector3d& x) { return x.z() > 1e-9; }

// The residual of one observation in pixels; false when the point is not in front.
bool residual(const State& s, const BundleObservation& o, double focal, Eigen::Vector2d& r,
              Eigen::Vector3d* in_camera = nullptr) {
  const Eigen::Vector3d x = inCamera(s, o);
  if (!inFront(x)) return false;
  r = focal * Eigen::Vector2d(x.x() / x.z() - o.normalized.x, x.y() / x.z() - o.normalized.y);
  if (in_camera) *in_camera = x;
  return true;
}

// Huber's cost of a residual norm e: its square within delta, growing linearly beyond
// (an outlier pulls with a bounded force).
double huberCost(double e, double delta) {
  return e <= delta ? e * e : 2 * delta * e - delta * delta;
}

// The weight with which least squares takes the step of Huber's cost (IRLS).
double huberWeight(double e, double delta) { return e <= delta ? 1.0 : delta / e; }

// Per observation: its point in front of its camera.
std::vector<bool> inFront(const State& s, const std::vector<BundleObservation>& obs) {
  std::vector<bool> in_front(obs.size());
  for (size_t k = 0; k < obs.size(); ++k) in_front[k] = inFront(inCamera(s, obs[k]));
  return in_front;
}

// The Huber cost of the `counted` observations; nothing when one of them is behind its
// camera (a cost without its term would seem to fall: see levenbergMarquardt).
std::optional<double> cost(const State& s, const std::vector<BundleObservation>& obs,
                           const std::vector<bool>& counted, double focal, double delta) {
  double sum = 0;
  Eigen::Vector2d r;
  for (size_t k = 0; k < obs.size(); ++k) {
    if (!counted[k]) continue;
    if (!residual(s, obs[k], focal, r)) return std::nullopt;
    sum += huberCost(r.norm(), delta);
  }
  return sum;
}

double inlierRms(const State& s, const std::vector<BundleObservation>& obs, double focal,
                 double delta) {
  double sum = 0;
  int n = 0;
  Eigen::Vector2d r;
  for (const BundleObservation& o : obs)
    if (residual(s, o, focal, r) && r.norm() <= delta) {
      sum += r.squaredNorm();
      ++n;
    }
  return n > 0 ? std::sqrt(sum / n) : 0;
}

// The observations' noise, measured (median residual norm over its value for a 2D
// Gaussian, sqrt(2 ln 2) sigma): pixels mean different things on different cameras and
// trackers. Nothing when fewer than 6 observations are in front of their cameras.
std::optional<double> measureSigma(const State& s, const std::vector<BundleObservation>& obs,
                                   double focal, double min_sigma) {
  std::vector<double> norms;
  Eigen::Vector2d r;
  for (const BundleObservation& o : obs)
    if (residual(s, o, focal, r)) norms.push_back(r.norm());
  if (norms.size() < 6) return std::nullopt;
  return std::max(min_sigma, median(norms) / 1.1774);
}

// The normal equations J^T H J dx = -J^T H r by blocks (H: Huber's weights): U
// camera-camera, V point-point, W camera-point (one per observation).
struct NormalEquations {
  std::vector<Mat66> U;
  std::vector<Vec6> gc;  // J^T H r of the free cameras
  std::vector<Eigen::Matrix3d> V;
  std::vector<Eigen::Vector3d> gp;  // J^T H r of the free points
  std::vector<Mat63> W;             // per observation; zero unless view and point are free
  std::vector<bool> used;           // per observation: in the equations
};

NormalEquations normalEquations(const State& state, const std::vector<BundleObservation>& obs,
                                const std::vector<bool>& counted, const Layout& layout,
                                double focal, double delta) {
  NormalEquations ne;
  ne.U.assign(layout.free_views, Mat66::Zero());
  ne.gc.assign(layout.free_views, Vec6::Zero());
  ne.V.assign(layout.free_points, Eigen::Matrix3d::Zero());
  ne.gp.assign(layout.free_points, Eigen::Vector3d::Zero());
  ne.W.assign(obs.size(), Mat63::Zero());
  ne.used.assign(obs.size(), false);
  Eigen::Vector2d r;
  for (size_t k = 0; k < obs.size(); ++k) {
    const BundleObservation& o = obs[k];
    const int vi = layout.view_index[o.view], pj = layout.point_index[o.point];
    Eigen::Vector3d x;
    if ((vi < 0 && pj < 0) || !counted[k] || !residual(state, o, focal, r, &x)) continue;
    const double w = huberWeight(r.norm(), delta);
    // The projection's derivative at x (camera frame), in pixels.
    Mat23 P;
    P << 1 / x.z(), 0, -x.x() / (x.z() * x.z()), 0, 1 / x.z(), -x.y() / (x.z() * x.z());
    P *= focal;
    ne.used[k] = true;
    // A camera step turns and moves the point in the camera's frame: x -> x + w x x + t
    // (applyStep).
    Mat26 Jc;
    if (vi >= 0) {
      Jc.leftCols<3>() = -P * skew(x);
      Jc.rightCols<3>() = P;
      ne.U[vi] += w * Jc.transpose() * Jc;
      ne.gc[vi] += w * Jc.transpose() * r;
    }
    if (pj >= 0) {
      const Mat23 Jp = P * state.cameras[o.view].R;
      ne.V[pj] += w * Jp.transpose() * Jp;
      ne.gp[pj] += w * Jp.transpose() * r;
      if (vi >= 0) ne.W[k] = w * Jc.transpose() * Jp;
    }
  }
  return ne;
}

// The damped equations with the points eliminated (Schur complement),
// (U - W V^-1 W^T) dc = -gc + W V^-1 gp: 6 unknowns per free view (about ten) instead of
// 3 more per point (hundreds).
struct ReducedSystem {
  Eigen::MatrixXd S;
  Eigen::VectorXd b;
  std::vector<Eigen::Matrix3d> Vinv;  // per free point: its damped V inverted
  std::vector<bool> solvable;         // per free point: V invertible (else it stays)
};

ReducedSystem reduceToCameras(const NormalEquations& ne, const Layout& layout,
                              const std::vector<BundleObservation>& obs, double lambda) {
  const int n = 6 * layout.free_views;
  ReducedSystem rs;
  rs.S = Eigen::MatrixXd::Zero(n, n);
  rs.b = Eigen::VectorXd::Zero(n);
  // Marquardt's damping scales the diagonal; the small constant keeps a view or point no
  // observation constrains from a singular block.
  for (int i = 0; i < layout.free_views; ++i) {
    Mat66 u = ne.U[i];
    u.diagonal() *= 1 + lambda;
    u.diagonal().array() += 1e-9;
    rs.S.block<6, 6>(6 * i, 6 * i) = u;
    rs.b.segment<6>(6 * i) = -ne.gc[i];
  }
  rs.Vinv.assign(layout.free_points, Eigen::Matrix3d::Zero());
  rs.solvable.assign(layout.free_points, false);
  for (size_t j = 0; j < layout.point_index.size(); ++j) {
    const int pj = layout.point_index[j];
    if (pj < 0) continue;
    Eigen::Matrix3d v = ne.V[pj];
    v.diagonal() *= 1 + lambda;
    v.diagonal().array() += 1e-9 * (1 + v.trace());
    Eigen::FullPivLU<Eigen::Matrix3d> lu(v);
    if (!lu.isInvertible()) continue;
    rs.solvable[pj] = true;
    rs.Vinv[pj] = lu.inverse();
    // The point couples every two free views that see it.
    for (int ka : layout.of_point[j]) {
      const int va = layout.view_index[obs[ka].view];
      if (va < 0 || !ne.used[ka]) continue;
      const Mat63 WV = ne.W[ka] * rs.Vinv[pj];
      rs.b.segment<6>(6 * va) += WV * ne.gp[pj];
      for (int kb : layout.of_point[j]) {
        const int vb = layout.view_index[obs[kb].view];
        if (vb < 0 || !ne.used[kb]) continue;
        rs.S.block<6, 6>(6 * va, 6 * vb) -= WV * ne.W[kb].transpose();
      }
    }
  }
  return rs;
}

// The state moved by the cameras' step dc and the points' step that follows from it
// (back-substitution: dp = V^-1 (-gp - W^T dc)).
State applyStep(const State& state, const NormalEquations& ne, const ReducedSystem& rs,
                const Eigen::VectorXd& dc, const Layout& layout,
                const std::vector<BundleObservation>& obs) {
  State next = state;
  for (size_t i = 0; i < layout.view_index.size(); ++i) {
    const int vi = layout.view_index[i];
    if (vi < 0) continue;
    const Eigen::Vector3d w = dc.segment<3>(6 * vi);
    const double angle = w.norm();
    const Eigen::Matrix3d dR = angle > 0 ? Eigen::AngleAxisd(angle, w / angle).toRotationMatrix()
                                         : Eigen::Matrix3d::Identity();
    next.cameras[i].R = dR * state.cameras[i].R;
    next.cameras[i].t = dR * state.cameras[i].t + dc.segment<3>(6 * vi + 3);
  }
  for (size_t j = 0; j < layout.point_index.size(); ++j) {
    const int pj = layout.point_index[j];
    if (pj < 0 || !rs.solvable[pj]) continue;
    Eigen::Vector3d rhs = -ne.gp[pj];
    for (int k : layout.of_point[j]) {
      const int vi = layout.view_index[obs[k].view];
      if (vi >= 0 && ne.used[k]) rhs -= ne.W[k].transpose() * dc.segment<6>(6 * vi);
    }
    next.points[j] = state.points[j] + rs.Vinv[pj] * rhs;
  }
  return next;
}

struct Steps {
  int tried = 0;
  int taken = 0;
  int refused_behind = 0;  // refused because they put a point behind a camera
};

// Levenberg-Marquardt at one Huber threshold: a step is taken when it lowers the cost
// (and the damping lessened), else the damping grows tenfold; it stops when a step gains
// less than 1e-6 of the cost. The cost and the equations hold the observations in front
// of their cameras as the round starts, and a step must keep them there: a point behind
// a camera projects as its mirror image, and a step that dropped its observation from
// the sum seemed to lower the cost (a landmark given at twice its depth, exact
// observations, was thrown 0.065 m behind all its cameras: test_local_bundle_adjustment).
Steps levenbergMarquardt(State& state, const std::vector<BundleObservation>& obs,
                         const Layout& layout, double focal, double delta,
                         int max_iterations) {
  const std::vector<bool> counted = inFront(state, obs);
  double current = *cost(state, obs, counted, focal, delta);
  double lambda = 1e-3;
  Steps steps;
  // The equations of the current state: a refused step changes only the damping, so
  // they are built again only after a step is taken.
  std::optional<NormalEquations> ne;
  while (steps.tried < max_iterations) {
    ++steps.tried;
    if (!ne) ne = normalEquations(state, obs, counted, layout, focal, delta);
    const ReducedSystem rs = reduceToCameras(*ne, layout, obs, lambda);
    Eigen::VectorXd dc = Eigen::VectorXd::Zero(rs.b.size());
    if (dc.size() > 0) dc = rs.S.ldlt().solve(rs.b);
    State next;
    std::optional<double> next_cost;
    if (dc.allFinite()) {
      next = applyStep(state, *ne, rs, dc, layout, obs);
      next_cost = cost(next, obs, counted, focal, delta);
      if (!next_cost) ++steps.refused_behind;
    }
    if (next_cost && std::isfinite(*next_cost) && *next_cost < current) {
      const bool converged = current - *next_cost < 1e-6 * current;
      state = std::move(next);
      ++steps.taken;
      ne.reset();
      current = *next_cost;
      lambda = std::max(1e-7, lambda / 10);
      if (converged) break;
    } else {
      lambda *= 10;
      // Damped this much the step is nil: no step lowers the cost (and further tens
      // would overflow the damping to infinity; review).
      if (lambda > 1e12) break;
    }
  }
  return steps;
}

void writeBack(const State& state, const Layout& layout, BundleProblem& problem) {
  for (size_t i = 0; i < problem.views.size(); ++i)
    if (layout.view_index[i] >= 0) problem.views[i].map_from_camera = poseOf(state.cameras[i]);
  for (size_t j = 0; j < problem.points.size(); ++j)
    if (layout.point_index[j] >= 0)
      problem.points[j].position =
          cv::Vec3d(state.points[j].x(), state.points[j].y(), state.points[j].z());
}

// Each observation's residual after the adjustment, and whether it is beyond the Huber
// threshold (its weight was low: the map disagrees with it).
void flagOutliers(const State& state, const std::vector<BundleObservation>& obs, double focal,
                  double delta, BundleResult& result) {
  result.outlier.assign(obs.size(), true);
  result.residual_px.assign(obs.size(), std::numeric_limits<double>::infinity());
  Eigen::Vector2d r;
  for (size_t k = 0; k < obs.size(); ++k) {
    if (residual(state, obs[k], focal, r))
      result.residual_px[k] = r.norm();
    else
      ++result.behind_after;
    result.outlier[k] = !(result.residual_px[k] <= delta);
  }
}

}  // namespace

BundleResult adjustBundle(BundleProblem& problem, const BundleOptions& options) {
  BundleResult result;
  result.reason = whyNot(problem, options);
  if (!result.reason.empty()) return result;
  const double f = options.focal_px;
  const auto& obs = problem.observations;
  State state = stateOf(problem);
  const Layout layout = layoutOf(problem);
  const std::optional<double> first_sigma = measureSigma(state, obs, f, options.min_sigma_px);
  if (!first_sigma) {
    result.reason = "too few observations in front of their cameras";
    return result;
  }
  result.initial_rms_px = inlierRms(state, obs, f, options.huber_sigmas * *first_sigma);
  for (bool in_front : inFront(state, obs)) result.behind_given += !in_front;
  // The Huber threshold in sigmas of the measured noise, measured again after a first
  // round: the disturbed poses' residuals overstate it (and let gross outliers pull).
  double sigma = *first_sigma;
  int taken = 0;
  for (int round = 0; round < 2; ++round) {
    if (round > 0)
      sigma = measureSigma(state, obs, f, options.min_sigma_px).value_or(options.min_sigma_px);
    const Steps steps = levenbergMarquardt(state, obs, layout, f, options.huber_sigmas * sigma,
                                           options.max_iterations);
    result.iterations += steps.tried;
    taken += steps.taken;
    result.refused_behind += steps.refused_behind;
  }
  const double delta = options.huber_sigmas * sigma;
  // Untouched when no step was taken (the poses' round trip through camera_from_map
  // would change them by rounding).
  if (taken > 0) writeBack(state, layout, problem);
  flagOutliers(state, obs, f, delta, result);
  result.sigma_px = sigma;
  // The rms of the residuals within the threshold, those flagOutliers measured.
  double sum = 0;
  int inliers = 0;
  for (size_t k = 0; k < obs.size(); ++k)
    if (!result.outlier[k]) {
      sum += result.residual_px[k] * result.residual_px[k];
      ++inliers;
    }
  result.final_rms_px = inliers > 0 ? std::sqrt(sum / inliers) : 0;
  result.ok = true;
  return result;
}

}  // namespace mono_plane_detection
