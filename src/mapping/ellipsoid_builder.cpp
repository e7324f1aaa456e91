#include "ellreloc/mapping/ellipsoid_builder.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <functional>
#include <limits>

#include "ellreloc/core/statistics.hpp"

namespace ellreloc {

namespace {

/// The `m` smallest of `values` by `before` (the m largest with std::greater), in order, m <= M.
template <size_t M, class Before>
std::array<double, M> fewFirst(const std::vector<double>& values, size_t m, Before before) {
  std::array<double, M> kept{};
  size_t count = 0;
  for (const double x : values) {
    if (count == m && !before(x, kept[m - 1])) continue;
    size_t at = count < m ? count++ : m - 1;  // the last kept value makes room
    for (; at > 0 && before(x, kept[at - 1]); --at) kept[at] = kept[at - 1];
    kept[at] = x;
  }
  return kept;
}

/// The percentile rectangle of ground-plane points along `main` and across it (lo, hi in
/// (along, across) coordinates); `along` and `across` receive every point's coordinates.
void percentileRectangle(const std::vector<Eigen::Vector2d>& ground, const Eigen::Vector2d& main, double low,
                         double high, std::vector<double>* along, std::vector<double>* across, Eigen::Vector2d* lo,
                         Eigen::Vector2d* hi) {
  const Eigen::Vector2d side(-main.y(), main.x());
  along->resize(ground.size());
  across->resize(ground.size());
  for (size_t i = 0; i < ground.size(); ++i) (*along)[i] = main.dot(ground[i]), (*across)[i] = side.dot(ground[i]);
  thread_local std::vector<double> scratch;
  const auto [along_lo, along_hi] = detail::quantilePair(*along, low, high, &scratch);
  const auto [across_lo, across_hi] = detail::quantilePair(*across, low, high, &scratch);
  *lo = Eigen::Vector2d(along_lo, across_lo);
  *hi = Eigen::Vector2d(along_hi, across_hi);
}

/// The direction of the longer side of the smallest percentile rectangle of 2D points (the
/// rectangle percentileRectangle() gives, the extents the cuboid takes) within `reach` radians
/// of `start`: a sweep in 1 degree steps, then a golden-section search around its best. At most
/// `max_points` points (every k-th) are used: it runs at each update of an object.
Eigen::Vector2d smallestPercentileRectangleNear(const std::vector<Eigen::Vector2d>& points,
                                                const Eigen::Vector2d& start, double reach, double low, double high,
                                                size_t max_points) {
  const size_t stride = std::max<size_t>(1, (points.size() + max_points - 1) / max_points);
  std::vector<Eigen::Vector2d> p;
  for (size_t i = 0; i < points.size(); i += stride) p.push_back(points[i]);
  std::vector<double> along, across;
  Eigen::Vector2d lo, hi;
  const auto direction = [](double t) { return Eigen::Vector2d(std::cos(t), std::sin(t)); };
  const auto area = [&](double t) {
    percentileRectangle(p, direction(t), low, high, &along, &across, &lo, &hi);
    return (hi - lo).prod();
  };
  constexpr double kStep = M_PI / 180.0;
  const double t0 = std::atan2(start.y(), start.x());
  const int steps = static_cast<int>(std::ceil(reach / kStep));
  double best_t = t0, best_area = area(t0);
  for (int i = -steps; i <= steps; ++i) {
    if (i == 0) continue;  // t0, above
    if (const double a = area(t0 + i * kStep); a < best_area) best_area = a, best_t = t0 + i * kStep;
  }
  const double ratio = 0.5 * (std::sqrt(5.0) - 1.0);
  double a = best_t - kStep, b = best_t + kStep;
  double c = b - ratio * (b - a), d = a + ratio * (b - a), fc = area(c), fd = area(d);
  while (b - a > 1e-6) {
    if (fc < fd) {
      b = d, d = c, fd = fc, c = b - ratio * (b - a), fc = area(c);
    } else {
      a = c, c = d, fc = fd, d = a + ratio * (b - a), fd = area(d);
    }
  }
  const double t = std::min(fc, fd) < best_area ? 0.5 * (a + b) : best_t;
  percentileRectangle(p, direction(t), low, high, &along, &across, &lo, &hi);
  const Eigen::Vector2d u = direction(t);
  return (hi - lo).x() >= (hi - lo).y() ? u : Eigen::Vector2d(-u.y(), u.x());
}

}  // namespace

namespace detail {

// The yaw search takes thousands of quantile pairs per object, of the 1st and 99th percentiles
// of at most 512 values: near the ends one pass keeps the few smallest and largest values;
// elsewhere a copy in `scratch` is reordered.
std::pair<double, double> quantilePair(const std::vector<double>& values, double low, double high,
                                       std::vector<double>* scratch) {
  if (values.empty()) return {0.0, 0.0};
  const size_t n = values.size();
  // The q-quantile interpolates between the k-th and (k+1)-th smallest values, k = floor(q (n - 1)).
  const double pos_low = std::clamp(low, 0.0, 1.0) * static_cast<double>(n - 1);
  const double pos_high = std::clamp(high, 0.0, 1.0) * static_cast<double>(n - 1);
  const size_t k_low = static_cast<size_t>(pos_low), k_high = static_cast<size_t>(pos_high);
  const auto between = [](double pos, size_t k, double a, double b) {
    return a + (pos - static_cast<double>(k)) * (b - a);
  };
  constexpr size_t kFew = 16;
  if (n > 2 * kFew && k_low + 2 <= kFew && n - k_high <= kFew && k_low <= k_high) {
    const auto smallest = fewFirst<kFew>(values, k_low + 2, std::less<double>());
    const size_t from_top = n - 1 - k_high;  // the k_high-th smallest is the from_top-th largest
    const auto largest = fewFirst<kFew>(values, from_top + 1, std::greater<double>());
    const double high_next = from_top > 0 ? largest[from_top - 1] : largest[from_top];
    return {between(pos_low, k_low, smallest[k_low], smallest[k_low + 1]),
            between(pos_high, k_high, largest[from_top], high_next)};
  }
  std::vector<double>& v = *scratch;
  v.assign(values.begin(), values.end());
  const auto at = [&](double pos, size_t k, size_t from) {
    std::nth_element(v.begin() + static_cast<long>(from), v.begin() + static_cast<long>(k), v.end());
    if (k + 1 >= n) return v[k];
    return between(pos, k, v[k], *std::min_element(v.begin() + static_cast<long>(k) + 1, v.end()));
  };
  const double q_low = at(pos_low, k_low, 0);
  // Everything after the low quantile's k-th value is at least it: a higher quantile's k-th
  // value is among them.
  return {q_low, at(pos_high, k_high, k_high >= k_low ? k_low : 0)};
}

/// The direction of the longer side of the smallest-area rectangle enclosing 2D points: the
/// rectangle has a side on an edge of the convex hull, so each hull edge is tried.
std::optional<Eigen::Vector2d> minAreaRectangleAxis(std::vector<Eigen::Vector2d> p) {
  if (p.size() < 3) return std::nullopt;
  // Points well inside the quadrilateral of the leftmost, lowest, rightmost and highest points
  // are inside the hull: they are dropped before the sort (Akl and Toussaint), which leaves a
  // few percent of a footprint's thousands of points.
  const auto by = [&](int axis, bool least) {
    return *std::min_element(p.begin(), p.end(), [&](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
      return least ? a(axis) < b(axis) : a(axis) > b(axis);
    });
  };
  const std::array<Eigen::Vector2d, 4> quad = {by(0, true), by(1, true), by(0, false), by(1, false)};
  const double margin = 1e-9 * (quad[2].x() - quad[0].x() + quad[3].y() - quad[1].y()) *
                        (quad[2].x() - quad[0].x() + quad[3].y() - quad[1].y());
  const auto wellInside = [&](const Eigen::Vector2d& q) {
    for (int i = 0; i < 4; ++i) {
      const Eigen::Vector2d e = quad[(i + 1) % 4] - quad[i], d = q - quad[i];
      if (!(e.x() * d.y() - e.y() * d.x() > margin)) return false;  // counter-clockwise: inside is left
    }
    return true;
  };
  p.erase(std::remove_if(p.begin(), p.end(), wellInside), p.end());
  std::sort(p.begin(), p.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  if (p.size() < 3) return std::nullopt;
  const auto cross = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return (a - o).x() * (b - o).y() - (a - o).y() * (b - o).x();
  };
  std::vector<Eigen::Vector2d> hull(2 * p.size());  // Andrew's monotone chain
  size_t k = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], p[i]) <= 0) --k;
    hull[k++] = p[i];
  }
  for (size_t i = p.size() - 1, t = k + 1; i > 0; --i) {
    while (k >= t && cross(hull[k - 2], hull[k - 1], p[i - 1]) <= 0) --k;
    hull[k++] = p[i - 1];
  }
  hull.resize(k - 1);
  if (hull.size() < 3) return std::nullopt;
  double best_area = std::numeric_limits<double>::infinity();
  Eigen::Vector2d best = Eigen::Vector2d::UnitX();
  for (size_t i = 0; i < hull.size(); ++i) {
    const Eigen::Vector2d e = hull[(i + 1) % hull.size()] - hull[i];
    if (!(e.norm() > 0.0)) continue;
    const Eigen::Vector2d u = e.normalized(), v(-u.y(), u.x());
    double u_lo = 1e300, u_hi = -1e300, v_lo = 1e300, v_hi = -1e300;
    for (const Eigen::Vector2d& q : hull) {
      u_lo = std::min(u_lo, u.dot(q)), u_hi = std::max(u_hi, u.dot(q));
      v_lo = std::min(v_lo, v.dot(q)), v_hi = std::max(v_hi, v.dot(q));
    }
    const double area = (u_hi - u_lo) * (v_hi - v_lo);
    if (area < best_area) best_area = area, best = (u_hi - u_lo) >= (v_hi - v_lo) ? u : v;
  }
  return best;
}

}  // namespace detail

/// Builds the yaw-only cuboid and its inscribed ellipsoid from an object's points
/// (world coordinates). nullopt with fewer than options.min_points points, a zero or
/// non-finite `up`, or a degenerate (flat) point set.
std::optional<BuiltEllipsoid> buildEllipsoid(const std::vector<Eigen::Vector3d>& points,
                                             const EllipsoidBuilderOptions& options) {
  if (points.size() < std::max<size_t>(options.min_points, 4) || !options.up.allFinite() ||
      !(options.up.norm() > 1e-12))
    return std::nullopt;
  const Eigen::Matrix3d B = groundBasis(options.up);

  // PCA of the ground-plane projections: the main axis gives the yaw. PCA weighs far points
  // heavily, so it runs twice: on all points, then on those inside the percentile cuboid of
  // the first pass (a trimmed PCA).
  std::vector<Eigen::Vector2d> ground(points.size());
  std::vector<double> heights(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    ground[i] = B.leftCols<2>().transpose() * points[i];
    heights[i] = B.col(2).dot(points[i]);
  }
  std::vector<char> inlier(points.size(), 1);
  Eigen::Vector2d main, lo, hi;
  std::vector<double> along, across;
  for (int pass = 0; pass < 2; ++pass) {
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    double n = 0.0;
    for (size_t i = 0; i < ground.size(); ++i)
      if (inlier[i]) mean += ground[i], n += 1.0;
    if (n < 4.0) return std::nullopt;
    mean /= n;
    Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
    for (size_t i = 0; i < ground.size(); ++i)
      if (inlier[i]) cov += (ground[i] - mean) * (ground[i] - mean).transpose();
    if (!cov.allFinite()) return std::nullopt;
    main = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(cov).eigenvectors().col(1);  // largest eigenvalue
    percentileRectangle(ground, main, options.low_percentile, options.high_percentile, &along, &across, &lo, &hi);
    for (size_t i = 0; i < ground.size(); ++i)
      inlier[i] = along[i] >= lo.x() && along[i] <= hi.x() && across[i] >= lo.y() && across[i] <= hi.y();
  }
  if (options.yaw == YawMethod::MinAreaRectangle) {
    std::vector<Eigen::Vector2d> footprint;
    for (size_t i = 0; i < ground.size(); ++i)
      if (inlier[i]) footprint.push_back(ground[i]);
    const auto axis = detail::minAreaRectangleAxis(footprint);
    if (!axis) return std::nullopt;
    // The hull's rectangle rests on the outermost points, which a few stray voxels set; the
    // yaw is polished to the smallest percentile rectangle within 4 degrees of it. A wider
    // search can fall to the diagonal of a box seen on two faces only (an L-shaped footprint),
    // whose percentile rectangle is as small as the true one.
    main = smallestPercentileRectangleNear(footprint, *axis, 4.0 * M_PI / 180.0, options.low_percentile,
                                           options.high_percentile, 512);
    percentileRectangle(ground, main, options.low_percentile, options.high_percentile, &along, &across, &lo, &hi);
  }
  const double yaw = std::atan2(main.y(), main.x());

  Cuboid cuboid;  // axes: the main ground axis, the other ground axis, up
  cuboid.rotation.col(0) = B.leftCols<2>() * main;
  cuboid.rotation.col(2) = B.col(2);
  cuboid.rotation.col(1) = cuboid.rotation.col(2).cross(cuboid.rotation.col(0));
  const double h_lo = interpolatedQuantile(heights, options.low_percentile);
  const double h_hi = interpolatedQuantile(heights, options.high_percentile);
  const Eigen::Vector3d local_lo(lo.x(), lo.y(), h_lo), local_hi(hi.x(), hi.y(), h_hi);
  // The second pass's percentiles are of all points in its final frame: outliers stay out.
  cuboid.half = 0.5 * (local_hi - local_lo) + Eigen::Vector3d::Constant(options.extent_padding);
  const Eigen::Vector3d local_center = 0.5 * (local_lo + local_hi);
  // local coordinates are (main, side, up) in the basis B; side = up x main matches col(1).
  if (!(cuboid.half.minCoeff() > 0.0) || !cuboid.half.allFinite()) return std::nullopt;
  cuboid.center = cuboid.rotation * local_center;
  BuiltEllipsoid out;
  out.cuboid = cuboid;
  out.ellipsoid = cuboid.inscribedEllipsoid();
  out.yaw = yaw;
  return out;
}

}  // namespace ellreloc
