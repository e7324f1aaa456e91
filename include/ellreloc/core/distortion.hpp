#pragma once
/// \file distortion.hpp
/// Lens distortion of a raw image: the radial-tangential (Brown-Conrady) model of OpenCV and
/// ORB-SLAM camera files (Camera.k1, k2, p1, p2, k3). The library's geometry is pinhole; a
/// detector run on raw images of a distorted lens gives boxes and masks that are moved outwards
/// or inwards by up to tens of pixels near the image border; undistorting each observation
/// (ObserveOptions::lens) keeps it consistent with the map's pinhole projections.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "ellreloc/core/box.hpp"
#include "ellreloc/core/camera.hpp"
#include "ellreloc/core/detection.hpp"
#include "ellreloc/core/ellipse.hpp"

namespace ellreloc {

namespace detail {

/// The normalised coordinates ((u - cx) / fx, (v - cy) / fy) of a pixel, and back.
inline Eigen::Vector2d normalisedOf(const Intrinsics& K, const Eigen::Vector2d& uv) {
  return {(uv(0) - K.cx) / K.fx, (uv(1) - K.cy) / K.fy};
}
inline Eigen::Vector2d pixelOf(const Intrinsics& K, const Eigen::Vector2d& x) {
  return {K.fx * x(0) + K.cx, K.fy * x(1) + K.cy};
}

}  // namespace detail

/// x_d = x (1 + k1 r^2 + k2 r^4 + k3 r^6) + [2 p1 x y + p2 (r^2 + 2 x^2), p1 (r^2 + 2 y^2) + 2 p2 x y]
/// on normalised coordinates x = ((u - cx) / fx, (v - cy) / fy), r = |x|.
struct Distortion {
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0;

  bool isZero() const { return k1 == 0 && k2 == 0 && p1 == 0 && p2 == 0 && k3 == 0; }
  bool operator==(const Distortion& o) const {
    return k1 == o.k1 && k2 == o.k2 && p1 == o.p1 && p2 == o.p2 && k3 == o.k3;
  }
  bool operator!=(const Distortion& o) const { return !(*this == o); }
  bool isFinite() const {
    return std::isfinite(k1) && std::isfinite(k2) && std::isfinite(p1) && std::isfinite(p2) && std::isfinite(k3);
  }

  /// The distorted normalised coordinates of undistorted ones.
  Eigen::Vector2d distort(const Eigen::Vector2d& x) const {
    const double r2 = x.squaredNorm();
    const double radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
    return {x(0) * radial + 2.0 * p1 * x(0) * x(1) + p2 * (r2 + 2.0 * x(0) * x(0)),
            x(1) * radial + p1 * (r2 + 2.0 * x(1) * x(1)) + 2.0 * p2 * x(0) * x(1)};
  }

  /// The undistorted normalised coordinates of distorted ones, by Newton's method from `start`
  /// (x_d when not given; the model has no closed-form inverse). nullopt when it does not
  /// converge to 1e-12, as where the model folds over (beyond the radius where its radial part
  /// stops growing).
  std::optional<Eigen::Vector2d> undistort(const Eigen::Vector2d& xd,
                                           const std::optional<Eigen::Vector2d>& start = std::nullopt) const {
    if (!xd.allFinite()) return std::nullopt;
    Eigen::Vector2d x = start && start->allFinite() ? *start : xd;
    for (int iteration = 0; iteration < 30; ++iteration) {
      const Eigen::Vector2d residual = distort(x) - xd;
      if (residual.norm() < 1e-12) return x;
      const double r2 = x.squaredNorm();
      const double radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
      const double dradial = k1 + r2 * (2.0 * k2 + 3.0 * r2 * k3);  // d radial / d r2
      Eigen::Matrix2d J;
      J(0, 0) = radial + 2.0 * x(0) * x(0) * dradial + 2.0 * p1 * x(1) + 6.0 * p2 * x(0);
      J(0, 1) = 2.0 * x(0) * x(1) * dradial + 2.0 * p1 * x(0) + 2.0 * p2 * x(1);
      J(1, 0) = 2.0 * x(0) * x(1) * dradial + 2.0 * p1 * x(0) + 2.0 * p2 * x(1);
      J(1, 1) = radial + 2.0 * x(1) * x(1) * dradial + 6.0 * p1 * x(1) + 2.0 * p2 * x(0);
      const double det = J.determinant();
      if (!(std::abs(det) > 1e-12)) return std::nullopt;
      x -= J.inverse() * residual;
      if (!x.allFinite()) return std::nullopt;
    }
    return (distort(x) - xd).norm() < 1e-9 ? std::optional<Eigen::Vector2d>(x) : std::nullopt;
  }

  /// The pixel of a raw image where the undistorted image's pixel `uv` was taken.
  Eigen::Vector2d distortPixel(const Intrinsics& K, const Eigen::Vector2d& uv) const {
    return detail::pixelOf(K, distort(detail::normalisedOf(K, uv)));
  }

  /// The undistorted image's pixel of a raw image's pixel `uv`; nullopt where undistort() is.
  /// `near`: a pinhole pixel close to the answer (a neighbour's), where Newton's method starts.
  std::optional<Eigen::Vector2d> undistortPixel(const Intrinsics& K, const Eigen::Vector2d& uv,
                                                const std::optional<Eigen::Vector2d>& near = std::nullopt) const {
    std::optional<Eigen::Vector2d> start;
    if (near) start = detail::normalisedOf(K, *near);
    const std::optional<Eigen::Vector2d> x = undistort(detail::normalisedOf(K, uv), start);
    if (!x) return std::nullopt;
    return detail::pixelOf(K, *x);
  }

  /// Why the model cannot be undone over a width x height image of intrinsics K, or "" when it
  /// can: its coefficients must be finite, and its radial part must keep growing out to the
  /// farthest image corner (where r (1 + k1 r^2 + k2 r^4 + k3 r^6) turns back, two directions
  /// meet in one pixel: coefficients of another camera or of another model).
  std::string whyNotInvertible(const Intrinsics& K) const {
    if (!isFinite()) return "the distortion coefficients must be finite";
    if (!K.isValid()) return "invalid intrinsics";
    double corner_radius = 0.0;  // the farthest corner, in distorted normalised coordinates
    for (const double u : {-0.5, K.width - 0.5})
      for (const double v : {-0.5, K.height - 0.5}) {
        const Eigen::Vector2d corner = detail::normalisedOf(K, {u, v});
        corner_radius = std::max(corner_radius, std::hypot(corner(0), corner(1)));
      }
    // Walk out along r until the distorted radius passes the corner's (the tangential terms,
    // small beside the radial ones, are left to undistort(), which checks every point).
    const double step = corner_radius / 256.0;
    double previous = 0.0;
    for (int i = 1; i <= 256 * 64; ++i) {
      const double r = i * step, r2 = r * r;
      const double distorted = r * (1.0 + r2 * (k1 + r2 * (k2 + r2 * k3)));
      if (!(distorted > previous)) return "the radial distortion folds over inside the image (k1, k2, k3)";
      if (distorted > corner_radius) return "";
      previous = distorted;
    }
    return "the radial distortion shrinks the image to a point (k1, k2, k3)";
  }
};

/// A raw image's camera: its pinhole intrinsics and the distortion of its lens. Detections
/// made on the raw image are moved to the pinhole image of the same intrinsics, which is what
/// the library's geometry assumes.
struct Lens {
  Intrinsics intrinsics;
  Distortion distortion;

  bool operator==(const Lens& o) const { return intrinsics == o.intrinsics && distortion == o.distortion; }

  /// Why the lens cannot be undone over its image, or "" (Distortion::whyNotInvertible).
  std::string whyNotUsable() const { return distortion.whyNotInvertible(intrinsics); }

  /// The pinhole pixel of a raw pixel; nullopt where the model cannot be undone. `near`: a
  /// pinhole pixel close to the answer, where the search starts.
  std::optional<Eigen::Vector2d> undistortPixel(const Eigen::Vector2d& raw,
                                                const std::optional<Eigen::Vector2d>& near = std::nullopt) const {
    if (distortion.isZero()) return raw;  // exactly: no round trip through normalised coordinates
    return distortion.undistortPixel(intrinsics, raw, near);
  }

  /// The bounding box of a raw box's outline once undistorted: the object lies inside the raw
  /// box, so its pinhole image lies inside that outline, whose sides the lens bends. nullopt
  /// for an invalid box or one reaching where the model cannot be undone.
  std::optional<Box> undistortBox(const Box& raw) const {
    if (!raw.isValid()) return std::nullopt;
    if (distortion.isZero()) return raw;
    constexpr int kSamplesPerSide = 16;  // a side bends by pixels: followed to a hundredth of one
    const Eigen::Vector2d corners[4] = {{raw.x1, raw.y1}, {raw.x2, raw.y1}, {raw.x2, raw.y2}, {raw.x1, raw.y2}};
    Box out(INFINITY, INFINITY, -INFINITY, -INFINITY);
    std::optional<Eigen::Vector2d> u;  // the previous sample's: each search starts next to the answer
    for (int side = 0; side < 4; ++side)
      for (int k = 0; k < kSamplesPerSide; ++k) {
        const double t = static_cast<double>(k) / kSamplesPerSide;
        u = undistortPixel((1.0 - t) * corners[side] + t * corners[(side + 1) % 4], u);
        if (!u) return std::nullopt;
        out =
            Box(std::min(out.x1, u->x()), std::min(out.y1, u->y()), std::max(out.x2, u->x()), std::max(out.y2, u->y()));
      }
    return out;
  }

  /// The ellipse with the area moments of a raw ellipse's outline once undistorted; nullopt
  /// where the model cannot be undone.
  std::optional<Ellipse> undistortEllipse(const Ellipse& raw) const {
    if (distortion.isZero()) return raw;
    constexpr int kVertices = 256;
    std::vector<Eigen::Vector2d> outline = raw.sampleBoundary(kVertices);
    std::optional<Eigen::Vector2d> u;  // the previous vertex's: each search starts next to the answer
    for (Eigen::Vector2d& p : outline) {
      if (!(u = undistortPixel(p, u))) return std::nullopt;
      p = *u;
    }
    const std::optional<Ellipse> e = ellipseOfPolygon(outline);
    if (!e) return std::nullopt;
    // The polygon is inscribed: a regular n-gon in a circle has (2 + cos(2 pi / n)) / 3 of its
    // covariance, and an ellipse sampled evenly in its parameter is the affine image of one.
    const double shrink = std::sqrt((2.0 + std::cos(2.0 * M_PI / kVertices)) / 3.0);
    return Ellipse(e->center(), e->axes() / shrink, e->angle());
  }

  /// The ellipse with the area moments of a simple polygon: a uniform ellipse of semi-axes a, b
  /// has the covariance R diag(a^2, b^2) R^T / 4. nullopt for fewer than 3 vertices or no area.
  static std::optional<Ellipse> ellipseOfPolygon(const std::vector<Eigen::Vector2d>& p) {
    if (p.size() < 3) return std::nullopt;
    const Eigen::Vector2d origin = p.front();  // moments about a vertex: no cancellation far from 0
    double area = 0.0, sx = 0.0, sy = 0.0, sxx = 0.0, syy = 0.0, sxy = 0.0;
    for (size_t i = 0; i < p.size(); ++i) {
      const Eigen::Vector2d a = p[i] - origin, b = p[(i + 1) % p.size()] - origin;
      const double cross = a.x() * b.y() - b.x() * a.y();
      area += cross / 2.0;
      sx += (a.x() + b.x()) * cross / 6.0;
      sy += (a.y() + b.y()) * cross / 6.0;
      sxx += (a.x() * a.x() + a.x() * b.x() + b.x() * b.x()) * cross / 12.0;
      syy += (a.y() * a.y() + a.y() * b.y() + b.y() * b.y()) * cross / 12.0;
      sxy += (a.x() * b.y() + 2.0 * a.x() * a.y() + 2.0 * b.x() * b.y() + b.x() * a.y()) * cross / 24.0;
    }
    if (!(std::abs(area) > 0.0)) return std::nullopt;
    const Eigen::Vector2d mean(sx / area, sy / area);
    Eigen::Matrix2d cov;
    cov(0, 0) = sxx / area - mean.x() * mean.x();
    cov(1, 1) = syy / area - mean.y() * mean.y();
    cov(0, 1) = cov(1, 0) = sxy / area - mean.x() * mean.y();
    return Ellipse::fromGaussian(mean + origin, 4.0 * cov);
  }
};

/// Keypoints of a raw image moved to the pinhole image; one the model cannot undo (far outside
/// the image) is left out and counted in `left_out`.
inline std::vector<Keypoint> undistortKeypoints(const Lens& lens, const std::vector<Keypoint>& raw,
                                                size_t* left_out = nullptr) {
  std::vector<Keypoint> out;
  out.reserve(raw.size());
  for (const Keypoint& k : raw)
    if (const std::optional<Eigen::Vector2d> uv = lens.undistortPixel(k.uv))
      out.push_back({k.point_index, *uv});
    else if (left_out)
      ++*left_out;
  return out;
}

}  // namespace ellreloc
