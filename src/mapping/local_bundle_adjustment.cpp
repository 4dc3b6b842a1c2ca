#include "mono_plane_detection/mapping/local_bundle_adjustment.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/core/eigen.hpp>

#include "mono_plane_detection/geometry/stats.h"

namespace mono_plane_detection {
namespace {

using Mat36 = Eigen::Matrix<double, 3, 6>;
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

struct State {
  std::vector<Camera> cameras;
  std::vector<Eigen::Vector3d> points;
};

// The residual of one observation in pixels; false when the point is not in front.
bool residual(const State& s, const BundleObservation& o, double focal, Eigen::Vector2d& r,
              Eigen::Vector3d* in_camera = nullptr) {
  const Camera& c = s.cameras[o.view];
  const Eigen::Vector3d x = c.R * s.points[o.point] + c.t;
  if (!(x.z() > 1e-9)) return false;
  r = focal * Eigen::Vector2d(x.x() / x.z() - o.normalized.x, x.y() / x.z() - o.normalized.y);
  if (in_camera) *in_camera = x;
  return true;
}

double huberCost(double e, double delta) {
  return e <= delta ? e * e : 2 * delta * e - delta * delta;
}

double cost(const State& s, const std::vector<BundleObservation>& obs, double focal, double delta) {
  double sum = 0;
  Eigen::Vector2d r;
  for (const BundleObservation& o : obs)
    if (residual(s, o, focal, r)) sum += huberCost(r.norm(), delta);
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

}  // namespace

BundleResult adjustBundle(BundleProblem& problem, const BundleOptions& options) {
  BundleResult result;
  const double f = options.focal_px;
  const auto& obs = problem.observations;
  State state;
  for (const BundleView& v : problem.views) state.cameras.push_back(cameraOf(v.map_from_camera));
  for (const BundlePoint& p : problem.points)
    state.points.emplace_back(p.position[0], p.position[1], p.position[2]);
  for (const BundleObservation& o : obs)
    if (o.view < 0 || o.view >= static_cast<int>(problem.views.size()) || o.point < 0 ||
        o.point >= static_cast<int>(problem.points.size())) {
      result.reason = "an observation names no view or point";
      return result;
    }
  // Free views and points, numbered.
  std::vector<int> view_index(problem.views.size(), -1), point_index(problem.points.size(), -1);
  int free_views = 0, free_points = 0;
  for (size_t i = 0; i < problem.views.size(); ++i)
    if (!problem.views[i].fixed) view_index[i] = free_views++;
  for (size_t j = 0; j < problem.points.size(); ++j)
    if (!problem.points[j].fixed) point_index[j] = free_points++;
  std::vector<std::vector<int>> of_point(problem.points.size());
  for (size_t k = 0; k < obs.size(); ++k) of_point[obs[k].point].push_back(static_cast<int>(k));

  // The observations' noise, measured (median residual norm over its value for a 2D
  // Gaussian, sqrt(2 ln 2) sigma), sets the Huber threshold: pixels mean different
  // things on different cameras and trackers. Measured again after a first round: the
  // disturbed poses' residuals overstate it (and let gross outliers pull).
  Eigen::Vector2d r;
  auto measureSigma = [&]() {
    std::vector<double> norms;
    for (const BundleObservation& o : obs)
      if (residual(state, o, f, r)) norms.push_back(r.norm());
    return norms.size() < 6 ? -1.0 : std::max(options.min_sigma_px, median(norms) / 1.1774);
  };
  double sigma = measureSigma();
  if (sigma < 0) {
    result.reason = "too few observations in front of their cameras";
    return result;
  }
  result.sigma_px = sigma;
  result.initial_rms_px = inlierRms(state, obs, f, options.huber_sigmas * sigma);
  const int n = 6 * free_views;
  double delta = 0;
  for (int round = 0; round < 2; ++round) {
    if (round > 0) sigma = std::max(measureSigma(), options.min_sigma_px);
    delta = options.huber_sigmas * sigma;
    double current = cost(state, obs, f, delta);
    double lambda = 1e-3;
    for (int it = 0; it < options.max_iterations; ++it) {
      ++result.iterations;
      // Normal equations J^T W J, J^T W r per block.
      std::vector<Mat66> U(free_views, Mat66::Zero());
      std::vector<Vec6> gc(free_views, Vec6::Zero());
      std::vector<Eigen::Matrix3d> V(free_points, Eigen::Matrix3d::Zero());
      std::vector<Eigen::Vector3d> gp(free_points, Eigen::Vector3d::Zero());
      std::vector<Mat63> W(obs.size(), Mat63::Zero());
      std::vector<bool> used(obs.size(), false);
      for (size_t k = 0; k < obs.size(); ++k) {
        const BundleObservation& o = obs[k];
        const int vi = view_index[o.view], pj = point_index[o.point];
        Eigen::Vector3d x;
        if ((vi < 0 && pj < 0) || !residual(state, o, f, r, &x)) continue;
        const double e = r.norm();
        const double w = e <= delta ? 1.0 : delta / e;
        Mat23 P;
        P << 1 / x.z(), 0, -x.x() / (x.z() * x.z()), 0, 1 / x.z(), -x.y() / (x.z() * x.z());
        P *= f;
        used[k] = true;
        Mat26 Jc;
        if (vi >= 0) {
          Jc.leftCols<3>() = -P * skew(x);
          Jc.rightCols<3>() = P;
          U[vi] += w * Jc.transpose() * Jc;
          gc[vi] += w * Jc.transpose() * r;
        }
        if (pj >= 0) {
          const Mat23 Jp = P * state.cameras[o.view].R;
          V[pj] += w * Jp.transpose() * Jp;
          gp[pj] += w * Jp.transpose() * r;
          if (vi >= 0) W[k] = w * Jc.transpose() * Jp;
        }
      }
      // Damped, points eliminated: (U - W V^-1 W^T) dc = -gc + W V^-1 gp.
      Eigen::MatrixXd S = Eigen::MatrixXd::Zero(n, n);
      Eigen::VectorXd b = Eigen::VectorXd::Zero(n);
      for (int i = 0; i < free_views; ++i) {
        Mat66 u = U[i];
        u.diagonal() *= 1 + lambda;
        u.diagonal().array() += 1e-9;
        S.block<6, 6>(6 * i, 6 * i) = u;
        b.segment<6>(6 * i) = -gc[i];
      }
      std::vector<Eigen::Matrix3d> Vinv(free_points, Eigen::Matrix3d::Zero());
      std::vector<bool> solvable(free_points, false);
      for (size_t j = 0; j < problem.points.size(); ++j) {
        const int pj = point_index[j];
        if (pj < 0) continue;
        Eigen::Matrix3d v = V[pj];
        v.diagonal() *= 1 + lambda;
        v.diagonal().array() += 1e-9 * (1 + v.trace());
        Eigen::FullPivLU<Eigen::Matrix3d> lu(v);
        if (!lu.isInvertible()) continue;
        solvable[pj] = true;
        Vinv[pj] = lu.inverse();
        for (int ka : of_point[j]) {
          const int va = view_index[obs[ka].view];
          if (va < 0 || !used[ka]) continue;
          const Mat63 WV = W[ka] * Vinv[pj];
          b.segment<6>(6 * va) += WV * gp[pj];
          for (int kb : of_point[j]) {
            const int vb = view_index[obs[kb].view];
            if (vb < 0 || !used[kb]) continue;
            S.block<6, 6>(6 * va, 6 * vb) -= WV * W[kb].transpose();
          }
        }
      }
      Eigen::VectorXd dc = Eigen::VectorXd::Zero(n);
      if (n > 0) dc = S.ldlt().solve(b);
      if (!dc.allFinite()) {
        lambda *= 10;
        continue;
      }
      State next = state;
      for (size_t i = 0; i < problem.views.size(); ++i) {
        const int vi = view_index[i];
        if (vi < 0) continue;
        const Eigen::Vector3d w = dc.segment<3>(6 * vi);
        const double angle = w.norm();
        const Eigen::Matrix3d dR = angle > 0
                                       ? Eigen::AngleAxisd(angle, w / angle).toRotationMatrix()
                                       : Eigen::Matrix3d::Identity();
        next.cameras[i].R = dR * state.cameras[i].R;
        next.cameras[i].t = dR * state.cameras[i].t + dc.segment<3>(6 * vi + 3);
      }
      for (size_t j = 0; j < problem.points.size(); ++j) {
        const int pj = point_index[j];
        if (pj < 0 || !solvable[pj]) continue;
        Eigen::Vector3d rhs = -gp[pj];
        for (int k : of_point[j]) {
          const int vi = view_index[obs[k].view];
          if (vi >= 0 && used[k]) rhs -= W[k].transpose() * dc.segment<6>(6 * vi);
        }
        next.points[j] = state.points[j] + Vinv[pj] * rhs;
      }
      const double next_cost = cost(next, obs, f, delta);
      if (std::isfinite(next_cost) && next_cost < current) {
        const bool converged = current - next_cost < 1e-6 * current;
        state = std::move(next);
        current = next_cost;
        lambda = std::max(1e-7, lambda / 10);
        if (converged) break;
      } else {
        lambda *= 10;
      }
    }
  }
  for (size_t i = 0; i < problem.views.size(); ++i)
    if (view_index[i] >= 0) problem.views[i].map_from_camera = poseOf(state.cameras[i]);
  for (size_t j = 0; j < problem.points.size(); ++j)
    if (point_index[j] >= 0)
      problem.points[j].position =
          cv::Vec3d(state.points[j].x(), state.points[j].y(), state.points[j].z());
  result.outlier.assign(obs.size(), true);
  result.residual_px.assign(obs.size(), std::numeric_limits<double>::infinity());
  for (size_t k = 0; k < obs.size(); ++k) {
    if (residual(state, obs[k], f, r)) result.residual_px[k] = r.norm();
    result.outlier[k] = !(result.residual_px[k] <= delta);
  }
  result.sigma_px = sigma;
  result.final_rms_px = inlierRms(state, obs, f, delta);
  result.ok = true;
  return result;
}

}  // namespace mono_plane_detection
