#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "ellreloc/mapping/floor.hpp"
#include "ellreloc/mapping/mapper.hpp"
#include "fixtures/sim_sequence.hpp"

namespace ellreloc {
namespace {

double angleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) * 180.0 / M_PI;
}

/// The same rendered frame expressed in a world frame tilted by R_t: x' = R_t x, so the
/// world->camera pose becomes pose * R_t^T and the floor's normal R_t z.
Pose tiltedPose(const Pose& pose, const Eigen::Matrix3d& R_t) {
  return pose * Pose(R_t.transpose(), Eigen::Vector3d::Zero());
}

TEST(Floor, FindsTheFloorNormalInARenderedFrameInAnyWorldFrame) {
  const test::SimSequence seq = test::makeSimSequence(sim::ScenePreset::Office, 2, 6, test::mappingNoise());
  const Eigen::Matrix3d R_t = Eigen::AngleAxisd(0.15, Eigen::Vector3d(1, 2, 0).normalized()).toRotationMatrix();
  for (const auto& kf : seq.keyframes) {
    const auto plane = estimateFloor(seq.K, kf.pose, kf.depth);
    ASSERT_TRUE(plane);
    EXPECT_LT(angleDeg(plane->up, Eigen::Vector3d::UnitZ()), 1.0);
    FloorOptions tilted_prior;  // the prior stays z: the true up is 8.6 degrees away
    const auto tilted = estimateFloor(seq.K, tiltedPose(kf.pose, R_t), kf.depth, tilted_prior);
    ASSERT_TRUE(tilted);
    EXPECT_LT(angleDeg(tilted->up, R_t * Eigen::Vector3d::UnitZ()), 1.0);
  }
}

TEST(Floor, NoFloorNoAnswer) {
  const Intrinsics K(500, 500, 319.5, 239.5, 640, 480);
  DepthImage wall;
  wall.width = 640;
  wall.height = 480;
  wall.metres.assign(640 * 480, 2.0f);  // a wall straight ahead of a horizontal camera
  const Pose camera = Pose::lookAt(Eigen::Vector3d(0, 0, 1.5), Eigen::Vector3d(0, 5, 1.5));
  EXPECT_FALSE(estimateFloor(K, camera, wall));
  DepthImage empty = wall;
  std::fill(empty.metres.begin(), empty.metres.end(), 0.0f);
  EXPECT_FALSE(estimateFloor(K, camera, empty));
  // Looking along world z the same depth is a floor, one wall's depth away (2 m).
  const auto plane = estimateFloor(K, Pose(), wall);
  ASSERT_TRUE(plane);
  EXPECT_NEAR(plane->offset, 2.0, 1e-4);
  EXPECT_NEAR(plane->inlier_share, 1.0, 1e-9);
  DepthImage small = wall;
  small.width = 320;
  EXPECT_FALSE(estimateFloor(K, camera, small));
}

TEST(Floor, MapperUsesTheFloorForYawWhenAsked) {
  const test::SimSequence seq = test::makeSimSequence(sim::ScenePreset::Sparse, 3, 30, test::mappingNoise());
  const Eigen::Matrix3d R_t = Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  MapperOptions opt;
  opt.estimate_up_from_floor = true;
  Mapper mapper(seq.K, opt);
  for (const auto& kf : seq.keyframes) mapper.addKeyframe(tiltedPose(kf.pose, R_t), kf.detections, &kf.depth);
  EXPECT_LT(angleDeg(mapper.stats().up, R_t * Eigen::Vector3d::UnitZ()), 0.5);
  const ObjectMap map = mapper.map();
  ASSERT_FALSE(map.objects.empty());
  for (const MappedObject& m : mapper.objects()) {
    ASSERT_TRUE(m.cuboid);
    EXPECT_LT(angleDeg(m.cuboid->rotation.col(2), R_t * Eigen::Vector3d::UnitZ()), 0.5);
  }
}

}  // namespace
}  // namespace ellreloc
