#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <set>

#include "ellreloc/core/p3p.hpp"
#include "ellreloc/core/ransac.hpp"

using namespace ellreloc;

namespace {

/// A plain point PnP problem: bearings and world points, some of them wrong.
struct PnPProblem {
  std::vector<Eigen::Vector3d> bearings, points;
  std::vector<bool> inlier;
  Pose truth;
};

PnPProblem makeProblem(int n, double outlier_ratio, double noise_rad, uint32_t seed, bool inliers_first = false) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  PnPProblem p;
  p.truth = Pose(Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng)).normalized().toRotationMatrix(),
                 Eigen::Vector3d(normal(rng), normal(rng), normal(rng)));
  const int n_out = static_cast<int>(std::round(outlier_ratio * n));
  for (int i = 0; i < n; ++i) {
    const bool good = inliers_first ? i < n - n_out : i >= n_out;
    const Eigen::Vector3d x_c(uni(rng) * 2, uni(rng) * 1.5, 4.0 + 2.0 * uni(rng));
    p.points.push_back(p.truth.rotation().transpose() * (x_c - p.truth.translation()));
    Eigen::Vector3d b = x_c.normalized();
    if (good) {
      b = (b + noise_rad * Eigen::Vector3d(normal(rng), normal(rng), normal(rng))).normalized();
    } else {
      b = Eigen::Vector3d(uni(rng) * 0.5, uni(rng) * 0.4, 1.0).normalized();
    }
    p.bearings.push_back(b);
    p.inlier.push_back(good);
  }
  return p;
}

/// The estimator: P3P on three correspondences, MSAC cost on angular errors.
struct PnPEstimator {
  using Model = Pose;
  static constexpr int kSampleSize = 3;
  static constexpr int kMaxModels = 4;
  const PnPProblem* problem;
  double threshold_rad = 2e-3;

  size_t numData() const { return problem->points.size(); }
  int generate(const int* s, Model* models) const {
    std::array<Pose, 4> poses;
    const int n = p3p({problem->bearings[s[0]], problem->bearings[s[1]], problem->bearings[s[2]]},
                      {problem->points[s[0]], problem->points[s[1]], problem->points[s[2]]}, &poses);
    std::copy(poses.begin(), poses.begin() + n, models);
    return n;
  }
  double score(const Model& m, int* inliers) const {
    double cost = 0.0;
    *inliers = 0;
    const double t2 = threshold_rad * threshold_rad;
    for (size_t i = 0; i < numData(); ++i) {
      const Eigen::Vector3d x = m.transform(problem->points[i]);
      const double e2 = x(2) > 0 ? (x.normalized() - problem->bearings[i]).squaredNorm() : 4.0;
      cost += std::min(e2, t2);
      *inliers += e2 < t2;
    }
    return cost;
  }
};

double rotationErrorOf(const Pose& a, const Pose& b) { return rotationErrorDeg(a.rotation(), b.rotation()); }

}  // namespace

TEST(Ransac, SolvesPnPWithOutliers) {
  for (uint32_t seed = 1; seed <= 20; ++seed) {
    const PnPProblem p = makeProblem(100, 0.5, 1e-4, seed);
    PnPEstimator est{&p};
    UniformSampler sampler(100, 3, seed);
    Pose best;
    RansacStats stats;
    long observed = 0;
    double lowest = 1e300;
    const auto observer = [&](const Pose&, double score, int) { ++observed, lowest = std::min(lowest, score); };
    ASSERT_TRUE(ransac(est, sampler, RansacOptions{}, &best, &stats, observer));
    EXPECT_LT(rotationErrorOf(best, p.truth), 0.1);
    EXPECT_LT((best.center() - p.truth.center()).norm(), 0.02);
    EXPECT_GE(stats.num_inliers, 48);
    EXPECT_LE(stats.num_inliers, 52);
    EXPECT_EQ(observed, stats.hypotheses);  // the observer sees every scored model
    EXPECT_EQ(lowest, stats.score);
    EXPECT_FALSE(stats.budget_exhausted);
    // The adaptive count stops far below the cap for 50% inliers (~70 samples at p = 0.9999).
    EXPECT_LT(stats.iterations, 200);
  }
}

TEST(Ransac, SameSeedSameResult) {
  const PnPProblem p = makeProblem(60, 0.4, 1e-3, 7);
  PnPEstimator est{&p};
  Pose a, b;
  RansacStats sa, sb;
  UniformSampler s1(60, 3, 99), s2(60, 3, 99);
  ransac(est, s1, RansacOptions{}, &a, &sa);
  ransac(est, s2, RansacOptions{}, &b, &sb);
  EXPECT_EQ(a.rotation(), b.rotation());
  EXPECT_EQ(a.translation(), b.translation());
  EXPECT_EQ(sa.iterations, sb.iterations);
  EXPECT_EQ(sa.hypotheses, sb.hypotheses);
}

TEST(Ransac, ExhaustiveSamplerEnumeratesEveryTripleOnce) {
  ExhaustiveSampler s(9, 3);
  std::set<std::array<int, 3>> seen;
  int sample[3];
  while (s.next(sample)) {
    EXPECT_LT(sample[0], sample[1]);
    EXPECT_LT(sample[1], sample[2]);
    EXPECT_LT(sample[2], 9);
    EXPECT_TRUE(seen.insert({sample[0], sample[1], sample[2]}).second);
  }
  EXPECT_EQ(seen.size(), 84u);  // C(9, 3)
  ExhaustiveSampler empty(2, 3);
  EXPECT_FALSE(empty.next(sample));
}

TEST(Ransac, ExhaustiveSearchStopsWhenEnumerated) {
  const PnPProblem p = makeProblem(12, 0.25, 1e-4, 3);
  PnPEstimator est{&p};
  ExhaustiveSampler sampler(12, 3);
  RansacOptions opt;
  opt.min_iterations = 1000000;  // force the full enumeration
  opt.max_iterations = 1000000;
  Pose best;
  RansacStats stats;
  ASSERT_TRUE(ransac(est, sampler, opt, &best, &stats));
  EXPECT_TRUE(stats.sampler_exhausted);
  EXPECT_EQ(stats.iterations, 220);  // C(12, 3)
  EXPECT_EQ(stats.num_inliers, 9);
  EXPECT_LT(rotationErrorOf(best, p.truth), 0.1);
}

TEST(Ransac, UniformSamplesAreDistinctAndInRange) {
  UniformSampler s(5, 3, 1);
  int sample[3];
  std::vector<int> hits(5, 0);
  for (int i = 0; i < 10000; ++i) {
    ASSERT_TRUE(s.next(sample));
    EXPECT_NE(sample[0], sample[1]);
    EXPECT_NE(sample[0], sample[2]);
    EXPECT_NE(sample[1], sample[2]);
    for (int k : sample) ++hits.at(k);
  }
  for (int h : hits) EXPECT_NEAR(h, 6000, 400);  // each index in 3/5 of the samples
  UniformSampler tiny(2, 3, 1);
  EXPECT_FALSE(tiny.next(sample));
}

TEST(Ransac, ProsacFindsOrderedInliersFasterThanUniform) {
  // 85% outliers, but the inliers come first in quality order.
  long prosac_total = 0, uniform_total = 0;
  for (uint32_t seed = 1; seed <= 10; ++seed) {
    const PnPProblem p = makeProblem(200, 0.85, 1e-4, seed, /*inliers_first=*/true);
    PnPEstimator est{&p};
    RansacOptions opt;
    opt.min_iterations = 1;
    Pose best;
    RansacStats sp, su;
    ProsacSampler prosac(200, 3, seed);
    ASSERT_TRUE(ransac(est, prosac, opt, &best, &sp));
    EXPECT_LT(rotationErrorOf(best, p.truth), 0.1);
    UniformSampler uniform(200, 3, seed);
    ASSERT_TRUE(ransac(est, uniform, opt, &best, &su));
    EXPECT_LT(rotationErrorOf(best, p.truth), 0.1);
    prosac_total += sp.best_iteration;
    uniform_total += su.best_iteration;
  }
  EXPECT_LT(prosac_total * 3, uniform_total);
}

TEST(Ransac, BudgetsAreHonoured) {
  const PnPProblem p = makeProblem(200, 0.97, 1e-4, 5);
  PnPEstimator est{&p};
  RansacOptions opt;
  opt.max_hypotheses = 500;
  UniformSampler sampler(200, 3, 1);
  Pose best;
  RansacStats stats;
  ransac(est, sampler, opt, &best, &stats);
  EXPECT_TRUE(stats.budget_exhausted);
  EXPECT_LE(stats.hypotheses, 500 + PnPEstimator::kMaxModels);
  opt.max_hypotheses = 100000000;
  opt.max_iterations = 100000000;
  opt.max_time_ms = 20.0;
  UniformSampler sampler2(200, 3, 2);
  ransac(est, sampler2, opt, &best, &stats);
  EXPECT_TRUE(stats.budget_exhausted);
  EXPECT_LT(stats.iterations, 100000000);
}

TEST(Ransac, AdaptiveIterationCount) {
  // k = log(1 - p) / log(1 - w^s)
  EXPECT_EQ(adaptiveIterations(0.5, 3, 0.99), static_cast<int>(std::ceil(std::log(0.01) / std::log(1 - 0.125))));
  EXPECT_EQ(adaptiveIterations(1.0, 3, 0.99), 0);
  EXPECT_EQ(adaptiveIterations(0.0, 3, 0.99), std::numeric_limits<int>::max());
}
