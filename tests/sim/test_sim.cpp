#include <gtest/gtest.h>

#include <map>

#include "ellreloc/core/distances.hpp"
#include "ellreloc/core/projection.hpp"
#include "ellreloc/core/mask.hpp"
#include "ellreloc/sim/render.hpp"
#include "ellreloc/sim/scene.hpp"

using namespace ellreloc;
using namespace ellreloc::sim;

namespace {

const Intrinsics kK(525.0, 525.0, 319.5, 239.5, 640, 480);

}  // namespace

TEST(Scene, PresetsAreDeterministicAndPlausible) {
  for (ScenePreset preset : {ScenePreset::Office, ScenePreset::Cluttered, ScenePreset::Sparse}) {
    const Scene a = makeScene(preset, 7), b = makeScene(preset, 7), c = makeScene(preset, 8);
    ASSERT_EQ(a.objects.size(), b.objects.size());
    for (size_t i = 0; i < a.objects.size(); ++i) {
      EXPECT_EQ(a.objects[i].category, b.objects[i].category);
      EXPECT_EQ(a.objects[i].box_center, b.objects[i].box_center);
    }
    EXPECT_NE(a.objects[0].box_center, c.objects[0].box_center);
    const size_t expected = preset == ScenePreset::Office ? 20 : preset == ScenePreset::Cluttered ? 40 : 6;
    EXPECT_EQ(a.objects.size(), expected) << toString(preset);
    for (const SimObject& o : a.objects) {
      // Yaw only: the rotation keeps z.
      EXPECT_LT((o.box_rotation.col(2) - Eigen::Vector3d::UnitZ()).norm(), 1e-12);
      // Resting on the floor (0) or a table (0.75 / 1.1 m).
      const double bottom = o.box_center(2) - o.box_half(2);
      EXPECT_TRUE(std::abs(bottom) < 1e-9 || std::abs(bottom - 0.75) < 1e-9 || std::abs(bottom - 1.1) < 1e-9) << bottom;
      EXPECT_TRUE(o.ellipsoid().isValid());
      // Every part lies inside the bounding cuboid (its corners, with a little slack).
      for (const Primitive& p : o.parts)
        for (int k = 0; k < 8; ++k) {
          const Eigen::Vector3d corner =
              p.center + p.rotation * Eigen::Vector3d((k & 1 ? 1 : -1) * p.half(0), (k & 2 ? 1 : -1) * p.half(1),
                                                      (k & 4 ? 1 : -1) * p.half(2));
          const Eigen::Vector3d local = o.box_rotation.transpose() * (corner - o.box_center);
          EXPECT_LE((local.cwiseAbs() - o.box_half).maxCoeff(), 1e-6) << o.label;
        }
    }
    EXPECT_GT(a.points.size(), 5 * a.objects.size());
  }
  // Cluttered: many objects of the same category.
  std::map<int, int> counts;
  for (const SimObject& o : makeScene(ScenePreset::Cluttered, 3).objects) ++counts[o.category];
  int most = 0;
  for (const auto& [c, n] : counts) most = std::max(most, n);
  EXPECT_GE(most, 6);
}

TEST(Scene, TrajectoriesLookAtTheRoomFromOtherViewpoints) {
  const Scene s = makeScene(ScenePreset::Office, 1);
  const auto mapping = mappingTrajectory(s, 60);
  const auto query = queryTrajectory(s, 60, 2);
  ASSERT_EQ(mapping.size(), 60u);
  ASSERT_EQ(query.size(), 60u);
  double min_height = 10, max_height = 0;
  for (const Pose& p : mapping) EXPECT_NEAR(p.center()(2), 1.4, 1e-9);
  for (const Pose& p : query) {
    EXPECT_TRUE(p.isValid());
    min_height = std::min(min_height, p.center()(2));
    max_height = std::max(max_height, p.center()(2));
    // The room's centre is in front of the camera.
    EXPECT_GT(p.transform(Eigen::Vector3d(0, 0, 0.6))(2), 0.5);
  }
  EXPECT_LT(min_height, 1.1);
  EXPECT_GT(max_height, 1.7);
}

TEST(Render, AnEllipsoidsMaskIsItsProjectedEllipse) {
  Scene s;
  SimObject o;
  o.box_center = Eigen::Vector3d(0.2, 0.1, 0.8);
  o.box_half = Eigen::Vector3d(0.3, 0.15, 0.2);
  o.box_rotation = Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  o.parts.push_back({PrimitiveShape::Ellipsoid, o.box_center, o.box_half, o.box_rotation});
  s.objects.push_back(o);
  for (const Eigen::Vector3d& eye :
       {Eigen::Vector3d(2, -1, 1.5), Eigen::Vector3d(-1.5, -1.5, 0.5), Eigen::Vector3d(0, 2, 2.5)}) {
    const Pose pose = Pose::lookAt(eye, o.box_center);
    const RenderedFrame f = render(s, kK, pose);
    const Projection p = project(o.ellipsoid(), kK, pose);
    ASSERT_TRUE(p.ok());
    long agree = 0, total = 0;
    for (int y = 0; y < f.height; ++y)
      for (int x = 0; x < f.width; ++x) {
        const bool in_mask = f.instanceAt(x, y) == 0;
        const bool in_ellipse = p.ellipse.contains({double(x), double(y)});
        if (in_mask || in_ellipse) ++total, agree += in_mask == in_ellipse;
      }
    EXPECT_GT(static_cast<double>(agree) / total, 0.995);  // only boundary pixels may disagree
    // The RLE mask and box describe the same pixels.
    const BinaryMask m = *decodeMask(f.masks[0]);
    EXPECT_EQ(m.count(), f.visible_pixels[0]);
    const auto mom = rleMoments(f.masks[0]);
    EXPECT_EQ(mom->bounds.x1, f.boxes[0].x1);
    EXPECT_EQ(mom->bounds.y2, f.boxes[0].y2);
  }
}

TEST(Render, OcclusionDepthAndClipping) {
  Scene s;
  // Two boxes on the camera's axis: the near one hides the far one where they overlap.
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  SimObject near_box, far_box;
  near_box.parts.push_back({PrimitiveShape::Box, Eigen::Vector3d(0, -1.0, 1.0), Eigen::Vector3d(0.1, 0.1, 0.1), I});
  far_box.parts.push_back({PrimitiveShape::Box, Eigen::Vector3d(0.15, 0.0, 1.0), Eigen::Vector3d(0.2, 0.2, 0.2), I});
  s.objects = {near_box, far_box};
  const Pose pose = Pose::lookAt(Eigen::Vector3d(0, -3.0, 1.0), Eigen::Vector3d(0, 0, 1.0));
  const RenderedFrame f = render(s, kK, pose);
  // Centre pixel: the near box's front face, 1.9 m away (analytic).
  EXPECT_EQ(f.instanceAt(319, 239), 0);
  EXPECT_NEAR(f.depthAt(319, 239), 1.9, 1e-3);
  EXPECT_GT(f.visible_pixels[1], 0);
  // Where the far box shows, its depth is its front face at 2.8 m.
  int far_pixels_checked = 0;
  for (int y = 0; y < f.height; y += 5)
    for (int x = 0; x < f.width; x += 5)
      if (f.instanceAt(x, y) == 1) {
        EXPECT_NEAR(f.depthAt(x, y), 2.8, 1e-3);
        ++far_pixels_checked;
      }
  EXPECT_GT(far_pixels_checked, 10);
  // Floor: the depth of a pixel below the horizon agrees with a ray-plane intersection.
  const Eigen::Vector3d d =
      pose.rotation().transpose() * Eigen::Vector3d((10 - kK.cx) / kK.fx, (470 - kK.cy) / kK.fy, 1.0);
  EXPECT_NEAR(f.depthAt(10, 470), -pose.center()(2) / d(2), 1e-4);
  // Clipping: an object half outside the image has a box reaching the border.
  Scene edge;
  SimObject e;
  e.parts.push_back({PrimitiveShape::Box, Eigen::Vector3d(1.7, 0, 1.0), Eigen::Vector3d(0.3, 0.3, 0.3), I});
  edge.objects.push_back(e);
  const RenderedFrame fe = render(edge, kK, pose);
  ASSERT_GT(fe.visible_pixels[0], 0);
  EXPECT_DOUBLE_EQ(fe.boxes[0].x2, kK.width - 0.5);
}

TEST(Render, DepthAgreesWithRayCastingAtSampledPixels) {
  const Scene s = makeScene(ScenePreset::Office, 5);
  const Pose pose = queryTrajectory(s, 1, 9)[0];
  const RenderedFrame f = render(s, kK, pose);
  const Eigen::Matrix3d R_wc = pose.rotation().transpose();
  for (int y = 3; y < f.height; y += 37)
    for (int x = 5; x < f.width; x += 41) {
      const Eigen::Vector3d d = R_wc * Eigen::Vector3d((x - kK.cx) / kK.fx, (y - kK.cy) / kK.fy, 1.0);
      double best = std::numeric_limits<double>::infinity();
      int who = kNoObject;
      if (d(2) < 0) best = -pose.center()(2) / d(2);
      for (const Primitive& p : s.furniture) {
        const double t = rayDepth(p, pose.center(), d);
        if (t < best) best = t, who = kNoObject;
      }
      for (size_t j = 0; j < s.objects.size(); ++j)
        for (const Primitive& p : s.objects[j].parts) {
          const double t = rayDepth(p, pose.center(), d);
          if (t < best) best = t, who = static_cast<int>(j);
        }
      EXPECT_NEAR(f.depthAt(x, y), std::isfinite(best) ? best : 0.0, 1e-4);
      EXPECT_EQ(f.instanceAt(x, y), who);
    }
  // Every mask is consistent with the image size.
  for (const RleMask& m : f.masks) EXPECT_TRUE(m.isConsistent());
}
