#include <gtest/gtest.h>

#include "ellreloc/core/projection.hpp"
#include "ellreloc/io/detections.hpp"
#include "ellreloc/io/map.hpp"
#include "ellreloc/io/trajectory.hpp"
#include "ellreloc/sim/noise.hpp"
#include "ellreloc/sim/truth.hpp"
#include "ellreloc/sim/writer.hpp"
#include "fixtures/mask_shapes.hpp"
#include "fixtures/temp_dir.hpp"

using namespace ellreloc;
using namespace ellreloc::sim;

namespace {

bool quadrilateral(const std::vector<Eigen::Vector2d>& polygon) {
  return outlineIsConvexQuadrilateral(encodeMask(test::rasterPolygon(polygon, 320, 240)));
}

}  // namespace

TEST(Truth, ConvexQuadrilateralOutlines) {
  // One face of a box: a rectangle, a rotated one, a perspective trapezoid.
  EXPECT_TRUE(quadrilateral({{40, 50}, {200, 50}, {200, 150}, {40, 150}}));
  EXPECT_TRUE(quadrilateral({{160, 20}, {260, 120}, {160, 220}, {60, 120}}));
  EXPECT_TRUE(quadrilateral({{60, 60}, {250, 40}, {270, 200}, {80, 170}}));
  // Three faces of a box (a hexagon), a triangle, an L, an ellipse: not regular.
  EXPECT_FALSE(quadrilateral({{100, 40}, {200, 60}, {220, 150}, {180, 210}, {80, 190}, {60, 100}}));
  EXPECT_FALSE(quadrilateral({{50, 200}, {160, 30}, {270, 200}}));
  EXPECT_FALSE(quadrilateral({{40, 40}, {120, 40}, {120, 140}, {240, 140}, {240, 200}, {40, 200}}));
  EXPECT_FALSE(outlineIsConvexQuadrilateral(
      encodeMask(test::rasterEllipse(Ellipse(Eigen::Vector2d(160, 120), Eigen::Vector2d(90, 50), 0.3), 320, 240))));
  EXPECT_FALSE(outlineIsConvexQuadrilateral(RleMask{}));  // empty
}

TEST(Truth, DetectionTruthIsTheProjectionOfTheDetectedObject) {
  const Scene scene = makeScene(ScenePreset::Office, 5);
  const Intrinsics K(525.0, 525.0, 319.5, 239.5, 640, 480);
  const Pose pose = queryTrajectory(scene, 3, 9)[1];
  const RenderedFrame f = render(scene, K, pose);
  std::mt19937_64 rng(1);
  std::vector<Detection> dets = detect(scene, f, NoiseModel::preset(NoiseLevel::Realistic), rng);
  Detection false_positive;
  false_positive.bbox = Box(10, 10, 40, 40);
  dets.push_back(false_positive);
  const std::vector<Detection> truth = detectionTruth(scene, f, K, pose, dets);
  ASSERT_EQ(truth.size(), dets.size() - 1);  // the false positive has no truth
  int regular = 0;
  for (size_t i = 0; i < truth.size(); ++i) {
    ASSERT_TRUE(dets[i].object_id);
    EXPECT_EQ(truth[i].object_id, dets[i].object_id);
    EXPECT_EQ(truth[i].bbox.x1, dets[i].bbox.x1);
    const SimObject& o = scene.objects[static_cast<size_t>(*dets[i].object_id)];
    EXPECT_EQ(truth[i].category_id, o.category);
    const Projection p = project(o.ellipsoid(), K, pose);
    ASSERT_TRUE(p.ok() && truth[i].ellipse);
    EXPECT_LT((truth[i].ellipse->center() - p.ellipse.center()).norm(), 1e-9);
    ASSERT_TRUE(truth[i].regular);
    regular += *truth[i].regular;
  }
  EXPECT_GT(regular, 0);                               // monitors and books seen face-on
  EXPECT_LT(regular, static_cast<int>(truth.size()));  // chairs, cups, boxes seen on two faces
}

TEST(Truth, SimulateWritesTheTruthOfEveryTrueDetection) {
  test::TempDir dir;
  SimulationOptions opt;
  opt.seed = 3;
  opt.mapping_frames = 3;
  opt.query_frames = 4;
  opt.write_rgb = false;
  writeSimulation(dir.path("s"), opt);
  for (const char* part : {"query", "mapping"}) {
    const std::string base = dir.path("s/") + part;
    const auto frames = io::readDetections(base + "/detections.json");
    const auto truth = io::readDetections(base + "/ellipse_truth.json");
    ASSERT_EQ(frames.size(), truth.size());
    for (size_t i = 0; i < frames.size(); ++i) {
      EXPECT_EQ(frames[i].file_name, truth[i].file_name);
      size_t with_object = 0;
      for (const Detection& d : frames[i].detections) with_object += d.object_id.has_value();
      EXPECT_EQ(truth[i].detections.size(), with_object) << part << " frame " << i;
      for (const Detection& t : truth[i].detections) EXPECT_TRUE(t.object_id && t.regular && t.ellipse);
    }
  }
}
