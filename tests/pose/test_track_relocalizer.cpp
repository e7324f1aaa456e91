#include <gtest/gtest.h>

#include <random>

#include "ellreloc/core/evaluation.hpp"
#include "ellreloc/observe/observe.hpp"
#include "ellreloc/pose/object_relocalizer.hpp"
#include "ellreloc/pose/track_relocalizer.hpp"
#include "ellreloc/sim/map_observations.hpp"
#include "ellreloc/sim/noise.hpp"
#include "ellreloc/sim/render.hpp"
#include "fixtures/map_in_unit.hpp"
#include "fixtures/random_geometry.hpp"
#include "fixtures/twin_desks.hpp"

using namespace ellreloc;
using ellreloc::test::uniform;

namespace {

constexpr int kPlantId = 50;

/// The twin desks with a plant beside the first desk only: a view that holds the plant can tell
/// the desks apart, one of a desk alone cannot.
ObjectMap desksAndAPlant() {
  ObjectMap map = test::twinDesks();
  map.objects.push_back(
      {kPlantId, 58, "potted plant", Ellipsoid({-1.1, 0.2, 0.3}, {0.15, 0.15, 0.3}, Eigen::Matrix3d::Identity())});
  return map;
}

/// A view of the first desk from in front of it, 0.8-1.4 m away: its objects only.
Pose deskView(std::mt19937& rng) {
  const Eigen::Vector3d eye(uniform(rng, -0.3, 0.4), uniform(rng, -1.4, -0.8), uniform(rng, 0.4, 0.8));
  return Pose::lookAt(eye, Eigen::Vector3d(uniform(rng, -0.05, 0.1), 0.1, 0.1), Eigen::Vector3d::UnitZ());
}

/// A view of the plant and the left of the first desk.
Pose plantView(std::mt19937& rng) {
  const Eigen::Vector3d eye(uniform(rng, -0.9, -0.5), uniform(rng, -1.6, -1.2), uniform(rng, 0.6, 0.9));
  return Pose::lookAt(eye, Eigen::Vector3d(-0.6, 0.15, 0.2), Eigen::Vector3d::UnitZ());
}

/// Exact observations of a view and the ids of their objects.
std::vector<Observation> observe(const ObjectMap& map, const Pose& pose, std::mt19937& rng, std::vector<int>* ids) {
  std::vector<int> object_of;
  std::vector<Observation> observations =
      sim::observeMap(map, test::testIntrinsics(), pose, sim::MapObservationOptions{}, &rng, &object_of);
  ids->clear();
  for (int o : object_of) ids->push_back(map.objects[static_cast<size_t>(o)].id);
  return observations;
}

bool holds(const std::vector<int>& ids, int id) { return std::find(ids.begin(), ids.end(), id) != ids.end(); }

/// An odometry frame of its own: the map's world seen through an arbitrary rigid motion, so that
/// only the relative poses of the track's frames carry over (x_world = odometry_to_world x_odometry).
Pose odometryOf(const Pose& truth, const Pose& odometry_to_world) { return truth * odometry_to_world; }

Pose arbitraryMotion(std::mt19937& rng) {
  return Pose(test::randomRotation(rng),
              Eigen::Vector3d(uniform(rng, -5, 5), uniform(rng, -5, 5), uniform(rng, -5, 5)));
}

}  // namespace

TEST(TrackRelocalizer, AnEarlierViewOfAUniqueObjectTellsTheLookAlikeDesksApart) {
  const ObjectMap map = desksAndAPlant();
  const ObjectRelocalizer relocalizer(map, test::testIntrinsics());
  const Eigen::Vector3d twin_offset(test::kTwinDeskOffset, 0.0, 0.0);
  std::mt19937 rng(3);
  int trials = 0;
  while (trials < 10) {
    std::vector<int> ids_a, ids_b;
    const Pose truth_a = plantView(rng), truth_b = deskView(rng);
    const std::vector<Observation> a = observe(map, truth_a, rng, &ids_a);
    const std::vector<Observation> b = observe(map, truth_b, rng, &ids_b);
    if (!holds(ids_a, kPlantId) || a.size() < 4 || b.size() < 4 || holds(ids_b, kPlantId)) continue;
    for (int id : ids_b) ASSERT_LT(id, 10) << "the desk view must not reach the second desk";
    ++trials;

    // The desk view alone: the twin pose explains it exactly as well as the truth.
    const Pose twin = Pose::fromCameraToWorld(truth_b.inverse().rotation(), truth_b.center() + twin_offset);
    EXPECT_NEAR(relocalizer.scorePose(b, truth_b).cost, relocalizer.scorePose(b, twin).cost, 1e-9);

    const Pose odometry_to_world = arbitraryMotion(rng);
    TrackRelocalizer track(relocalizer);
    track.add(a, odometryOf(truth_a, odometry_to_world));
    const TrackResult r = track.add(b, odometryOf(truth_b, odometry_to_world));
    ASSERT_EQ(r.result.status, RelocalizationStatus::Success) << r.result.reason;
    EXPECT_EQ(r.frames, 2);
    EXPECT_LT(poseError(r.result.pose, truth_b).position_cm, 1.0);
    EXPECT_LT(poseError(r.result.pose, truth_b).rotation_deg, 0.2);
    for (const ObjectCorrespondence& m : r.result.inliers) EXPECT_EQ(map.objects[m.object].id, ids_b[m.observation]);
    // The plant view, carried to the desk view, rules the twin out by what it leaves unexplained.
    EXPECT_GT(r.result.margin, 0.5);
  }
}

// A monocular system's map is in a unit of its own, and the host's odometry may be metric
// (visual-inertial): the track carries the frames' poses in the map's units per metre, and finds
// the pose the metric map gives, in the map's unit.
TEST(TrackRelocalizer, MetricOdometryAgainstAMapInAnotherUnit) {
  const double unit = 4.0;
  const ObjectMap map = test::mapInUnit(desksAndAPlant(), unit);
  const ObjectRelocalizer relocalizer(map, test::testIntrinsics());
  std::mt19937 rng(5);
  int trials = 0;
  while (trials < 6) {
    std::vector<int> ids_a, ids_b;
    const Pose truth_a = plantView(rng), truth_b = deskView(rng);
    const std::vector<Observation> a = observe(desksAndAPlant(), truth_a, rng, &ids_a);
    const std::vector<Observation> b = observe(desksAndAPlant(), truth_b, rng, &ids_b);
    if (!holds(ids_a, kPlantId) || a.size() < 4 || b.size() < 4 || holds(ids_b, kPlantId)) continue;
    ++trials;
    const Pose odometry_to_world = arbitraryMotion(rng);  // metres
    TrackRelocalizer track(relocalizer);
    track.add(a, odometryOf(truth_a, odometry_to_world));
    const TrackResult r = track.add(b, odometryOf(truth_b, odometry_to_world));
    ASSERT_EQ(r.result.status, RelocalizationStatus::Success) << r.result.reason;
    EXPECT_EQ(r.scale, 1.0 / unit);
    EXPECT_LT(poseError(r.result.pose, test::poseInUnit(truth_b, unit), unit).position_cm, 1.0);
    EXPECT_GT(r.result.margin, 0.5);  // the plant view, carried in the map's unit, rules the twin out
  }
}

// A track ranks each frame's poses over all of its frames; a pose polished on its own frame
// (refinement.polish_loss_scale) fits that frame's agreeing matches more tightly and carries to
// the others worse, so the track takes the frames' poses unpolished: its results are those of a
// relocalizer without the polish, while single frames differ.
TEST(TrackRelocalizer, TakesTheFramesPosesUnpolished) {
  const sim::Scene scene = sim::makeScene(sim::ScenePreset::Office, 5);
  const sim::NoiseModel noise = sim::NoiseModel::preset(sim::NoiseLevel::Realistic);
  const Intrinsics K(525.0, 525.0, 319.5, 239.5, 640, 480);
  const ObjectMap map = sim::perturbMap(scene.groundTruthMap(), noise, 3);
  RelocalizerOptions off;
  off.refinement.polish_loss_scale = 0.0;
  const ObjectRelocalizer polished(map, K), unpolished(map, K, off);
  TrackRelocalizer a(polished, TrackOptions{4}), b(unpolished, TrackOptions{4});
  std::mt19937_64 rng(4);
  int frames_that_differ_alone = 0, tracked = 0;
  for (const Pose& truth : sim::queryTrajectory(scene, 12, 4)) {
    const sim::RenderedFrame frame = sim::render(scene, K, truth);
    const std::vector<Observation> observations =
        observeDetections(sim::detect(scene, frame, noise, rng), K.width, K.height);
    const TrackResult ta = a.add(observations, truth), tb = b.add(observations, truth);
    ASSERT_EQ(ta.result.status, tb.result.status);
    tracked += ta.result.pose.isValid();
    EXPECT_TRUE(ta.result.pose.translation() == tb.result.pose.translation() &&
                ta.result.pose.rotation() == tb.result.pose.rotation());
    frames_that_differ_alone +=
        !(polished.relocalize(observations).pose.translation() == unpolished.relocalize(observations).pose.translation());
  }
  EXPECT_GE(tracked, 8);
  EXPECT_GE(frames_that_differ_alone, 3);
}

TEST(TrackRelocalizer, AFrameWithoutObjectsGetsItsPoseFromTheTrack) {
  const ObjectMap map = desksAndAPlant();
  const ObjectRelocalizer relocalizer(map, test::testIntrinsics());
  std::mt19937 rng(8);
  std::vector<int> ids;
  std::vector<Observation> a;
  Pose truth_a;
  do {
    truth_a = plantView(rng);
    a = observe(map, truth_a, rng, &ids);
  } while (!holds(ids, kPlantId) || a.size() < 4);
  // The camera then turned away from every object (a blank wall, a covered lens).
  const Pose truth_b = Pose::lookAt(truth_a.center() + Eigen::Vector3d(0.1, -0.2, 0.0),
                                    truth_a.center() + Eigen::Vector3d(0.0, -3.0, 0.0), Eigen::Vector3d::UnitZ());
  ASSERT_TRUE(observe(map, truth_b, rng, &ids).empty());

  const Pose odometry_to_world = arbitraryMotion(rng);
  TrackRelocalizer track(relocalizer);
  track.add(a, odometryOf(truth_a, odometry_to_world));
  const TrackResult r = track.add({}, odometryOf(truth_b, odometry_to_world));
  ASSERT_EQ(r.result.status, RelocalizationStatus::Success) << r.result.reason;
  EXPECT_EQ(r.found_by, 1);
  EXPECT_TRUE(r.result.inliers.empty());
  EXPECT_LT(poseError(r.result.pose, truth_b).position_cm, 1.0);
  EXPECT_LT(poseError(r.result.pose, truth_b).rotation_deg, 0.2);
}

TEST(TrackRelocalizer, KeepsTheNewestFramesAndTurnsDownBadInput) {
  const ObjectMap map = desksAndAPlant();
  const ObjectRelocalizer relocalizer(map, test::testIntrinsics());
  std::mt19937 rng(4);
  TrackOptions options;
  options.max_frames = 2;
  TrackRelocalizer track(relocalizer, options);
  std::vector<int> ids;
  for (int k = 0; k < 3; ++k) {
    const Pose truth = deskView(rng);
    const TrackResult r = track.add(observe(map, truth, rng, &ids), truth);
    EXPECT_EQ(r.frames, std::min(k + 1, 2));
  }
  EXPECT_EQ(track.size(), 2);

  const Pose nan_pose(Eigen::Matrix3d::Identity(), Eigen::Vector3d(std::nan(""), 0.0, 0.0));
  const TrackResult bad = track.add({}, nan_pose);
  EXPECT_EQ(bad.result.status, RelocalizationStatus::InvalidInput);
  EXPECT_NE(bad.result.reason.find("odometry pose"), std::string::npos) << bad.result.reason;
  EXPECT_EQ(track.size(), 2);
  track.reset();
  EXPECT_EQ(track.size(), 0);

  options.max_frames = 0;
  TrackRelocalizer unusable(relocalizer, options);
  const TrackResult r = unusable.add({}, deskView(rng));
  EXPECT_EQ(r.result.status, RelocalizationStatus::InvalidInput);
  EXPECT_NE(r.result.reason.find("max_frames"), std::string::npos) << r.result.reason;
  EXPECT_EQ(unusable.size(), 0);
}

// The track's evidence is weighed against its length: frames that pass at the default bar per
// frame are turned down, pose still given, when each must explain more than it can.
TEST(TrackRelocalizer, ATrackThatExplainsTooLittlePerFrameIsLowEvidence) {
  const ObjectMap map = desksAndAPlant();
  std::mt19937 rng(8);
  std::vector<std::pair<std::vector<Observation>, Pose>> frames;
  std::vector<int> ids;
  while (frames.size() < 3) {
    const Pose truth = plantView(rng);
    std::vector<Observation> observations = observe(map, truth, rng, &ids);
    if (holds(ids, kPlantId) && observations.size() >= 4) frames.emplace_back(std::move(observations), truth);
  }
  const auto lastOfTrack = [&](const ObjectRelocalizer& relocalizer, const TrackOptions& options) {
    TrackRelocalizer track(relocalizer, options);
    TrackResult r;
    for (const auto& [observations, truth] : frames) r = track.add(observations, truth);
    return r;
  };
  const ObjectRelocalizer relocalizer(map, test::testIntrinsics());
  const TrackResult passed = lastOfTrack(relocalizer, TrackOptions{});
  ASSERT_EQ(passed.result.status, RelocalizationStatus::Success) << passed.result.reason;
  ASSERT_EQ(passed.frames, 3);
  TrackOptions demanding;
  demanding.min_mean_evidence = passed.track_evidence / 3 + 0.01;
  const TrackResult weak = lastOfTrack(relocalizer, demanding);
  EXPECT_EQ(weak.result.status, RelocalizationStatus::LowEvidence);
  EXPECT_NE(weak.result.reason.find("per frame"), std::string::npos) << weak.result.reason;
  EXPECT_TRUE(weak.result.pose.rotation().isApprox(passed.result.pose.rotation()));
  EXPECT_TRUE(weak.result.pose.translation().isApprox(passed.result.pose.translation()));
}

TEST(TrackRelocalizer, TracksOfRandomBoxesGetNoPose) {
  // Boxes of the map's categories at random places and sizes, frame after frame, along a walk:
  // no evidence of the map, so no pose may be reported.
  const ObjectMap map = desksAndAPlant();
  const Intrinsics K = test::testIntrinsics();
  const ObjectRelocalizer relocalizer(map, K);
  std::mt19937 rng(21);
  const int categories[] = {62, 66, 73, 41, 58};
  TrackRelocalizer track(relocalizer);
  Pose odometry;
  int reported = 0, frames = 0;
  for (int k = 0; k < 60; ++k, ++frames) {
    std::vector<Observation> observations;
    const int n = std::uniform_int_distribution<int>(3, 7)(rng);
    for (int i = 0; i < n; ++i) {
      const double w = uniform(rng, 15, 160), h = uniform(rng, 15, 160);
      const double x = uniform(rng, 0, K.width - w), y = uniform(rng, 0, K.height - h);
      observations.push_back(*observationFromBox(categories[std::uniform_int_distribution<int>(0, 4)(rng)], 1.0,
                                                 Box(x, y, x + w, y + h), K.width, K.height));
    }
    odometry = Pose(Eigen::AngleAxisd(uniform(rng, -0.05, 0.05), Eigen::Vector3d::UnitY()).toRotationMatrix(),
                    Eigen::Vector3d(uniform(rng, -0.05, 0.05), 0.0, uniform(rng, -0.05, 0.05))) *
               odometry;
    const TrackResult r = track.add(observations, odometry);
    reported += r.result.status == RelocalizationStatus::Success;
  }
  EXPECT_EQ(reported, 0) << "of " << frames << " frames";
}

TEST(TrackRelocalizer, EstimatesTheScaleOfAMonocularOdometry) {
  // A monocular host's odometry: the map's world through an arbitrary motion and in units of its
  // own (here 0.3 of a metre each). The plant view, then two views of the desk alone, which its
  // twin explains as well: the track must find the scale to carry the plant view to them.
  const ObjectMap map = desksAndAPlant();
  const ObjectRelocalizer relocalizer(map, test::testIntrinsics());
  constexpr double kUnit = 0.3;
  std::mt19937 rng(5);
  int trials = 0;
  while (trials < 5) {
    std::vector<int> ids_a, ids_b, ids_c;
    const Pose truth_a = plantView(rng), truth_b = deskView(rng), truth_c = deskView(rng);
    const std::vector<Observation> a = observe(map, truth_a, rng, &ids_a);
    const std::vector<Observation> b = observe(map, truth_b, rng, &ids_b);
    const std::vector<Observation> c = observe(map, truth_c, rng, &ids_c);
    if (!holds(ids_a, kPlantId) || a.size() < 4 || b.size() < 4 || c.size() < 4 || holds(ids_b, kPlantId) ||
        holds(ids_c, kPlantId))
      continue;
    ++trials;
    const Pose odometry_to_world = arbitraryMotion(rng);
    const auto odometry = [&](const Pose& truth) {
      const Pose metric = odometryOf(truth, odometry_to_world);
      return Pose(metric.rotation(), metric.translation() / kUnit);
    };
    TrackOptions options;
    options.metric_odometry = false;
    TrackRelocalizer track(relocalizer, options);
    const TrackResult first = track.add(a, odometry(truth_a));
    EXPECT_EQ(first.frames, 1);  // no scale before two frames propose one
    EXPECT_EQ(first.scale, 0.0);
    track.add(b, odometry(truth_b));
    const TrackResult r = track.add(c, odometry(truth_c));
    ASSERT_EQ(r.result.status, RelocalizationStatus::Success) << r.result.reason;
    EXPECT_EQ(r.frames, 3);
    EXPECT_NEAR(std::log(r.scale / kUnit), 0.0, 0.15) << "scale " << r.scale;
    EXPECT_LT(poseError(r.result.pose, truth_c).position_cm, 1.0);
    EXPECT_LT(poseError(r.result.pose, truth_c).rotation_deg, 0.2);
    EXPECT_GT(r.result.margin, 0.5);  // the plant view rules the twin out
  }
}
