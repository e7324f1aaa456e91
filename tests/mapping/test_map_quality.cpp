#include <gtest/gtest.h>

#include "ellreloc/mapping/map_quality.hpp"

namespace ellreloc {
namespace {

const Intrinsics kCamera(500.0, 500.0, 320.0, 240.0, 640, 480);

MapObject object(int id, int category, const Eigen::Vector3d& centre, double radius) {
  MapObject o;
  o.id = id;
  o.category = category;
  o.ellipsoid = Ellipsoid(centre, Eigen::Vector3d::Constant(radius), Eigen::Matrix3d::Identity());
  return o;
}

/// The frames a detector would give for `truth`: each object's projected bounding box.
std::vector<PosedDetections> framesOf(const ObjectMap& truth) {
  std::vector<PosedDetections> frames;
  for (double x : {-0.4, 0.0, 0.4}) {
    PosedDetections f;
    f.pose = Pose::lookAt(Eigen::Vector3d(x, -2.0, 0.3), Eigen::Vector3d(0.0, 0.0, 0.0));
    for (const MapObject& o : truth.objects) {
      Detection d;
      d.category_id = o.category;
      d.score = 0.9;
      d.bbox = project(o.ellipsoid, kCamera, f.pose).ellipse.boundingBox();
      f.detections.push_back(d);
    }
    frames.push_back(f);
  }
  return frames;
}

TEST(MapQuality, OneForTheMapTheBoxesCameFromAndLowerForAMovedObject) {
  ObjectMap truth;
  truth.objects = {object(0, 41, {-0.3, 0.0, 0.0}, 0.05), object(1, 62, {0.3, 0.1, 0.1}, 0.2)};
  const std::vector<PosedDetections> frames = framesOf(truth);
  const MapQuality q = measureMapQuality(truth, kCamera, frames);
  EXPECT_EQ(q.frames, 3u);
  EXPECT_EQ(q.boxes, 6u);
  EXPECT_EQ(q.explained, 6u);
  EXPECT_NEAR(q.median_best_iou, 1.0, 1e-9);

  // The cup moved by its own radius: its boxes overlap less; the monitor's are still exact.
  ObjectMap moved = truth;
  moved.objects[0].ellipsoid =
      Ellipsoid({-0.25, 0.0, 0.0}, Eigen::Vector3d::Constant(0.05), Eigen::Matrix3d::Identity());
  const std::vector<double> ious = bestCategoryIoUs(moved, kCamera, frames[0]);
  ASSERT_EQ(ious.size(), 2u);
  EXPECT_LT(ious[0], 0.6);
  EXPECT_NEAR(ious[1], 1.0, 1e-9);

  // An object of another category explains nothing: the cup's boxes score 0.
  ObjectMap relabelled = truth;
  relabelled.objects[0].category = 39;
  const MapQuality r = measureMapQuality(relabelled, kCamera, frames);
  EXPECT_EQ(r.explained, 3u);
  EXPECT_NEAR(r.mean_best_iou, 0.5, 1e-9);
}

// A box cut by the image border is compared with the projection cut the same way.
TEST(MapQuality, ProjectionsAreCutToTheImageLikeDetections) {
  ObjectMap map;
  map.objects = {object(0, 62, {0.0, 0.0, 0.0}, 0.3)};
  PosedDetections f;
  f.pose = Pose::lookAt(Eigen::Vector3d(0.0, -0.45, 0.0), Eigen::Vector3d(0.0, 0.0, 0.0));
  const Box full = project(map.objects[0].ellipsoid, kCamera, f.pose).ellipse.boundingBox();
  ASSERT_LT(full.x1, 0.0);  // larger than the image
  Detection d;
  d.category_id = 62;
  d.bbox = full.intersection(Box(-0.5, -0.5, 639.5, 479.5));
  f.detections = {d};
  EXPECT_NEAR(measureMapQuality(map, kCamera, {f}).median_best_iou, 1.0, 1e-9);
}

}  // namespace
}  // namespace ellreloc
