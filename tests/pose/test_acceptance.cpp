// The acceptance test (AcceptanceOptions): frames that hold no evidence of the map get no pose.
// Null frames are independent of the threshold's calibration data (other seeds, other scenes).

#include <gtest/gtest.h>

#include <random>

#include "ellreloc/core/evaluation.hpp"
#include "ellreloc/io/camera.hpp"
#include "ellreloc/io/detections.hpp"
#include "ellreloc/io/map.hpp"
#include "ellreloc/observe/observe.hpp"
#include "ellreloc/pose/object_relocalizer.hpp"
#include "ellreloc/sim/map_observations.hpp"
#include "fixtures/data_dir.hpp"
#include "fixtures/random_geometry.hpp"

using namespace ellreloc;

namespace {

/// A layout of `count` random ellipsoids on a 2.4 m x 2.4 m table-top, of `categories` categories.
ObjectMap randomLayout(std::mt19937& rng, int count, int categories) {
  ObjectMap map;
  for (int i = 0; i < count; ++i) {
    // One draw per statement: the order of a call's arguments is the compiler's to choose.
    Eigen::Vector3d centre, axes;
    for (int k = 0; k < 3; ++k) centre(k) = test::uniform(rng, k < 2 ? -1.2 : -0.3, k < 2 ? 1.2 : 0.3);
    for (int k = 0; k < 3; ++k) axes(k) = test::uniform(rng, 0.05, 0.25);
    const Eigen::Matrix3d rotation = test::randomRotation(rng);
    map.objects.push_back({i, i % categories, "", Ellipsoid(centre, axes, rotation)});
  }
  return map;
}

/// `layout` `copies` times, copy k moved by k x `shift`, its ids + 100 k.
ObjectMap repeatedLayout(const ObjectMap& layout, const Eigen::Vector3d& shift, int copies) {
  ObjectMap map;
  for (int k = 0; k < copies; ++k)
    for (MapObject copy : layout.objects) {
      copy.id += 100 * k;
      copy.ellipsoid = Ellipsoid(copy.ellipsoid.center() + k * shift, copy.ellipsoid.axes(), copy.ellipsoid.rotation());
      map.objects.push_back(copy);
    }
  return map;
}

/// The same view of copy k of repeatedLayout(layout, shift, ...) as `view` has of the layout.
Pose viewOfCopy(const Pose& view, const Eigen::Vector3d& shift, int k) {
  return Pose(view.rotation(), view.translation() - view.rotation() * (k * shift));
}

/// A random layout and a view of it that sees at least five of its objects.
struct LayoutView {
  ObjectMap layout;
  Pose truth;
  std::vector<Observation> observations;
};
LayoutView viewOfRandomLayout(std::mt19937& rng, const Intrinsics& K, int count, int categories) {
  for (;;) {
    LayoutView v{randomLayout(rng, count, categories), test::randomLookAtPose(rng), {}};
    v.observations = sim::observeMap(v.layout, K, v.truth);
    if (v.observations.size() >= 5) return v;
  }
}

/// Box observations of every detection of each frame.
std::vector<std::vector<Observation>> boxObservations(const std::vector<DetectionFrame>& frames, const Intrinsics& K) {
  std::vector<std::vector<Observation>> out;
  for (const DetectionFrame& f : frames) {
    out.emplace_back();
    for (const Detection& d : f.detections)
      if (auto o = observationFromBox(d.category_id, d.score, d.bbox, K.width, K.height)) out.back().push_back(*o);
  }
  return out;
}

/// The frames with each box moved to a uniformly random place and given the size of a random
/// box of the sequence: the categories and box sizes of real frames, no geometry.
std::vector<DetectionFrame> randomBoxes(std::vector<DetectionFrame> frames, const Intrinsics& K, uint32_t seed) {
  std::vector<Box> boxes;
  for (const DetectionFrame& f : frames)
    for (const Detection& d : f.detections) boxes.push_back(d.bbox);
  std::mt19937 rng(seed);
  std::uniform_int_distribution<size_t> pick(0, boxes.size() - 1);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (DetectionFrame& f : frames)
    for (Detection& d : f.detections) {
      const Box& b = boxes[pick(rng)];
      const double x = u(rng) * std::max(0.0, K.width - b.width()), y = u(rng) * std::max(0.0, K.height - b.height());
      d.bbox = Box(x, y, x + b.width(), y + b.height());
    }
  return frames;
}

/// Frames given a pose: reported (Success) and found at all (Success or LowEvidence).
struct Posed {
  int reported = 0, found = 0;
};

Posed posed(const ObjectRelocalizer& reloc, const std::vector<std::vector<Observation>>& frames) {
  Posed n;
  for (const auto& observations : frames) {
    const RelocalizationStatus s = reloc.relocalize(observations).status;
    n.reported += s == RelocalizationStatus::Success;
    n.found += s == RelocalizationStatus::Success || s == RelocalizationStatus::LowEvidence;
  }
  return n;
}

}  // namespace

TEST(Acceptance, NoPoseFromRandomBoxesOrFromAnotherScene) {
  const std::string fr2 = test::dataPath("tum_fr2_desk"), s11 = test::dataPath("independent_synth/office_s11");
  const Intrinsics K = io::readCamera(fr2 + "/camera.yaml");
  const ObjectMap desk = io::readMap(fr2 + "/map.json");
  const std::vector<DetectionFrame> keyframes = io::readDetections(fr2 + "/keyframes.detections.json");
  const std::vector<DetectionFrame> office = io::readDetections(s11 + "/query.detections.json");
  const ObjectRelocalizer ours(desk, K);

  // Random boxes of the desk's categories, and the other scene's frames, against the desk's map:
  // without the test nearly every frame gets a pose; with it, a few.
  std::vector<DetectionFrame> every_other;
  for (size_t i = 0; i < keyframes.size(); i += 2) every_other.push_back(keyframes[i]);
  const auto random = boxObservations(randomBoxes(every_other, K, 2024), K);
  const Posed from_random = posed(ours, random), from_other_scene = posed(ours, boxObservations(office, K));
  EXPECT_GE(from_random.found, 80);       // of 99: measured 91
  EXPECT_GE(from_other_scene.found, 90);  // of 100: measured 100
  // Measured 0 and 5: the office scene's many chairs, monitors and keyboards against the desk's
  // map is the hardest of the null sets of docs/reliability.md (1% overall).
  EXPECT_LE(from_random.reported, 5);
  EXPECT_LE(from_other_scene.reported, 7);

  // The real keyframes keep most of their poses: the evidence of a true pose is far above it.
  const Posed real = posed(ours, boxObservations(every_other, K));
  EXPECT_GE(real.reported, 62);  // measured 67 of 99 (91 without the test)

  // A withheld pose says why and keeps the pose for a host's own check.
  for (const auto& observations : random) {
    const RelocalizationResult r = ours.relocalize(observations);
    if (r.status != RelocalizationStatus::LowEvidence) continue;
    EXPECT_LT(r.evidence, ours.options().acceptance.min_evidence);
    EXPECT_NE(r.reason.find("evidence"), std::string::npos);
    EXPECT_TRUE(r.pose.isValid());
    EXPECT_FALSE(r.inliers.empty());
    break;
  }
}

// The margin: a map holding the same layout twice, 20 m apart, fits every frame at two poses
// alike, so the chosen pose has a rival of the same cost, the other copy's view; the layout
// alone has none close.
TEST(Acceptance, TwinLayoutsLeaveNoMargin) {
  std::mt19937 rng(7);
  const Intrinsics K = test::testIntrinsics();
  const Eigen::Vector3d shift(20.0, 0.0, 0.0);
  for (int trial = 0; trial < 5; ++trial) {
    const auto [map, truth, observations] = viewOfRandomLayout(rng, K, 8, 4);

    const RelocalizationResult alone = ObjectRelocalizer(map, K).relocalize(observations);
    ASSERT_EQ(alone.status, RelocalizationStatus::Success) << alone.reason;
    EXPECT_LT(test::positionError(alone.pose, truth), 0.01);
    EXPECT_GT(alone.margin, 1.0);  // a rival pose explains at most a few observations, poorly

    const ObjectMap twins = repeatedLayout(map, shift, 2);
    const Pose shifted = viewOfCopy(truth, shift, 1);
    // Every triplet, so that both copies' views are found whatever the sampler's stopping rule
    // (the twin map doubles the candidates: beyond the exhaustive search's default bound).
    RelocalizerOptions every_triplet;
    every_triplet.search.sampler = HypothesisSampler::Exhaustive;
    const ObjectRelocalizer twin_reloc(twins, K, every_triplet);
    const RelocalizationResult r = twin_reloc.relocalize(observations);
    ASSERT_EQ(r.status, RelocalizationStatus::Success) << r.reason;
    EXPECT_LT(std::min(test::positionError(r.pose, truth), test::positionError(r.pose, shifted)), 0.01);
    EXPECT_LT(r.margin, 0.01);
    // The rival is the view of the other copy: the pose a host would try next.
    ASSERT_TRUE(r.rival);
    const Pose& other = test::positionError(r.pose, truth) < 1.0 ? shifted : truth;
    EXPECT_LT(test::positionError(*r.rival, other), 0.01);
    EXPECT_LT(test::rotationError(*r.rival, other), 0.5);

    // Asked for a margin, the acceptance test withholds the pose and says why.
    RelocalizerOptions strict = every_triplet;
    strict.acceptance.min_margin = 0.1;
    const RelocalizationResult withheld = ObjectRelocalizer(twins, K, strict).relocalize(observations);
    EXPECT_EQ(withheld.status, RelocalizationStatus::LowEvidence);
    EXPECT_NE(withheld.reason.find("margin"), std::string::npos) << withheld.reason;
    EXPECT_TRUE(withheld.pose.isValid());
    EXPECT_EQ(ObjectRelocalizer(map, K, strict).relocalize(observations).status, RelocalizationStatus::Success);
  }
}

// The alternatives: with the layout three times, 20 m apart, the other two copies' views are the
// other answers, each once however many starts refined to it, cheapest first, the rival first.
TEST(Acceptance, EachOtherCopyOfALayoutIsOneAlternative) {
  std::mt19937 rng(11);
  const Intrinsics K = test::testIntrinsics();
  const Eigen::Vector3d shift(20.0, 0.0, 0.0);
  for (int trial = 0; trial < 3; ++trial) {
    const auto [first_copy, truth, observations] = viewOfRandomLayout(rng, K, 6, 3);
    const ObjectMap map = repeatedLayout(first_copy, shift, 3);

    RelocalizerOptions every_triplet;
    every_triplet.search.sampler = HypothesisSampler::Exhaustive;
    const RelocalizationResult r = ObjectRelocalizer(map, K, every_triplet).relocalize(observations);
    ASSERT_EQ(r.status, RelocalizationStatus::Success) << r.reason;
    std::vector<Pose> views;  // the same view of each copy
    for (int copy = 0; copy < 3; ++copy) views.push_back(viewOfCopy(truth, shift, copy));
    const auto copyOf = [&](const Pose& p) {
      for (int copy = 0; copy < 3; ++copy)
        if (test::positionError(p, views[static_cast<size_t>(copy)]) < 0.01 &&
            test::rotationError(p, views[static_cast<size_t>(copy)]) < 0.5)
          return copy;
      return -1;
    };
    const int chosen = copyOf(r.pose);
    ASSERT_GE(chosen, 0);
    // The other two copies' views cost what the pose costs and come first; answers that explain
    // the frame worse (look-alikes within one copy) may follow.
    ASSERT_GE(r.alternatives.size(), 2u);
    const int a = copyOf(r.alternatives[0].pose), b = copyOf(r.alternatives[1].pose);
    EXPECT_GE(a, 0);
    EXPECT_GE(b, 0);
    EXPECT_TRUE(a != chosen && b != chosen && a != b);
    for (size_t k = 0; k < r.alternatives.size(); ++k) {
      EXPECT_FALSE(poseError(r.alternatives[k].pose, r.pose).valid()) << k;
      for (size_t m = 0; m < k; ++m) {
        EXPECT_FALSE(poseError(r.alternatives[k].pose, r.alternatives[m].pose).valid()) << k << " " << m;
        EXPECT_LE(r.alternatives[m].cost, r.alternatives[k].cost);
      }
    }
    EXPECT_NEAR(r.margin, r.alternatives[0].cost - r.cost, 1e-12);
    ASSERT_TRUE(r.rival);
    EXPECT_EQ(r.rival->translation(), r.alternatives[0].pose.translation());

    // The layout alone: any other answer explains the frame far worse.
    const RelocalizationResult alone = ObjectRelocalizer(first_copy, K).relocalize(observations);
    ASSERT_EQ(alone.status, RelocalizationStatus::Success) << alone.reason;
    for (const ScoredPose& other : alone.alternatives) EXPECT_GT(other.cost - alone.cost, 1.0);
    EXPECT_EQ(alone.rival.has_value(), !alone.alternatives.empty());
  }
}
