// Candidate pairs and the count of usable triplets that decides between enumerating every
// triplet and sampling them.

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "pose/pipeline/candidates.hpp"

using namespace ellreloc;

// The count equals a brute-force enumeration of the triplets of pairs with three distinct
// observations, for pair lists in PROSAC order (observations interleaved); observations without
// a candidate (not usable) add nothing.
TEST(Candidates, UsableTripletsCountsTripletsOfDistinctObservations) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 30; ++trial) {
    pipeline::Candidates c;
    const int observations = 1 + trial % 7;
    c.of_observation.resize(static_cast<size_t>(observations));
    for (int o = 0; o < observations; ++o) {
      const int candidates = std::uniform_int_distribution<int>(0, 6)(rng);
      for (int j = 0; j < candidates; ++j) {
        c.of_observation[static_cast<size_t>(o)].push_back(j);
        c.pairs.push_back({o, j, 0.0});
      }
    }
    std::shuffle(c.pairs.begin(), c.pairs.end(), rng);
    const std::vector<pipeline::CandidatePair>& pairs = c.pairs;
    long brute = 0;
    for (size_t i = 0; i < pairs.size(); ++i)
      for (size_t j = i + 1; j < pairs.size(); ++j)
        for (size_t k = j + 1; k < pairs.size(); ++k)
          brute += pairs[i].observation != pairs[j].observation && pairs[i].observation != pairs[k].observation &&
                   pairs[j].observation != pairs[k].observation;
    EXPECT_DOUBLE_EQ(pipeline::usableTriplets(c), static_cast<double>(brute)) << "trial " << trial;
  }
  EXPECT_EQ(pipeline::usableTriplets(pipeline::Candidates{}), 0.0);
}

// With a pose region, a pair leaves the triplet search only if no camera in the region sees its
// object along its observation's bearing: observations made from random poses inside the region
// keep their pair, and pairs of objects far off the region's view are removed.
TEST(Candidates, WithinARegionEveryPairAPoseInItCouldSeeIsKept) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Intrinsics K(525.0, 525.0, 319.5, 239.5, 640, 480);
  ObjectMap map;
  for (int j = 0; j < 40; ++j)
    map.objects.push_back(
        {j, 1, "", Ellipsoid({3 * u(rng), 3 * u(rng), u(rng)}, {0.1, 0.1, 0.1}, Eigen::Matrix3d::Identity())});
  int kept_total = 0, pairs_total = 0;
  for (int trial = 0; trial < 20; ++trial) {
    PoseRegion region;
    region.pose = Pose::lookAt({3 * u(rng), 3 * u(rng), u(rng)}, {u(rng), u(rng), 0.0});
    region.radius_m = 0.2 + 0.3 * (u(rng) + 1.0);
    region.max_rotation_deg = 15.0 + 20.0 * (u(rng) + 1.0);
    // Observations of random objects from random poses in the region, each with every object as
    // its candidate.
    std::vector<Observation> observations;
    std::vector<int> seen;
    while (observations.size() < 12) {
      const Eigen::Vector3d axis(u(rng), u(rng), u(rng));
      const double angle = region.max_rotation_deg * M_PI / 180.0 * 0.5 * (u(rng) + 1.0);
      Eigen::Vector3d shift(u(rng), u(rng), u(rng));
      if (shift.norm() > 1.0) continue;
      const Pose p = Pose::fromCameraToWorld(
          region.pose.inverse().rotation() * Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix(),
          region.pose.center() + region.radius_m * shift);
      ASSERT_TRUE(region.admits(p));
      const int j = std::uniform_int_distribution<int>(0, 39)(rng);
      const Eigen::Vector3d x = p.transform(map.objects[static_cast<size_t>(j)].ellipsoid.center());
      if (!(x.z() > 0.1)) continue;
      Observation o;
      o.category = 1;
      o.ellipse = Ellipse(K.project(x), {10.0, 5.0}, 0.0);
      observations.push_back(o);
      seen.push_back(j);
    }
    pipeline::Candidates all;
    all.usable.assign(observations.size(), 1);
    all.num_usable = static_cast<int>(observations.size());
    all.of_observation.resize(observations.size());
    for (int o = 0; o < static_cast<int>(observations.size()); ++o)
      for (int j = 0; j < 40; ++j) {
        all.pairs.push_back({o, j, 1.0});
        all.of_observation[static_cast<size_t>(o)].push_back(j);
      }
    const pipeline::Candidates in = pipeline::candidatesWithinRegion(all, observations, map, K, region);
    EXPECT_EQ(in.num_usable, all.num_usable);
    EXPECT_EQ(in.usable, all.usable);
    for (size_t o = 0; o < observations.size(); ++o) {
      const int j = seen[o];
      EXPECT_TRUE(
          std::any_of(in.pairs.begin(), in.pairs.end(),
                      [&](const pipeline::CandidatePair& p) { return p.observation == int(o) && p.object == j; }))
          << "trial " << trial << ", observation " << o;
      const std::vector<int>& of = in.of_observation[o];
      EXPECT_NE(std::find(of.begin(), of.end(), j), of.end());
    }
    kept_total += static_cast<int>(in.pairs.size());
    pairs_total += static_cast<int>(all.pairs.size());
    // Without an angle bound every pair stays.
    PoseRegion any_angle = region;
    any_angle.max_rotation_deg = 180.0;
    EXPECT_EQ(pipeline::candidatesWithinRegion(all, observations, map, K, any_angle).pairs.size(), all.pairs.size());
  }
  // Objects all around the room: many pairs are out of every view the regions allow (46% here).
  EXPECT_LT(kept_total, 0.7 * pairs_total);
}
