#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <limits>
#include <random>
#include <vector>

#include "ellreloc/core/distances.hpp"
#include "fixtures/random_geometry.hpp"

using namespace ellreloc;
using ellreloc::test::uniform;

namespace {

/// Square root of a symmetric PSD matrix by eigen decomposition (rounding can push an
/// eigenvalue of a thin ellipse slightly below zero: clamp it).
Eigen::Matrix2d sqrtm(const Eigen::Matrix2d& S) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(S);
  const Eigen::Vector2d root = eig.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  return eig.eigenvectors() * root.asDiagonal() * eig.eigenvectors().transpose();
}

/// W2^2 through generic matrix square roots (the textbook formula).
double w2SquaredReference(const Ellipse& a, const Ellipse& b) {
  const Eigen::Matrix2d S1 = a.covariance(), S2 = b.covariance();
  const Eigen::Matrix2d r1 = sqrtm(S1);
  const Eigen::Matrix2d cross = sqrtm(r1 * S2 * r1);
  return (a.center() - b.center()).squaredNorm() + (S1 + S2 - 2.0 * cross).trace();
}

/// IoU by counting the centres of a fine grid of n x n cells over the union's bounding box. Each
/// grid row is cut by the two ellipses along chords ((x-c)^T S^-1 (x-c) <= 1 solved for x), so
/// the centres inside are counted per row, not tested one by one.
double iouRaster(const Ellipse& a, const Ellipse& b, int n) {
  const Box ba = a.boundingBox(), bb = b.boundingBox();
  const Box u(std::min(ba.x1, bb.x1), std::min(ba.y1, bb.y1), std::max(ba.x2, bb.x2), std::max(ba.y2, bb.y2));
  const double dx = u.width() / n, dy = u.height() / n;
  const Eigen::Matrix2d Ia = a.covariance().inverse(), Ib = b.covariance().inverse();
  // The chord [lo, hi] of an ellipse (inverse covariance I) on the row at height y (empty when
  // lo > hi).
  const auto chord = [](const Ellipse& e, const Eigen::Matrix2d& I, double y, double* lo, double* hi) {
    const double v = y - e.center().y();
    const double disc = (I(0, 1) * v) * (I(0, 1) * v) - I(0, 0) * (I(1, 1) * v * v - 1.0);
    if (disc < 0.0) return *lo = 1.0, *hi = 0.0, void();
    *lo = e.center().x() + (-I(0, 1) * v - std::sqrt(disc)) / I(0, 0);
    *hi = e.center().x() + (-I(0, 1) * v + std::sqrt(disc)) / I(0, 0);
  };
  // Grid centres x = u.x1 + (i + 0.5) dx, 0 <= i < n, within [lo, hi].
  const auto centres = [&](double lo, double hi) -> long {
    if (lo > hi) return 0;
    const long first = std::max(0L, static_cast<long>(std::ceil((lo - u.x1) / dx - 0.5)));
    const long last = std::min(static_cast<long>(n) - 1, static_cast<long>(std::floor((hi - u.x1) / dx - 0.5)));
    return std::max(0L, last - first + 1);
  };
  long inter = 0, uni = 0;
  for (int j = 0; j < n; ++j) {
    const double y = u.y1 + (j + 0.5) * dy;
    double a_lo, a_hi, b_lo, b_hi;
    chord(a, Ia, y, &a_lo, &a_hi);
    chord(b, Ib, y, &b_lo, &b_hi);
    const long both = centres(std::max(a_lo, b_lo), std::min(a_hi, b_hi));
    inter += both;
    uni += centres(a_lo, a_hi) + centres(b_lo, b_hi) - both;
  }
  return uni ? static_cast<double>(inter) / uni : 0.0;
}

Ellipse nearby(std::mt19937& rng, const Ellipse& e) {
  return Ellipse(e.center() + Eigen::Vector2d(uniform(rng, -1, 1), uniform(rng, -1, 1)) * e.axes()(0),
                 {uniform(rng, 5, 120), uniform(rng, 5, 120)}, uniform(rng, -M_PI, M_PI));
}

/// An ellipse centred within `spread` of e's largest semi-axis from e's centre, each semi-axis
/// e's times a factor in [lo, hi], at any angle.
Ellipse anyNear(std::mt19937& rng, const Ellipse& e, double spread, double lo, double hi) {
  return Ellipse(e.center() + Eigen::Vector2d(uniform(rng, -spread, spread), uniform(rng, -spread, spread)) *
                                  e.axes().maxCoeff(),
                 e.axes().cwiseProduct(Eigen::Vector2d(uniform(rng, lo, hi), uniform(rng, lo, hi))),
                 uniform(rng, 0, M_PI));
}

}  // namespace

TEST(Wasserstein, AgreesWithMatrixSquareRootEvaluation) {
  std::mt19937 rng(31);
  for (int i = 0; i < 1000; ++i) {
    const Ellipse a = ellreloc::test::randomEllipse(rng), b = ellreloc::test::randomEllipse(rng);
    const double ref = w2SquaredReference(a, b);
    EXPECT_NEAR(wasserstein2Squared(a, b), ref, 1e-9 * std::max(1.0, ref));
    EXPECT_NEAR(wasserstein2Squared(a, b), wasserstein2Squared(b, a), 1e-9 * std::max(1.0, ref));
  }
}

TEST(Wasserstein, ExactlyZeroForEqualEllipses) {
  std::mt19937 rng(32);
  for (int i = 0; i < 1000; ++i) {
    const Ellipse a = ellreloc::test::randomEllipse(rng);
    EXPECT_EQ(wasserstein2Squared(a, a), 0.0);
  }
}

TEST(Wasserstein, SafeForNearDegenerateEllipses) {
  std::mt19937 rng(33);
  for (int i = 0; i < 500; ++i) {
    const double a = uniform(rng, 1, 100);
    const Ellipse thin({uniform(rng, 0, 100), 0}, {a, a * std::pow(10.0, uniform(rng, -9, -3))}, uniform(rng, -3, 3));
    const Ellipse other = i % 2 ? thin : ellreloc::test::randomEllipse(rng);
    const Ellipse thin2(thin.center(), {thin.axes()(0), thin.axes()(1) * 1.5}, thin.angle() + 1e-7);
    for (const Ellipse& b : {other, thin2}) {
      const double w = wasserstein2Squared(thin, b);
      ASSERT_TRUE(std::isfinite(w));
      EXPECT_GE(w, 0.0);
      const double ref = w2SquaredReference(thin, b);
      // The reference loses precision here itself; compare at the scale of the ellipses.
      EXPECT_NEAR(w, ref, 1e-6 * (thin.covariance().norm() + b.covariance().norm()) + 1e-9);
    }
  }
}

TEST(Wasserstein, PureTranslationAndScaling) {
  const Ellipse a({10, 20}, {30, 10}, 0.4);
  const Ellipse moved({13, 24}, {30, 10}, 0.4);
  EXPECT_NEAR(wasserstein2Squared(a, moved), 25.0, 1e-9);
  // Concentric, same orientation: W2^2 = (a1 - a2)^2 + (b1 - b2)^2.
  const Ellipse scaled({10, 20}, {33, 14}, 0.4);
  EXPECT_NEAR(wasserstein2Squared(a, scaled), 9.0 + 16.0, 1e-9);
}

TEST(Bhattacharyya, AgreesWithNumericalIntegration) {
  std::mt19937 rng(34);
  for (int i = 0; i < 30; ++i) {
    const Ellipse a = ellreloc::test::randomEllipse(rng);
    const Ellipse b = nearby(rng, a);
    // BC = integral of sqrt(p q), D_B = -ln BC, on a grid covering +-6 sigma of both.
    const Eigen::Matrix2d Ia = a.covariance().inverse(), Ib = b.covariance().inverse();
    const double na = 1.0 / (2 * M_PI * a.axes().prod()), nb = 1.0 / (2 * M_PI * b.axes().prod());
    const Box ba = a.boundingBox(), bb = b.boundingBox();
    const double x1 = std::min(a.center()(0) - 6 * (ba.width() / 2), b.center()(0) - 6 * (bb.width() / 2));
    const double x2 = std::max(a.center()(0) + 6 * (ba.width() / 2), b.center()(0) + 6 * (bb.width() / 2));
    const double y1 = std::min(a.center()(1) - 6 * (ba.height() / 2), b.center()(1) - 6 * (bb.height() / 2));
    const double y2 = std::max(a.center()(1) + 6 * (ba.height() / 2), b.center()(1) + 6 * (bb.height() / 2));
    const int n = 1200;
    const double dx = (x2 - x1) / n, dy = (y2 - y1) / n;
    double bc = 0.0;
    for (int u = 0; u < n; ++u) {
      for (int v = 0; v < n; ++v) {
        const Eigen::Vector2d p(x1 + (u + 0.5) * dx, y1 + (v + 0.5) * dy);
        const Eigen::Vector2d da = p - a.center(), db = p - b.center();
        bc += std::sqrt(na * nb) * std::exp(-0.25 * (da.dot(Ia * da) + db.dot(Ib * db)));
      }
    }
    bc *= dx * dy;
    EXPECT_NEAR(bhattacharyya(a, b), -std::log(bc), 2e-3);
  }
  const Ellipse e({1, 2}, {3, 1}, 0.2);
  EXPECT_NEAR(bhattacharyya(e, e), 0.0, 1e-12);
}

TEST(EllipseIoU, AgreesWithRasterisationTo1e3) {
  std::mt19937 rng(35);
  double worst = 0.0;
  for (int i = 0; i < 150; ++i) {
    const Ellipse a = ellreloc::test::randomEllipse(rng);
    const Ellipse b = nearby(rng, a);
    const double iou = ellipseIoU(a, b);
    const double ref = iouRaster(a, b, 1500);
    worst = std::max(worst, std::abs(iou - ref));
    EXPECT_NEAR(iou, ref, 1e-3) << i;
    EXPECT_DOUBLE_EQ(iou, ellipseIoU(b, a));
  }
  RecordProperty("worst_abs_error", std::to_string(worst));
}

TEST(EllipseIoU, SpecialCases) {
  const Ellipse a({100, 100}, {40, 20}, 0.3);
  EXPECT_NEAR(ellipseIoU(a, a), 1.0, 1e-3);
  EXPECT_EQ(ellipseIoU(a, Ellipse({300, 100}, {40, 20}, 0.3)), 0.0);
  // Nested: IoU = area ratio.
  const Ellipse inner({100, 100}, {20, 10}, 0.3);
  EXPECT_NEAR(ellipseIoU(a, inner), 0.25, 1e-3);
  // Thin ellipses crossing at a right angle.
  const Ellipse h({0, 0}, {100, 1}, 0.0), v({0, 0}, {100, 1}, M_PI / 2);
  EXPECT_NEAR(ellipseIoU(h, v), iouRaster(h, v, 4000), 1e-3);
  EXPECT_EQ(ellipseIoU(a, Ellipse({100, 100}, {0, 20}, 0.3)), 0.0);
  EXPECT_EQ(ellipseIoU(a, Ellipse({std::nan(""), 100}, {10, 20}, 0.3)), 0.0);
}

// The bound the relocalizer's scoring uses to skip pairs: never below the IoU it stands for
// (at both polygon sizes in use), and tight enough to skip far-apart or mismatched pairs.
TEST(EllipseIoU, UpperBoundHoldsAndPrunes) {
  std::mt19937 rng(135);
  int pruned = 0, pairs = 0;
  for (int i = 0; i < 20000; ++i) {
    const Ellipse a = test::randomEllipse(rng);
    const Ellipse b = anyNear(rng, a, 3, 0.1, 3);  // centred within a few semi-axes, of any size
    for (int vertices : {32, 128}) {
      const double iou = ellipseIoU(a, b, vertices), bound = ellipseIoUUpperBound(a, b, vertices);
      ASSERT_GE(bound, iou - 1e-12) << i << " " << vertices;
      if (vertices == 32) ++pairs, pruned += bound < 0.15;
    }
  }
  EXPECT_GT(pruned, pairs / 4);
  EXPECT_EQ(ellipseIoUUpperBound(Ellipse({0, 0}, {1, 1}, 0), Ellipse({10, 0}, {1, 1}, 0)), 0.0);
  EXPECT_NEAR(ellipseIoUUpperBound(Ellipse({0, 0}, {2, 1}, 0), Ellipse({0, 0}, {2, 1}, 0)), 1.0, 1e-12);
}

// The bound the relocalizer's sample check uses to skip the exact overlap: never above the IoU
// it stands for, and high enough to settle most pairs that reach 0.15.
TEST(EllipseIoU, LowerBoundHoldsAndSettles) {
  std::mt19937 rng(137);
  int settled = 0, reaching = 0;
  for (int i = 0; i < 20000; ++i) {
    const Ellipse a = test::randomEllipse(rng);
    const Ellipse b(
        a.center() + Eigen::Vector2d(test::uniform(rng, -1, 1), test::uniform(rng, -1, 1)) * a.axes().maxCoeff(),
        a.axes().cwiseProduct(Eigen::Vector2d(test::uniform(rng, 0.3, 2), test::uniform(rng, 0.3, 2))),
        a.angle() + test::uniform(rng, -0.5, 0.5));
    for (int vertices : {32, 128}) {
      const double iou = ellipseIoU(a, b, vertices), bound = ellipseIoULowerBound(a, b, vertices);
      ASSERT_LE(bound, iou + 1e-12) << i << " " << vertices;
      ASSERT_GE(bound, 0.0);
      if (vertices == 32 && iou >= 0.15) ++reaching, settled += bound >= 0.15;
    }
  }
  EXPECT_GT(settled, reaching / 4);
  EXPECT_EQ(ellipseIoULowerBound(Ellipse({0, 0}, {1, 1}, 0), Ellipse({1.5, 0}, {1, 1}, 0)), 0.0);
  EXPECT_GT(ellipseIoULowerBound(Ellipse({0, 0}, {2, 1}, 0.3), Ellipse({0, 0}, {2, 1}, 0.3), 32), 0.98);
}

// ellipseIoU adds the sectors of consecutive polygon edges outside the disc with one atan2 per
// run; the reference here builds the same polygon vertex by vertex and adds every edge's exact
// triangle-disc area with std::atan2.
TEST(EllipseIoU, SectorRunsAgreeWithTheEdgeByEdgeArea) {
  const auto reference = [](const Ellipse& e1, const Ellipse& e2, int n) {
    const auto [big, small] = detail::discAndPolygon(e1, e2, e1.area(), e2.area());
    const Eigen::Matrix2d to_disc = detail::toUnitDisc(big);
    const Eigen::Matrix2d shape =
        detail::polygonConstants(n).k * to_disc * small.rotation() * small.axes().asDiagonal();
    const Eigen::Vector2d offset = to_disc * (small.center() - big.center());
    const auto vertex = [&](int i) {
      return Eigen::Vector2d(offset + shape * Eigen::Vector2d(std::cos(2 * M_PI * i / n), std::sin(2 * M_PI * i / n)));
    };
    double area = 0.0;
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector2d p = vertex(i), q = vertex(i + 1), d = q - p;
      const double A = d.squaredNorm(), B = p.dot(d), C = p.squaredNorm() - 1.0, disc = B * B - A * C;
      std::vector<double> cuts = {0.0};
      for (double t : {(-B - std::sqrt(std::max(disc, 0.0))) / A, (-B + std::sqrt(std::max(disc, 0.0))) / A})
        if (disc > 0.0 && t > 0.0 && t < 1.0) cuts.push_back(t);
      cuts.push_back(1.0);
      for (size_t k = 0; k + 1 < cuts.size(); ++k) {
        const Eigen::Vector2d a = p + cuts[k] * d, b = p + cuts[k + 1] * d;
        const double cross = a(0) * b(1) - a(1) * b(0);
        area += (0.5 * (a + b)).squaredNorm() <= 1.0 ? 0.5 * cross : 0.5 * std::atan2(cross, a.dot(b));
      }
    }
    const double inter = std::min(std::abs(area) * big.axes().prod(), small.area());
    return inter / (e1.area() + e2.area() - inter);
  };
  std::mt19937 rng(138);
  double worst = 0.0;
  for (int i = 0; i < 5000; ++i) {
    const Ellipse a = test::randomEllipse(rng);
    const Ellipse b = anyNear(rng, a, 2, 0.05, 4);  // thin ones too: long runs of edges outside the disc
    if (ellipseIoU(a, b, 32) == 0.0) continue;  // disjoint boxes: no polygon
    for (int n : {32, 128}) worst = std::max(worst, std::abs(ellipseIoU(a, b, n) - reference(a, b, n)));
  }
  EXPECT_LT(worst, 1e-7);
  // A thin ellipse across a round one: two runs of edges outside, each far under pi.
  const Ellipse round({0, 0}, {10, 10}, 0), thin({0, 0}, {30, 1}, 0.4);
  EXPECT_NEAR(ellipseIoU(round, thin), reference(round, thin, 128), 1e-7);
}

TEST(EllipseIoU, FastAtan2IsWithin2e8OfStdAtan2) {
  std::mt19937 rng(136);
  double worst = 0.0;
  for (int i = 0; i < 200000; ++i) {
    const double y = i % 7 == 0 ? 0.0 : uniform(rng, -10, 10), x = i % 11 == 0 ? 0.0 : uniform(rng, -10, 10);
    worst = std::max(worst, std::abs(detail::fastAtan2(y, x) - std::atan2(y, x)));
  }
  EXPECT_LT(worst, 2e-8);
  EXPECT_EQ(detail::fastAtan2(0.0, 0.0), 0.0);
  EXPECT_NEAR(detail::fastAtan2(1.0, -1.0), 0.75 * M_PI, 2e-8);
  EXPECT_NEAR(detail::fastAtan2(-1e-300, 1.0), 0.0, 1e-12);
}

TEST(BoxIoU, HandComputedAndDegenerate) {
  EXPECT_DOUBLE_EQ(boxIoU(Box(0, 0, 10, 10), Box(5, 0, 15, 10)), 50.0 / 150.0);
  EXPECT_DOUBLE_EQ(boxIoU(Box(0, 0, 10, 10), Box(0, 0, 10, 10)), 1.0);
  EXPECT_DOUBLE_EQ(boxIoU(Box(0, 0, 10, 10), Box(20, 20, 30, 30)), 0.0);
  EXPECT_DOUBLE_EQ(boxIoU(Box(0, 0, 10, 10), Box(2, 2, 4, 4)), 4.0 / 100.0);
  EXPECT_DOUBLE_EQ(boxIoU(Box(0, 0, 0, 0), Box(0, 0, 0, 0)), 0.0);
  EXPECT_DOUBLE_EQ(boxIoU(Box(0, 0, 10, 10), Box(std::nan(""), 0, 4, 4)), 0.0);
  EXPECT_DOUBLE_EQ(boxIoU(Box(0, 0, 10, 10), Box(8, 0, 4, 4)), 0.0);  // x2 < x1: invalid
}

TEST(LevelSet, ZeroForEqualSymmetricAndMonotoneInOffset) {
  std::mt19937 rng(36);
  for (int i = 0; i < 300; ++i) {
    const Ellipse a = ellreloc::test::randomEllipse(rng);
    EXPECT_NEAR(levelSetDistance(a, a), 0.0, 1e-9);
    const Ellipse b = nearby(rng, a);
    EXPECT_NEAR(levelSetDistance(a, b), levelSetDistance(b, a), 1e-9 * (1 + levelSetDistance(a, b)));
    // Sliding a copy away along a fixed direction only increases the distance.
    double previous = 0.0;
    for (int k = 1; k <= 5; ++k) {
      const Ellipse moved(a.center() + Eigen::Vector2d(0.2 * k * a.axes()(1), 0.0), a.axes(), a.angle());
      const double d = levelSetDistance(a, moved);
      EXPECT_GT(d, previous);
      previous = d;
    }
  }
}

TEST(LevelSet, MatchesTheDefinitionOnAConcentricScaledCircle) {
  // Circles of radius 1 and 2: the level-s points of the small one have radius s/2 in the big
  // one (residual -s/2), and the level-s points of the big one have radius 2s (residual s).
  const Ellipse small({0, 0}, {1, 1}, 0.0), big({0, 0}, {2, 2}, 0.0);
  const double mean_sq = (0.25 * (0.25 + 1.0 + 2.25) + (0.25 + 1.0 + 2.25)) / 6.0;
  EXPECT_NEAR(levelSetDistance(small, big), std::sqrt(mean_sq), 1e-12);
}

TEST(Distances, InvalidInputGivesInfinityNotNaN) {
  const Ellipse good({0, 0}, {2, 1}, 0.0);
  const Ellipse bad({0, 0}, {-2, 1}, 0.0);
  const Ellipse nan({std::nan(""), 0}, {2, 1}, 0.0);
  for (const Ellipse& b : {bad, nan}) {
    EXPECT_TRUE(std::isinf(wasserstein2Squared(good, b)));
    EXPECT_TRUE(std::isinf(bhattacharyya(good, b)));
    EXPECT_TRUE(std::isinf(levelSetDistance(b, good)));
    EXPECT_EQ(ellipseIoU(b, good), 0.0);
  }
}

TEST(Wasserstein, ResidualSquaredNormIsW2Squared) {
  std::mt19937 rng(37);
  for (int i = 0; i < 1000; ++i) {
    const Ellipse a = ellreloc::test::randomEllipse(rng), b = ellreloc::test::randomEllipse(rng);
    double r[6];
    wasserstein2Residual<double>(a.center(), a.covariance(), b.center(), b.covariance(), r);
    const double sq = r[0] * r[0] + r[1] * r[1] + r[2] * r[2] + r[3] * r[3] + r[4] * r[4] + r[5] * r[5];
    EXPECT_NEAR(sq, w2SquaredReference(a, b), 1e-9 * std::max(1.0, sq));
    // The closed-form square root squares back to the covariance.
    const Eigen::Matrix2d root = sqrtSpd2<double>(a.covariance());
    EXPECT_LT((root * root - a.covariance()).norm(), 1e-9 * a.covariance().norm());
    wasserstein2Residual<double>(a.center(), a.covariance(), a.center(), a.covariance(), r);
    for (double v : r) EXPECT_NEAR(v, 0.0, 1e-9 * a.axes()(0));
  }
}
