// The scorer's early exit: a cost is either exact or, when the pose could not reach the
// threshold, infinite, and then only for poses whose exact cost is at least the threshold.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "ellreloc/sim/map_observations.hpp"
#include "fixtures/random_geometry.hpp"
#include "pose/pipeline/candidates.hpp"
#include "pose/pipeline/pose_scorer.hpp"

using namespace ellreloc;

TEST(PoseScorer, GivingUpIsExactOrProvablyAboveTheThreshold) {
  std::mt19937 rng(91);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Intrinsics K = test::testIntrinsics();
  int given_up = 0, exact = 0;
  for (int scene = 0; scene < 20; ++scene) {
    ObjectMap map;
    for (int i = 0; i < 25; ++i)
      map.objects.push_back(
          {i, i % 4, "",
           Ellipsoid({1.2 * u(rng), 1.2 * u(rng), 0.3 * u(rng)},
                     {0.15 + 0.1 * u(rng), 0.15 + 0.1 * u(rng), 0.15 + 0.1 * u(rng)}, Eigen::Matrix3d::Identity())});
    const Pose truth = test::randomLookAtPose(rng);
    sim::MapObservationOptions noise;
    noise.centre_sigma_px = 3.0;
    const std::vector<Observation> observations = sim::observeMap(map, K, truth, noise, &rng);
    for (const ScoringOptions& options : {RelocalizerOptions().scoring, RelocalizerOptions::oaSlam().scoring}) {
      std::vector<std::pair<int, std::string>> skipped;
      const pipeline::Candidates candidates =
          pipeline::collectCandidates(observations, map, options, 1000000, &skipped);
      pipeline::PoseScorer scorer(observations, candidates, map, K, options);
      for (int k = 0; k < 40; ++k) {
        // Poses from near the truth to far off it, so that costs span the whole range.
        const double step = 0.02 * k;
        const Pose pose = Pose(
            Eigen::AngleAxisd(step * u(rng), Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized()).toRotationMatrix() *
                truth.rotation(),
            truth.translation() + step * Eigen::Vector3d(u(rng), u(rng), u(rng)));
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
