#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <limits>
#include <numeric>
#include <random>
#include <set>
#include <thread>

#include "ellreloc/core/mask.hpp"
#include "ellreloc/core/projection.hpp"
#include "ellreloc/core/statistics.hpp"
#include "ellreloc/error.hpp"
#include "ellreloc/io/map.hpp"
#include "ellreloc/mapping/mapper.hpp"
#include "fixtures/sim_sequence.hpp"
#include "fixtures/temp_dir.hpp"

namespace ellreloc {
namespace {

/// Map objects within `radius` of a ground-truth object.
int objectsNear(const ObjectMap& map, const Eigen::Vector3d& centre, double radius) {
  int n = 0;
  for (const MapObject& o : map.objects) n += (o.ellipsoid.center() - centre).norm() < radius;
  return n;
}

// Two office scenes (seed 7 has bottles standing close together, the hardest of seeds 1-10):
// most objects seen in at least 10 keyframes are mapped within 6 cm with the right label and
// once. Known limit: neighbours of one category a few centimetres apart can merge.
TEST(Mapper, MapsRenderedOfficesWithNoisyDepthAndMasks) {
  int checked = 0, good = 0;
  std::vector<double> axis_errors;
  for (const uint64_t seed : {3, 7}) {
    const test::SimSequence seq = test::makeSimSequence(sim::ScenePreset::Office, seed, 40, test::mappingNoise());
    Mapper mapper(seq.K);
    std::vector<int> seen(seq.scene.objects.size(), 0);
    for (const auto& kf : seq.keyframes) {
      mapper.addKeyframe(kf.pose, kf.detections, &kf.depth);
      for (const auto& d : kf.detections) ++seen[static_cast<size_t>(*d.object_id)];
    }
    const ObjectMap map = mapper.map();
    int checked_here = 0;
    for (size_t i = 0; i < seq.scene.objects.size(); ++i) {
      if (seen[i] < 10) continue;
      const sim::SimObject& truth = seq.scene.objects[i];
      ++checked, ++checked_here;
      const MapObject* best = nullptr;
      for (const MapObject& o : map.objects)
        if (!best ||
            (o.ellipsoid.center() - truth.box_center).norm() < (best->ellipsoid.center() - truth.box_center).norm())
          best = &o;
      ASSERT_TRUE(best);
      good += (best->ellipsoid.center() - truth.box_center).norm() < 0.06 && best->category == truth.category &&
              objectsNear(map, truth.box_center, 0.1) == 1 &&
              best->ellipsoid.axes().maxCoeff() < truth.box_half.maxCoeff() + 0.1;
      if ((best->ellipsoid.center() - truth.box_center).norm() < 0.06)
        for (int k = 0; k < 3; ++k) {  // the estimate's extent along each true axis
          const Eigen::Vector3d u = truth.box_rotation.col(k);
          axis_errors.push_back(std::abs(std::sqrt(u.dot(best->ellipsoid.shapeMatrix() * u)) - truth.box_half(k)) /
                                truth.box_half(k));
        }
    }
    EXPECT_GE(checked_here, 15);
    EXPECT_LE(map.objects.size(), static_cast<size_t>(checked_here) + 3);
    // Memory is reported per object, and the label histograms are kept.
    for (const MappedObject& m : mapper.objects()) {
      EXPECT_GT(m.memory_bytes, 0u);
      EXPECT_GE(m.observations, 3);
      EXPECT_FALSE(m.object.category_counts.empty());
      ASSERT_TRUE(m.cuboid);
    }
  }
  EXPECT_GE(good, 0.85 * checked) << good << " of " << checked;  // measured: 35 of 40
  // Extents from the voxels' mean depth points, not their centres: median error along the true
  // axes 9.4% (12.0% from the centres, whose steps of a voxel blur the thin sides of books and
  // monitors).
  EXPECT_LT(median(axis_errors), 0.105) << axis_errors.size() << " axes";
}

TEST(Mapper, LabelNoiseDoesNotSplitObjectsOrChangeTheirLabel) {
  sim::NoiseModel noise = test::mappingNoise();
  noise.label_confusion = 0.2;
  const test::SimSequence seq = test::makeSimSequence(sim::ScenePreset::Sparse, 2, 40, noise);
  Mapper mapper(seq.K);
  std::vector<int> seen(seq.scene.objects.size(), 0);
  for (const auto& kf : seq.keyframes) {
    mapper.addKeyframe(kf.pose, kf.detections, &kf.depth);
    for (const auto& d : kf.detections) ++seen[static_cast<size_t>(*d.object_id)];
  }
  const ObjectMap map = mapper.map();
  for (size_t i = 0; i < seq.scene.objects.size(); ++i) {
    if (seen[i] < 10) continue;
    const sim::SimObject& truth = seq.scene.objects[i];
    EXPECT_EQ(objectsNear(map, truth.box_center, 0.15), 1) << truth.label;
    for (const MapObject& o : map.objects)
      if ((o.ellipsoid.center() - truth.box_center).norm() < 0.15) EXPECT_EQ(o.category, truth.category);
  }
}

/// A scene of one box (a backpack) on the floor.
sim::Scene oneBoxScene() {
  sim::Scene scene;
  sim::SimObject box;
  box.id = 0;
  box.category = 24;
  box.label = "backpack";
  box.box_center = Eigen::Vector3d(0.0, 0.0, 0.25);
  box.box_half = Eigen::Vector3d(0.25, 0.15, 0.25);
  box.parts.push_back({sim::PrimitiveShape::Box, box.box_center, box.box_half, Eigen::Matrix3d::Identity()});
  scene.objects.push_back(box);
  return scene;
}

/// One box on the floor, seen, then out of view, then seen again from the other side.
TEST(Mapper, AnObjectLeavingAndReenteringTheViewIsFoundAgainIn3D) {
  const sim::Scene scene = oneBoxScene();
  const sim::SimObject& box = scene.objects[0];
  const Intrinsics K(525.0, 525.0, 319.5, 239.5, 640, 480);
  std::vector<Pose> poses;
  for (int i = 0; i < 12; ++i) {
    const double a = -0.3 + 0.1 * i;  // an arc around the box
    const Eigen::Vector3d eye(2.0 * std::cos(a), 2.0 * std::sin(a), 1.2);
    const bool away = i >= 4 && i < 8;
    poses.push_back(Pose::lookAt(eye, away ? Eigen::Vector3d(2 * eye.x(), 2 * eye.y(), 1.2) : box.box_center));
  }
  Mapper mapper(K);
  std::mt19937_64 rng(1);
  int matched_3d = 0, created = 0;
  for (size_t i = 0; i < poses.size(); ++i) {
    const sim::RenderedFrame frame = sim::render(scene, K, poses[i]);
    const auto detections = sim::detect(scene, frame, sim::NoiseModel(), rng);
    const DepthImage depth = sim::noisyDepth(frame, sim::NoiseModel(), rng);
    if (i >= 4 && i < 8) {
      EXPECT_TRUE(detections.empty());
    }
    const KeyframeReport r = mapper.addKeyframe(poses[i], detections, &depth);
    matched_3d += r.matched_3d;
    created += r.new_objects;
  }
  EXPECT_EQ(created, 1);
  EXPECT_EQ(matched_3d, 1);  // the first frame after the gap
  const ObjectMap map = mapper.map();
  ASSERT_EQ(map.objects.size(), 1u);
  EXPECT_LT((map.objects[0].ellipsoid.center() - box.box_center).norm(), 0.03);
  EXPECT_EQ(map.objects[0].category, 24);
}

/// A detector that reports one box twice in several keyframes (two overlapping detections of
/// one label): the second detection cannot join the object the first one already updated, so
/// it starts a second model of the same surfaces, which then joins the first.
TEST(Mapper, ASecondModelOfOneObjectJoinsTheFirst) {
  const sim::Scene scene = oneBoxScene();
  const sim::SimObject& box = scene.objects[0];
  const Intrinsics K(525.0, 525.0, 319.5, 239.5, 640, 480);
  Mapper mapper(K);
  std::mt19937_64 rng(1);
  int created = 0;
  for (int i = 0; i < 10; ++i) {
    const double a = -0.3 + 0.08 * i;  // an arc around the box
    const Pose pose = Pose::lookAt(Eigen::Vector3d(2.0 * std::cos(a), 2.0 * std::sin(a), 1.2), box.box_center);
    const sim::RenderedFrame frame = sim::render(scene, K, pose);
    std::vector<Detection> detections = sim::detect(scene, frame, sim::NoiseModel(), rng);
    ASSERT_EQ(detections.size(), 1u);
    if (i >= 2 && i < 6) detections.push_back(detections[0]);  // reported twice
    const DepthImage depth = sim::noisyDepth(frame, sim::NoiseModel(), rng);
    created += mapper.addKeyframe(pose, detections, &depth).new_objects;
  }
  EXPECT_EQ(created, 5);  // each repeated detection starts a model, which joins the object at once
  const ObjectMap map = mapper.map();
  ASSERT_EQ(map.objects.size(), 1u);
  EXPECT_EQ(map.objects[0].id, 0);  // the younger joined the older
  EXPECT_LT((map.objects[0].ellipsoid.center() - box.box_center).norm(), 0.05);
  EXPECT_EQ(mapper.objects()[0].observations, 14);  // every detection counts once
}

/// 30 keyframes of the sparse scene with boxes jittered by a pixel, for boxes mode.
test::SimSequence boxSequence() {
  sim::NoiseModel noise;
  noise.box_jitter_px = 1.0;
  return test::makeSimSequence(sim::ScenePreset::Sparse, 4, 30, noise);
}

MapperOptions boxesMode() {
  MapperOptions opt;
  opt.mode = MappingMode::Boxes;
  return opt;
}

TEST(Mapper, BoxesOnlyMode) {
  const test::SimSequence seq = boxSequence();
  Mapper mapper(seq.K, boxesMode());
  std::vector<int> seen(seq.scene.objects.size(), 0);
  for (const auto& kf : seq.keyframes) {
    mapper.addKeyframe(kf.pose, kf.detections);  // no depth needed
    for (const auto& d : kf.detections) ++seen[static_cast<size_t>(*d.object_id)];
  }
  const ObjectMap map = mapper.map();
  int found = 0, expected = 0;
  for (size_t i = 0; i < seq.scene.objects.size(); ++i) {
    if (seen[i] < 10) continue;
    ++expected;
    found += objectsNear(map, seq.scene.objects[i].box_center, 0.1) >= 1;
  }
  EXPECT_GE(expected, 3);
  EXPECT_GE(found, expected - 1);
}

/// The detection a box detector would give of an ellipsoid: its image's bounding box.
Detection boxOf(const Ellipsoid& e, int category, const Intrinsics& K, const Pose& pose, double scale = 1.0) {
  const Projection p = project(e, K, pose);
  EXPECT_TRUE(p);
  const Box b = p.ellipse.boundingBox();
  const Eigen::Vector2d c(0.5 * (b.x1 + b.x2), 0.5 * (b.y1 + b.y2));
  const Eigen::Vector2d h(0.5 * scale * b.width(), 0.5 * scale * b.height());
  Detection d;
  d.category_id = category;
  d.bbox = Box(c.x() - h.x(), c.y() - h.y(), c.x() + h.x(), c.y() + h.y());
  return d;
}

/// Cameras on an arc 1.5 m from the origin, 0.8 m above it, looking at it.
Pose arcPose(int i) {
  const double a = -0.6 + 0.1 * i;
  return Pose::lookAt(Eigen::Vector3d(1.5 * std::cos(a), 1.5 * std::sin(a), 0.8), Eigen::Vector3d(0, 0, 0.04));
}

// Boxes mode: two objects of one label whose centres lie within the smaller one's mean
// semi-axis (a book lying on another) stay two objects when keyframes detected both, since a
// detector gives one box per object; an object whose track broke (its boxes suddenly much
// smaller, as if half hidden, so that tracking started again) is joined again; and an object a
// detector reports twice (two nearly equal boxes) is one.
TEST(Mapper, BoxesOfOneKeyframeAreTwoObjectsAndABrokenTrackIsJoined) {
  const Intrinsics K(525.0, 525.0, 319.5, 239.5, 640, 480);
  const int kBook = 73;
  const Eigen::Matrix3d level = Eigen::Matrix3d::Identity();
  const Ellipsoid lower(Eigen::Vector3d(0, 0, 0.02), Eigen::Vector3d(0.12, 0.09, 0.02), level);
  const Ellipsoid upper(Eigen::Vector3d(0.01, 0.01, 0.06), Eigen::Vector3d(0.1, 0.08, 0.02), level);
  MapperOptions options;
  options.mode = MappingMode::Boxes;
  Mapper stacked(K, options);
  for (int i = 0; i < 12; ++i) {
    const Pose pose = arcPose(i);
    stacked.addKeyframe(pose, {boxOf(lower, kBook, K, pose), boxOf(upper, kBook, K, pose)});
  }
  stacked.finish();
  const ObjectMap two = stacked.map();
  ASSERT_EQ(two.objects.size(), 2u);
  const double apart = (two.objects[0].ellipsoid.center() - two.objects[1].ellipsoid.center()).norm();
  const double reach = std::min(two.objects[0].ellipsoid.axes().mean(), two.objects[1].ellipsoid.axes().mean());
  EXPECT_LT(apart, reach);  // close enough for the centre test alone to join them

  Mapper broken(K, options);
  int created = 0;
  std::vector<int> reported;  // the object each keyframe's box joined, as the keyframe reported it
  for (int i = 0; i < 12; ++i) {
    const Pose pose = arcPose(i);
    const KeyframeReport r = broken.addKeyframe(pose, {boxOf(lower, kBook, K, pose, i < 6 ? 1.0 : 0.4)});
    created += r.new_objects;
    ASSERT_EQ(r.object_ids.size(), 1u);
    reported.push_back(r.object_ids[0]);
  }
  broken.finish();
  EXPECT_EQ(created, 2);  // the smaller boxes overlap the object's image too little to be tracked
  const ObjectMap one = broken.map();
  ASSERT_EQ(one.objects.size(), 1u);
  // The second track's boxes were reported under its own id until it joined the first.
  EXPECT_EQ(std::set<int>(reported.begin(), reported.end()).size(), 2u);
  for (const int id : reported) EXPECT_EQ(broken.currentObjectId(id), one.objects[0].id);
  EXPECT_FALSE(broken.currentObjectId(99).has_value());
  EXPECT_EQ(broken.objects()[0].observations, 12);
  EXPECT_LT((one.objects[0].ellipsoid.center() - lower.center()).norm(), 0.05);

  Mapper twice(K, options);
  int ignored = 0;
  for (int i = 0; i < 12; ++i) {
    const Pose pose = arcPose(i);
    Detection first = boxOf(lower, kBook, K, pose), second = first;
    first.score = 0.6;
    second.score = 0.9;
    second.bbox.x1 += 2.0;  // the same object, boxed a little differently
    const KeyframeReport r = twice.addKeyframe(pose, {first, second});
    ignored += r.ignored;
    EXPECT_EQ(r.object_ids, (std::vector<int>{-1, 0}));  // in the order given
  }
  twice.finish();
  EXPECT_EQ(ignored, 12);  // the less confident report of each keyframe
  ASSERT_EQ(twice.map().objects.size(), 1u);
  EXPECT_LT((twice.map().objects[0].ellipsoid.center() - lower.center()).norm(), 0.05);
}

// A keyframe's report names each detection's object; a stray box seen once starts a candidate
// that, never seen again, is forgotten: its id then names no object.
TEST(Mapper, ACandidateNeverConfirmedIsForgotten) {
  const Intrinsics K(525.0, 525.0, 319.5, 239.5, 640, 480);
  const Ellipsoid book(Eigen::Vector3d(0, 0, 0.02), Eigen::Vector3d(0.12, 0.09, 0.02), Eigen::Matrix3d::Identity());
  const Ellipsoid cup(Eigen::Vector3d(0.3, -0.3, 0.05), Eigen::Vector3d(0.04, 0.04, 0.05), Eigen::Matrix3d::Identity());
  Mapper mapper(K, boxesMode());
  const KeyframeReport first =
      mapper.addKeyframe(arcPose(0), {boxOf(book, 73, K, arcPose(0)), boxOf(cup, 41, K, arcPose(0))});
  ASSERT_EQ(first.object_ids.size(), 2u);
  const int book_id = first.object_ids[0], cup_id = first.object_ids[1];
  ASSERT_GE(cup_id, 0);
  EXPECT_NE(book_id, cup_id);
  EXPECT_EQ(mapper.currentObjectId(cup_id), cup_id);  // a candidate, not in the map yet
  for (int i = 1; i <= mapper.options().candidate_lifetime + 1; ++i) {
    const KeyframeReport r = mapper.addKeyframe(arcPose(i), {boxOf(book, 73, K, arcPose(i))});
    EXPECT_EQ(r.object_ids, std::vector<int>{book_id});
  }
  EXPECT_FALSE(mapper.currentObjectId(cup_id).has_value());
  ASSERT_EQ(mapper.map().objects.size(), 1u);
  EXPECT_EQ(mapper.currentObjectId(book_id), mapper.map().objects[0].id);
}

// Boxes mode with keyframes far apart, as a SLAM system gives them: a camera sliding 10 cm per
// keyframe past a row of cups 1.6 m away moves each cup's image by more than its width, so its
// last box would meet the next cup's box instead of its own. Its box moved with the camera
// finds it: each cup is mapped once, where it is.
TEST(Mapper, BoxTracksFollowTheCameraBetweenKeyframesFarApart) {
  const Intrinsics K(525.0, 525.0, 319.5, 239.5, 640, 480);
  const int kCup = 41;
  std::vector<Ellipsoid> cups;
  for (int k = 0; k < 6; ++k)
    cups.emplace_back(Eigen::Vector3d(-0.3 + 0.12 * k, 0.0, 0.05), Eigen::Vector3d(0.04, 0.04, 0.05),
                      Eigen::Matrix3d::Identity());
  MapperOptions options;
  options.mode = MappingMode::Boxes;
  Mapper mapper(K, options);
  for (int i = 0; i < 12; ++i) {
    const Eigen::Vector3d eye(-0.6 + 0.1 * i, -1.5, 0.6);
    const Pose pose = Pose::lookAt(eye, eye + Eigen::Vector3d(0.0, 1.5, -0.55));
    std::vector<Detection> boxes;
    for (const Ellipsoid& cup : cups) {
      const Projection p = project(cup, K, pose);
      const Box b = p ? p.ellipse.boundingBox() : Box();
      if (p && b.x1 > 0.0 && b.x2 < K.width) boxes.push_back(boxOf(cup, kCup, K, pose));
    }
    mapper.addKeyframe(pose, boxes);
  }
  mapper.finish();
  const ObjectMap map = mapper.map();
  EXPECT_EQ(map.objects.size(), cups.size());
  for (const Ellipsoid& cup : cups) {
    int near = 0;
    for (const MapObject& o : map.objects) near += (o.ellipsoid.center() - cup.center()).norm() < 0.03;
    EXPECT_EQ(near, 1) << "the cup at x = " << cup.center().x();
  }
}

// The objects, their ids included, do not depend on the order a detector lists a keyframe's
// boxes in, in either mode: the same keyframes with each one's detections shuffled give the
// same objects to the bit.
TEST(Mapper, TheOrderOfTheDetectionsDoesNotMatter) {
  const test::SimSequence seq = test::makeSimSequence(sim::ScenePreset::Office, 3, 12, test::mappingNoise());
  for (const MappingMode mode : {MappingMode::Boxes, MappingMode::Voxel}) {
    MapperOptions options;
    options.mode = mode;
    Mapper given(seq.K, options), shuffled(seq.K, options);
    std::mt19937 rng(5);
    int associated = 0;
    for (const auto& kf : seq.keyframes) {
      const KeyframeReport a = given.addKeyframe(kf.pose, kf.detections, &kf.depth);
      std::vector<size_t> order(kf.detections.size());
      std::iota(order.begin(), order.end(), size_t{0});
      std::shuffle(order.begin(), order.end(), rng);
      std::vector<Detection> reordered;
      for (size_t i : order) reordered.push_back(kf.detections[i]);
      const KeyframeReport b = shuffled.addKeyframe(kf.pose, reordered, &kf.depth);
      // Each detection joins the same object, reported in the order each was given.
      ASSERT_EQ(b.object_ids.size(), order.size());
      for (size_t k = 0; k < order.size(); ++k) EXPECT_EQ(b.object_ids[k], a.object_ids[order[k]]);
      associated +=
          static_cast<int>(std::count_if(a.object_ids.begin(), a.object_ids.end(), [](int id) { return id >= 0; }));
    }
    EXPECT_GT(associated, 30) << toString(mode);
    given.finish();
    shuffled.finish();
    const std::vector<MappedObject> a = given.objects(), b = shuffled.objects();
    ASSERT_GE(a.size(), 5u) << toString(mode);
    ASSERT_EQ(a.size(), b.size()) << toString(mode);
    for (size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].object.id, b[i].object.id) << toString(mode);
      EXPECT_EQ(a[i].object.category, b[i].object.category);
      EXPECT_EQ(a[i].observations, b[i].observations);
      EXPECT_EQ(a[i].object.ellipsoid.center(), b[i].object.ellipsoid.center());
      EXPECT_EQ(a[i].object.ellipsoid.axes(), b[i].object.ellipsoid.axes());
    }
  }
}

/// A keyframe of squares (centre, half-size), each turned about the vertical so that its depth
/// grows by half its sideways offset, seen by a camera at `eye` looking along +z: the depth
/// image and, for each square in `detected`, a detection whose mask is the part of it in view
/// (nearer squares hide farther ones).
struct Squares {
  DepthImage depth;
  std::vector<Detection> detections;
};
Squares renderSquares(const Intrinsics& K, const Eigen::Vector3d& eye,
                      const std::vector<std::pair<Eigen::Vector3d, double>>& squares, const std::vector<int>& detected,
                      int category) {
  Squares out{{K.width, K.height, std::vector<float>(static_cast<size_t>(K.width * K.height), 0.0f)}, {}};
  std::vector<BinaryMask> masks(squares.size(), BinaryMask(K.height, K.width));
  for (int v = 0; v < K.height; ++v)
    for (int u = 0; u < K.width; ++u) {
      const double a = (u - K.cx) / K.fx, b = (v - K.cy) / K.fy;
      int nearest = -1;
      double nearest_z = 0.0;
      for (size_t i = 0; i < squares.size(); ++i) {
        const Eigen::Vector3d c = squares[i].first - eye;
        const double z = (c.z() - 0.5 * c.x()) / (1.0 - 0.5 * a);  // the ray meets z = c_z + (x - c_x) / 2
        const bool inside =
            std::abs(a * z - c.x()) <= squares[i].second && std::abs(b * z - c.y()) <= squares[i].second;
        if (inside && z > 0.0 && (nearest < 0 || z < nearest_z)) nearest = static_cast<int>(i), nearest_z = z;
      }
      if (nearest < 0) continue;
      out.depth.metres[static_cast<size_t>(v * K.width + u)] = static_cast<float>(nearest_z);
      masks[static_cast<size_t>(nearest)].data[static_cast<size_t>(v * K.width + u)] = 1;
    }
  for (const int i : detected) {
    Detection d;
    d.category_id = category;
    d.mask = encodeMask(masks[static_cast<size_t>(i)]);
    d.bbox = *maskBox(*d.mask);
    out.detections.push_back(d);
  }
  return out;
}

// Voxel mode: a detection is tracked in 2D only to an object whose depth range in the keyframe
// holds its mask's median depth. Two books 1 m apart in depth, the nearer one missed in a
// keyframe; then the camera moves to where the nearer hides the farther: its detection overlaps
// the farther one's expected box (the only object tracked from the keyframe before), but lies a
// metre in front of it, so it is matched in 3D to its own object instead of joining the other.
TEST(Mapper, ADetectionIsNotTrackedToAnObjectAtAnotherDepth) {
  const Intrinsics K(525.0, 525.0, 319.5, 239.5, 640, 480);
  const int kBook = 73;
  const Eigen::Vector3d far(0.0, 0.0, 3.0), near(-0.5, 0.0, 2.0);  // in line with a camera at x = -1.5
  const std::vector<std::pair<Eigen::Vector3d, double>> squares{{far, 0.1}, {near, 0.1}};
  const Eigen::Vector3d start(0.0, 0.0, 0.0), behind(-1.5, 0.0, 0.0);
  const std::vector<std::pair<Eigen::Vector3d, std::vector<int>>> keyframes{
      {start, {0, 1}}, {start, {0, 1}}, {start, {0}}, {behind, {1}}, {behind, {1}}};
  MapperOptions options;
  options.ellipsoid.up = -Eigen::Vector3d::UnitY();  // the cameras' image-up
  Mapper mapper(K, options);
  for (const auto& [eye, detected] : keyframes) {
    const Squares frame = renderSquares(K, eye, squares, detected, kBook);
    const Pose pose(Eigen::Matrix3d::Identity(), -eye);  // world->camera, no rotation
    mapper.addKeyframe(pose, frame.detections, &frame.depth);
  }
  const std::vector<MappedObject> objects = mapper.objects();
  ASSERT_EQ(objects.size(), 2u);
  for (const Eigen::Vector3d& truth : {far, near}) {
    const auto at = std::find_if(objects.begin(), objects.end(), [&](const MappedObject& o) {
      return (o.object.ellipsoid.center() - truth).norm() < 0.03;
    });
    ASSERT_NE(at, objects.end()) << truth.transpose();
    EXPECT_LT(at->object.ellipsoid.axes().maxCoeff(), 0.15);  // one square, not both
  }
  EXPECT_EQ(objects[0].observations + objects[1].observations, 7);
}

// Voxel mode: an object is expected in a keyframe where its voxels near its ellipsoid project,
// not where stray voxels put it. Two books side by side; in one keyframe the left one's mask
// bleeds onto a strip of the right one (a segmentation error at the same depth), which the right
// one's detection misses. The camera then moves right, so that the left book leaves the view and
// the right one sits at its left edge: the strip's voxels still project there, over the right
// book's detection, but lie far outside the left book's ellipsoid, and the detection joins its
// own book.
TEST(Mapper, StrayVoxelsDoNotDrawADetectionToTheirObject) {
  const Intrinsics K(525.0, 525.0, 319.5, 239.5, 640, 480);
  const int kBook = 73;
  const Eigen::Vector3d left(0.0, 0.0, 2.0), right(0.35, 0.0, 2.0);
  const std::vector<std::pair<Eigen::Vector3d, double>> squares{{left, 0.1}, {right, 0.1}};
  MapperOptions options;
  options.ellipsoid.up = -Eigen::Vector3d::UnitY();  // the cameras' image-up
  Mapper mapper(K, options);
  const auto add = [&](const Eigen::Vector3d& eye, const std::vector<int>& detected, bool bleed) {
    Squares frame = renderSquares(K, eye, squares, detected, kBook);
    if (bleed) {  // the right book's left third joins the left book's mask
      BinaryMask mask = *decodeMask(*frame.detections[0].mask);
      const Squares both = renderSquares(K, eye, squares, {1}, kBook);
      const BinaryMask other = *decodeMask(*both.detections[0].mask);
      const Box b = *maskBox(*both.detections[0].mask);
      for (int v = 0; v < K.height; ++v)
        for (int u = 0; u < K.width; ++u)
          if (other.at(u, v) && u < b.x1 + 0.3 * b.width()) mask.data[static_cast<size_t>(v * K.width + u)] = 1;
      frame.detections[0].mask = encodeMask(mask);
      frame.detections[0].bbox = *maskBox(*frame.detections[0].mask);
    }
    return mapper.addKeyframe(Pose(Eigen::Matrix3d::Identity(), -eye), frame.detections, &frame.depth);
  };
  const Eigen::Vector3d start = Eigen::Vector3d::Zero(), moved(1.4, 0.0, 0.0);
  std::vector<int> ids;
  for (int k = 0; k < 3; ++k) ids = add(start, {0, 1}, false).object_ids;
  const int left_id = ids[0], right_id = ids[1];
  ASSERT_NE(left_id, right_id);
  EXPECT_EQ(add(start, {0}, true).object_ids, std::vector<int>{left_id});
  EXPECT_EQ(add(moved, {1}, false).object_ids, std::vector<int>{right_id});
  ASSERT_EQ(mapper.objects().size(), 2u);
}

/// Two objects in the map, one at each book (the left one at negative x), with these counts of
/// observations.
void expectTwoBooks(const Mapper& mapper, const Eigen::Vector3d& left, const Eigen::Vector3d& right,
                    int left_observations, int right_observations) {
  const std::vector<MappedObject> objects = mapper.objects();
  ASSERT_EQ(objects.size(), 2u);
  for (const MappedObject& o : objects) {
    const bool is_right = o.object.ellipsoid.center().x() > 0.0;
    EXPECT_LT((o.object.ellipsoid.center() - (is_right ? right : left)).norm(), 0.015);
    EXPECT_EQ(o.observations, is_right ? right_observations : left_observations);
  }
}

// Voxel mode: a detection left over by 2D tracking joins the object its voxels match best, not
// the first that passes eq. 4. Two small books side by side, 1 cm apart, both pass it for a
// detection of the right one seen again after two keyframes without either; the left one was
// mapped first.
TEST(Mapper, ADetectionJoinsTheObjectItsVoxelsMatchBest) {
  const Intrinsics K(525.0, 525.0, 319.5, 239.5, 640, 480);
  const int kBook = 73;
  const Eigen::Vector3d left(-0.035, 0.0, 2.0), right(0.035, 0.0, 2.0);
  const std::vector<std::pair<Eigen::Vector3d, double>> squares{{left, 0.03}, {right, 0.03}};
  const std::vector<std::vector<int>> keyframes{{0, 1}, {0, 1}, {0, 1}, {}, {}, {1}};
  MapperOptions options;
  options.ellipsoid.up = -Eigen::Vector3d::UnitY();  // the cameras' image-up
  Mapper mapper(K, options);
  int matched_3d = 0;
  for (const std::vector<int>& detected : keyframes) {
    const Squares frame = renderSquares(K, Eigen::Vector3d::Zero(), squares, detected, kBook);
    matched_3d += mapper.addKeyframe(Pose(), frame.detections, &frame.depth).matched_3d;
  }
  EXPECT_EQ(matched_3d, 1);
  expectTwoBooks(mapper, left, right, 3, 4);
}

// Voxel mode: an object that 2D tracking pairs with one detection of a keyframe takes no other
// detection of it by 3D matching. Two small books side by side, 1 cm apart (each passes eq. 4
// for the other); the left one is mapped alone, then both are detected, the right one with the
// higher score, so it is taken first: its voxels match the left book's, which its own detection
// will take by 2D tracking. The right book starts an object of its own.
TEST(Mapper, ADetectionDoesNotJoinAnObjectAnotherDetectionOfItsKeyframeTracks) {
  const Intrinsics K(525.0, 525.0, 319.5, 239.5, 640, 480);
  const int kBook = 73;
  const Eigen::Vector3d left(-0.035, 0.0, 2.0), right(0.035, 0.0, 2.0);
  const std::vector<std::pair<Eigen::Vector3d, double>> squares{{left, 0.03}, {right, 0.03}};
  MapperOptions options;
  options.ellipsoid.up = -Eigen::Vector3d::UnitY();  // the cameras' image-up
  Mapper mapper(K, options);
  const auto add = [&](const std::vector<int>& detected) {
    Squares frame = renderSquares(K, Eigen::Vector3d::Zero(), squares, detected, kBook);
    for (size_t j = 0; j < detected.size(); ++j) frame.detections[j].score = detected[j] == 1 ? 0.9 : 0.6;
    return mapper.addKeyframe(Pose(), frame.detections, &frame.depth);
  };
  const int left_id = add({0}).object_ids[0];
  add({0});
  add({0});
  const KeyframeReport both = add({0, 1});
  EXPECT_EQ(both.object_ids[0], left_id);
  EXPECT_NE(both.object_ids[1], left_id);
  EXPECT_EQ(both.matched_3d, 0);
  add({0, 1});
  add({0, 1});
  expectTwoBooks(mapper, left, right, 6, 3);
}

// The map records where its keyframes were taken: their heights and tilts along the world's up
// when the mapper has one (voxel mode, or boxes mode given `boxes.up`), else along their mean
// image-up, widened by 1 m and 30 degrees; none before two keyframes.
TEST(Mapper, TheMapRecordsTheKeyframesCameraEnvelope) {
  const test::SimSequence seq = test::makeSimSequence(sim::ScenePreset::Sparse, 4, 12, sim::NoiseModel{});
  Eigen::Vector3d mean_image_up = Eigen::Vector3d::Zero();
  for (const auto& kf : seq.keyframes) mean_image_up -= kf.pose.rotation().row(1).transpose();  // camera -y
  for (const bool given_up : {true, false}) {
    MapperOptions opt;
    opt.mode = MappingMode::Boxes;
    if (given_up) opt.boxes.up = Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d up = given_up ? Eigen::Vector3d::UnitZ() : mean_image_up.normalized();
    Mapper mapper(seq.K, opt);
    EXPECT_FALSE(mapper.map().camera_envelope);
    double low = 1e9, high = -1e9, least_tilt = 1e9, most_tilt = -1e9;
    for (const auto& kf : seq.keyframes) {
      mapper.addKeyframe(kf.pose, kf.detections);
      const double height = up.dot(kf.pose.center());
      const double tilt = std::acos(-kf.pose.rotation().row(1).dot(up)) * 180.0 / M_PI;
      low = std::min(low, height), high = std::max(high, height);
      least_tilt = std::min(least_tilt, tilt), most_tilt = std::max(most_tilt, tilt);
    }
    const std::optional<CameraEnvelope> e = mapper.map().camera_envelope;
    ASSERT_TRUE(e);
    EXPECT_LT((e->up - up).norm(), 1e-12) << given_up;
    EXPECT_NEAR(e->min_height, low - 1.0, 1e-9);
    EXPECT_NEAR(e->max_height, high + 1.0, 1e-9);
    EXPECT_NEAR(e->min_tilt_deg, std::max(0.0, least_tilt - 30.0), 1e-6);
    EXPECT_NEAR(e->max_tilt_deg, std::min(180.0, most_tilt + 30.0), 1e-6);
    for (const auto& kf : seq.keyframes) EXPECT_TRUE(e->admits(kf.pose));
  }
}

TEST(Mapper, BadKeyframesAreErrorsAndLeaveTheMapUnchanged) {
  const test::SimSequence seq = test::makeSimSequence(sim::ScenePreset::Sparse, 1, 3, sim::NoiseModel());
  Mapper mapper(seq.K);
  const auto& kf = seq.keyframes[0];
  mapper.addKeyframe(kf.pose, kf.detections, &kf.depth);
  const MapperStats before = mapper.stats();

  DepthImage zeros = kf.depth;
  std::fill(zeros.metres.begin(), zeros.metres.end(), 0.0f);
  EXPECT_THROW(mapper.addKeyframe(kf.pose, kf.detections, &zeros), Error);
  EXPECT_THROW(mapper.addKeyframe(kf.pose, kf.detections, nullptr), Error);
  DepthImage small = kf.depth;
  small.width = 320;
  EXPECT_THROW(mapper.addKeyframe(kf.pose, kf.detections, &small), Error);
  const double nan = std::nan("");
  EXPECT_THROW(
      mapper.addKeyframe(Pose(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, nan, 0)), kf.detections, &kf.depth),
      Error);
  ASSERT_FALSE(kf.detections.empty());
  auto wrong_mask = kf.detections;
  wrong_mask[0].mask->width = 320;
  wrong_mask[0].mask->height = 960;  // same pixel count, other size
  try {
    mapper.addKeyframe(kf.pose, wrong_mask, &kf.depth);
    FAIL() << "a mask of another size was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("mask is 320x960, camera is 640x480"), std::string::npos) << e.what();
  }
  const MapperStats after = mapper.stats();
  EXPECT_EQ(after.keyframes, before.keyframes);
  EXPECT_EQ(after.voxels, before.voxels);
  EXPECT_THROW(Mapper{Intrinsics()}, Error);
}

/// The map objects of `map` that lie within `tolerance` of a same-category object of `other`
/// moved by `G` (x -> G x), with semi-axes within `tolerance` of its.
int objectsMatched(const ObjectMap& map, const ObjectMap& other, const Pose& G, double tolerance) {
  int n = 0;
  for (const MapObject& a : map.objects)
    for (const MapObject& b : other.objects)
      if (a.category == b.category && (a.ellipsoid.center() - G.transform(b.ellipsoid.center())).norm() < tolerance) {
        Eigen::Vector3d sa = a.ellipsoid.axes(), sb = b.ellipsoid.axes();
        std::sort(sa.data(), sa.data() + 3);
        std::sort(sb.data(), sb.data() + 3);
        n += (sa - sb).cwiseAbs().maxCoeff() < tolerance;
        break;
      }
  return n;
}

// A host whose world origin is elsewhere (every keyframe pose moved by one shift G: the same
// frames, so the same tracks; a box fit starts with the world's axes, so a rotation would start
// it elsewhere) builds the same boxes map in its frame; given the poses in this frame, its
// objects are fitted again and are this frame's map to the last digits (each fit starts from
// the boxes alone).
TEST(Mapper, BoxMapsAreFittedAgainAtTheHostsNewKeyframePoses) {
  const test::SimSequence seq = boxSequence();
  const Pose G(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.4, -0.2, 0.1));
  Mapper here(seq.K, boxesMode()), there(seq.K, boxesMode());
  std::vector<Pose> poses;
  for (const auto& kf : seq.keyframes) {
    here.addKeyframe(kf.pose, kf.detections);
    there.addKeyframe(kf.pose * G, kf.detections);
    poses.push_back(kf.pose);
  }
  here.finish();
  there.finish();
  const ObjectMap expected = here.map(), before = there.map();
  ASSERT_GE(expected.objects.size(), 3u);
  ASSERT_EQ(before.objects.size(), expected.objects.size());
  EXPECT_EQ(objectsMatched(expected, before, G, 1e-6), static_cast<int>(expected.objects.size()));
  EXPECT_EQ(objectsMatched(expected, before, Pose(), 0.1), 0);

  there.updateKeyframePoses(poses);
  const ObjectMap after = there.map();
  ASSERT_EQ(after.objects.size(), expected.objects.size());
  for (size_t i = 0; i < after.objects.size(); ++i) {
    const MapObject &a = after.objects[i], &e = expected.objects[i];
    EXPECT_EQ(a.id, e.id);
    EXPECT_EQ(a.category, e.category);
    EXPECT_LT((a.ellipsoid.center() - e.ellipsoid.center()).norm(), 1e-9) << a.id;
    EXPECT_LT((a.ellipsoid.axes() - e.ellipsoid.axes()).norm(), 1e-9) << a.id;
  }
  ASSERT_TRUE(after.camera_envelope && expected.camera_envelope);
  EXPECT_NEAR(after.camera_envelope->min_height, expected.camera_envelope->min_height, 1e-9);
  EXPECT_NEAR(after.camera_envelope->max_height, expected.camera_envelope->max_height, 1e-9);
}

// A trajectory that drifts (each keyframe's pose off by a rotation and a shift growing to 6
// degrees and 30 cm) places the objects where no keyframe agrees; once the host corrects the
// poses (a loop closure), the objects are fitted to their boxes at the corrected poses.
TEST(Mapper, ABoxMapFollowsALoopClosure) {
  const test::SimSequence seq = boxSequence();
  Mapper mapper(seq.K, boxesMode()), truth(seq.K, boxesMode());
  std::vector<Pose> poses;
  const double n = static_cast<double>(seq.keyframes.size());
  for (size_t i = 0; i < seq.keyframes.size(); ++i) {
    const auto& kf = seq.keyframes[i];
    const Pose drift(Eigen::AngleAxisd(0.1 * i / n, Eigen::Vector3d::UnitZ()).toRotationMatrix(),
                     Eigen::Vector3d(0.3 * i / n, 0.0, 0.0));
    mapper.addKeyframe(kf.pose * drift, kf.detections);
    truth.addKeyframe(kf.pose, kf.detections);
    poses.push_back(kf.pose);
  }
  mapper.finish();
  truth.finish();
  const ObjectMap expected = truth.map();
  const int drifted = objectsMatched(expected, mapper.map(), Pose(), 0.02);
  mapper.updateKeyframePoses(poses);
  const int corrected = objectsMatched(expected, mapper.map(), Pose(), 0.02);
  EXPECT_GE(corrected, static_cast<int>(expected.objects.size()) - 1);
  EXPECT_LE(drifted, corrected / 2);
}

// Voxel mode keeps no depth image: each voxel moves with the keyframe that last hit it. With
// every pose moved by one rigid transform, that brings each object where the map made in this
// frame has it (to a voxel: the grids differ), and the up measured on the floor with it.
TEST(Mapper, VoxelObjectsMoveWithTheKeyframeThatSawThemLast) {
  const test::SimSequence seq = test::makeSimSequence(sim::ScenePreset::Sparse, 3, 12, test::mappingNoise());
  const Pose G(Eigen::AngleAxisd(0.1, Eigen::Vector3d(1, 2, 0).normalized()).toRotationMatrix(),
               Eigen::Vector3d(0.3, 0.2, -0.1));
  MapperOptions opt;
  opt.estimate_up_from_floor = true;
  Mapper here(seq.K, opt), there(seq.K, opt);
  std::vector<Pose> poses;
  for (const auto& kf : seq.keyframes) {
    here.addKeyframe(kf.pose, kf.detections, &kf.depth);
    there.addKeyframe(kf.pose * G, kf.detections, &kf.depth);
    poses.push_back(kf.pose);
  }
  const ObjectMap expected = here.map();
  ASSERT_GE(expected.objects.size(), 3u);
  EXPECT_EQ(objectsMatched(expected, there.map(), Pose(), 0.05), 0);
  there.updateKeyframePoses(poses);
  EXPECT_EQ(objectsMatched(expected, there.map(), Pose(), 0.01), static_cast<int>(expected.objects.size()));
  EXPECT_LT((there.stats().up - here.stats().up).norm(), 1e-6);
  EXPECT_LT((there.stats().up - Eigen::Vector3d::UnitZ()).norm(), 0.02);
}

// A drift over part of the trajectory, corrected: a box on the floor seen from 12 keyframes on an
// arc, half of them drifted by 3, 6 or 10 cm. Each voxel moves with the keyframe that last hit
// it, so what the undrifted keyframes placed stays and what the drifted ones placed is brought
// back: 0.4 cm off afterwards in every case (measured). Before the correction, drifted late by
// 6 / 10 cm the box lies 5.4 / 9.5 cm off (the later keyframes' misses carve away what the
// earlier ones placed); by 3 cm, within the voxels' 4 cm depth tolerance, 0.9 cm (carved in part:
// both placements remain, which moving the whole object with its last keyframe overcorrected to
// 2.2 cm). Drifted early: 0.4-0.7 cm off before and after.
TEST(Mapper, AVoxelObjectFollowsTheCorrectionOfTheKeyframesThatSawItLast) {
  const sim::Scene scene = oneBoxScene();
  const sim::SimObject& box = scene.objects[0];
  const Intrinsics K(525.0, 525.0, 319.5, 239.5, 640, 480);
  for (const bool late : {true, false})
    for (const double d : {0.03, 0.06, 0.1}) {
      const Pose drift(Eigen::Matrix3d::Identity(), Eigen::Vector3d(d, 0.0, 0.0));
      Mapper mapper(K);
      std::mt19937_64 rng(1);
      std::vector<Pose> poses;
      for (int i = 0; i < 12; ++i) {
        const double a = -0.3 + 0.1 * i;
        const Pose pose = Pose::lookAt(Eigen::Vector3d(2.0 * std::cos(a), 2.0 * std::sin(a), 1.2), box.box_center);
        const sim::RenderedFrame frame = sim::render(scene, K, pose);
        const DepthImage depth = sim::noisyDepth(frame, sim::NoiseModel(), rng);
        const bool drifted = late == (i >= 6);
        mapper.addKeyframe(drifted ? pose * drift : pose, sim::detect(scene, frame, sim::NoiseModel(), rng), &depth);
        poses.push_back(pose);
      }
      const auto off = [&] { return (mapper.map().objects.at(0).ellipsoid.center() - box.box_center).norm(); };
      ASSERT_EQ(mapper.map().objects.size(), 1u);
      if (late && d > 0.05)
        EXPECT_GT(off(), 0.8 * d) << d;
      else
        EXPECT_LT(off(), 0.01) << d;
      mapper.updateKeyframePoses(poses);
      ASSERT_EQ(mapper.map().objects.size(), 1u);
      EXPECT_LT(off(), 0.01) << d << (late ? " late" : " early");
    }
}

// A correction that turns the map: the voxels move with their keyframes and, turned against
// the grid, some fall into one cell. With an ellipsoid that needs every point it was built from,
// the moved voxels build none, and the ellipsoid they had moves with them instead of staying
// where the drifted keyframes put it.
TEST(Mapper, AVoxelObjectThatCannotBeRebuiltAfterACorrectionMovesWithItsVoxels) {
  const sim::Scene scene = oneBoxScene();
  const sim::SimObject& box = scene.objects[0];
  const Intrinsics K(525.0, 525.0, 319.5, 239.5, 640, 480);
  const Pose drift(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()).toRotationMatrix(),
                   Eigen::Vector3d(0.3, -0.2, 0.0));
  std::mt19937_64 rng(1);
  std::vector<Pose> poses;
  std::vector<std::vector<Detection>> detections;
  std::vector<DepthImage> depths;
  for (int i = 0; i < 4; ++i) {
    const double a = -0.2 + 0.15 * i;
    poses.push_back(Pose::lookAt(Eigen::Vector3d(2.0 * std::cos(a), 2.0 * std::sin(a), 1.2), box.box_center));
    const sim::RenderedFrame frame = sim::render(scene, K, poses.back());
    depths.push_back(sim::noisyDepth(frame, sim::NoiseModel(), rng));
    detections.push_back(sim::detect(scene, frame, sim::NoiseModel(), rng));
  }
  const auto drifted = [&](size_t min_points) {
    MapperOptions opt;
    opt.ellipsoid.min_points = min_points;
    auto mapper = std::make_unique<Mapper>(K, opt);
    for (size_t i = 0; i < poses.size(); ++i) mapper->addKeyframe(poses[i] * drift, detections[i], &depths[i]);
    return mapper;
  };
  // The most points the object had when its ellipsoid was built.
  size_t lo = 8, hi = drifted(8)->objects().at(0).voxels + 1;
  while (hi - lo > 1) {
    const size_t mid = (lo + hi) / 2;
    (drifted(mid)->map().objects.empty() ? hi : lo) = mid;
  }
  const auto mapper = drifted(lo);
  const auto off = [&] { return (mapper->map().objects.at(0).ellipsoid.center() - box.box_center).norm(); };
  ASSERT_EQ(mapper->map().objects.size(), 1u);
  EXPECT_GT(off(), 0.2) << off();
  const size_t voxels = mapper->objects().at(0).voxels;
  const Ellipsoid before = mapper->map().objects.at(0).ellipsoid;
  mapper->updateKeyframePoses(poses);
  ASSERT_EQ(mapper->map().objects.size(), 1u);
  EXPECT_EQ(mapper->objects().at(0).voxels, voxels);  // not rebuilt: its voxel count is the old one
  EXPECT_LT(off(), 0.05) << off();                    // a box seen from one side: its ellipsoid a few cm deep
  // Moved as a whole: every keyframe's correction is `drift`.
  const Ellipsoid after = mapper->map().objects.at(0).ellipsoid;
  EXPECT_LT((after.center() - drift.transform(before.center())).norm(), 1e-9);
  const Eigen::Matrix3d turned = drift.rotation() * before.shapeMatrix() * drift.rotation().transpose();
  EXPECT_LT((after.shapeMatrix() - turned).norm(), 1e-9);
}

// A loop: the camera maps a book from an arc (keyframes 0-7), looks away (8-11), and comes back
// along the arc with its poses drifted by 40 cm, so the book's boxes fall where the map holds
// nothing and a second book is made there. Once the host closes the loop (the true poses), both
// are fitted where the book is, and joined: one book, with every detection.
TEST(Mapper, ALoopClosureJoinsTheTwoObjectsADriftMadeOfOne) {
  const Intrinsics K(525.0, 525.0, 319.5, 239.5, 640, 480);
  const int kBook = 73;
  const Ellipsoid book(Eigen::Vector3d(0, 0, 0.02), Eigen::Vector3d(0.12, 0.09, 0.02), Eigen::Matrix3d::Identity());
  const Pose drift(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.4, 0.0, 0.0));
  Mapper mapper(K, boxesMode());
  std::vector<Pose> poses;
  std::set<int> reported;
  for (int i = 0; i < 20; ++i) {
    const bool away = i >= 8 && i < 12;
    const Pose pose =
        away ? Pose::lookAt(Eigen::Vector3d(1.5, 0, 0.8), Eigen::Vector3d(3, 0, 0.8)) : arcPose(i < 8 ? i : 19 - i);
    std::vector<Detection> boxes;
    if (!away) boxes.push_back(boxOf(book, kBook, K, pose));
    for (const int id : mapper.addKeyframe(i < 12 ? pose : pose * drift, boxes).object_ids) reported.insert(id);
    poses.push_back(pose);
  }
  mapper.finish();
  ASSERT_EQ(mapper.map().objects.size(), 2u);
  EXPECT_EQ(reported.size(), 2u);
  mapper.updateKeyframePoses(poses);
  const ObjectMap map = mapper.map();
  ASSERT_EQ(map.objects.size(), 1u);
  for (const int id : reported) EXPECT_EQ(mapper.currentObjectId(id), map.objects[0].id);  // the younger joined
  EXPECT_LT((map.objects[0].ellipsoid.center() - book.center()).norm(), 0.02);
  EXPECT_EQ(mapper.objects()[0].observations, 16);
}

// The same loop in voxel mode (a box on the floor, the return drifted by a metre): the two models
// of the box, moved with their keyframes, share their surface again and are joined.
TEST(Mapper, ALoopClosureJoinsTwoVoxelModelsOfOneObject) {
  const sim::Scene scene = oneBoxScene();
  const sim::SimObject& box = scene.objects[0];
  const Intrinsics K(525.0, 525.0, 319.5, 239.5, 640, 480);
  const Pose drift(Eigen::Matrix3d::Identity(), Eigen::Vector3d(1.0, 0.0, 0.0));
  Mapper mapper(K);
  std::mt19937_64 rng(1);
  std::vector<Pose> poses;
  for (int i = 0; i < 16; ++i) {
    const bool away = i >= 6 && i < 10;
    const double a = -0.3 + 0.1 * (i < 6 ? i : 15 - i);  // out along an arc around the box, and back
    const Eigen::Vector3d eye(2.0 * std::cos(a), 2.0 * std::sin(a), 1.2);
    const Pose pose = Pose::lookAt(eye, away ? Eigen::Vector3d(2 * eye.x(), 2 * eye.y(), 1.2) : box.box_center);
    const sim::RenderedFrame frame = sim::render(scene, K, pose);
    const auto detections = sim::detect(scene, frame, sim::NoiseModel(), rng);
    const DepthImage depth = sim::noisyDepth(frame, sim::NoiseModel(), rng);
    mapper.addKeyframe(i < 10 ? pose : pose * drift, detections, &depth);
    poses.push_back(pose);
  }
  ASSERT_EQ(mapper.map().objects.size(), 2u);
  mapper.updateKeyframePoses(poses);
  const ObjectMap map = mapper.map();
  ASSERT_EQ(map.objects.size(), 1u);
  EXPECT_LT((map.objects[0].ellipsoid.center() - box.box_center).norm(), 0.03);
  EXPECT_EQ(mapper.objects()[0].observations, 12);
  // The joined model keeps the keyframes of each part: a correction of the return's keyframes
  // alone moves what they saw last (the return retraced the way out: nearly every voxel), where
  // those voxels counted as the older model's before.
  const Pose shift(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.1, 0.0, 0.0));
  for (size_t k = 10; k < poses.size(); ++k) poses[k] = poses[k] * shift;
  mapper.updateKeyframePoses(poses);
  ASSERT_EQ(mapper.map().objects.size(), 1u);
  const Eigen::Vector3d moved = mapper.map().objects[0].ellipsoid.center() - map.objects[0].ellipsoid.center();
  EXPECT_LT((moved - Eigen::Vector3d(-0.1, 0.0, 0.0)).norm(), 0.01);  // by the correction's inverse shift
}

// A monocular host's poses in a unit of its own (here 2.5 m: every translation divided by it),
// with that unit given, make the metric map in that unit: the size prior, its bounds and the
// envelope's margin are divided by it, and the box fit is the same fit at another scale.
TEST(Mapper, BoxMapsOfPosesInAnotherUnitAreTheMetricMapInThatUnit) {
  const test::SimSequence seq = boxSequence();
  const double unit = 2.5;
  MapperOptions in_unit = boxesMode();
  in_unit.unit_metres = unit;
  Mapper metric(seq.K, boxesMode()), scaled(seq.K, in_unit), unaware(seq.K, boxesMode());
  for (const auto& kf : seq.keyframes) {
    const Pose pose(kf.pose.rotation(), kf.pose.translation() / unit);
    metric.addKeyframe(kf.pose, kf.detections);
    scaled.addKeyframe(pose, kf.detections);
    unaware.addKeyframe(pose, kf.detections);
  }
  metric.finish();
  scaled.finish();
  unaware.finish();
  const ObjectMap expected = metric.map(), got = scaled.map();
  ASSERT_GE(expected.objects.size(), 3u);
  ASSERT_EQ(got.objects.size(), expected.objects.size());
  double largest_difference = 0.0;
  for (size_t i = 0; i < got.objects.size(); ++i) {
    const Ellipsoid &g = got.objects[i].ellipsoid, &e = expected.objects[i].ellipsoid;
    largest_difference =
        std::max({largest_difference, (unit * g.center() - e.center()).norm(), (unit * g.axes() - e.axes()).norm()});
  }
  EXPECT_LT(largest_difference, 1e-5);
  ASSERT_TRUE(got.camera_envelope && expected.camera_envelope);
  EXPECT_NEAR(unit * got.camera_envelope->min_height, expected.camera_envelope->min_height, 1e-9);
  // Unaware of the unit, the prior pulls the sizes towards metres taken for units: not the same map.
  double unaware_difference = 0.0;
  const ObjectMap off = unaware.map();
  for (size_t i = 0; i < std::min(off.objects.size(), expected.objects.size()); ++i)
    unaware_difference = std::max(
        unaware_difference, (unit * off.objects[i].ellipsoid.axes() - expected.objects[i].ellipsoid.axes()).norm());
  EXPECT_GT(unaware_difference, 0.01);
  // The unit the objects tell scales with the poses' (how near it comes on real data: the Python
  // test on fr3; the simulator's objects are not of their categories' typical sizes).
  const std::optional<double> estimate = scaled.estimatedUnitMetres(3), in_metres = metric.estimatedUnitMetres(3);
  ASSERT_TRUE(estimate && in_metres);
  EXPECT_NEAR(*estimate, unit * *in_metres, 1e-6);
  MapperOptions voxel_unit;
  voxel_unit.unit_metres = 2.0;
  EXPECT_NE(voxel_unit.validate().find("unit_metres must be 1 in voxel mode"), std::string::npos);
  EXPECT_FALSE(Mapper(seq.K).estimatedUnitMetres());
}

TEST(Mapper, KeyframePosesOfAnotherCountOrNotFiniteAreRefused) {
  const test::SimSequence seq = test::makeSimSequence(sim::ScenePreset::Sparse, 1, 3, sim::NoiseModel());
  Mapper mapper(seq.K);
  std::vector<Pose> poses;
  for (const auto& kf : seq.keyframes) {
    mapper.addKeyframe(kf.pose, kf.detections, &kf.depth);
    poses.push_back(kf.pose);
  }
  const ObjectMap before = mapper.map();
  const auto refused = [&](const std::vector<Pose>& given, const std::string& why) {
    try {
      mapper.updateKeyframePoses(given);
      ADD_FAILURE() << "accepted: " << why;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
    }
  };
  refused({poses.begin(), poses.end() - 1}, "2 keyframe pose(s) given for 3 keyframe(s) added");
  std::vector<Pose> bad = poses;
  bad[1] = Pose(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, std::nan(""), 0));
  refused(bad, "keyframe 1: pose is not a finite rigid transform");
  const ObjectMap after = mapper.map();
  ASSERT_EQ(after.objects.size(), before.objects.size());
  for (size_t i = 0; i < after.objects.size(); ++i)
    EXPECT_EQ(after.objects[i].ellipsoid.center(), before.objects[i].ellipsoid.center());
}

TEST(Mapper, OptionsOutOfRangeAreRefusedNamingTheField) {
  EXPECT_EQ(MapperOptions().validate(), "");
  const auto problem = [](void (*change)(MapperOptions&)) {
    MapperOptions o;
    change(o);
    try {
      Mapper mapper(Intrinsics(525.0, 525.0, 319.5, 239.5, 640, 480), o);
      return std::string("accepted");
    } catch (const Error& e) {
      return std::string(e.what());
    }
  };
  EXPECT_NE(problem([](MapperOptions& o) { o.voxels.voxel_size = NAN; }).find("voxels.voxel_size"), std::string::npos);
  EXPECT_NE(problem([](MapperOptions& o) { o.voxels.hit_probability = 1.5; }).find("voxels.hit_probability"),
            std::string::npos);
  EXPECT_NE(problem([](MapperOptions& o) { o.voxels.min_depth = 9; }).find("voxels.min_depth"), std::string::npos);
  EXPECT_NE(problem([](MapperOptions& o) { o.tracking.min_iou = -0.1; }).find("tracking.min_iou"), std::string::npos);
  EXPECT_NE(problem([](MapperOptions& o) { o.prune_probability = INFINITY; }).find("prune_probability"),
            std::string::npos);
  EXPECT_NE(problem([](MapperOptions& o) { o.boxes.max_views = 1; }).find("boxes.max_views"), std::string::npos);
  EXPECT_NE(problem([](MapperOptions& o) { o.boxes.loss_scale = 0.0; }).find("boxes.loss_scale"), std::string::npos);
  EXPECT_NE(problem([](MapperOptions& o) {
              o.boxes.loss_scale = std::numeric_limits<double>::infinity();
            }).find("boxes.loss_scale"),
            std::string::npos);
  EXPECT_NE(problem([](MapperOptions& o) { o.boxes.up = Eigen::Vector3d::Zero(); }).find("boxes.up"),
            std::string::npos);
  EXPECT_NE(problem([](MapperOptions& o) { o.min_score = NAN; }).find("min_score"), std::string::npos);
  EXPECT_NE(problem([](MapperOptions& o) {
              o.mode = MappingMode::Boxes;
              o.lens = Lens{Intrinsics(500.0, 500.0, 320.0, 240.0, 640, 480), {}};
            }).find("not the camera's"),
            std::string::npos);
  EXPECT_NE(problem([](MapperOptions& o) {
              o.mode = MappingMode::Boxes;
              o.lens = Lens{Intrinsics(525.0, 525.0, 319.5, 239.5, 640, 480), {-0.9, 0, 0, 0, 0}};
            }).find("folds over"),
            std::string::npos);
}

// Boxes a detector gives on the raw images of a distorted lens (fr2's): the bounding box of the
// object's projected outline moved by the lens. Mapped with the lens, each object lands where
// the pinhole boxes put it; taken as pinhole boxes, off by centimetres. A lens without
// distortion maps exactly as none.
TEST(Mapper, BoxesOfARawImageAreUndistortedWithTheLens) {
  const Intrinsics K(520.90862, 521.007327, 325.141442, 249.701764, 640, 480);
  const Lens fr2{K, {0.231222, -0.784899, -0.003257, -0.000105, 0.917205}};
  // A book, a cup and a bottle far off the image centre, where the lens moves their boxes most.
  const int categories[3] = {73, 41, 39};
  const std::vector<Ellipsoid> objects = {
      Ellipsoid({0.1, 0.75, 0.1}, {0.12, 0.08, 0.1}, Eigen::Matrix3d::Identity()),
      Ellipsoid({-0.3, -0.7, 0.05}, {0.06, 0.06, 0.05}, Eigen::Matrix3d::Identity()),
      Ellipsoid({0.0, 0.0, 0.6}, {0.1, 0.1, 0.15}, Eigen::Matrix3d::Identity())};
  const auto build = [&](const std::optional<Lens>& lens, bool raw_boxes) {
    MapperOptions options;
    options.mode = MappingMode::Boxes;
    options.lens = lens;
    Mapper mapper(K, options);
    for (int i = 0; i < 13; ++i) {
      std::vector<Detection> detections;
      for (size_t k = 0; k < objects.size(); ++k) {
        Detection d = boxOf(objects[k], categories[k], K, arcPose(i));
        if (raw_boxes) {  // the bounding box of the outline where the lens images it
          const Projection p = project(objects[k], K, arcPose(i));
          Box raw(INFINITY, INFINITY, -INFINITY, -INFINITY);
          for (const Eigen::Vector2d& q : p.ellipse.sampleBoundary(720)) {
            const Eigen::Vector2d r = fr2.distortion.distortPixel(K, q);
            raw =
                Box(std::min(raw.x1, r.x()), std::min(raw.y1, r.y()), std::max(raw.x2, r.x()), std::max(raw.y2, r.y()));
          }
          d.bbox = raw;
        }
        detections.push_back(d);
      }
      mapper.addKeyframe(arcPose(i), detections);
    }
    mapper.finish();
    return mapper.map();
  };
  const ObjectMap pinhole = build(std::nullopt, false);
  // How far a map's objects lie from the pinhole boxes' map (the fit's own bias set aside).
  const auto offset = [&](const ObjectMap& map) {
    double worst = 0.0;
    for (const MapObject& p : pinhole.objects) {
      double nearest = INFINITY;
      for (const MapObject& o : map.objects)
        nearest = std::min(nearest, (o.ellipsoid.center() - p.ellipsoid.center()).norm());
      worst = std::max(worst, nearest);
    }
    return worst;
  };
  const ObjectMap undistorted = build(fr2, true);
  const ObjectMap taken_as_pinhole = build(std::nullopt, true);
  ASSERT_EQ(pinhole.objects.size(), objects.size());
  ASSERT_EQ(undistorted.objects.size(), objects.size());
  EXPECT_LT(offset(undistorted), 0.002);      // measured 0.2 mm
  EXPECT_GT(offset(taken_as_pinhole), 0.01);  // measured 1.8 cm
  const ObjectMap no_distortion = build(Lens{K, {}}, false);
  ASSERT_EQ(no_distortion.objects.size(), pinhole.objects.size());
  for (size_t i = 0; i < pinhole.objects.size(); ++i)
    EXPECT_EQ(no_distortion.objects[i].ellipsoid.center(), pinhole.objects[i].ellipsoid.center());
}

// RGB-D keyframes whose depth images and masks are raw images of a distorted lens (made here by
// resampling the simulator's pinhole images through fr2's lens, nearest pixel): mapped with the
// lens, the objects land where the pinhole images put them; taken as pinhole images, farther off.
TEST(Mapper, VoxelKeyframesOfARawImageAreUndistortedWithTheLens) {
  const test::SimSequence seq = test::makeSimSequence(sim::ScenePreset::Office, 3, 16, test::mappingNoise());
  const Lens lens{seq.K, {0.231222, -0.784899, -0.003257, -0.000105, 0.917205}};
  const int W = seq.K.width, H = seq.K.height;
  std::vector<int> pinhole_of_raw(static_cast<size_t>(W) * H, -1);  // where each raw pixel comes from
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      if (const std::optional<Eigen::Vector2d> p = lens.undistortPixel({x, y})) {
        const long px = std::lround(p->x()), py = std::lround(p->y());
        if (px >= 0 && py >= 0 && px < W && py < H) pinhole_of_raw[static_cast<size_t>(y) * W + x] = py * W + px;
      }
  std::vector<test::SimKeyframe> raw = seq.keyframes;
  for (test::SimKeyframe& kf : raw) {
    for (size_t i = 0; i < pinhole_of_raw.size(); ++i) {
      const int p = pinhole_of_raw[i];
      kf.depth.metres[i] = p < 0 ? 0.0f : seq.keyframes[&kf - raw.data()].depth.metres[static_cast<size_t>(p)];
    }
    for (Detection& d : kf.detections) {
      if (!d.mask) continue;
      const BinaryMask pinhole = *decodeMask(*d.mask);
      d.mask = encodeRuns(H, W, [&](int x, int y) {
        const int p = pinhole_of_raw[static_cast<size_t>(y) * W + x];
        return p >= 0 && pinhole.at(p % W, p / W) != 0;
      });
      if (const std::optional<Box> box = maskBox(*d.mask)) d.bbox = *box;
    }
  }
  const auto build = [&](const std::vector<test::SimKeyframe>& keyframes, const std::optional<Lens>& l) {
    MapperOptions options;
    options.lens = l;
    Mapper mapper(seq.K, options);
    for (const test::SimKeyframe& kf : keyframes) mapper.addKeyframe(kf.pose, kf.detections, &kf.depth);
    return mapper.map();
  };
  const ObjectMap pinhole = build(seq.keyframes, std::nullopt);
  // The median distance of the pinhole map's objects to their nearest in another map, and the
  // median relative difference of the sums of their semi-axes.
  const auto offset = [&](const ObjectMap& map) {
    std::vector<double> d, size;
    for (const MapObject& p : pinhole.objects) {
      const MapObject* nearest = nullptr;
      double distance = INFINITY;
      for (const MapObject& o : map.objects)
        if (const double to_o = (o.ellipsoid.center() - p.ellipsoid.center()).norm(); to_o < distance)
          nearest = &o, distance = to_o;
      if (!nearest) return std::pair(1e9, 1e9);
      d.push_back(distance);
      size.push_back(std::abs(nearest->ellipsoid.axes().sum() / p.ellipsoid.axes().sum() - 1));
    }
    return std::pair(median(d), median(size));
  };
  ASSERT_GE(pinhole.objects.size(), 8u);
  const auto undistorted = offset(build(raw, lens)), as_pinhole = offset(build(raw, std::nullopt));
  // Measured 0 and 0 (the round trip through the raw image returns the pixels to themselves); a
  // mask undistorted into a window 2 pixels too narrow moves them by 0.3 mm and 0.06%. Taken as
  // pinhole images: 1.1 cm and 1.7%.
  EXPECT_LT(undistorted.first, 1e-4);
  EXPECT_LT(undistorted.second, 1e-4);
  EXPECT_GT(as_pinhole.first, 0.006);
}

TEST(Mapper, ReadsWhileMappingAndExportToTheMapFormat) {
  const test::SimSequence seq = test::makeSimSequence(sim::ScenePreset::Sparse, 5, 30, test::mappingNoise());
  Mapper mapper(seq.K);
  std::atomic<bool> done(false);
  std::atomic<long> reads(0);
  std::thread reader([&] {
    while (!done) {
      const ObjectMap m = mapper.map();
      for (const MapObject& o : m.objects) ASSERT_TRUE(o.ellipsoid.isValid());
      ++reads;
    }
  });
  for (const auto& kf : seq.keyframes) mapper.addKeyframe(kf.pose, kf.detections, &kf.depth);
  done = true;
  reader.join();
  EXPECT_GT(reads.load(), 0);

  // The same keyframes mapped serially give the same map.
  Mapper serial(seq.K);
  for (const auto& kf : seq.keyframes) serial.addKeyframe(kf.pose, kf.detections, &kf.depth);
  const ObjectMap a = mapper.map(), b = serial.map();
  ASSERT_EQ(a.objects.size(), b.objects.size());
  ASSERT_FALSE(a.objects.empty());
  for (size_t i = 0; i < a.objects.size(); ++i)
    EXPECT_LT((a.objects[i].ellipsoid.center() - b.objects[i].ellipsoid.center()).norm(), 1e-12);

  test::TempDir dir;
  const std::string path = dir.path("map.json");
  io::writeMap(path, a);
  const ObjectMap back = io::readMap(path);
  ASSERT_EQ(back.objects.size(), a.objects.size());
  for (size_t i = 0; i < a.objects.size(); ++i) {
    EXPECT_EQ(back.objects[i].category, a.objects[i].category);
    EXPECT_LT((back.objects[i].ellipsoid.center() - a.objects[i].ellipsoid.center()).norm(), 1e-9);
    EXPECT_LT((back.objects[i].ellipsoid.axes() - a.objects[i].ellipsoid.axes()).norm(), 1e-9);
  }
}

}  // namespace
}  // namespace ellreloc
