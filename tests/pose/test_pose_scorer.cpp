// The scorer's early exit: a cost is either exact or, when the pose could not reach the
// threshold, infinite, and then only for poses whose exact cost is at least the threshold; and
// its lazily evaluated matching, against the greedy matching of every exact overlap.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "ellreloc/core/distances.hpp"
#include "fixtures/observed_scene.hpp"
#include "pose/pipeline/candidates.hpp"
#include "pose/pipeline/pose_scorer.hpp"

using namespace ellreloc;

namespace {

/// 25 objects of four categories (look-alikes) within +-spread m of the origin, with 3 px of
/// centre noise.
test::ObservedScene randomScorerScene(double spread, const Intrinsics& K, std::mt19937& rng) {
  return test::randomObservedScene(25, 4, spread, 3.0, K, rng);
}

/// The truth turned by up to `step` radians and moved by up to `step` m along each axis.
Pose offTheTruth(const Pose& truth, double step, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  return Pose(
      Eigen::AngleAxisd(step * u(rng), Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized()).toRotationMatrix() *
          truth.rotation(),
      truth.translation() + step * Eigen::Vector3d(u(rng), u(rng), u(rng)));
}

}  // namespace

TEST(PoseScorer, GivingUpIsExactOrProvablyAboveTheThreshold) {
  std::mt19937 rng(91);
  const Intrinsics K = test::testIntrinsics();
  int given_up = 0, exact = 0;
  for (int scene = 0; scene < 20; ++scene) {
    const auto [map, truth, observations] = randomScorerScene(1.2, K, rng);
    for (const ScoringOptions& options : {RelocalizerOptions().scoring, RelocalizerOptions::oaSlam().scoring}) {
      std::vector<std::pair<int, std::string>> skipped;
      const pipeline::Candidates candidates =
          pipeline::collectCandidates(observations, map, options, 1000000, &skipped);
      pipeline::PoseScorer scorer(observations, candidates, map, K, options);
      for (int k = 0; k < 40; ++k) {
        // Poses from near the truth to far off it, so that costs span the whole range.
        const Pose pose = offTheTruth(truth, 0.02 * k, rng);
        const double full = scorer.cost(pose, pipeline::kRankingIoUVertices);
        for (const double threshold : {full - 0.5, full, full + 1e-6, full + 0.5, 0.0, 1.0, 3.0}) {
          std::vector<ObjectCorrespondence> matches;
          const double c = scorer.cost(pose, pipeline::kRankingIoUVertices, &matches, nullptr, threshold);
          if (std::isinf(c)) {
            EXPECT_GE(full, threshold - 1e-9) << "gave up on a pose below the threshold";
            EXPECT_TRUE(matches.empty());
            ++given_up;
          } else {
            EXPECT_EQ(c, full);
            ++exact;
          }
        }
      }
    }
  }
  EXPECT_GT(given_up, 500);  // the early exit is taken often
  EXPECT_GT(exact, 500);
}

// The scorer matches greedily on credit but computes exact overlaps lazily (in order of their
// bounds): its matches must be those of sorting every pair's exact overlap, computed here from
// plain projections.
TEST(PoseScorer, MatchesAreTheGreedyMatchingOfEveryExactOverlap) {
  std::mt19937 rng(92);
  const Intrinsics K = test::testIntrinsics();
  int matched = 0, contested = 0;
  for (int scene = 0; scene < 20; ++scene) {
    const auto [map, truth, observations] = randomScorerScene(0.8, K, rng);  // packed more closely
    for (const ScoringOptions& options : {RelocalizerOptions().scoring, RelocalizerOptions::oaSlam().scoring}) {
      std::vector<std::pair<int, std::string>> skipped;
      const pipeline::Candidates candidates =
          pipeline::collectCandidates(observations, map, options, 1000000, &skipped);
      pipeline::PoseScorer scorer(observations, candidates, map, K, options);
      for (int k = 0; k < 20; ++k) {
        const Pose pose = offTheTruth(truth, 0.02 * k, rng);
        std::vector<ObjectCorrespondence> matches;
        const double cost = scorer.cost(pose, pipeline::kRankingIoUVertices, &matches);
        // Every candidate pair's exact overlap, sorted by credit (ties: observation, object).
        std::vector<ObjectCorrespondence> pairs;
        for (size_t i = 0; i < observations.size(); ++i) {
          if (!candidates.usable[i]) continue;
          for (const int j : candidates.of_observation[i]) {
            const Projection p = project(map.objects[static_cast<size_t>(j)].ellipsoid, K, pose);
            if (!p.ok()) continue;
            const double ov = options.overlap == OverlapMeasure::BoxIoU
                                  ? boxIoU(observations[i].box, p.ellipse.boundingBox())
                                  : ellipseIoU(observations[i].ellipse, p.ellipse, pipeline::kRankingIoUVertices);
            if (ov >= options.min_overlap) pairs.push_back({static_cast<int>(i), j, ov, ov});  // one label: weight 1
          }
        }
        std::sort(pairs.begin(), pairs.end(), [](const ObjectCorrespondence& a, const ObjectCorrespondence& b) {
          if (a.credit != b.credit) return a.credit > b.credit;
          return a.observation != b.observation ? a.observation < b.observation : a.object < b.object;
        });
        std::vector<char> obs_taken(observations.size(), 0), obj_taken(map.objects.size(), 0);
        std::vector<ObjectCorrespondence> greedy;
        double expected = options.unmatched_cost * candidates.num_usable;
        for (const ObjectCorrespondence& m : pairs) {
          if (obs_taken[m.observation] || obj_taken[m.object]) continue;
          obs_taken[m.observation] = obj_taken[m.object] = 1;
          greedy.push_back(m);
          expected += (1.0 - m.credit) - options.unmatched_cost;
        }
        contested += static_cast<int>(pairs.size() - greedy.size());
        matched += static_cast<int>(greedy.size());
        ASSERT_EQ(matches.size(), greedy.size()) << "scene " << scene << ", pose " << k;
        for (size_t m = 0; m < greedy.size(); ++m) {
          EXPECT_EQ(matches[m].observation, greedy[m].observation);
          EXPECT_EQ(matches[m].object, greedy[m].object);
          EXPECT_NEAR(matches[m].credit, greedy[m].credit, 1e-12);
        }
        EXPECT_NEAR(cost, expected, 1e-9);
      }
    }
  }
  EXPECT_GT(matched, 500);
  EXPECT_GT(contested, 100);  // pairs left out because their observation or object was taken
}
