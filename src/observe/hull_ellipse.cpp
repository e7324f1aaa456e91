#include <algorithm>
#include <cmath>

#include "ellreloc/observe/ellipse_fit.hpp"
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
