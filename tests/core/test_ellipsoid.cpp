#include "ellreloc/core/ellipsoid.hpp"

#include "fixtures/random_geometry.hpp"

#include <gtest/gtest.h>

#include <limits>

using namespace ellreloc;
using ellreloc::test::uniform;

TEST(Ellipsoid, DualQuadricRoundTripAtAnyScaleAndSign) {
  std::mt19937 rng(11);
  for (int i = 0; i < 500; ++i) {
    const Ellipsoid e = ellreloc::test::randomEllipsoid(rng);
    // OA-SLAM normalises Q*(3,3) = -1, gtsam_quadrics +1; any scale must work.
    double scale = std::pow(10.0, uniform(rng, -6, 6));
    if (i % 2) scale = -scale;
    const auto back = Ellipsoid::fromDualQuadric(scale * e.dualQuadric());
    ASSERT_TRUE(back.has_value());
    EXPECT_TRUE(back->isValid());
    EXPECT_LT((back->center() - e.center()).norm(), 1e-9);
    EXPECT_LT((back->shapeMatrix() - e.shapeMatrix()).norm(), 1e-9);
    EXPECT_LE(back->axes()(0), back->axes()(1));
    EXPECT_LE(back->axes()(1), back->axes()(2));
    EXPECT_NEAR(back->rotation().determinant(), 1.0, 1e-12);
  }
}

TEST(Ellipsoid, SurfaceSamplesAreOnTheSurface) {
  std::mt19937 rng(12);
  for (int i = 0; i < 100; ++i) {
    const Ellipsoid e = ellreloc::test::randomEllipsoid(rng);
    const Eigen::Matrix4d Q = e.dualQuadric();
    const Eigen::Matrix4d A = Q.inverse();  // primal quadric
    for (const auto& x : e.sampleSurface(64)) {
      EXPECT_NEAR(e.mahalanobisRadius(x), 1.0, 1e-12);
      const Eigen::Vector4d h(x(0), x(1), x(2), 1.0);
      EXPECT_NEAR(h.dot(A * h) / A.norm(), 0.0, 1e-9);
      EXPECT_TRUE(e.contains(e.center() + 0.999 * (x - e.center())));
      EXPECT_FALSE(e.contains(e.center() + 1.001 * (x - e.center())));
    }
  }
}

TEST(Ellipsoid, BoundingBoxIsExact) {
  std::mt19937 rng(13);
  for (int i = 0; i < 100; ++i) {
    const Ellipsoid e = ellreloc::test::randomEllipsoid(rng);
    const Eigen::AlignedBox3d box = e.boundingBox();
    // The extreme point along world axis k is c +- M e_k / sqrt(M_kk) (support function).
    const Eigen::Matrix3d M = e.shapeMatrix();
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d extreme = e.center() + M.col(k) / std::sqrt(M(k, k));
      EXPECT_NEAR(e.mahalanobisRadius(extreme), 1.0, 1e-12);
      EXPECT_NEAR(box.max()(k), extreme(k), 1e-12);
    }
    for (const auto& x : e.sampleSurface(2000)) {
      EXPECT_TRUE(box.exteriorDistance(x) < 1e-12);
    }
  }
}

TEST(Ellipsoid, VolumeMatchesMonteCarlo) {
  std::mt19937 rng(14);
  const Ellipsoid e = ellreloc::test::randomEllipsoid(rng);
  const Eigen::AlignedBox3d box = e.boundingBox();
  const int n = 400000;
  int inside = 0;
  for (int i = 0; i < n; ++i) {
    Eigen::Vector3d x;
    for (int k = 0; k < 3; ++k) x(k) = uniform(rng, box.min()(k), box.max()(k));
    inside += e.contains(x);
  }
  const double estimate = box.volume() * inside / n;
  EXPECT_NEAR(estimate, e.volume(), 0.01 * e.volume());
}

TEST(Ellipsoid, InvalidInput) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  EXPECT_FALSE(Ellipsoid({0, 0, 0}, {1, 0, 1}, I).isValid());
  EXPECT_FALSE(Ellipsoid({0, 0, 0}, {1, -1, 1}, I).isValid());
  EXPECT_FALSE(Ellipsoid({0, 0, 0}, {1, nan, 1}, I).isValid());
  EXPECT_FALSE(Ellipsoid({0, 0, 0}, {1, 1, std::numeric_limits<double>::infinity()}, I).isValid());
  EXPECT_FALSE(Ellipsoid({0, nan, 0}, {1, 1, 1}, I).isValid());
  EXPECT_FALSE(Ellipsoid({0, 0, 0}, {1, 1, 1}, 2.0 * I).isValid());
  EXPECT_FALSE(Ellipsoid({0, 0, 0}, {1, 1, 1}, -I).isValid());  // a reflection
  EXPECT_TRUE(Ellipsoid({0, 0, 0}, {1, 1, 1}, I).isValid());

  EXPECT_FALSE(Ellipsoid::fromDualQuadric(Eigen::Matrix4d::Zero()).has_value());
  EXPECT_FALSE(Ellipsoid::fromDualQuadric(Eigen::Matrix4d::Identity()).has_value());  // imaginary
  Eigen::Matrix4d hyperboloid = Eigen::Vector4d(1, 1, -1, -1).asDiagonal();
  EXPECT_FALSE(Ellipsoid::fromDualQuadric(hyperboloid).has_value());
  Eigen::Matrix4d Q = Ellipsoid().dualQuadric();
  Q(1, 2) = nan;
  EXPECT_FALSE(Ellipsoid::fromDualQuadric(Q).has_value());
}

TEST(Ellipsoid, NearestRotationRepairsRoundedMatrices) {
  std::mt19937 rng(15);
  for (int i = 0; i < 100; ++i) {
    const Eigen::Matrix3d R = ellreloc::test::randomRotation(rng);
    Eigen::Matrix3d noisy = R;
    for (int k = 0; k < 9; ++k) noisy(k) += uniform(rng, -1e-4, 1e-4);
    EXPECT_FALSE(isRotation(noisy));
    const Eigen::Matrix3d fixed = nearestRotation(noisy);
    EXPECT_TRUE(isRotation(fixed, 1e-12));
    EXPECT_LT((fixed - R).norm(), 1e-3);
  }
}
