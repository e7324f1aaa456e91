#include "ellreloc/core/ellipse.hpp"

#include "fixtures/random_geometry.hpp"

#include <gtest/gtest.h>

#include <limits>

using namespace ellreloc;
using ellreloc::test::uniform;

namespace {

void expectSameEllipse(const Ellipse& a, const Ellipse& b, double tol) {
  EXPECT_LT((a.center() - b.center()).norm(), tol);
  EXPECT_LT((a.covariance() - b.covariance()).norm(), tol * a.covariance().norm());
}

}  // namespace

TEST(Ellipse, DualConicRoundTripAtAnyScaleAndSign) {
  std::mt19937 rng(1);
  for (int i = 0; i < 500; ++i) {
    const Ellipse e = ellreloc::test::randomEllipse(rng);
    double scale = std::pow(10.0, uniform(rng, -6, 6));
    if (i % 2) scale = -scale;
    const auto back = Ellipse::fromDualConic(scale * e.dualConic());
    ASSERT_TRUE(back.has_value());
    expectSameEllipse(e, *back, 1e-9);
    EXPECT_GE(back->axes()(0), back->axes()(1));
    EXPECT_GT(back->angle(), -M_PI / 2);
    EXPECT_LE(back->angle(), M_PI / 2);
  }
}

// The centre and size alone, for callers that need no axes or angle: the centre and
// sqrt(a b) of the ellipse the conic describes, and nothing exactly where fromDualConic gives
// nothing.
TEST(Ellipse, CentreAndSizeFromDualConicAgreeWithTheEllipse) {
  std::mt19937 rng(7);
  for (int i = 0; i < 500; ++i) {
    const Ellipse e = ellreloc::test::randomEllipse(rng);
    const double scale = (i % 2 ? -1.0 : 1.0) * std::pow(10.0, uniform(rng, -6, 6));
    const auto cs = Ellipse::centreAndSizeFromDualConic(scale * e.dualConic());
    ASSERT_TRUE(cs.has_value());
    EXPECT_LT((cs->centre - e.center()).norm(), 1e-9 * (1.0 + e.center().norm()));
    EXPECT_NEAR(cs->size, std::sqrt(e.axes()(0) * e.axes()(1)), 1e-9 * e.axes()(0));
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Eigen::Matrix3d with_nan = Ellipse({1, 2}, {3, 2}, 0.3).dualConic(), parabola = with_nan;
  with_nan(0, 1) = nan;
  parabola(2, 2) = 0.0;
  for (const Eigen::Matrix3d& C : {with_nan, parabola, Eigen::Matrix3d(Eigen::Matrix3d::Zero()),
                                   Eigen::Matrix3d(Eigen::Vector3d(1, -1, -1).asDiagonal()),
                                   Eigen::Matrix3d(Eigen::Matrix3d::Identity())}) {
    EXPECT_FALSE(Ellipse::fromDualConic(C).has_value());
    EXPECT_FALSE(Ellipse::centreAndSizeFromDualConic(C).has_value());
  }
}

TEST(Ellipse, GaussianRoundTrip) {
  std::mt19937 rng(2);
  for (int i = 0; i < 500; ++i) {
    const Ellipse e = ellreloc::test::randomEllipse(rng);
    const auto back = Ellipse::fromGaussian(e.center(), e.covariance());
    ASSERT_TRUE(back.has_value());
    expectSameEllipse(e, *back, 1e-9);
    // Semi-axes are the square roots of the covariance's eigenvalues.
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(e.covariance());
    EXPECT_NEAR(back->axes()(0), std::sqrt(eig.eigenvalues()(1)), 1e-9 * back->axes()(0));
    EXPECT_NEAR(back->axes()(1), std::sqrt(eig.eigenvalues()(0)), 1e-9 * back->axes()(0));
  }
}

TEST(Ellipse, AngleFromAGaussianIsHalfTheAtan2OfItsCovariance) {
  // The textbook angle of axis a: 0.5 atan2(2 q, p - r), moved into (-pi/2, pi/2].
  const auto textbook = [](const Eigen::Matrix2d& S) {
    double angle = 0.5 * std::atan2(2.0 * S(0, 1), S(0, 0) - S(1, 1));
    return angle <= -M_PI / 2 ? angle + M_PI : angle;
  };
  std::mt19937 rng(3);
  std::vector<Eigen::Matrix2d> covariances;
  for (int i = 0; i < 1000; ++i) covariances.push_back(ellreloc::test::randomEllipse(rng).covariance());
  // Axis-aligned either way (angle 0 and pi/2, with q = +0 and -0), a circle (angle 0).
  for (const double q : {0.0, -0.0}) {
    covariances.push_back((Eigen::Matrix2d() << 9.0, q, q, 4.0).finished());
    covariances.push_back((Eigen::Matrix2d() << 4.0, q, q, 9.0).finished());
    covariances.push_back((Eigen::Matrix2d() << 4.0, q, q, 4.0).finished());
  }
  for (const Eigen::Matrix2d& S : covariances) {
    const auto e = Ellipse::fromGaussian(Eigen::Vector2d(1.0, 2.0), S);
    ASSERT_TRUE(e.has_value());
    EXPECT_NEAR(e->angle(), textbook(S), 1e-12) << S;
    EXPECT_NEAR(e->rotation()(0, 0), std::cos(textbook(S)), 1e-12);
    EXPECT_NEAR(e->rotation()(1, 0), std::sin(textbook(S)), 1e-12);
    EXPECT_NEAR((e->covariance() - S).norm(), 0.0, 1e-12 * S.norm());
  }
}

// Covariances at any finite scale: the angle neither underflows nor overflows (a fuzzer found
// conics of 1e-170 px^2 whose axis direction vanished when squared).
TEST(Ellipse, AngleFromGaussiansOfExtremeScale) {
  for (const double scale : {1e-300, 1e-170, 1e-100, 1.0, 1e100, 1e150}) {
    const Eigen::Matrix2d S = scale * (Eigen::Matrix2d() << 9.0, 2.0, 2.0, 4.0).finished();
    const auto e = Ellipse::fromGaussian(Eigen::Vector2d(1.0, 2.0), S);
    ASSERT_TRUE(e.has_value()) << scale;
    EXPECT_TRUE(e->isValid()) << scale;
    EXPECT_NEAR(e->angle(), 0.5 * std::atan2(4.0, 5.0), 1e-12) << scale;
    EXPECT_NEAR(e->rotation().determinant(), 1.0, 1e-12) << scale;
  }
}

TEST(Ellipse, PrimalConicVanishesOnTheBoundaryAndIsTheInverseOfTheDual) {
  std::mt19937 rng(3);
  for (int i = 0; i < 300; ++i) {
    const Ellipse e = ellreloc::test::randomEllipse(rng);
    const Eigen::Matrix3d A = e.conic();
    for (const auto& p : e.sampleBoundary(16)) {
      const Eigen::Vector3d x(p(0), p(1), 1.0);
      EXPECT_NEAR(x.dot(A * x), 0.0, 1e-9);
    }
    const Eigen::Matrix3d AC = A * e.dualConic();  // proportional to the identity
    EXPECT_LT((AC / AC(0, 0) - Eigen::Matrix3d::Identity()).norm(), 1e-8);
  }
}

TEST(Ellipse, BoundingBoxIsExact) {
  std::mt19937 rng(4);
  for (int i = 0; i < 300; ++i) {
    const Ellipse e = ellreloc::test::randomEllipse(rng);
    const Box box = e.boundingBox();
    double x1 = 1e9, y1 = 1e9, x2 = -1e9, y2 = -1e9;
    for (const auto& p : e.sampleBoundary(20000)) {
      x1 = std::min(x1, p(0)), y1 = std::min(y1, p(1)), x2 = std::max(x2, p(0)), y2 = std::max(y2, p(1));
    }
    // Sampling can only undershoot the extremes, by at most ~ (pi / n)^2 / 2 of a semi-axis.
    const double slack = 1e-6 * e.axes()(0);
    EXPECT_LE(box.x1, x1 + 1e-9);
    EXPECT_LE(box.y1, y1 + 1e-9);
    EXPECT_GE(box.x2, x2 - 1e-9);
    EXPECT_GE(box.y2, y2 - 1e-9);
    EXPECT_NEAR(box.x1, x1, slack);
    EXPECT_NEAR(box.y1, y1, slack);
    EXPECT_NEAR(box.x2, x2, slack);
    EXPECT_NEAR(box.y2, y2, slack);
  }
}

TEST(Ellipse, AreaMatchesThePolygonOfItsBoundary) {
  std::mt19937 rng(5);
  for (int i = 0; i < 200; ++i) {
    const Ellipse e = ellreloc::test::randomEllipse(rng);
    const auto pts = e.sampleBoundary(4000);
    double shoelace = 0.0;
    for (size_t k = 0; k < pts.size(); ++k) {
      const auto& p = pts[k];
      const auto& q = pts[(k + 1) % pts.size()];
      shoelace += 0.5 * (p(0) * q(1) - p(1) * q(0));
    }
    EXPECT_NEAR(shoelace, e.area(), 1e-5 * e.area());
  }
}

TEST(Ellipse, ContainmentAgreesWithTheBoundary) {
  std::mt19937 rng(6);
  for (int i = 0; i < 200; ++i) {
    const Ellipse e = ellreloc::test::randomEllipse(rng);
    for (const auto& p : e.sampleBoundary(32)) {
      EXPECT_TRUE(e.contains(e.center() + 0.999 * (p - e.center())));
      EXPECT_FALSE(e.contains(e.center() + 1.001 * (p - e.center())));
      EXPECT_NEAR(e.mahalanobisRadius(p), 1.0, 1e-12);
    }
  }
}

TEST(Ellipse, InscribedInBoxTouchesAllFourSides) {
  const Box box(10.0, 20.0, 110.0, 60.0);
  const auto e = Ellipse::inscribedInBox(box);
  ASSERT_TRUE(e.has_value());
  const Box b = e->boundingBox();
  EXPECT_NEAR(b.x1, box.x1, 1e-12);
  EXPECT_NEAR(b.y1, box.y1, 1e-12);
  EXPECT_NEAR(b.x2, box.x2, 1e-12);
  EXPECT_NEAR(b.y2, box.y2, 1e-12);
  const auto tall = Ellipse::inscribedInBox(Box(0, 0, 10, 50));
  ASSERT_TRUE(tall.has_value());
  EXPECT_GE(tall->axes()(0), tall->axes()(1));
  EXPECT_NEAR(tall->boundingBox().y2, 50.0, 1e-12);
  EXPECT_FALSE(Ellipse::inscribedInBox(Box(0, 0, 0, 10)).has_value());
  EXPECT_FALSE(Ellipse::inscribedInBox(Box(0, 0, std::nan(""), 10)).has_value());
  EXPECT_FALSE(Ellipse::inscribedInBox(Box(5, 0, 1, 10)).has_value());
}

TEST(Ellipse, InvalidInputIsReportedNotPropagated) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(Ellipse({0, 0}, {0, 1}, 0).isValid());
  EXPECT_FALSE(Ellipse({0, 0}, {-1, 1}, 0).isValid());
  EXPECT_FALSE(Ellipse({0, 0}, {nan, 1}, 0).isValid());
  EXPECT_FALSE(Ellipse({0, 0}, {inf, 1}, 0).isValid());
  EXPECT_FALSE(Ellipse({nan, 0}, {1, 1}, 0).isValid());
  EXPECT_FALSE(Ellipse({0, 0}, {1, 1}, inf).isValid());
  EXPECT_TRUE(Ellipse({0, 0}, {1, 1}, 0).isValid());

  Eigen::Matrix3d C = Ellipse({1, 2}, {3, 2}, 0.3).dualConic();
  Eigen::Matrix3d bad = C;
  bad(0, 1) = nan;
  EXPECT_FALSE(Ellipse::fromDualConic(bad).has_value());
  EXPECT_FALSE(Ellipse::fromDualConic(Eigen::Matrix3d::Zero()).has_value());
  // A hyperbola: diag(1, -1, -1).
  EXPECT_FALSE(Ellipse::fromDualConic(Eigen::Vector3d(1, -1, -1).asDiagonal().toDenseMatrix()).has_value());
  // A parabola's dual conic has C(2,2) = 0.
  bad = C;
  bad(2, 2) = 0.0;
  EXPECT_FALSE(Ellipse::fromDualConic(bad).has_value());
  // An imaginary conic: diag(1, 1, 1).
  EXPECT_FALSE(Ellipse::fromDualConic(Eigen::Matrix3d::Identity()).has_value());
  EXPECT_FALSE(Ellipse::fromGaussian({0, 0}, Eigen::Matrix2d::Zero()).has_value());
}
