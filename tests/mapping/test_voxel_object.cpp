#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <set>

#include "ellreloc/core/statistics.hpp"
#include "ellreloc/error.hpp"
#include "ellreloc/mapping/voxel_object.hpp"

namespace ellreloc {
namespace {

const Intrinsics kVoxelCamera(500.0, 500.0, 319.5, 239.5, 640, 480);

DepthImage flatDepth(float metres) {
  DepthImage d;
  d.width = kVoxelCamera.width;
  d.height = kVoxelCamera.height;
  d.metres.assign(static_cast<size_t>(d.width) * d.height, metres);
  return d;
}

BinaryMask rectMask(int x1, int y1, int x2, int y2) {
  BinaryMask m(kVoxelCamera.height, kVoxelCamera.width);
  for (int y = y1; y <= y2; ++y)
    for (int x = x1; x <= x2; ++x) m.at(x, y) = 1;
  return m;
}

/// The world point that pixel (u, v) of kVoxelCamera at `camera` (world->camera) sees at `depth`.
Eigen::Vector3d pointOfPixel(const Pose& camera, double u, double v, double depth) {
  return camera.inverse().transform(Eigen::Vector3d((u - kVoxelCamera.cx) / kVoxelCamera.fx * depth,
                                                    (v - kVoxelCamera.cy) / kVoxelCamera.fy * depth, depth));
}

/// Eq. 1 of the paper with prior 0.5: the posterior after an observation with P(n | z) = pz.
double bayes(double prior, double pz) { return 1.0 / (1.0 + (1.0 - pz) / pz * (1.0 - prior) / prior); }

TEST(VoxelObject, HitsFollowTheBayesFilterAndClamp) {
  VoxelObject v;
  const Pose camera;  // at the origin, looking along +z
  const BinaryMask mask = rectMask(300, 220, 340, 260);
  const Eigen::Vector3d on_plane(0.001, 0.001, 2.005);  // well inside one voxel
  v.integrate(kVoxelCamera, camera, flatDepth(2.005f), mask);
  EXPECT_NEAR(v.probabilityAt(on_plane), 0.7, 1e-6);
  v.integrate(kVoxelCamera, camera, flatDepth(2.005f), mask);
  EXPECT_NEAR(v.probabilityAt(on_plane), bayes(0.7, 0.7), 1e-6);
  for (int i = 0; i < 20; ++i) v.integrate(kVoxelCamera, camera, flatDepth(2.005f), mask);
  EXPECT_NEAR(v.probabilityAt(on_plane), 0.97, 1e-6);                // OctoMap-style clamping
  EXPECT_DOUBLE_EQ(v.probabilityAt(Eigen::Vector3d(0, 0, 5)), 0.5);  // unknown
}

TEST(VoxelObject, AbsorbingAnotherModelAddsItsEvidence) {
  const Pose camera;
  const BinaryMask left = rectMask(280, 220, 310, 260), right = rectMask(330, 220, 360, 260);
  // Two models of one plane from the same keyframe: fused, each voxel holds what one model
  // integrating that keyframe twice holds (eq. 1 with independent observations: log-odds add).
  VoxelObject a, b, twice;
  a.integrate(kVoxelCamera, camera, flatDepth(2.005f), left);
  b.integrate(kVoxelCamera, camera, flatDepth(2.005f), left);
  twice.integrate(kVoxelCamera, camera, flatDepth(2.005f), left);
  twice.integrate(kVoxelCamera, camera, flatDepth(2.005f), left);
  a.absorb(b);
  ASSERT_EQ(a.size(), twice.size());
  for (const Eigen::Vector3d& c : twice.occupiedCentres(0.01))
    EXPECT_NEAR(a.probabilityAt(c), twice.probabilityAt(c), 1e-6);
  // A model of another part of the object: its voxels join with their own evidence.
  VoxelObject other;
  other.integrate(kVoxelCamera, camera, flatDepth(2.005f), right);
  a.absorb(other);
  EXPECT_EQ(a.size(), twice.size() + other.size());
  for (const Eigen::Vector3d& c : other.occupiedCentres(0.01)) EXPECT_NEAR(a.probabilityAt(c), 0.7, 1e-6);
  for (const Eigen::Vector3d& c : twice.occupiedCentres(0.01)) EXPECT_NEAR(a.probabilityAt(c), bayes(0.7, 0.7), 1e-6);
  for (int i = 0; i < 20; ++i) a.absorb(b);
  EXPECT_NEAR(a.probabilityAt(twice.occupiedCentres(0.01).front()), 0.97, 1e-6);  // clamped as in integrate()
}

TEST(VoxelObject, VoxelsLieOnTheBackProjectedSurfaceAndProjectToTheMask) {
  VoxelObject v;
  const Pose camera = Pose::lookAt(Eigen::Vector3d(0.3, -2.0, 1.2), Eigen::Vector3d(0.3, 0.5, 0.8));
  const BinaryMask mask = rectMask(250, 200, 390, 300);
  const auto up = v.integrate(kVoxelCamera, camera, flatDepth(2.5f), mask);
  EXPECT_EQ(up.hits, up.added);
  ASSERT_GT(v.size(), 100u);
  const double half_diagonal = std::sqrt(3.0) * 0.5 * v.options().voxel_size;
  for (const Eigen::Vector3d& c : v.occupiedCentres()) {
    // Independent check: the voxel centre is within half a voxel diagonal of the plane z_c = 2.5.
    EXPECT_LE(std::abs(camera.transform(c).z() - 2.5), half_diagonal + 1e-9);
  }
  const auto box = v.projectedBox(kVoxelCamera, camera);
  ASSERT_TRUE(box);
  const double voxel_px = 500.0 * v.options().voxel_size / 2.5;  // one voxel at that depth
  EXPECT_NEAR(box->x1, 250, voxel_px);
  EXPECT_NEAR(box->x2, 390, voxel_px);
  EXPECT_NEAR(box->y1, 200, voxel_px);
  EXPECT_NEAR(box->y2, 300, voxel_px);
}

// With an ellipsoid, only the voxels within it grown twice make the box: a strip of strays 150
// px to the right of a plane's voxels stretches the plain box and not that one.
TEST(VoxelObject, TheBoxNearAnEllipsoidLeavesStraysOut) {
  VoxelObject v;
  const Pose camera = Pose::lookAt(Eigen::Vector3d(0.3, -2.0, 1.2), Eigen::Vector3d(0.3, 0.5, 0.8));
  v.integrate(kVoxelCamera, camera, flatDepth(2.5f), rectMask(250, 200, 390, 300));
  const std::vector<Eigen::Vector3d> plane = v.occupiedCentres();
  VoxelObject strays;
  strays.integrate(kVoxelCamera, camera, flatDepth(2.5f), rectMask(540, 240, 545, 260));
  v.absorb(strays);
  // The plane's ellipsoid: its voxels' centre, axes along the camera's x and y at that depth
  // (half of 140 and 100 px at 500 px per 2.5 m), a thin third along the camera's z.
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& c : plane) centre += c;
  centre /= static_cast<double>(plane.size());
  const Eigen::Matrix3d axes_in_world = camera.rotation().transpose();  // columns: the camera's x, y, z
  const Ellipsoid ellipsoid(centre, Eigen::Vector3d(0.35, 0.25, 0.01), axes_in_world);
  const auto plain = v.projectedBox(kVoxelCamera, camera);
  const auto near = v.projectedBox(kVoxelCamera, camera, 10, &ellipsoid);
  ASSERT_TRUE(plain && near);
  const double voxel_px = 500.0 * v.options().voxel_size / 2.5;
  EXPECT_NEAR(plain->x2, 545, voxel_px);
  EXPECT_NEAR(near->x1, 250, voxel_px);
  EXPECT_NEAR(near->x2, 390, voxel_px);
  EXPECT_NEAR(near->y1, 200, voxel_px);
  EXPECT_NEAR(near->y2, 300, voxel_px);
  // Shrunk, it cuts the plane's own sides off: 0.8 of its 70 px half-width each side.
  const auto tight = v.projectedBox(kVoxelCamera, camera, 10, &ellipsoid, 0.8);
  ASSERT_TRUE(tight);
  EXPECT_NEAR(tight->x1, 320 - 56, 2 * voxel_px);  // the voxels step by one each way
  EXPECT_NEAR(tight->x2, 320 + 56, 2 * voxel_px);
}

// Each voxel keeps the mean of the depth points that fell in it: on a plane, the means lie on
// the plane (to the storage's 1/65536 of a voxel) where the centres are up to half a voxel off;
// fused models average their points by count.
TEST(VoxelObject, PointMeansLieOnTheSurface) {
  VoxelObject v;
  const Pose camera = Pose::lookAt(Eigen::Vector3d(0.3, -2.0, 1.2), Eigen::Vector3d(0.3, 0.5, 0.8));
  v.integrate(kVoxelCamera, camera, flatDepth(2.5f), rectMask(250, 200, 390, 300));
  const std::vector<Eigen::Vector3d> means = v.occupiedPointMeans(), centres = v.occupiedCentres();
  ASSERT_EQ(means.size(), centres.size());
  ASSERT_GT(means.size(), 100u);
  const double voxel = v.options().voxel_size;
  double farthest_centre = 0.0;
  for (size_t i = 0; i < means.size(); ++i) {
    EXPECT_NEAR(camera.transform(means[i]).z(), 2.5, 1e-5);
    EXPECT_LE((means[i] - centres[i]).cwiseAbs().maxCoeff(), 0.5 * voxel + 1e-9);  // in its own voxel
    farthest_centre = std::max(farthest_centre, std::abs(camera.transform(centres[i]).z() - 2.5));
  }
  EXPECT_GT(farthest_centre, 0.3 * voxel);

  // A fronto-parallel plane inside one layer of voxels (z in [2.00, 2.01)): one model saw it at
  // 2.0031 once, the other at 2.0071 three times over the same pixels; fused, every voxel's
  // mean is 2.0031 + 3/4 of the way to 2.0071 wherever both models hold it evenly.
  VoxelObject a, b;
  const BinaryMask mask = rectMask(300, 220, 340, 260);
  a.integrate(kVoxelCamera, Pose(), flatDepth(2.0031f), mask);
  for (int i = 0; i < 3; ++i) b.integrate(kVoxelCamera, Pose(), flatDepth(2.0071f), mask);
  a.absorb(b);
  std::vector<double> z;
  for (const Eigen::Vector3d& m : a.occupiedPointMeans(0.01)) {
    EXPECT_GE(m.z(), 2.0031 - 1e-5);
    EXPECT_LE(m.z(), 2.0071 + 1e-5);
    z.push_back(m.z());
  }
  EXPECT_NEAR(median(z), 2.0031 + 0.75 * 0.004, 2e-4);
}

// Moved rigidly, a plane seen by one camera is the plane that camera sees once moved with it:
// every point mean moves exactly (to the storage's 1/65536 of a voxel) and stays in its voxel,
// the probabilities go with them, and two means that land in one voxel become one.
TEST(VoxelObject, MovedRigidlyTheVoxelsFollowTheirPoints) {
  VoxelObject v;
  const Pose camera = Pose::lookAt(Eigen::Vector3d(0.3, -2.0, 1.2), Eigen::Vector3d(0.3, 0.5, 0.8));
  const BinaryMask mask = rectMask(250, 200, 390, 300);
  v.integrate(kVoxelCamera, camera, flatDepth(2.5f), mask);
  v.integrate(kVoxelCamera, camera, flatDepth(2.5f), rectMask(250, 200, 320, 300));  // the left part twice
  const std::vector<Eigen::Vector3d> before = v.occupiedPointMeans(0.01);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  const Eigen::Vector3d t(1.234, -0.5, 3.0);
  VoxelObject moved = v;
  moved.moveRigidly(R, t);
  const Pose moved_camera = camera * Pose(R, t).inverse();  // sees the moved plane as `camera` saw it
  const std::vector<Eigen::Vector3d> after = moved.occupiedPointMeans(0.01), centres = moved.occupiedCentres(0.01);
  ASSERT_EQ(after.size(), centres.size());
  EXPECT_LE(after.size(), before.size());
  EXPECT_GT(after.size(), before.size() * 8 / 10);  // a rotated grid merges a few neighbours
  const double voxel = v.options().voxel_size;
  for (size_t i = 0; i < after.size(); ++i) {
    EXPECT_NEAR(moved_camera.transform(after[i]).z(), 2.5, 1e-5);
    EXPECT_LE((after[i] - centres[i]).cwiseAbs().maxCoeff(), 0.5 * voxel + 1e-9);
  }
  // Each moved mean is a mean of moved points: the nearest moved point lies within a voxel.
  for (const Eigen::Vector3d& a : after) {
    double nearest = 1e9;
    for (const Eigen::Vector3d& b : before) nearest = std::min(nearest, (R * b + t - a).norm());
    EXPECT_LT(nearest, voxel);
  }
  // The evidence goes with the points: the left part, hit twice, and the right part, hit once
  // and then missed (outside the second mask).
  const auto meanNear = [&](double u, double v_px) {
    const Eigen::Vector3d x = pointOfPixel(camera, u, v_px, 2.5);
    return *std::min_element(before.begin(), before.end(), [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
      return (a - x).norm() < (b - x).norm();
    });
  };
  const Eigen::Vector3d left = meanNear(260, 250), right = meanNear(380, 250);
  EXPECT_NEAR(v.probabilityAt(left), bayes(0.7, 0.7), 1e-6);
  EXPECT_NEAR(v.probabilityAt(right), bayes(0.7, 0.3), 1e-6);
  EXPECT_NEAR(moved.probabilityAt(R * left + t), bayes(0.7, 0.7), 1e-6);
  EXPECT_NEAR(moved.probabilityAt(R * right + t), bayes(0.7, 0.3), 1e-6);
  // Moved back, the means are where they were.
  moved.moveRigidly(R.transpose(), -R.transpose() * t);
  const std::vector<Eigen::Vector3d> back = moved.occupiedPointMeans(0.01);
  ASSERT_FALSE(back.empty());
  for (const Eigen::Vector3d& a : back) {
    double nearest = 1e9;
    for (const Eigen::Vector3d& b : before) nearest = std::min(nearest, (b - a).norm());
    EXPECT_LT(nearest, voxel);
  }
}

// Each voxel moves with the keyframe that last hit it: a plane's left part hit by both
// keyframes, its right part by the first only (the second misses it, outside its mask).
TEST(VoxelObject, MovedWithTheirKeyframesEachVoxelFollowsTheKeyframeThatLastHitIt) {
  VoxelObject v;
  const Pose camera = Pose::lookAt(Eigen::Vector3d(0.3, -2.0, 1.2), Eigen::Vector3d(0.3, 0.5, 0.8));
  v.integrate(kVoxelCamera, camera, flatDepth(2.5f), rectMask(250, 200, 390, 300));
  v.integrate(kVoxelCamera, camera, flatDepth(2.5f), rectMask(250, 200, 320, 300));
  const Eigen::Vector3d left = pointOfPixel(camera, 260, 250, 2.5), right = pointOfPixel(camera, 380, 250, 2.5);
  const Pose first(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, 1)),
      second(Eigen::Matrix3d::Identity(), Eigen::Vector3d(1, 0, 0));
  VoxelObject each = v;
  each.moveWithKeyframes({first, second});
  EXPECT_NEAR(each.probabilityAt(first.transform(right)), bayes(0.7, 0.3), 1e-6);
  EXPECT_NEAR(each.probabilityAt(second.transform(left)), bayes(0.7, 0.7), 1e-6);
  EXPECT_EQ(each.probabilityAt(second.transform(right)), 0.5);  // nothing there: the prior
  EXPECT_EQ(each.probabilityAt(first.transform(left)), 0.5);
  EXPECT_EQ(each.size(), v.size());  // translations by whole metres: no two voxels meet
  // One motion for all, as moveRigidly; none, nothing moves.
  VoxelObject all = v, rigid = v, still = v;
  all.moveWithKeyframes({first});
  rigid.moveRigidly(first.rotation(), first.translation());
  EXPECT_EQ(all.occupiedPointMeans(0.01), rigid.occupiedPointMeans(0.01));
  still.moveWithKeyframes({});
  EXPECT_EQ(still.occupiedPointMeans(0.01), v.occupiedPointMeans(0.01));
}

// A model absorbed into another keeps its keyframes: its integrations count after the other's,
// so its voxels move with its own keyframes' corrections, not with the other's latest.
TEST(VoxelObject, AbsorbedVoxelsMoveWithTheKeyframesThatPlacedThem) {
  const Pose camera = Pose::lookAt(Eigen::Vector3d(0.3, -2.0, 1.2), Eigen::Vector3d(0.3, 0.5, 0.8));
  VoxelObject older, younger;  // the plane's left part, twice; its right part, once
  older.integrate(kVoxelCamera, camera, flatDepth(2.5f), rectMask(250, 200, 310, 300));
  older.integrate(kVoxelCamera, camera, flatDepth(2.5f), rectMask(250, 200, 310, 300));
  younger.integrate(kVoxelCamera, camera, flatDepth(2.5f), rectMask(330, 200, 390, 300));
  older.absorb(younger);
  const Eigen::Vector3d left = pointOfPixel(camera, 260, 250, 2.5), right = pointOfPixel(camera, 380, 250, 2.5);
  const Pose first(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, 1)),
      second(Eigen::Matrix3d::Identity(), Eigen::Vector3d(1, 0, 0)),
      third(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 1, 0));
  older.moveWithKeyframes({first, second, third});  // the older model's two keyframes, the younger's one
  EXPECT_NEAR(older.probabilityAt(second.transform(left)), bayes(0.7, 0.7), 1e-6);
  EXPECT_NEAR(older.probabilityAt(third.transform(right)), 0.7, 1e-6);
  EXPECT_EQ(older.probabilityAt(second.transform(right)), 0.5);  // not with the older model's latest
  EXPECT_EQ(older.probabilityAt(first.transform(left)), 0.5);
}

TEST(VoxelObject, MissesOutsideTheMaskAndInFreeSpaceButNotWhenHidden) {
  const Pose camera;
  const BinaryMask full = rectMask(300, 220, 340, 260);
  // Points well inside two voxels: the left one's centre (-0.05, 0.01, 2.01) projects to x = 307,
  // inside `full` only; the right one's (0.07, 0.01, 2.01) to x = 337, inside both masks.
  const Eigen::Vector3d left(-0.051, 0.001, 2.005);
  const Eigen::Vector3d right(0.071, 0.001, 2.005);
  {
    VoxelObject v;
    v.integrate(kVoxelCamera, camera, flatDepth(2.005f), full);
    v.integrate(kVoxelCamera, camera, flatDepth(2.005f), rectMask(320, 220, 340, 260));
    EXPECT_NEAR(v.probabilityAt(left), bayes(0.7, 0.3), 1e-6);  // seen outside the mask
    EXPECT_NEAR(v.probabilityAt(right), bayes(0.7, 0.7), 1e-6);
  }
  {
    VoxelObject v;
    v.integrate(kVoxelCamera, camera, flatDepth(2.005f), full);
    v.integrate(kVoxelCamera, camera, flatDepth(3.005f), full);  // the surface moved back: free space
    EXPECT_NEAR(v.probabilityAt(left), bayes(0.7, 0.3), 1e-6);
  }
  {
    VoxelObject v;
    v.integrate(kVoxelCamera, camera, flatDepth(2.005f), full);
    v.integrate(kVoxelCamera, camera, flatDepth(1.0f), rectMask(0, 0, 10, 10));  // something in front hides it
    EXPECT_NEAR(v.probabilityAt(left), 0.7, 1e-6);
  }
  {
    VoxelObject v;
    v.integrate(kVoxelCamera, camera, flatDepth(2.005f), full);
    const auto up = v.integrate(kVoxelCamera, camera, flatDepth(0.0f), rectMask(0, 0, 10, 10));  // no reading
    EXPECT_EQ(up.hits + up.misses, 0);
    EXPECT_NEAR(v.probabilityAt(left), 0.7, 1e-6);
  }
}

TEST(VoxelObject, DepthGateDropsMaskPixelsOnTheBackground) {
  DepthImage depth = flatDepth(2.005f);
  for (int y = 0; y < kVoxelCamera.height; ++y)
    for (int x = 0; x < 310; ++x)
      depth.metres[static_cast<size_t>(y) * kVoxelCamera.width + x] = 4.0f;  // a wall behind
  VoxelObject v;
  v.integrate(kVoxelCamera, Pose(), depth, rectMask(300, 220, 360, 260));  // a sixth of the mask bleeds onto the wall
  for (const Eigen::Vector3d& c : v.occupiedCentres()) EXPECT_LT(c.z(), 2.1);
  VoxelOptions no_gate;
  no_gate.depth_gate_sigmas = 0.0;
  VoxelObject w(no_gate);
  w.integrate(kVoxelCamera, Pose(), depth, rectMask(300, 220, 360, 260));
  EXPECT_GT(w.size(), v.size());
}

TEST(VoxelObject, CountNearIsEquationFourCounting) {
  VoxelObject a, b, far;
  a.integrate(kVoxelCamera, Pose(), flatDepth(2.005f), rectMask(300, 220, 340, 260));
  b.integrate(kVoxelCamera, Pose(), flatDepth(2.005f), rectMask(320, 220, 360, 260));  // half overlapping
  far.integrate(kVoxelCamera, Pose(), flatDepth(3.005f), rectMask(300, 220, 340, 260));
  const long n = static_cast<long>(a.occupiedCount());
  EXPECT_EQ(a.countNear(a, 0.0), n);
  EXPECT_EQ(a.countNear(far, 0.05), 0);
  // b covers x >= 320 px; a's voxels with x_c >= (320 - 319.5) / 500 * 2 - r are near b's.
  // Brute force over every pair, at radii below, at and above a voxel and across several.
  for (const double r : {0.005, 0.01, 0.015, 0.03, 0.05}) {
    long expected = 0;
    for (const Eigen::Vector3d& c : a.occupiedCentres()) {
      bool near = false;
      for (const Eigen::Vector3d& d : b.occupiedCentres()) near = near || (c - d).norm() <= r + 1e-9;
      expected += near;
    }
    EXPECT_EQ(a.countNear(b, r), expected) << r;
    EXPECT_GT(expected, n / 3) << r;
    EXPECT_LT(expected, n) << r;
  }
}

TEST(VoxelObject, PruneAndMemoryBudget) {
  VoxelOptions small;
  small.max_voxels = 100;
  VoxelObject v(small);
  v.integrate(kVoxelCamera, Pose(), flatDepth(2.005f), rectMask(200, 200, 400, 300));
  EXPECT_LE(v.size(), 100u);
  EXPECT_GT(v.memoryBytes(), 100u * 8u);
  VoxelObject w;
  w.integrate(kVoxelCamera, Pose(), flatDepth(2.005f), rectMask(300, 220, 340, 260));
  w.integrate(kVoxelCamera, Pose(), flatDepth(2.005f), rectMask(320, 220, 340, 260));
  const size_t before = w.size();
  const size_t removed = w.prune(0.6);  // the left half dropped to 0.5
  EXPECT_GT(removed, 0u);
  EXPECT_EQ(w.size(), before - removed);
  for (const Eigen::Vector3d& c : w.occupiedCentres()) EXPECT_GT(c.x(), -0.01);
}

// The voxels are found by position through an index of their own: after it grows, after
// pruning and after the memory budget cut it, every voxel is found where it is (a voxel the
// index lost reads as unknown, 0.5) and none is held twice (a lost one would be made again).
TEST(VoxelObject, EveryVoxelIsFoundAfterGrowthPruningAndTheBudget) {
  VoxelOptions budget;
  budget.max_voxels = 5000;
  VoxelObject v(budget);
  size_t pruned = 0;
  for (int k = 0; k < 12; ++k) {
    // Each keyframe a plane further and to the right: the last one's voxels are seen outside
    // the mask (a miss), and every few keyframes the pruning takes them.
    const DepthImage depth = flatDepth(1.5f + 0.013f * static_cast<float>(k));
    const BinaryMask mask = rectMask(30 * k, 100, 30 * k + 150, 300);
    v.integrate(kVoxelCamera, Pose(), depth, mask);
    if (k % 4 == 3) pruned += v.prune(0.8);
    v.integrate(kVoxelCamera, Pose(), depth, mask);
  }
  EXPECT_GT(pruned, 0u);
  EXPECT_EQ(v.size(), 5000u);
  const std::vector<Eigen::Vector3d> strong = v.occupiedCentres(0.75);
  ASSERT_GT(strong.size(), 1000u);
  for (const Eigen::Vector3d& c : strong) ASSERT_GE(v.probabilityAt(c), 0.75) << c.transpose();
  std::set<std::array<long, 3>> cells;
  for (const Eigen::Vector3d& c : v.occupiedCentres(1e-6))
    cells.insert({std::lround(c.x() / 0.01 - 0.5), std::lround(c.y() / 0.01 - 0.5), std::lround(c.z() / 0.01 - 0.5)});
  EXPECT_EQ(cells.size(), v.size());
}

TEST(VoxelObject, BadInputIsAnErrorNotACrash) {
  VoxelObject v;
  const BinaryMask mask = rectMask(300, 220, 340, 260);
  BinaryMask wrong(240, 320);
  EXPECT_THROW(v.integrate(kVoxelCamera, Pose(), flatDepth(2.005f), wrong), Error);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(
      v.integrate(kVoxelCamera, Pose(Eigen::Matrix3d::Identity(), Eigen::Vector3d(nan, 0, 0)), flatDepth(2.005f), mask),
      Error);
  DepthImage small = flatDepth(2.005f);
  small.width = 320;
  EXPECT_THROW(v.integrate(kVoxelCamera, Pose(), small, mask), Error);
  EXPECT_EQ(v.size(), 0u);
  DepthImage nan_depth = flatDepth(std::numeric_limits<float>::quiet_NaN());
  EXPECT_EQ(v.integrate(kVoxelCamera, Pose(), nan_depth, mask).hits, 0);
}

TEST(VoxelObject, MajorityFilterAndBoxMasks) {
  BinaryMask m = rectMask(100, 100, 120, 120);
  m.at(110, 110) = 0;  // a pinhole
  m.at(50, 50) = 1;    // a speck
  const BinaryMask f = majorityFiltered(m);
  EXPECT_EQ(f.at(110, 110), 1);
  EXPECT_EQ(f.at(50, 50), 0);
  EXPECT_EQ(f.at(105, 105), 1);
  EXPECT_EQ(f.at(100, 100), 0);  // a corner has 4 of 9 votes
  // A box [x1, x2] holds the pixels whose centres lie inside it.
  const BinaryMask b = maskFromBox(Box(9.5, 19.5, 14.5, 29.5), 640, 480);
  EXPECT_EQ(b.x0, 10);
  EXPECT_EQ(b.y0, 20);
  EXPECT_EQ(b.width, 5);
  EXPECT_EQ(b.height, 10);
  EXPECT_EQ(b.count(), 50);
  EXPECT_EQ(maskFromBox(Box(700, 10, 800, 20), 640, 480).count(), 0);
}

}  // namespace
}  // namespace ellreloc
