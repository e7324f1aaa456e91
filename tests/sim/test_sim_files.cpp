#include <gtest/gtest.h>

#include <filesystem>

#include "fixtures/temp_dir.hpp"
#include "ellreloc/io/camera.hpp"
#include "ellreloc/io/detections.hpp"
#include "ellreloc/io/files.hpp"
#include "ellreloc/io/map.hpp"
#include "ellreloc/io/rgbd.hpp"
#include "ellreloc/io/trajectory.hpp"
#include "ellreloc/observe/observe.hpp"
#include "ellreloc/pose/object_relocalizer.hpp"
#include "ellreloc/sim/noise.hpp"
#include "ellreloc/sim/writer.hpp"

using namespace ellreloc;
using namespace ellreloc::sim;

TEST(Noise, NoneGivesTheRenderedTruth) {
  const Scene s = makeScene(ScenePreset::Office, 4);
  const Intrinsics K(525.0, 525.0, 319.5, 239.5, 640, 480);
  const RenderedFrame f = render(s, K, queryTrajectory(s, 1, 3)[0]);
  std::mt19937_64 rng(1);
  const auto dets = detect(s, f, NoiseModel::preset(NoiseLevel::None), rng);
  size_t visible = 0;
  for (long v : f.visible_pixels) visible += v >= 150;
  EXPECT_EQ(dets.size(), visible);
  for (const Detection& d : dets) {
    const int j = *d.object_id;
    EXPECT_EQ(d.category_id, s.objects[j].category);
    EXPECT_EQ(d.mask->counts, f.masks[j].counts);
    EXPECT_EQ(d.bbox.x1, f.boxes[j].x1);
    EXPECT_EQ(d.bbox.y2, f.boxes[j].y2);
  }
  const DepthImage depth = noisyDepth(f, NoiseModel::preset(NoiseLevel::None), rng);
  EXPECT_EQ(depth.metres, f.depth);
}

TEST(Noise, RealisticNoiseAndPerturbedMap) {
  const Scene s = makeScene(ScenePreset::Cluttered, 5);
  const Intrinsics K(525.0, 525.0, 319.5, 239.5, 640, 480);
  const NoiseModel noise = NoiseModel::preset(NoiseLevel::Realistic);
  std::mt19937_64 rng(2);
  int detected = 0, visible = 0, false_pos = 0, moved_masks = 0;
  for (const Pose& p : queryTrajectory(s, 30, 6)) {
    const RenderedFrame f = render(s, K, p);
    for (long v : f.visible_pixels) visible += v >= 150;
    for (const Detection& d : detect(s, f, noise, rng)) {
      if (!d.object_id) {
        ++false_pos;
        continue;
      }
      ++detected;
      moved_masks += d.mask->counts != f.masks[*d.object_id].counts;
      EXPECT_TRUE(d.mask->isConsistent());
    }
  }
  EXPECT_LT(detected, visible);        // some missed
  EXPECT_GT(detected, 0.7 * visible);  // ~10% missed
  EXPECT_GT(false_pos, 0);
  EXPECT_GT(moved_masks, 0.9 * detected);  // boundaries eroded or dilated
  const ObjectMap truth = s.groundTruthMap();
  const ObjectMap noisy = perturbMap(truth, noise, 3);
  double centre_sq = 0.0;
  for (size_t i = 0; i < truth.objects.size(); ++i) {
    centre_sq += (noisy.objects[i].ellipsoid.center() - truth.objects[i].ellipsoid.center()).squaredNorm();
    EXPECT_TRUE(noisy.objects[i].ellipsoid.isValid());
    // Still yaw-only.
    EXPECT_LT((noisy.objects[i].ellipsoid.rotation().col(2) - Eigen::Vector3d::UnitZ()).norm(), 1e-9);
  }
  const double rms = std::sqrt(centre_sq / truth.objects.size());
  EXPECT_NEAR(rms, noise.map_centre_sigma * std::sqrt(3.0), 0.5 * noise.map_centre_sigma * std::sqrt(3.0));
}

TEST(Writer, WritesTheTumLayoutDeterministically) {
  test::TempDir a, b;
  SimulationOptions opt;
  opt.preset = ScenePreset::Sparse;
  opt.seed = 11;
  opt.mapping_frames = 4;
  opt.query_frames = 6;
  const SimulationSummary sa = writeSimulation(a.path("scene"), opt);
  const SimulationSummary sb = writeSimulation(b.path("scene"), opt);
  ASSERT_EQ(sa.files, sb.files);
  for (const std::string& f : sa.files)
    EXPECT_EQ(io::readTextFile(a.path("scene/" + f)), io::readTextFile(b.path("scene/" + f))) << f;
  // Everything reads back with the library's own readers, and fits together.
  const std::string dir = a.path("scene/");
  const Intrinsics K = io::readCamera(dir + "camera.yaml");
  const ObjectMap truth = io::readMap(dir + "map_groundtruth.json");
  EXPECT_EQ(static_cast<int>(truth.objects.size()), sa.objects);
  EXPECT_FALSE(truth.points.empty());
  const auto assoc = io::readAssociations(dir + "mapping/associations.txt");
  ASSERT_EQ(assoc.size(), 4u);
  const DepthImage depth = io::readDepthPng(assoc[0].depth_path);
  EXPECT_EQ(depth.width, K.width);
  EXPECT_TRUE(std::filesystem::exists(assoc[0].rgb_path));
  EXPECT_EQ(io::readTumTrajectory(dir + "mapping/trajectory.txt").size(), 4u);
  const auto query = io::readDetections(dir + "query/detections.json");
  const auto gt = io::readTumTrajectory(dir + "query/groundtruth.txt");
  ASSERT_EQ(query.size(), 6u);
  for (const auto& frame : query) EXPECT_TRUE(io::findNearest(gt, *frame.timestamp()).has_value());
}

TEST(Writer, SimulatedQueriesRelocalize) {
  // End to end on files: simulate without noise, observe the query detections, relocalize
  // against the ground-truth map, compare with the ground truth.
  test::TempDir dir;
  SimulationOptions opt;
  opt.seed = 21;
  opt.noise = NoiseLevel::None;
  opt.mapping_frames = 1;
  opt.query_frames = 10;
  opt.write_rgb = false;
  writeSimulation(dir.path("s"), opt);
  const Intrinsics K = io::readCamera(dir.path("s/camera.yaml"));
  const ObjectRelocalizer reloc(io::readMap(dir.path("s/map_groundtruth.json")), K);
  const auto gt = io::readTumTrajectory(dir.path("s/query/groundtruth.txt"));
  int tried = 0, good = 0;
  for (const auto& frame : io::readDetections(dir.path("s/query/detections.json"))) {
    std::vector<Observation> obs;
    for (const Detection& d : frame.detections)
      if (auto r = observeDetection(d, K.width, K.height); r.observation) obs.push_back(*r.observation);
    if (obs.size() < 4) continue;
    ++tried;
    const RelocalizationResult r = reloc.relocalize(obs);
    const Pose& truth = gt[*io::findNearest(gt, *frame.timestamp())].pose;
    good += r.status == RelocalizationStatus::Success && (r.pose.center() - truth.center()).norm() < 0.1;
  }
  EXPECT_GE(tried, 5);
  EXPECT_GE(good, tried - 1);
}

TEST(Noise, KeypointsAreVisibleMapPointsWithOutliers) {
  const Scene s = makeScene(ScenePreset::Office, 8);
  const Intrinsics K(525.0, 525.0, 319.5, 239.5, 640, 480);
  const Pose pose = queryTrajectory(s, 1, 4)[0];
  const RenderedFrame f = render(s, K, pose);
  std::mt19937_64 rng(5);
  const auto clean = keypoints(s, f, K, pose, NoiseModel::preset(NoiseLevel::None), rng);
  ASSERT_GT(clean.size(), 20u);
  for (const Keypoint& k : clean) EXPECT_LT((K.project(pose.transform(s.points[k.point_index])) - k.uv).norm(), 1e-9);
  NoiseModel noisy = NoiseModel::preset(NoiseLevel::Realistic);
  const auto kps = keypoints(s, f, K, pose, noisy, rng);
  int wrong = 0;
  for (const Keypoint& k : kps) wrong += (K.project(pose.transform(s.points[k.point_index])) - k.uv).norm() > 10.0;
  EXPECT_GT(wrong, 0);
  EXPECT_LT(wrong, static_cast<int>(0.4 * kps.size()));
}
