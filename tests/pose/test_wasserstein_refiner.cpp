#include <ceres/jet.h>
#include <ceres/loss_function.h>
#include <gtest/gtest.h>

#include "ellreloc/core/distances.hpp"
#include "ellreloc/core/projection.hpp"
#include "ellreloc/pose/wasserstein_refiner.hpp"
#include "fixtures/random_geometry.hpp"

using namespace ellreloc;
using ellreloc::test::positionError;
using ellreloc::test::rotationError;
using ellreloc::test::uniform;

namespace {

struct Scene {
  Pose truth;
  std::vector<EllipseMatch> matches;
  std::vector<PointMatch> points;
};

/// n objects near the origin seen from a random camera, observed with centre noise (px) and
/// relative axis noise; optional keypoints with pixel noise.
Scene makeScene(std::mt19937& rng, int n, double centre_noise_px, double axis_noise, int n_points = 0) {
  const Intrinsics K = test::testIntrinsics();
  std::normal_distribution<double> normal(0.0, 1.0);
  Scene s;
  s.truth = test::randomLookAtPose(rng);
  while (static_cast<int>(s.matches.size()) < n) {
    const Ellipsoid e({uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -0.5, 0.5)},
                      {uniform(rng, 0.05, 0.3), uniform(rng, 0.05, 0.3), uniform(rng, 0.05, 0.3)},
                      test::randomRotation(rng));
    const Projection p = project(e, K, s.truth);
    if (!p) continue;
    const Ellipse& el = p.ellipse;
    const Ellipse noisy(
        el.center() + centre_noise_px * Eigen::Vector2d(normal(rng), normal(rng)),
        el.axes().cwiseProduct(Eigen::Vector2d(1 + axis_noise * normal(rng), 1 + axis_noise * normal(rng))),
        el.angle() + 0.5 * axis_noise * normal(rng));
    s.matches.push_back({noisy, e});
  }
  for (int i = 0; i < n_points; ++i) {
    const Eigen::Vector3d X(uniform(rng, -1.5, 1.5), uniform(rng, -1.5, 1.5), uniform(rng, -1, 1));
    const Eigen::Vector3d x = s.truth.transform(X);
    if (x(2) <= 0.5) continue;
    s.points.push_back({K.project(x) + 1.0 * Eigen::Vector2d(normal(rng), normal(rng)), X});
  }
  return s;
}

Pose perturb(std::mt19937& rng, const Pose& p, double deg, double metres) {
  std::normal_distribution<double> normal(0.0, 1.0);
  const Eigen::Vector3d axis = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
  const Eigen::Vector3d dir = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
  const Eigen::Matrix3d dR = Eigen::AngleAxisd(deg * M_PI / 180.0, axis).toRotationMatrix();
  // Rotate about the camera centre and move the centre, as a relocalizer's error would.
  const Eigen::Matrix3d R_wc = p.rotation().transpose() * dR;
  return Pose::fromCameraToWorld(R_wc, p.center() + metres * dir);
}

}  // namespace

// Converged = reaches the minimum that a refinement started at the true pose reaches (the
// noise floor of the observations), not the true pose itself.
TEST(WassersteinRefiner, ConvergesFromLargePerturbations) {
  std::mt19937 rng(71);
  const Intrinsics K = test::testIntrinsics();
  int good = 0, total = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 3 + trial % 13;  // 3 to 15 objects
    const Scene s = makeScene(rng, n, 1.0, 0.02);
    const Pose start = perturb(rng, s.truth, uniform(rng, 0, 15), uniform(rng, 0, 0.3));
    const RefinementResult r = refinePose(K, start, s.matches);
    const RefinementResult floor = refinePose(K, s.truth, s.matches);
    ASSERT_FALSE(r.fell_back) << r.message;
    EXPECT_LE(r.final_cost, r.initial_cost);
    EXPECT_TRUE(r.pose.isValid());
    ++total;
    const bool ok = positionError(r.pose, floor.pose) < 0.01 && rotationError(r.pose, floor.pose) < 0.2;
    good += ok;
  }
  EXPECT_GE(good, 0.9 * total) << good << " of " << total;
}

TEST(WassersteinRefiner, RobustLossResistsWrongCorrespondences) {
  std::mt19937 rng(72);
  const Intrinsics K = test::testIntrinsics();
  double robust_err = 0.0, plain_err = 0.0;
  int robust_good = 0;
  for (int trial = 0; trial < 60; ++trial) {
    Scene s = makeScene(rng, 10, 1.0, 0.02);
    const Pose floor = refinePose(K, s.truth, s.matches).pose;  // with correct matches only
    // 20% wrong: swap the observed ellipses of two pairs.
    std::swap(s.matches[0].observed, s.matches[5].observed);
    const Pose start = perturb(rng, s.truth, 3.0, 0.05);
    RefinerOptions plain;
    plain.object_loss = RobustLoss::None;
    const RefinementResult a = refinePose(K, start, s.matches);
    const RefinementResult b = refinePose(K, start, s.matches, {}, plain);
    robust_err += positionError(a.pose, s.truth);
    plain_err += positionError(b.pose, s.truth);
    // Within a few cm of what the clean matches give (the two wrong matches still pull a
    // little), where the plain loss ends metres away.
    robust_good += positionError(a.pose, floor) < 0.07 && rotationError(a.pose, floor) < 1.0;
  }
  EXPECT_LT(robust_err, 0.5 * plain_err);
  EXPECT_GE(robust_good, 57);
}

TEST(WassersteinRefiner, PointsMakeItMoreAccurate) {
  std::mt19937 rng(73);
  const Intrinsics K = test::testIntrinsics();
  double with_points = 0.0, objects_only = 0.0;
  for (int trial = 0; trial < 60; ++trial) {
    const Scene s = makeScene(rng, 4, 3.0, 0.08, 80);
    const Pose start = perturb(rng, s.truth, 2.0, 0.05);
    objects_only += positionError(refinePose(K, start, s.matches).pose, s.truth);
    with_points += positionError(refinePose(K, start, s.matches, s.points).pose, s.truth);
  }
  EXPECT_LT(with_points, 0.5 * objects_only);
}

TEST(WassersteinRefiner, NormalisationWeighsSmallAndLargeObjectsAlike) {
  // A small and a large object, each observed 10% too large: their normalised residuals are
  // equal, while raw W2 differs by the ratio of their sizes.
  const Intrinsics K = test::testIntrinsics();
  const Pose pose;
  const Ellipsoid small({-0.5, 0, 4}, {0.05, 0.05, 0.05}, Eigen::Matrix3d::Identity());
  const Ellipsoid large({0.5, 0, 4}, {0.5, 0.5, 0.5}, Eigen::Matrix3d::Identity());
  std::vector<EllipseMatch> m;
  for (const Ellipsoid& e : {small, large}) {
    const Ellipse p = project(e, K, pose).ellipse;
    m.push_back({Ellipse(p.center(), 1.1 * p.axes(), p.angle()), e});
  }
  RefinerOptions opt;
  opt.max_iterations = 0;  // just evaluate
  const RefinementResult r = refinePose(K, pose, m, {}, opt);
  ASSERT_EQ(r.object_residuals.size(), 2u);
  EXPECT_NEAR(r.object_residuals[0], r.object_residuals[1], 0.01 * r.object_residuals[1]);
  EXPECT_NEAR(r.object_residuals[0], 0.1 * std::sqrt(2.0) / 1.1, 0.005);  // W2 = 0.1 a sqrt 2, scale 1.1 a
}

TEST(WassersteinRefiner, SigmaWeighsReliableEllipsesMore) {
  // Six exact observations and one 20 px off: the pose the refiner settles on moves towards
  // the wrong one less when the exact ones are declared more reliable (sigma 0.5: 4x the
  // weight), and not at all when the wrong one is left out (sigma 0).
  std::mt19937 rng(5);
  const Intrinsics K = test::testIntrinsics();
  Scene s = makeScene(rng, 7, 0.0, 0.0);
  EllipseMatch& wrong = s.matches.back();
  wrong.observed =
      Ellipse(wrong.observed.center() + Eigen::Vector2d(20, 0), wrong.observed.axes(), wrong.observed.angle());
  RefinerOptions opt;
  opt.object_loss = RobustLoss::None;  // least squares: the weights alone decide
  const auto errorWith = [&](double exact_sigma, double wrong_sigma) {
    std::vector<EllipseMatch> m = s.matches;
    for (EllipseMatch& e : m) e.sigma = exact_sigma;
    m.back().sigma = wrong_sigma;
    const RefinementResult r = refinePose(K, s.truth, m, {}, opt);
    return positionError(r.pose, s.truth);
  };
  const double equal = errorWith(1.0, 1.0), reliable = errorWith(0.5, 1.0);
  EXPECT_GT(equal, 1e-3);
  EXPECT_LT(reliable, 0.5 * equal);
  EXPECT_LT(errorWith(1.0, 0.0), 1e-6);  // not a positive sigma: left out, the rest are exact
  EXPECT_LT(errorWith(1.0, std::nan("")), 1e-6);
}

TEST(WassersteinRefiner, DegenerateInputIsHandled) {
  std::mt19937 rng(74);
  const Intrinsics K = test::testIntrinsics();
  // One object: under-determined, but never worse and never NaN.
  const Scene s = makeScene(rng, 1, 1.0, 0.02);
  const RefinementResult one = refinePose(K, perturb(rng, s.truth, 5, 0.1), s.matches);
  EXPECT_FALSE(one.fell_back);
  EXPECT_LE(one.final_cost, one.initial_cost);
  EXPECT_TRUE(one.pose.isValid());
  // No match projects (the object is behind the camera at the initial pose): falls back.
  const Pose behind = Pose::fromCameraToWorld(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, 10));
  std::vector<EllipseMatch> m = {
      {Ellipse({320, 240}, {20, 10}, 0), Ellipsoid({0, 0, 0}, {0.1, 0.1, 0.1}, Eigen::Matrix3d::Identity())}};
  const RefinementResult fb = refinePose(K, behind, m);
  EXPECT_TRUE(fb.fell_back);
  EXPECT_FALSE(fb.message.empty());
  EXPECT_EQ(fb.object_residuals, std::vector<double>{-1.0});
  // An object close to the camera: large steps would take it behind; such steps are refused.
  std::vector<EllipseMatch> near = {
      {Ellipse({320, 240}, {200, 150}, 0), Ellipsoid({0, 0, 0.6}, {0.3, 0.2, 0.2}, Eigen::Matrix3d::Identity())},
      {Ellipse({100, 240}, {30, 30}, 0), Ellipsoid({-1, 0, 3}, {0.1, 0.1, 0.1}, Eigen::Matrix3d::Identity())}};
  const RefinementResult r = refinePose(K, Pose(), near);
  EXPECT_FALSE(r.fell_back);
  EXPECT_LE(r.final_cost, r.initial_cost);
  for (const auto& mm : near) EXPECT_TRUE(project(mm.ellipsoid, K, r.pose).ok());
  // A matched point behind the camera at the initial pose: no cost to start from, the initial
  // pose comes back, and the point's residual says it does not project.
  const std::vector<PointMatch> behind_point = {{Eigen::Vector2d(320, 240), s.truth.inverse().transform({0, 0, -1})}};
  const RefinementResult bp = refinePose(K, s.truth, s.matches, behind_point);
  EXPECT_TRUE(bp.fell_back);
  EXPECT_NE(bp.message.find("cost not finite"), std::string::npos) << bp.message;
  EXPECT_TRUE(bp.pose.translation().isApprox(s.truth.translation()));
  EXPECT_EQ(bp.point_residuals, std::vector<double>{-1.0});
  // Invalid observation (NaN): skipped, reported as -1.
  std::vector<EllipseMatch> bad = s.matches;
  bad.push_back({Ellipse({std::nan(""), 1}, {1, 1}, 0), s.matches[0].ellipsoid});
  const RefinementResult rb = refinePose(K, s.truth, bad);
  EXPECT_EQ(rb.object_residuals.back(), -1.0);
  // Invalid intrinsics or a non-finite initial pose: the pose given comes back, said so.
  const RefinementResult no_camera = refinePose(Intrinsics(), s.truth, s.matches);
  EXPECT_TRUE(no_camera.fell_back);
  EXPECT_NE(no_camera.message.find("invalid intrinsics"), std::string::npos) << no_camera.message;
  EXPECT_TRUE(no_camera.pose.translation().isApprox(s.truth.translation()));
  const Pose nan_pose(Eigen::Matrix3d::Identity(), Eigen::Vector3d(std::nan(""), 0.0, 0.0));
  EXPECT_TRUE(refinePose(K, nan_pose, s.matches).fell_back);
}

TEST(WassersteinRefiner, CeresBackendReachesTheSameMinimum) {
  std::mt19937 rng(75);
  const Intrinsics K = test::testIntrinsics();
  RefinerOptions ceres_opt;
  ceres_opt.backend = RefinerBackend::Ceres;
  int agree = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const Scene s = makeScene(rng, 4 + trial % 8, 1.0, 0.02, trial % 2 ? 30 : 0);
    const Pose start = perturb(rng, s.truth, 5.0, 0.1);
    const RefinementResult ours = refinePose(K, start, s.matches, s.points);
    const RefinementResult cer = refinePose(K, start, s.matches, s.points, ceres_opt);
    EXPECT_LE(cer.final_cost, cer.initial_cost);
    EXPECT_NEAR(cer.initial_cost, ours.initial_cost, 1e-9 * ours.initial_cost);
    agree += positionError(ours.pose, cer.pose) < 1e-3 && rotationError(ours.pose, cer.pose) < 0.02;
  }
  EXPECT_GE(agree, 38);
}

TEST(WassersteinRefiner, ResidualDerivativesAreFiniteAtZeroDistance) {
  // The refiner differentiates the W2 residual with Jets; at W2 = 0 (a perfect fit) sqrt(W2^2)
  // would have an infinite derivative. The 6-vector residual has none.
  using Jet = ceres::Jet<double, 3>;
  const Ellipse e({100, 50}, {30, 10}, 0.4);
  Vec2<Jet> m(Jet(100.0, 0), Jet(50.0, 1));
  Mat2<Jet> S = e.covariance().cast<Jet>();
  S(0, 0).v(2) = 1.0;  // derivative w.r.t. one covariance entry
  Jet r[6];
  wasserstein2Residual<Jet>(e.center().cast<Jet>(), e.covariance().cast<Jet>(), m, S, r);
  for (const Jet& x : r) {
    EXPECT_NEAR(x.a, 0.0, 1e-9);
    EXPECT_TRUE(x.v.allFinite());
  }
  // At the true pose with exact observations the refiner stays put, without NaN.
  std::mt19937 rng(76);
  const Scene s = makeScene(rng, 6, 0.0, 0.0);
  const RefinementResult r0 = refinePose(test::testIntrinsics(), s.truth, s.matches);
  EXPECT_FALSE(r0.fell_back);
  EXPECT_LT(positionError(r0.pose, s.truth), 1e-6);
  EXPECT_LT(r0.final_cost, 1e-12);
}

// One robust loss for the refiner and the two-object sweep, in Ceres' convention: checked
// against Ceres' own loss functions.
TEST(RobustLoss, MatchesCeresLossFunctions) {
  for (const double c : {0.3, 1.0, 2.5})
    for (const double s : {0.0, 0.01, 0.5, 1.0, 4.0, 50.0}) {
      double ceres_rho[3];
      ceres::HuberLoss(c).Evaluate(s, ceres_rho);
      double drho = 0.0;
      EXPECT_NEAR(robustLoss(RobustLoss::Huber, c, s, &drho), ceres_rho[0], 1e-12);
      EXPECT_NEAR(drho, ceres_rho[1], 1e-12);
      ceres::CauchyLoss(c).Evaluate(s, ceres_rho);
      EXPECT_NEAR(robustLoss(RobustLoss::Cauchy, c, s, &drho), ceres_rho[0], 1e-12);
      EXPECT_NEAR(drho, ceres_rho[1], 1e-12);
      EXPECT_EQ(robustLoss(RobustLoss::None, c, s), s);
    }
}
