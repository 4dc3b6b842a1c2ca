#include "mono_plane_detection/geometry/homography_fit.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

namespace mono_plane_detection {
namespace {

// Similarity that moves the points' centroid to 0 and their mean distance to sqrt(2).
std::optional<Eigen::Matrix3d> normaliser(const std::vector<cv::Point2d>& p) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& q : p) mean += Eigen::Vector2d(q.x, q.y);
  mean /= static_cast<double>(p.size());
  double spread = 0.0;
  for (const auto& q : p) spread += (Eigen::Vector2d(q.x, q.y) - mean).norm();
  spread /= static_cast<double>(p.size());
  if (!(spread > 1e-12) || !std::isfinite(spread)) return std::nullopt;
  const double s = std::sqrt(2.0) / spread;
  Eigen::Matrix3d T;
  T << s, 0, -s * mean.x(), 0, s, -s * mean.y(), 0, 0, 1;
  return T;
}

// normaliser of both point sets in one pass each over the points: the same sums in the
// same order (the same result), but two independent chains of additions at a time
// instead of one (the refits' normalisers were a twentieth of the plane core at 1000
// points, bound by the additions' latency).
void normalisers(const std::vector<cv::Point2d>& p, const std::vector<cv::Point2d>& q,
                 std::optional<Eigen::Matrix3d>& tp, std::optional<Eigen::Matrix3d>& tq) {
  if (p.size() != q.size()) {
    tp = normaliser(p);
    tq = normaliser(q);
    return;
  }
  Eigen::Vector2d mean_p = Eigen::Vector2d::Zero(), mean_q = Eigen::Vector2d::Zero();
  for (size_t i = 0; i < p.size(); ++i) {
    mean_p += Eigen::Vector2d(p[i].x, p[i].y);
    mean_q += Eigen::Vector2d(q[i].x, q[i].y);
  }
  mean_p /= static_cast<double>(p.size());
  mean_q /= static_cast<double>(q.size());
  double spread_p = 0.0, spread_q = 0.0;
  for (size_t i = 0; i < p.size(); ++i) {
    spread_p += (Eigen::Vector2d(p[i].x, p[i].y) - mean_p).norm();
    spread_q += (Eigen::Vector2d(q[i].x, q[i].y) - mean_q).norm();
  }
  auto make = [](double spread, size_t n,
                 const Eigen::Vector2d& mean) -> std::optional<Eigen::Matrix3d> {
    spread /= static_cast<double>(n);
    if (!(spread > 1e-12) || !std::isfinite(spread)) return std::nullopt;
    const double s = std::sqrt(2.0) / spread;
    Eigen::Matrix3d T;
    T << s, 0, -s * mean.x(), 0, s, -s * mean.y(), 0, 0, 1;
    return T;
  };
  tp = make(spread_p, p.size(), mean_p);
  tq = make(spread_q, q.size(), mean_q);
}

using Matrix9d = Eigen::Matrix<double, 9, 9>;
using Vector9d = Eigen::Matrix<double, 9, 1>;

// The eigenvector of the full eigensolver, nothing when a second (near-)zero eigenvalue
// means the points do not fix H (e.g. collinear).
std::optional<Vector9d> eigensolverSmallest(const Matrix9d& normal) {
  const Eigen::SelfAdjointEigenSolver<Matrix9d> solver(normal);
  if (solver.info() != Eigen::Success) return std::nullopt;
  const auto& values = solver.eigenvalues();
  if (values(1) <= 1e-12 * std::max(1.0, values(8))) return std::nullopt;
  return Vector9d(solver.eigenvectors().col(0));
}

// The smallest eigenvector of the DLT's (positive semi-definite) normal matrix by inverse
// iteration (a few solves instead of the full eigensolver, which took a quarter of the
// plane stage's time), using the matrix's blocks
//   [ S0   0   -Sx ]
//   [ 0    S0  -Sy ]
//   [ -Sx  -Sy  Sr ]
// (S0, Sx, Sy, Sr symmetric 3x3): a solve eliminates the first two block rows with S0's
// factors (once) and solves the 3x3 Schur complement C = Sr - Sx S0^-1 Sx - Sy S0^-1 Sy,
// which holds the small eigenvalue: a few 3x3 products instead of the 9x9 LDLT and its
// triangular solves (the pilot's and the candidates' five-point fits, hundreds per image
// pair, were the largest single cost of the core: this is 2x faster than the pivoted 9x9
// LDLT it replaces, with the same eigenvector to the iteration's tolerance). When the
// smallest eigenvalue is not well separated from the next (a pivot of S0 or C besides the
// smallest close to zero: near-degenerate points) or the iteration does not settle, the
// eigensolver decides, with its degeneracy test.
std::optional<Vector9d> smallestEigenvectorOfBlocks(const Eigen::Matrix3d& s0,
                                                    const Eigen::Matrix3d& sx,
                                                    const Eigen::Matrix3d& sy,
                                                    const Eigen::Matrix3d& sr) {
  auto full = [&]() {
    Matrix9d normal = Matrix9d::Zero();
    normal.block<3, 3>(0, 0) = s0;
    normal.block<3, 3>(3, 3) = s0;
    normal.block<3, 3>(0, 6) = -sx;
    normal.block<3, 3>(6, 0) = -sx;
    normal.block<3, 3>(3, 6) = -sy;
    normal.block<3, 3>(6, 3) = -sy;
    normal.block<3, 3>(6, 6) = sr;
    return normal;
  };
  const double trace = 2.0 * s0.trace() + sr.trace();
  if (!(trace > 0.0) || !std::isfinite(trace)) return eigensolverSmallest(full());
  // The same tiny shift as smallestEigenvector's.
  const Eigen::Matrix3d shift = 1e-13 * trace * Eigen::Matrix3d::Identity();
  const Eigen::LDLT<Eigen::Matrix3d> f0(s0 + shift);
  if (f0.info() != Eigen::Success) return eigensolverSmallest(full());
  const Eigen::Matrix3d p = f0.solve(Eigen::Matrix3d::Identity());  // S0^-1
  const Eigen::Matrix3d psx = p * sx, psy = p * sy;
  const Eigen::Matrix3d c = sr + shift - sx * psx - sy * psy;
  const Eigen::LDLT<Eigen::Matrix3d> fc(c);
  if (fc.info() != Eigen::Success || !p.allFinite()) return eigensolverSmallest(full());
  Vector9d d;
  d << f0.vectorD().cwiseAbs(), f0.vectorD().cwiseAbs(), fc.vectorD().cwiseAbs();
  std::sort(d.data(), d.data() + 9);
  if (!(d(1) > 1e-6 * d(8))) return eigensolverSmallest(full());
  auto solve = [&](const Vector9d& b) {
    const Eigen::Vector3d t1 = p * b.segment<3>(0), t2 = p * b.segment<3>(3);
    const Eigen::Vector3d x3 = fc.solve(b.segment<3>(6) + sx * t1 + sy * t2);
    Vector9d x;
    x << t1 + psx * x3, t2 + psy * x3, x3;
    return x;
  };
  Vector9d x = Vector9d::Constant(1.0 / 3.0);
  for (int it = 0; it < 20; ++it) {
    Vector9d y = solve(x);
    const double norm = y.norm();
    if (!(norm > 0.0) || !std::isfinite(norm)) break;
    y /= norm;
    if (y.dot(x) < 0.0) y = -y;
    const double change = (y - x).norm();
    x = y;
    if (it > 0 && change < 1e-11) return x;
  }
  return eigensolverSmallest(full());
}

}  // namespace

std::optional<cv::Matx33d> fitHomography(const std::vector<cv::Point2d>& from,
                                         const std::vector<cv::Point2d>& to,
                                         const std::vector<double>& weights) {
  const size_t n = from.size();
  if (n < 4 || to.size() != n || (!weights.empty() && weights.size() != n)) return std::nullopt;
  std::optional<Eigen::Matrix3d> Tf, Tt;
  normalisers(from, to, Tf, Tt);
  if (!Tf || !Tt) return std::nullopt;

  // The normal matrix A^T W A summed over points. A point's two DLT rows are
  // (0, -a, b_y a) and (a, 0, -b_x a) (a, b homogeneous, third coordinate 1), so A^T W A
  // is made of four 3x3 sums of w a a^T (times 1, b_x, b_y, b_x^2 + b_y^2): a fifth of
  // the work of summing the 9x9 rank-2 updates (refits run on hundreds of points).
  // The normalisers are similarities (scale s, shift t): a = (s x + t_x, s y + t_y, 1).
  // w a a^T is symmetric: its 6 distinct entries (xx, xy, x, yy, y, 1) are summed, each
  // times 1, b_x, b_y and |b|^2 (refits run on hundreds of points).
  const double fs = (*Tf)(0, 0), ftx = (*Tf)(0, 2), fty = (*Tf)(1, 2);
  const double ts = (*Tt)(0, 0), ttx = (*Tt)(0, 2), tty = (*Tt)(1, 2);
  // The sums two at a time (pairs of e) in 12 accumulators that stay in registers, each
  // entry summed in point order: the same sums as the 4 x 6 array's, which GCC kept in
  // memory one entry at a time (the refits' sums were most of fitHomography's time at
  // 1000 points).
  typedef double Pair __attribute__((vector_size(16)));
  Pair sum[4][3] = {};
  for (size_t i = 0; i < n; ++i) {
    const double ax = fs * from[i].x + ftx, ay = fs * from[i].y + fty;
    const double bx = ts * to[i].x + ttx, by = ts * to[i].y + tty;
    const double w = weights.empty() ? 1.0 : weights[i];
    const Pair m[3] = {Pair{w * ax * ax, w * ax * ay}, Pair{w * ax, w * ay * ay}, Pair{w * ay, w}};
    const double f[4] = {1.0, bx, by, bx * bx + by * by};
    for (int k = 0; k < 4; ++k) {
      const Pair fk = {f[k], f[k]};
      for (int e = 0; e < 3; ++e) sum[k][e] += fk * m[e];
    }
  }
  double acc[4][6];
  for (int k = 0; k < 4; ++k)
    for (int e = 0; e < 3; ++e) {
      acc[k][2 * e] = sum[k][e][0];
      acc[k][2 * e + 1] = sum[k][e][1];
    }
  auto block = [&acc](int k) {
    const double* q = acc[k];
    Eigen::Matrix3d b;
    b << q[0], q[1], q[2], q[1], q[3], q[4], q[2], q[4], q[5];
    return b;
  };
  const Eigen::Matrix3d s0 = block(0), sx = block(1), sy = block(2), sr = block(3);
  const auto smallest = smallestEigenvectorOfBlocks(s0, sx, sy, sr);
  if (!smallest) return std::nullopt;
  const Eigen::Matrix<double, 9, 1>& h = *smallest;
  Eigen::Matrix3d Hn;
  Hn << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), h(8);
  Eigen::Matrix3d H = Tt->inverse() * Hn * *Tf;
  if (std::abs(H(2, 2)) > 1e-15) H /= H(2, 2);
  if (!H.allFinite()) return std::nullopt;
  cv::Matx33d out;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out(r, c) = H(r, c);
  return out;
}

}  // namespace mono_plane_detection
