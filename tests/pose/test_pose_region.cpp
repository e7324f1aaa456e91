#include <gtest/gtest.h>

#include <random>

#include "ellreloc/pose/object_relocalizer.hpp"
#include "ellreloc/pose/pose_region.hpp"
#include "ellreloc/sim/map_observations.hpp"
#include "fixtures/random_geometry.hpp"
#include "fixtures/twin_desks.hpp"

using namespace ellreloc;
using ellreloc::test::twinDesks;
using ellreloc::test::uniform;

TEST(PoseRegion, AdmitsExactlyThePosesWithinItsDistanceAndAngle) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 2000; ++trial) {
    PoseRegion region;
    region.pose = test::randomLookAtPose(rng);
    region.radius_m = uniform(rng, 0.1, 2.0);
    region.max_rotation_deg = trial % 4 == 0 ? 180.0 : uniform(rng, 5.0, 170.0);
    // Poses about the region's: moved up to twice its radius, turned up to twice its angle.
    const Eigen::Vector3d axis = Eigen::Vector3d(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1));
    const double angle = uniform(rng, 0.0, std::min(179.0, 2.0 * region.max_rotation_deg)) * M_PI / 180.0;
    const Eigen::Matrix3d turn = Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
    const Eigen::Vector3d shift =
        Eigen::Vector3d(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1)).normalized() *
        uniform(rng, 0.0, 2.0 * region.radius_m);
    const Pose p = Pose::fromCameraToWorld(region.pose.inverse().rotation() * turn, region.pose.center() + shift);
    // Independently: the distance between the centres, the angle by rotationErrorDeg's quaternion.
    const double distance = (p.center() - region.pose.center()).norm();
    const double turned = rotationErrorDeg(p.rotation(), region.pose.rotation());
    const double margin = 1e-6;
    if (std::abs(distance - region.radius_m) < margin || std::abs(turned - region.max_rotation_deg) < margin) continue;
    EXPECT_EQ(region.admits(p), distance <= region.radius_m && turned <= region.max_rotation_deg)
        << "distance " << distance << " of " << region.radius_m << ", angle " << turned << " of "
        << region.max_rotation_deg;
  }
}

TEST(PoseRegion, ValidityNamesNonFiniteAndOutOfRangeBounds) {
  PoseRegion ok;
  EXPECT_TRUE(ok.isValid());
  for (double r : {0.0, -1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    PoseRegion bad = ok;
    bad.radius_m = r;
    EXPECT_FALSE(bad.isValid()) << r;
  }
  for (double a : {0.0, -5.0, 180.5, std::nan("")}) {
    PoseRegion bad = ok;
    bad.max_rotation_deg = a;
    EXPECT_FALSE(bad.isValid()) << a;
  }
  PoseRegion nan_pose = ok;
  nan_pose.pose = Pose(Eigen::Matrix3d::Identity(), Eigen::Vector3d(std::nan(""), 0, 0));
  EXPECT_FALSE(nan_pose.isValid());
}

namespace {

Pose shifted(const Pose& p, const Eigen::Vector3d& by) {
  return Pose::fromCameraToWorld(p.inverse().rotation(), p.center() + by);
}

}  // namespace

TEST(PoseRegion, TheRegionChoosesBetweenLookAlikesAndEveryPoseLiesInIt) {
  const Intrinsics K = test::testIntrinsics();
  const ObjectMap map = twinDesks();
  const ObjectRelocalizer relocalizer(map, K);
  const Eigen::Vector3d twin_offset(test::kTwinDeskOffset, 0.0, 0.0);
  std::mt19937 rng(11);
  int trials = 0;
  while (trials < 20) {
    // A camera in front of the first desk, 0.8-1.4 m away, looking at it from above.
    const Eigen::Vector3d eye(uniform(rng, -0.4, 0.4), uniform(rng, -1.4, -0.8), uniform(rng, 0.4, 0.8));
    const Pose truth = Pose::lookAt(eye, Eigen::Vector3d(uniform(rng, -0.1, 0.1), 0.1, 0.1), Eigen::Vector3d::UnitZ());
    sim::MapObservationOptions exact;
    std::vector<int> object_of;
    const std::vector<Observation> observations = sim::observeMap(map, K, truth, exact, &rng, &object_of);
    if (observations.size() < 4) continue;
    for (int o : object_of) ASSERT_LT(o, 5) << "the view must not reach the second desk";
    ++trials;

    // Around where the host last tracked the camera, 30 cm and 10 degrees off the truth.
    PoseRegion region;
    const Eigen::Matrix3d turn = Eigen::AngleAxisd(10.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
    region.pose =
        Pose::fromCameraToWorld(truth.inverse().rotation() * turn, truth.center() + Eigen::Vector3d(0.3, 0.0, 0.0));
    region.radius_m = 1.0;
    region.max_rotation_deg = 30.0;
    const RelocalizationResult here = relocalizer.relocalize(observations, {}, std::nullopt, region);
    ASSERT_EQ(here.status, RelocalizationStatus::Success) << here.reason;
    EXPECT_LT((here.pose.center() - truth.center()).norm(), 0.01);
    EXPECT_LT(rotationErrorDeg(here.pose.rotation(), truth.rotation()), 0.2);
    EXPECT_TRUE(region.admits(here.pose));
    for (const ObjectCorrespondence& m : here.inliers) EXPECT_EQ(map.objects[m.object].id, object_of[m.observation]);

    // The same region about the second desk: the twin pose, which explains the image as well.
    PoseRegion there = region;
    there.pose = shifted(region.pose, twin_offset);
    const RelocalizationResult twin = relocalizer.relocalize(observations, {}, std::nullopt, there);
    ASSERT_EQ(twin.status, RelocalizationStatus::Success) << twin.reason;
    EXPECT_LT((twin.pose.center() - (truth.center() + twin_offset)).norm(), 0.01);
    for (const ObjectCorrespondence& m : twin.inliers)
      EXPECT_EQ(map.objects[m.object].id, 10 + object_of[m.observation]);

    // A region between the desks that holds neither pose: no pose, or one inside it.
    PoseRegion between = region;
    between.pose = shifted(region.pose, 0.5 * twin_offset);
    between.radius_m = 0.5;
    const RelocalizationResult none = relocalizer.relocalize(observations, {}, std::nullopt, between);
    if (none.status == RelocalizationStatus::Success || none.status == RelocalizationStatus::LowEvidence)
      EXPECT_TRUE(between.admits(none.pose));
  }
}

TEST(PoseRegion, AnInvalidRegionIsInvalidInput) {
  const Intrinsics K = test::testIntrinsics();
  const ObjectMap map = twinDesks();
  const Pose truth = Pose::lookAt({0.0, -1.0, 0.6}, {0.0, 0.1, 0.1}, Eigen::Vector3d::UnitZ());
  const std::vector<Observation> observations = sim::observeMap(map, K, truth, sim::MapObservationOptions{});
  PoseRegion bad;
  bad.pose = truth;
  bad.radius_m = 0.0;
  const RelocalizationResult r = ObjectRelocalizer(map, K).relocalize(observations, {}, std::nullopt, bad);
  EXPECT_EQ(r.status, RelocalizationStatus::InvalidInput);
  EXPECT_NE(r.reason.find("pose region"), std::string::npos) << r.reason;
}
