#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
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

namespace {

/// The serial RANSAC loop written out plainly, as the reference for ransacOnThreads.
template <typename Sampler>
RansacStats referenceRansac(const PnPEstimator& est, Sampler& sampler, const RansacOptions& o, Pose* best,
                            std::vector<double>* seen) {
  RansacStats st;
  int needed = o.max_iterations, enough_stop = std::numeric_limits<int>::max();
  int sample[3];
  Pose models[4];
  std::set<std::set<int>> drawn;
  while (true) {
    if (st.iterations >= o.max_iterations || st.hypotheses >= o.max_hypotheses) {
      st.budget_exhausted = true;
      break;
    }
    if (st.iterations >= std::max(o.min_iterations, std::min(needed, enough_stop))) break;
    if (!sampler.next(sample)) {
      st.sampler_exhausted = true;
      break;
    }
    ++st.iterations;
    const bool repeated = o.skip_repeated_samples && !drawn.insert({sample[0], sample[1], sample[2]}).second;
    st.repeated_samples += repeated;
    const int m = repeated ? 0 : est.generate(sample, models);
    for (int i = 0; i < m; ++i) {
      ++st.hypotheses;
      int inliers = 0;
      const double score = est.score(models[i], &inliers);
      seen->push_back(score);
      if (score < st.score) {
        st.score = score, st.num_inliers = inliers, st.best_iteration = st.iterations, *best = models[i];
        needed = adaptiveIterations(static_cast<double>(inliers) / est.numData(), 3, o.success_probability);
        if (enough_stop == std::numeric_limits<int>::max() && inliers >= o.enough_inliers && score <= o.enough_score)
          enough_stop = static_cast<int>(std::ceil(st.iterations * (1.0 + o.enough_extension)));
      }
    }
  }
  return st;
}

}  // namespace

// Batches scored on threads, taken in sample order: the serial loop's result, statistics and
// observer calls, for every sampler and for budgets that stop in the middle of a batch (the last
// one at a good enough model, which ends the uniform search after about half its samples).
TEST(Ransac, OnThreadsIsTheSerialLoopThreadSafe) {
  const PnPProblem p = makeProblem(40, 0.6, 1e-3, 11);
  const PnPEstimator est{&p};
  RansacOptions budgets[5];
  budgets[1].max_hypotheses = 37;
  budgets[2].min_iterations = 300, budgets[2].max_iterations = 301;
  budgets[3].min_iterations = 1, budgets[3].enough_inliers = 10, budgets[3].enough_score = INFINITY;
  budgets[4].min_iterations = 2000, budgets[4].skip_repeated_samples = true;
  for (const RansacOptions& o : budgets)
    for (int kind = 0; kind < 3; ++kind) {
      Pose expected;
      std::vector<double> expected_seen;
      UniformSampler u(40, 3, 5);
      ExhaustiveSampler e(40, 3);
      ProsacSampler pr(40, 3, 5, 1000);
      const RansacStats ref = kind == 0   ? referenceRansac(est, u, o, &expected, &expected_seen)
                              : kind == 1 ? referenceRansac(est, e, o, &expected, &expected_seen)
                                          : referenceRansac(est, pr, o, &expected, &expected_seen);
      for (int threads = 1; threads <= 3; ++threads) {
        const std::vector<PnPEstimator> copies(static_cast<size_t>(threads), est);
        std::vector<const PnPEstimator*> estimators;
        for (const PnPEstimator& c : copies) estimators.push_back(&c);
        Pose best;
        RansacStats st;
        std::vector<double> seen;
        const auto observer = [&](const Pose&, double score, int) { seen.push_back(score); };
        UniformSampler u2(40, 3, 5);
        ExhaustiveSampler e2(40, 3);
        ProsacSampler pr2(40, 3, 5, 1000);
        if (kind == 0) ransacOnThreads(estimators, u2, o, &best, &st, observer);
        if (kind == 1) ransacOnThreads(estimators, e2, o, &best, &st, observer);
        if (kind == 2) ransacOnThreads(estimators, pr2, o, &best, &st, observer);
        SCOPED_TRACE("sampler " + std::to_string(kind) + ", threads " + std::to_string(threads));
        EXPECT_EQ(st.iterations, ref.iterations);
        EXPECT_EQ(st.hypotheses, ref.hypotheses);
        EXPECT_EQ(st.best_iteration, ref.best_iteration);
        EXPECT_EQ(st.num_inliers, ref.num_inliers);
        EXPECT_EQ(st.score, ref.score);
        EXPECT_EQ(st.budget_exhausted, ref.budget_exhausted);
        EXPECT_EQ(st.sampler_exhausted, ref.sampler_exhausted);
        EXPECT_EQ(st.repeated_samples, ref.repeated_samples);
        EXPECT_EQ(seen, expected_seen);
        EXPECT_EQ(best.translation(), expected.translation());
      }
    }
}

namespace {

/// The PnP estimator that also records the samples it is asked to generate from.
struct RecordingEstimator : PnPEstimator {
  mutable std::vector<std::set<int>> generated;
  int generate(const int* s, Model* models) const {
    generated.push_back({s[0], s[1], s[2]});
    return PnPEstimator::generate(s, models);
  }
};

}  // namespace

// Six data give 20 triples: 400 random samples repeat most of them, in any order. Skipped, a
// repeat still counts as drawn (the same count, so the same stopping point) but generates
// nothing; each triple drawn is generated once, and the best model is the one found without
// skipping.
TEST(Ransac, RepeatedSamplesAreCountedButNotGeneratedAgain) {
  const PnPProblem p = makeProblem(6, 0.0, 1e-4, 13);
  RansacOptions o;
  o.min_iterations = 400, o.max_iterations = 400;
  for (const bool prosac : {false, true}) {
    SCOPED_TRACE(prosac ? "prosac" : "uniform");
    RecordingEstimator plain{{&p}}, skipping{{&p}};
    Pose best_plain, best_skipping;
    RansacStats plain_stats, skipping_stats;
    o.skip_repeated_samples = false;
    UniformSampler u1(6, 3, 3), u2(6, 3, 3);
    ProsacSampler p1(6, 3, 3, 100), p2(6, 3, 3, 100);
    prosac ? ransac(plain, p1, o, &best_plain, &plain_stats) : ransac(plain, u1, o, &best_plain, &plain_stats);
    o.skip_repeated_samples = true;
    prosac ? ransac(skipping, p2, o, &best_skipping, &skipping_stats)
           : ransac(skipping, u2, o, &best_skipping, &skipping_stats);
    EXPECT_EQ(plain_stats.iterations, 400);
    EXPECT_EQ(skipping_stats.iterations, 400);
    EXPECT_EQ(plain_stats.repeated_samples, 0);
    ASSERT_EQ(plain.generated.size(), 400u);
    // What the plain run drew, each triple once, in the order first drawn.
    std::vector<std::set<int>> distinct;
    for (const std::set<int>& t : plain.generated)
      if (std::find(distinct.begin(), distinct.end(), t) == distinct.end()) distinct.push_back(t);
    EXPECT_EQ(skipping.generated, distinct);
    EXPECT_EQ(skipping_stats.repeated_samples, 400 - static_cast<int>(distinct.size()));
    EXPECT_NEAR(skipping_stats.score, plain_stats.score, 1e-12);
    EXPECT_LT(rotationErrorOf(best_skipping, p.truth), 0.1);
  }
}

// A best model with the support asked for ends the search after enough_extension times as many
// samples again, though the adaptive count (12 inliers in 60) asks for about 1,430.
TEST(Ransac, AGoodEnoughModelEndsTheSearch) {
  const PnPProblem p = makeProblem(60, 0.8, 1e-4, 21);
  const int inliers = static_cast<int>(std::count(p.inlier.begin(), p.inlier.end(), true));
  ASSERT_EQ(inliers, 12);
  const PnPEstimator est{&p};
  RansacOptions o;
  o.min_iterations = 1;
  o.success_probability = 0.99999;
  UniformSampler a(60, 3, 7);
  Pose full;
  RansacStats full_stats;
  ransac(est, a, o, &full, &full_stats);
  EXPECT_EQ(full_stats.num_inliers, inliers);

  // The first sample whose model is the best so far and has every inlier, by a plain loop over
  // the same samples.
  UniformSampler plain(60, 3, 7);
  int sample[3], first = 0;
  Pose models[4];
  double best = INFINITY;
  for (int k = 1; first == 0 && k < 100000 && plain.next(sample); ++k) {
    const int m = est.generate(sample, models);
    for (int i = 0; i < m; ++i) {
      int n = 0;
      const double score = est.score(models[i], &n);
      if (score < best && n >= inliers && first == 0) first = k;
      best = std::min(best, score);
    }
  }
  ASSERT_GT(first, 0);
  for (const double extension : {0.0, 0.5, 1.0}) {
    o.enough_inliers = inliers;
    o.enough_score = INFINITY;
    o.enough_extension = extension;
    UniformSampler b(60, 3, 7);
    Pose early;
    RansacStats st;
    ASSERT_TRUE(ransac(est, b, o, &early, &st));
    EXPECT_EQ(st.iterations, static_cast<int>(std::ceil(first * (1.0 + extension)))) << extension;
    EXPECT_LT(st.iterations, full_stats.iterations);
    EXPECT_EQ(st.num_inliers, inliers);
    EXPECT_LT((early.center() - p.truth.center()).norm(), 0.02);
  }
  // A score bar no model reaches leaves the adaptive count alone.
  o.enough_score = -1.0;
  UniformSampler c(60, 3, 7);
  Pose same;
  RansacStats st;
  ransac(est, c, o, &same, &st);
  EXPECT_EQ(st.iterations, full_stats.iterations);
}
