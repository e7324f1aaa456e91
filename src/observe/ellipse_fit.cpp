#include "ellreloc/observe/ellipse_fit.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "polygon.hpp"

namespace ellreloc {

namespace {

using polygon::Point;

/// Area, centroid and covariance of a uniform convex polygon (a fan of triangles about its
/// first vertex).
struct PolygonMoments {
  double area = 0.0;
  Point mean = Point::Zero();
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
};

PolygonMoments polygonMoments(const std::vector<Point>& p) {
  PolygonMoments m;
  const Point o = p[0];
  Eigen::Vector2d first = Eigen::Vector2d::Zero();
  Eigen::Matrix2d second = Eigen::Matrix2d::Zero();
  double signed_area = 0.0;
  for (size_t i = 1; i + 1 < p.size(); ++i) {
    const Point a = p[i] - o, b = p[i + 1] - o;
    const double t = 0.5 * (a(0) * b(1) - a(1) * b(0));  // the triangle (o, a, b)
    signed_area += t;
    first += t * (a + b) / 3.0;
    second += t / 12.0 * (a * a.transpose() + b * b.transpose() + (a + b) * (a + b).transpose());
  }
  if (!(std::abs(signed_area) > 0.0)) return m;
  m.area = std::abs(signed_area);
  const Point mean = first / signed_area;
  m.mean = o + mean;
  m.covariance = second / signed_area - mean * mean.transpose();
  return m;
}

}  // namespace

std::optional<Ellipse> fitEllipseDirect(const std::vector<Eigen::Vector2d>& points) {
  const size_t n = points.size();
  if (n < 5) return std::nullopt;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : points) mean += p;
  mean /= static_cast<double>(n);
  double spread = 0.0;
  for (const auto& p : points) spread += (p - mean).squaredNorm();
  const double scale = std::sqrt(spread / static_cast<double>(n));  // RMS distance to the mean
  if (!(scale > 0.0) || !std::isfinite(scale)) return std::nullopt;
  // The scatter matrices of D1 = [x^2, xy, y^2] and D2 = [x, y, 1] only need the 15 monomial
  // sums x^i y^j, i + j <= 4.
  double s40 = 0, s31 = 0, s22 = 0, s13 = 0, s04 = 0, s30 = 0, s21 = 0, s12 = 0, s03 = 0, s20 = 0, s11 = 0, s02 = 0,
         s10 = 0, s01 = 0;
  const double inv = 1.0 / scale;
  for (const auto& p : points) {
    const double x = (p(0) - mean(0)) * inv, y = (p(1) - mean(1)) * inv;
    const double xx = x * x, xy = x * y, yy = y * y;
    s40 += xx * xx, s31 += xx * xy, s22 += xx * yy, s13 += xy * yy, s04 += yy * yy;
    s30 += xx * x, s21 += xx * y, s12 += x * yy, s03 += yy * y;
    s20 += xx, s11 += xy, s02 += yy, s10 += x, s01 += y;
  }
  Eigen::Matrix3d S1, S2, S3;
  S1 << s40, s31, s22, s31, s22, s13, s22, s13, s04;
  S2 << s30, s21, s20, s21, s12, s11, s12, s03, s02;
  S3 << s20, s11, s10, s11, s02, s01, s10, s01, static_cast<double>(n);
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(S3);
  if (!lu.isInvertible()) return std::nullopt;
  const Eigen::Matrix3d T = -lu.solve(S2.transpose());  // a2 = T a1
  const Eigen::Matrix3d M = S1 + S2 * T;
  // Premultiply by C1^-1 = [[0, 0, 1/2], [0, -1, 0], [1/2, 0, 0]].
  Eigen::Matrix3d Mc;
  Mc.row(0) = 0.5 * M.row(2);
  Mc.row(1) = -M.row(1);
  Mc.row(2) = 0.5 * M.row(0);
  const Eigen::EigenSolver<Eigen::Matrix3d> eig(Mc);
  if (eig.info() != Eigen::Success) return std::nullopt;
  // The ellipse is the eigenvector with 4ac - b^2 > 0 (exactly one for a proper fit).
  int best = -1;
  double best_cond = 0.0;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d v = eig.eigenvectors().col(k).real();
    const double cond = 4.0 * v(0) * v(2) - v(1) * v(1);
    if (cond > best_cond) best = k, best_cond = cond;
  }
  if (best < 0) return std::nullopt;
  const Eigen::Vector3d a1 = eig.eigenvectors().col(best).real();
  const Eigen::Vector3d a2 = T * a1;
  // Conic in normalised coordinates; map back with q = (p - mean) / scale.
  Eigen::Matrix3d A;
  A << a1(0), a1(1) / 2, a2(0) / 2, a1(1) / 2, a1(2), a2(1) / 2, a2(0) / 2, a2(1) / 2, a2(2);
  Eigen::Matrix3d H;  // q = H p (homogeneous)
  H << 1.0 / scale, 0, -mean(0) / scale, 0, 1.0 / scale, -mean(1) / scale, 0, 0, 1;
  const Eigen::Matrix3d A_img = H.transpose() * A * H;
  const Eigen::FullPivLU<Eigen::Matrix3d> lu_a(A_img);
  if (!lu_a.isInvertible()) return std::nullopt;
  return Ellipse::fromDualConic(lu_a.inverse());
}

std::optional<Ellipse> projectivelyInscribedEllipse(const std::array<Eigen::Vector2d, 4>& q) {
  const Eigen::Vector2d src[4] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  // DLT with h33 = 1: 8 equations.
  Eigen::Matrix<double, 8, 8> A;
  Eigen::Matrix<double, 8, 1> b;
  for (int i = 0; i < 4; ++i) {
    const double x = src[i](0), y = src[i](1), u = q[i](0), v = q[i](1);
    A.row(2 * i) << x, y, 1, 0, 0, 0, -u * x, -u * y;
    A.row(2 * i + 1) << 0, 0, 0, x, y, 1, -v * x, -v * y;
    b(2 * i) = u;
    b(2 * i + 1) = v;
  }
  const Eigen::FullPivLU<Eigen::Matrix<double, 8, 8>> lu(A);
  if (!lu.isInvertible()) return std::nullopt;
  const Eigen::Matrix<double, 8, 1> h = lu.solve(b);
  if (!h.allFinite()) return std::nullopt;
  Eigen::Matrix3d H;
  H << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), 1.0;
  // The square must stay in front of the "camera" of H: w > 0 at all corners (convex image).
  for (const auto& s : src)
    if (!(H.row(2).dot(Eigen::Vector3d(s(0), s(1), 1.0)) > 0.0)) return std::nullopt;
  const Eigen::Matrix3d C = H * Eigen::Vector3d(1, 1, -1).asDiagonal() * H.transpose();
  return Ellipse::fromDualConic(C);
}

std::optional<Ellipse> hullEllipse(const std::vector<Eigen::Vector2d>& hull) {
  if (hull.size() < 3) return std::nullopt;
  const PolygonMoments moments = polygonMoments(hull);
  if (!(moments.area > 0.0)) return std::nullopt;
  const Eigen::Matrix2d round_shape = 4.0 * moments.covariance;

  // The box model: six corners, consecutive sides within 10 degrees of each other merged into
  // one: a side the reduction split (noise along a straight edge). Two edges of a box whose
  // images are that close to parallel are merged too: a silhouette cannot tell them apart.
  const double kParallel = std::cos(10.0 * M_PI / 180.0);
  const auto parallel = [kParallel](const Point& a, const Point& b) {
    return a.dot(b) > kParallel * a.norm() * b.norm();
  };
  const std::vector<Point> corners = polygon::reduceTo(hull, 6);
  std::vector<Point> sides;
  for (size_t i = 0; i < corners.size(); ++i) {
    const Point side = corners[(i + 1) % corners.size()] - corners[i];
    if (!sides.empty() && parallel(side, sides.back()))
      sides.back() += side;
    else
      sides.push_back(side);
  }
  if (sides.size() > 2 && parallel(sides.front(), sides.back())) {
    sides.front() += sides.back();
    sides.pop_back();
  }
  double box_weight = 0.0;
  Eigen::Matrix2d box_shape = Eigen::Matrix2d::Zero();
  if (sides.size() >= 4) {  // a triangle is no box's silhouette
    for (const Point& s : sides) box_shape += s * s.transpose() / 8.0;
    // The best hexagon in an ellipse keeps 3 sqrt(3) / (2 pi) of its area; six corners keep all
    // of a box's silhouette.
    const double kept_by_ellipse = 3.0 * std::sqrt(3.0) / (2.0 * M_PI);
    const double kept = polygon::polygonArea(corners) / moments.area;
    box_weight = std::clamp((kept - kept_by_ellipse) / (1.0 - kept_by_ellipse), 0.0, 1.0);
  }
  const Eigen::Matrix2d shape = box_weight * box_shape + (1.0 - box_weight) * round_shape;
  return Ellipse::fromGaussian(moments.mean, shape);
}

}  // namespace ellreloc
