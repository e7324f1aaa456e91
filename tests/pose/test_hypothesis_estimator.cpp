// The hypothesis estimator's local optimisation: a hypothesis that explains every usable
// observation, but loosely, is refined (refineIfLoose), and the refined pose replaces it when it
// scores lower; any other hypothesis, or one that could not enter the pool, is kept as it is.

#include <gtest/gtest.h>

#include <limits>
#include <random>

#include "fixtures/observed_scene.hpp"
#include "pose/pipeline/candidates.hpp"
#include "pose/pipeline/hypothesis_estimator.hpp"

using namespace ellreloc;
using ellreloc::test::positionError;

namespace {

/// 12 objects of three categories within a metre of the origin, seen exactly from a random pose
/// that sees at least five of them.
test::ObservedScene randomEstimatorScene(const Intrinsics& K, std::mt19937& rng) {
  test::ObservedScene s = test::randomObservedScene(12, 3, 1.0, 0.0, K, rng);
  while (s.observations.size() < 5) s = test::randomObservedScene(12, 3, 1.0, 0.0, K, rng);
  return s;
}

/// The truth turned by `angle` radians about a random axis and moved by `shift` m.
Pose offTheTruth(const Pose& truth, double angle, double shift, std::mt19937& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  const Eigen::Vector3d axis = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
  const Eigen::Vector3d move = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized() * shift;
  return Pose(Eigen::AngleAxisd(angle, axis).toRotationMatrix() * truth.rotation(), truth.translation() + move);
}

}  // namespace

TEST(HypothesisEstimator, ALooseHypothesisExplainingEveryObservationIsRefined) {
  std::mt19937 rng(95);
  const Intrinsics K = test::testIntrinsics();
  const double anything = std::numeric_limits<double>::infinity();  // an admission any cost passes
  int refined = 0, loose = 0;
  for (int scene = 0; scene < 10; ++scene) {
    auto [map, truth, observations] = randomEstimatorScene(K, rng);
    // Every other scene holds a detection in an image corner that no object projects near: no
    // hypothesis near the truth explains it, and none is refined.
    const bool decoy = scene % 2 == 1;
    if (decoy) {
      Observation o = observations.front();
      o.ellipse = Ellipse({20.0, 20.0}, {12.0, 8.0}, 0.0);
      o.box = o.ellipse.boundingBox();
      observations.push_back(o);
    }
    RelocalizerOptions on, off;
    off.search.refine_explained = false;
    std::vector<std::pair<int, std::string>> skipped;
    const pipeline::Candidates candidates =
        pipeline::collectCandidates(observations, map, on.scoring, 100000, &skipped);
    pipeline::PoseScorer scorer(observations, candidates, map, K, on.scoring);
    const pipeline::HypothesisEstimator refining(observations, candidates, map, K, on, {}, scorer);
    const pipeline::HypothesisEstimator raw(observations, candidates, map, K, off, {}, scorer);
    const double explained_cost = candidates.num_usable * (1.0 - on.search.explained_mean_credit);
    for (int k = 0; k < 6; ++k) {
      const Pose start = offTheTruth(truth, 0.035, 0.06, rng);
      std::vector<ObjectCorrespondence> matches;
      const double start_cost = scorer.cost(start, pipeline::kRankingIoUVertices, &matches);
      pipeline::PoseHypothesis h{start, {}};
      int inliers = 0;
      const double scored = refining.score(h, &inliers);
      EXPECT_EQ(scored, start_cost);
      // Kept as it is with the option off, or when it could not enter the pool.
      for (const double admission : {anything, scored}) {
        pipeline::PoseHypothesis kept = h;
        int kept_inliers = inliers;
        const pipeline::HypothesisEstimator& estimator = admission == anything ? raw : refining;
        EXPECT_EQ(estimator.refineIfLoose(&kept, scored, &kept_inliers, admission), scored);
        EXPECT_TRUE(kept.pose.translation() == start.translation() && kept.pose.rotation() == start.rotation());
        EXPECT_EQ(kept_inliers, inliers);
      }
      const double cost = refining.refineIfLoose(&h, scored, &inliers, anything);
      const bool is_loose = static_cast<int>(matches.size()) == candidates.num_usable && start_cost > explained_cost;
      loose += is_loose;
      if (decoy) EXPECT_FALSE(is_loose);
      if (!is_loose || cost == start_cost) {  // scored as it is
        EXPECT_EQ(cost, start_cost);
        EXPECT_TRUE(h.pose.translation() == start.translation() && h.pose.rotation() == start.rotation());
        continue;
      }
      ++refined;
      EXPECT_LT(cost, start_cost);
      std::vector<ObjectCorrespondence> rematched;
      EXPECT_NEAR(cost, scorer.cost(h.pose, pipeline::kRankingIoUVertices, &rematched), 1e-12);
      EXPECT_EQ(inliers, static_cast<int>(rematched.size()));
      // Exact observations: the refined pose is nearer the truth than the start.
      EXPECT_LT(positionError(h.pose, truth), positionError(start, truth));
    }
  }
  EXPECT_GE(loose, 15);
  EXPECT_GE(refined, loose - 2);
}
