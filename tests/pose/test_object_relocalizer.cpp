#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <limits>
#include <numeric>
#include <random>
#include <thread>

#include "ellreloc/core/projection.hpp"
#include "ellreloc/error.hpp"
#include "ellreloc/observe/observe.hpp"
#include "ellreloc/pose/object_relocalizer.hpp"
#include "ellreloc/sim/map_observations.hpp"
#include "ellreloc/sim/noise.hpp"
#include "ellreloc/sim/render.hpp"
#include "fixtures/map_in_unit.hpp"
#include "fixtures/random_geometry.hpp"
#include "fixtures/twin_desks.hpp"

using namespace ellreloc;
using ellreloc::test::positionError;
using ellreloc::test::rotationError;
using ellreloc::test::uniform;

namespace {

/// A room-sized map of n objects with categories drawn from `categories`, and a camera that
/// sees most of them. Observations are the exact projections (plus optional noise).
struct Synthetic {
  ObjectMap map;
  Pose truth;
  std::vector<Observation> observations;
  std::vector<int> object_of;  // ground-truth object index of each observation
};

Synthetic makeScene(std::mt19937& rng, int n, int categories, double centre_noise_px = 0.0) {
  const Intrinsics K = test::testIntrinsics();
  Synthetic s;
  for (int i = 0; i < n; ++i) {
    const double yaw = uniform(rng, -M_PI, M_PI);
    s.map.objects.push_back({i, i % categories, "",
                             Ellipsoid({uniform(rng, -1.2, 1.2), uniform(rng, -1.2, 1.2), uniform(rng, -0.3, 0.3)},
                                       {uniform(rng, 0.05, 0.25), uniform(rng, 0.05, 0.25), uniform(rng, 0.05, 0.25)},
                                       Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix())});
  }
  s.truth = test::randomLookAtPose(rng);
  sim::MapObservationOptions noise;
  noise.centre_sigma_px = centre_noise_px;
  s.observations = sim::observeMap(s.map, K, s.truth, noise, &rng, &s.object_of);
  return s;
}

/// makeScene, drawn again until the camera sees at least `min_observations` objects.
Synthetic makeSceneSeeing(std::mt19937& rng, size_t min_observations, int n, int categories,
                          double centre_noise_px = 0.0) {
  Synthetic s = makeScene(rng, n, categories, centre_noise_px);
  while (s.observations.size() < min_observations) s = makeScene(rng, n, categories, centre_noise_px);
  return s;
}

}  // namespace

// With every sampler: Auto (the default), every triplet, random triplets, PROSAC.
TEST(ObjectRelocalizer, RecoversThePoseAndTheCorrespondences) {
  const Intrinsics K = test::testIntrinsics();
  for (const HypothesisSampler sampler : {HypothesisSampler::Auto, HypothesisSampler::Exhaustive,
                                          HypothesisSampler::Uniform, HypothesisSampler::Prosac}) {
    RelocalizerOptions options;
    options.search.sampler = sampler;
    std::mt19937 rng(81);
    int tried = 0, recovered = 0;
    for (int trial = 0; trial < 40; ++trial) {
      const Synthetic s = makeScene(rng, 12, 6, 0.5);
      if (s.observations.size() < 4) continue;
      ++tried;
      const ObjectRelocalizer reloc(s.map, K, options);
      const RelocalizationResult r = reloc.relocalize(s.observations);
      ASSERT_EQ(r.status, RelocalizationStatus::Success) << r.reason;
      // 0.5 px of centre noise on ellipses of 10-50 px: about 1 cm and 0.2 degrees.
      if (positionError(r.pose, s.truth) < 0.05 && rotationErrorDeg(r.pose.rotation(), s.truth.rotation()) < 1.0) {
        ++recovered;
        for (const ObjectCorrespondence& c : r.inliers) EXPECT_EQ(c.object, s.object_of[c.observation]);
        EXPECT_GE(r.inliers.size(), s.observations.size() - 1);
      }
    }
    EXPECT_GE(tried, 30);
    EXPECT_GE(recovered, tried - 1) << static_cast<int>(sampler);
  }
}

// A partly hidden object's mask shows only its visible part, so its ellipse is smaller than
// the object's projection and shifted towards that part. Once the matches are settled, the
// chosen pose is refined again with a tighter loss (refinement.polish_loss_scale), which lets
// such matches pull it less; it is kept only when it explains the observations at least as well.
TEST(ObjectRelocalizer, ThePolishLetsPartlyHiddenObjectsPullThePoseLess) {
  const sim::NoiseModel noise = sim::NoiseModel::preset(sim::NoiseLevel::Realistic);
  const Intrinsics K(525.0, 525.0, 319.5, 239.5, 640, 480);
  RelocalizerOptions off;
  off.refinement.polish_loss_scale = 0.0;
  std::vector<double> with, without;
  int moved = 0;
  for (const uint64_t seed : {5, 6, 7}) {  // three offices, their exact maps: the observations set the error
    const sim::Scene scene = sim::makeScene(sim::ScenePreset::Office, seed);
    const ObjectRelocalizer polished(scene.groundTruthMap(), K), unpolished(scene.groundTruthMap(), K, off);
    std::mt19937_64 rng(seed);
    for (const Pose& truth : sim::queryTrajectory(scene, 20, seed)) {
      const sim::RenderedFrame frame = sim::render(scene, K, truth);
      const std::vector<Observation> observations =
          observeDetections(sim::detect(scene, frame, noise, rng), K.width, K.height);
      const RelocalizationResult a = polished.relocalize(observations), b = unpolished.relocalize(observations);
      ASSERT_EQ(a.status, b.status);
      if (a.status != RelocalizationStatus::Success) continue;
      EXPECT_LE(a.cost, b.cost);  // the same search and choice; the polish is kept only when it costs no more
      moved += !(a.pose.translation() == b.pose.translation());
      with.push_back(positionError(a.pose, truth));
      without.push_back(positionError(b.pose, truth));
    }
  }
  ASSERT_GE(with.size(), 45u);
  EXPECT_GE(moved, static_cast<int>(with.size()) / 2);
  std::sort(with.begin(), with.end());
  std::sort(without.begin(), without.end());
  std::printf("%d of %zu poses polished; median position error with / without: %.2f / %.2f cm\n", moved, with.size(),
              100 * with[with.size() / 2], 100 * without[without.size() / 2]);
  EXPECT_LT(with[with.size() / 2], 0.9 * without[without.size() / 2]);
}

TEST(ObjectRelocalizer, ManyObjectsOfOneCategory) {
  std::mt19937 rng(82);
  const Intrinsics K = test::testIntrinsics();
  int tried = 0, recovered = 0;
  for (int trial = 0; trial < 6; ++trial) {
    const Synthetic s = makeScene(rng, 25, 1, 0.5);  // 25 cups
    if (s.observations.size() < 5) continue;
    ++tried;
    RelocalizerOptions opt;
    opt.search.budget.seed = trial;
    const RelocalizationResult r = ObjectRelocalizer(s.map, K, opt).relocalize(s.observations);
    EXPECT_LE(r.hypotheses, opt.search.budget.max_hypotheses + 4);
    recovered += r.status == RelocalizationStatus::Success && positionError(r.pose, s.truth) < 0.05;
  }
  EXPECT_GE(tried, 4);
  EXPECT_GE(recovered, tried - 1);
}

// Among 12 cups every observation has 12 candidates, so the stopping rule, reading inliers over
// all pairs, draws about 12,000 samples whatever the search found; a pose explaining every cup
// in view ends the sampled search instead.
TEST(ObjectRelocalizer, APoseExplainingEveryObservationEndsASampledSearch) {
  std::mt19937 rng(87);
  const Intrinsics K = test::testIntrinsics();
  int tried = 0, shorter = 0;
  long early_samples = 0, all_samples = 0;
  for (int trial = 0; trial < 8; ++trial) {
    const Synthetic s = makeScene(rng, 12, 1, 0.5);
    if (s.observations.size() < 5) continue;
    ++tried;
    RelocalizerOptions full;
    full.search.stop_when_explained = false;
    const RelocalizationResult early = ObjectRelocalizer(s.map, K).relocalize(s.observations);
    const RelocalizationResult all = ObjectRelocalizer(s.map, K, full).relocalize(s.observations);
    EXPECT_LE(early.iterations, all.iterations);
    shorter += early.iterations < all.iterations;
    early_samples += early.iterations, all_samples += all.iterations;
    ASSERT_EQ(early.status, RelocalizationStatus::Success) << early.reason;
    EXPECT_LT(positionError(early.pose, s.truth), 0.05);
    EXPECT_EQ(early.inliers.size(), s.observations.size());
  }
  EXPECT_GE(tried, 4);
  // A frame may reach no such pose before the adaptive count ends its search (one of the eight
  // scenes clang's argument order draws; 426-3,936 samples instead of 11,934 for GCC's).
  EXPECT_GE(shorter, tried - 1);
  EXPECT_LT(early_samples, all_samples);
}

// Auto enumerates when the triplets of distinct observations are few, though the triplets of
// candidate pairs are many: 4 observations with 6 candidates each form 864 usable triplets
// (within max_exhaustive_triplets, 1000) among 2024 triplets of pairs. The result is then the
// Exhaustive sampler's, every usable triplet tried.
TEST(ObjectRelocalizer, AutoEnumeratesWhenUsableTripletsAreFew) {
  std::mt19937 rng(86);
  const Intrinsics K = test::testIntrinsics();
  int checked = 0;
  for (int trial = 0; trial < 40 && checked < 3; ++trial) {
    const Synthetic s = makeScene(rng, 24, 4, 0.5);  // 6 objects of each of 4 categories
    std::vector<Observation> four;
    std::vector<char> seen(4, 0);
    for (const Observation& o : s.observations)
      if (!seen[static_cast<size_t>(o.category)]) seen[static_cast<size_t>(o.category)] = 1, four.push_back(o);
    if (four.size() < 4) continue;
    ++checked;
    RelocalizerOptions exhaustive;
    exhaustive.search.sampler = HypothesisSampler::Exhaustive;
    const RelocalizationResult automatic = ObjectRelocalizer(s.map, K).relocalize(four);
    const RelocalizationResult every = ObjectRelocalizer(s.map, K, exhaustive).relocalize(four);
    EXPECT_EQ(automatic.iterations, 2024);
    EXPECT_EQ(automatic.iterations, every.iterations);
    EXPECT_EQ(automatic.hypotheses, every.hypotheses);
    EXPECT_EQ(automatic.status, every.status);
    EXPECT_TRUE(automatic.pose.rotation().isApprox(every.pose.rotation()));
    EXPECT_TRUE(automatic.pose.translation().isApprox(every.pose.translation()));
  }
  EXPECT_EQ(checked, 3);
}

// Options out of range are refused with the field's name, before any work (a NaN cost used to
// give Success with a NaN score).
TEST(ObjectRelocalizer, InvalidOptionsGiveInvalidInputNamingTheField) {
  std::mt19937 rng(84);
  const Intrinsics K = test::testIntrinsics();
  const Synthetic s = makeSceneSeeing(rng, 5, 12, 6);
  EXPECT_TRUE(RelocalizerOptions().validate().empty());
  EXPECT_TRUE(RelocalizerOptions::oaSlam().validate().empty());
  const auto expectRefused = [&](const RelocalizerOptions& o, const std::string& field) {
    const RelocalizationResult r = ObjectRelocalizer(s.map, K, o).relocalize(s.observations);
    EXPECT_EQ(r.status, RelocalizationStatus::InvalidInput) << field;
    EXPECT_NE(r.reason.find(field), std::string::npos) << r.reason;
    EXPECT_EQ(ObjectRelocalizer(s.map, K, o).scorePose(s.observations, s.truth).status,
              RelocalizationStatus::InvalidInput);
  };
  RelocalizerOptions o;
  o.scoring.unmatched_cost = std::nan("");
  expectRefused(o, "scoring.unmatched_cost");
  o = RelocalizerOptions();
  o.scoring.min_overlap = 1.5;
  expectRefused(o, "scoring.min_overlap");
  o = RelocalizerOptions();
  o.search.budget.max_time_ms = -1.0;
  expectRefused(o, "search.budget.max_time_ms");
  o = RelocalizerOptions();
  o.refinement.top_k = 0;
  expectRefused(o, "refinement.top_k");
  o = RelocalizerOptions();
  o.search.explained_mean_credit = 1.2;
  expectRefused(o, "search.explained_mean_credit");
  o = RelocalizerOptions();
  o.search.budget.enough_extension = std::nan("");
  expectRefused(o, "search.budget.enough_extension");
  o = RelocalizerOptions();
  o.refinement.regular_mask_sigma = 0.0;
  expectRefused(o, "refinement.regular_mask_sigma");
  o = RelocalizerOptions();
  o.refinement.polish_loss_scale = -0.1;
  expectRefused(o, "refinement.polish_loss_scale");
  o.refinement.polish_loss_scale = std::numeric_limits<double>::infinity();
  expectRefused(o, "refinement.polish_loss_scale");
  // One field of each remaining check, each with the name its message gives.
  const std::vector<std::pair<std::function<void(RelocalizerOptions&)>, std::string>> others = {
      {[](RelocalizerOptions& x) { x.search.budget.max_iterations = -1; }, "search.budget iteration counts"},
      {[](RelocalizerOptions& x) { x.search.budget.success_probability = 1.0; }, "search.budget.success_probability"},
      {[](RelocalizerOptions& x) { x.scoring.min_category_share = -0.1; }, "scoring.min_category_share"},
      {[](RelocalizerOptions& x) { x.few_objects.max_pair_hypotheses = -1; }, "few_objects.max_pair_hypotheses"},
      {[](RelocalizerOptions& x) { x.few_objects.solver.axis_step_deg = 0.0; }, "few_objects.solver"},
      {[](RelocalizerOptions& x) { x.refinement.refiner.object_loss_scale = 0.0; }, "refinement.refiner"},
      {[](RelocalizerOptions& x) { x.refinement.refiner.function_tolerance = -1e-9; }, "refinement.refiner"},
      {[](RelocalizerOptions& x) { x.acceptance.min_evidence = std::nan(""); }, "acceptance.min_evidence"},
      {[](RelocalizerOptions& x) { x.acceptance.unexplained_penalty = -0.5; }, "acceptance.unexplained_penalty"},
      {[](RelocalizerOptions& x) { x.acceptance.min_margin = -0.1; }, "acceptance.min_margin"},
  };
  for (const auto& [spoil, field] : others) {
    o = RelocalizerOptions();
    spoil(o);
    expectRefused(o, field);
  }
}

TEST(ObjectRelocalizer, StatusesInsteadOfCrashes) {
  std::mt19937 rng(83);
  const Intrinsics K = test::testIntrinsics();
  const Synthetic s = makeSceneSeeing(rng, 5, 12, 6);
  const ObjectRelocalizer reloc(s.map, K);
  // One observation without gravity; none at all; fewer than three for the OA-SLAM preset.
  const std::vector<Observation> one(s.observations.begin(), s.observations.begin() + 1);
  const RelocalizationResult r1 = reloc.relocalize(one);
  EXPECT_EQ(r1.status, RelocalizationStatus::NotEnoughObservations);
  EXPECT_NE(r1.reason.find("with a gravity prior"), std::string::npos) << r1.reason;
  EXPECT_EQ(reloc.relocalize({}).status, RelocalizationStatus::NotEnoughObservations);
  const std::vector<Observation> two(s.observations.begin(), s.observations.begin() + 2);
  EXPECT_EQ(ObjectRelocalizer(s.map, K, RelocalizerOptions::oaSlam()).relocalize(two).status,
            RelocalizationStatus::NotEnoughObservations);
  // No map object of the observed categories.
  std::vector<Observation> unknown = s.observations;
  for (auto& o : unknown) o.category = 999;
  const RelocalizationResult ru = reloc.relocalize(unknown);
  EXPECT_EQ(ru.status, RelocalizationStatus::NotEnoughObservations);
  EXPECT_EQ(ru.skipped.size(), unknown.size());
  EXPECT_NE(ru.skipped[0].second.find("no map object of category 999"), std::string::npos);
  // NaN and degenerate observations are skipped with a reason; the rest still works.
  std::vector<Observation> bad = s.observations;
  Observation nan_obs = bad[0];
  nan_obs.ellipse = Ellipse({std::nan(""), 10}, {5, 5}, 0);
  Observation flat = bad[1];
  flat.ellipse = Ellipse({10, 10}, {5, 0}, 0);
  bad.push_back(nan_obs);
  bad.push_back(flat);
  const RelocalizationResult rb = reloc.relocalize(bad);
  EXPECT_EQ(rb.status, RelocalizationStatus::Success);
  ASSERT_EQ(rb.skipped.size(), 2u);
  EXPECT_EQ(rb.skipped[0].first, static_cast<int>(bad.size()) - 2);
  EXPECT_LT(positionError(rb.pose, s.truth), 0.02);
  // Invalid intrinsics, invalid gravity prior.
  EXPECT_EQ(ObjectRelocalizer(s.map, Intrinsics()).relocalize(s.observations).status,
            RelocalizationStatus::InvalidInput);
  GravityPrior zero;
  zero.up_in_camera.setZero();
  const RelocalizationResult rg = reloc.relocalize(s.observations, {}, zero);
  EXPECT_EQ(rg.status, RelocalizationStatus::InvalidInput);
  EXPECT_NE(rg.reason.find("gravity"), std::string::npos);
  // A map whose unit is no length.
  for (const double unit : {0.0, -2.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    ObjectMap map = s.map;
    map.unit_metres = unit;
    const RelocalizationResult ri = ObjectRelocalizer(map, K).relocalize(s.observations);
    EXPECT_EQ(ri.status, RelocalizationStatus::InvalidInput);
    EXPECT_NE(ri.reason.find("unit_metres"), std::string::npos) << ri.reason;
  }
}

// A host process must be able to bound the work: 200 objects of one category and 50
// observations are about 1.7e11 triplets of pairs; the hypothesis and time budgets stop the search.
TEST(ObjectRelocalizer, BudgetsBoundTheWorkOnHugeAmbiguousInput) {
  std::mt19937 rng(91);
  const Intrinsics K = test::testIntrinsics();
  Synthetic s = makeScene(rng, 200, 1);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  while (s.observations.size() < 50) {  // pad with clutter of the same category
    Observation o = s.observations[0];
    o.ellipse = Ellipse({640 * u(rng), 480 * u(rng)}, {5 + 40 * u(rng), 5 + 20 * u(rng)}, u(rng));
    s.observations.push_back(o);
  }
  s.observations.resize(50);
  RelocalizerOptions hypotheses_only;
  hypotheses_only.search.budget.max_hypotheses = 100;
  const RelocalizationResult a = ObjectRelocalizer(s.map, K, hypotheses_only).relocalize(s.observations);
  EXPECT_LE(a.hypotheses, 100 + 4);  // the last triplet's P3P solutions may finish
  EXPECT_TRUE(a.budget_exhausted);
  RelocalizerOptions work_only;  // the machine-independent bound: 1e6 overlaps = 100 hypotheses here
  work_only.search.max_overlap_evaluations = 200L * 50 * 100;
  const RelocalizationResult w = ObjectRelocalizer(s.map, K, work_only).relocalize(s.observations);
  EXPECT_LE(w.hypotheses, 100 + 4);
  EXPECT_TRUE(w.budget_exhausted);
  RelocalizerOptions time_only;
  time_only.search.max_overlap_evaluations = 0;
  time_only.search.budget.max_hypotheses = 1L << 40;
  time_only.search.budget.max_time_ms = 1.0;
  const RelocalizationResult b = ObjectRelocalizer(s.map, K, time_only).relocalize(s.observations);
  EXPECT_TRUE(b.budget_exhausted);  // stopped by the clock, not by running out of triplets
  EXPECT_LT(b.hypotheses, 1L << 30);
  // The OA-SLAM preset's exhaustive search is bounded the same way (by default at 2e8 overlaps,
  // 20,000 hypotheses here; 100 in this test, for time).
  RelocalizerOptions preset = RelocalizerOptions::oaSlam();
  EXPECT_EQ(preset.search.max_overlap_evaluations, 200000000L);
  preset.search.max_overlap_evaluations = 200L * 50 * 100;
  const RelocalizationResult p = ObjectRelocalizer(s.map, K, preset).relocalize(s.observations);
  EXPECT_LE(p.hypotheses, 100 + 4);
  EXPECT_TRUE(p.budget_exhausted);
  // No pair table beyond its bound: the least confident observations are left out, named.
  RelocalizerOptions few_pairs;
  few_pairs.search.max_candidate_pairs = 200 * 10;  // every object is a candidate: 10 observations
  few_pairs.search.budget.max_hypotheses = 100;
  const RelocalizationResult c = ObjectRelocalizer(s.map, K, few_pairs).relocalize(s.observations);
  EXPECT_EQ(c.skipped.size(), 40u);
  for (const auto& [index, reason] : c.skipped) EXPECT_NE(reason.find("max_candidate_pairs"), std::string::npos);
}

// Every path honours max_hypotheses and max_time_ms, 0 hypotheses included: triplets,
// the two-object solver, the one-object solver with gravity.
TEST(ObjectRelocalizer, BudgetsHoldOnEveryPathIncludingZero) {
  std::mt19937 rng(92);
  const Intrinsics K = test::testIntrinsics();
  const Synthetic s = makeSceneSeeing(rng, 6, 30, 2);
  const std::vector<Observation> two(s.observations.begin(), s.observations.begin() + 2);
  const std::vector<Observation> one(s.observations.begin(), s.observations.begin() + 1);
  const GravityPrior gravity{s.truth.rotation() * Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitZ(), 1.0};
  RelocalizerOptions every_pose;  // with the acceptance test, one or two objects are never searched
  every_pose.acceptance.enabled = false;
  const ObjectRelocalizer unbounded(s.map, K, every_pose);
  ASSERT_GT(unbounded.relocalize(two).few_object_hypotheses, 0);
  ASSERT_GT(unbounded.relocalize(one, {}, gravity).few_object_hypotheses, 0);
  for (long max_hypotheses : {0L, 3L}) {
    RelocalizerOptions o = every_pose;
    o.search.budget.max_hypotheses = max_hypotheses;
    const ObjectRelocalizer bounded(s.map, K, o);
    for (const auto& [observations, prior] :
         {std::pair(s.observations, std::optional<GravityPrior>()), std::pair(two, std::optional<GravityPrior>()),
          std::pair(one, std::optional<GravityPrior>(gravity))}) {
      const RelocalizationResult r = bounded.relocalize(observations, {}, prior);
      EXPECT_LE(r.hypotheses, max_hypotheses + (observations.size() > 2 ? 3 : 0)) << observations.size();
      if (max_hypotheses == 0) EXPECT_EQ(r.status, RelocalizationStatus::NoConsistentHypothesis);
    }
  }
  // A budget spent before the search starts: no hypothesis at all, on every path.
  RelocalizerOptions no_time = every_pose;
  no_time.search.budget.max_time_ms = 1e-9;
  const ObjectRelocalizer hurried(s.map, K, no_time);
  EXPECT_EQ(hurried.relocalize(s.observations).hypotheses, 0);
  EXPECT_EQ(hurried.relocalize(two).hypotheses, 0);
  EXPECT_EQ(hurried.relocalize(one, {}, gravity).hypotheses, 0);
  EXPECT_TRUE(hurried.relocalize(two).budget_exhausted);
}

TEST(ObjectRelocalizer, DeterministicAndThreadSafe) {
  std::mt19937 rng(84);
  const Intrinsics K = test::testIntrinsics();
  std::vector<Synthetic> scenes;
  while (scenes.size() < 8) {
    Synthetic s = makeScene(rng, 30, 3, 1.0);  // large enough to use PROSAC, not enumeration
    if (s.observations.size() >= 6) scenes.push_back(s);
  }
  // One map shared by all scenes: use the first scene's map and reproject for each pose.
  const ObjectRelocalizer reloc(scenes[0].map, K);
  std::vector<std::vector<Observation>> queries;
  for (const Synthetic& s : scenes) {
    sim::MapObservationOptions every;
    every.inside_image_only = false;
    queries.push_back(sim::observeMap(scenes[0].map, K, s.truth, every));
  }
  std::vector<RelocalizationResult> serial;
  for (const auto& q : queries) serial.push_back(reloc.relocalize(q));
  for (size_t i = 0; i < queries.size(); ++i) {
    const RelocalizationResult again = reloc.relocalize(queries[i]);
    EXPECT_EQ(again.pose.rotation(), serial[i].pose.rotation());
    EXPECT_EQ(again.pose.translation(), serial[i].pose.translation());
  }
  std::vector<RelocalizationResult> parallel(queries.size());
  std::vector<std::thread> threads;
  for (size_t i = 0; i < queries.size(); ++i)
    threads.emplace_back([&, i] { parallel[i] = reloc.relocalize(queries[i]); });
  for (auto& t : threads) t.join();
  for (size_t i = 0; i < queries.size(); ++i) {
    EXPECT_EQ(parallel[i].status, serial[i].status);
    EXPECT_EQ(parallel[i].pose.rotation(), serial[i].pose.rotation());
    EXPECT_EQ(parallel[i].pose.translation(), serial[i].pose.translation());
    EXPECT_EQ(parallel[i].hypotheses, serial[i].hypotheses);
  }
}

// A detector lists its detections in an order of its own: the same detections in another order
// give the same result, down to the bit, with the indices of the order given. Look-alike objects
// and equal detection scores make many near-equal hypotheses, whose ties the order would settle.
TEST(ObjectRelocalizer, TheOrderOfTheObservationsDoesNotMatter) {
  std::mt19937 rng(87);
  const Intrinsics K = test::testIntrinsics();
  for (int trial = 0; trial < 12; ++trial) {
    const Synthetic s = makeSceneSeeing(rng, 6, 30, 3, 1.5);
    std::vector<Observation> given = s.observations;
    Observation broken = given.front();
    broken.box = Box(NAN, 0, 10, 10);  // left out, and reported at its own index
    given.insert(given.begin() + 2, broken);
    std::vector<int> order(given.size());  // order[k]: the index in `given` of shuffled[k]
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), rng);
    std::vector<Observation> shuffled;
    for (int i : order) shuffled.push_back(given[static_cast<size_t>(i)]);

    const ObjectRelocalizer reloc(s.map, K);
    const RelocalizationResult a = reloc.relocalize(given), b = reloc.relocalize(shuffled);
    ASSERT_EQ(a.status, b.status);
    EXPECT_EQ(a.pose.rotation(), b.pose.rotation());
    EXPECT_EQ(a.pose.translation(), b.pose.translation());
    EXPECT_EQ(a.hypotheses, b.hypotheses);
    EXPECT_EQ(a.alternatives.size(), b.alternatives.size());
    ASSERT_EQ(a.inliers.size(), b.inliers.size());
    for (size_t k = 0; k < a.inliers.size(); ++k) {
      EXPECT_EQ(a.inliers[k].observation, order[static_cast<size_t>(b.inliers[k].observation)]);
      EXPECT_EQ(a.inliers[k].object, b.inliers[k].object);
    }
    ASSERT_EQ(a.skipped.size(), 1u);
    EXPECT_EQ(a.skipped[0].first, 2);
    ASSERT_EQ(b.skipped.size(), 1u);
    EXPECT_EQ(order[static_cast<size_t>(b.skipped[0].first)], 2);

    const RelocalizationResult scored_a = reloc.scorePose(given, s.truth),
                               scored_b = reloc.scorePose(shuffled, s.truth);
    EXPECT_EQ(scored_a.cost, scored_b.cost);
    ASSERT_EQ(scored_a.inliers.size(), scored_b.inliers.size());
    for (size_t k = 0; k < scored_a.inliers.size(); ++k)
      EXPECT_EQ(scored_a.inliers[k].observation, order[static_cast<size_t>(scored_b.inliers[k].observation)]);
    const RelocalizationResult refined_a = reloc.refineFrom(given, a.pose),
                               refined_b = reloc.refineFrom(shuffled, a.pose);
    EXPECT_EQ(refined_a.pose.translation(), refined_b.pose.translation());
  }
}

// search.threads splits one frame's triplet hypotheses over threads: the same result, to the
// bit, as one thread (ours with PROSAC and enumeration, and the exhaustive preset; 12 cups with
// 3 px of centre noise give loose poses explaining every cup, which the search refines).
TEST(ObjectRelocalizer, OneFrameOnThreadsGivesTheSerialResultThreadSafe) {
  std::mt19937 rng(86);
  const Intrinsics K = test::testIntrinsics();
  for (int preset = 0; preset < 2; ++preset)
    for (int objects : {8, 30, 12}) {
      const Synthetic s = objects == 12 ? makeScene(rng, 12, 1, 3.0) : makeScene(rng, objects, 3, 1.0);
      if (s.observations.size() < 4) continue;
      RelocalizerOptions options = preset ? RelocalizerOptions::oaSlam() : RelocalizerOptions();
      // The preset's exhaustive search of 30 objects would try 222,000 hypotheses: a budget
      // keeps the test short and checks that a split search stops where the serial one does.
      if (preset) options.search.budget.max_hypotheses = 20000;
      const RelocalizationResult serial = ObjectRelocalizer(s.map, K, options).relocalize(s.observations);
      if (preset && objects == 30) EXPECT_TRUE(serial.budget_exhausted);
      for (int threads : {2, 3}) {
        options.search.threads = threads;
        const RelocalizationResult split = ObjectRelocalizer(s.map, K, options).relocalize(s.observations);
        SCOPED_TRACE(std::to_string(objects) + " objects, preset " + std::to_string(preset) + ", " +
                     std::to_string(threads) + " threads");
        EXPECT_EQ(split.status, serial.status);
        EXPECT_EQ(split.pose.rotation(), serial.pose.rotation());
        EXPECT_EQ(split.pose.translation(), serial.pose.translation());
        EXPECT_EQ(split.hypotheses, serial.hypotheses);
        EXPECT_EQ(split.iterations, serial.iterations);
        EXPECT_EQ(split.budget_exhausted, serial.budget_exhausted);
        EXPECT_EQ(split.inliers.size(), serial.inliers.size());
        EXPECT_EQ(split.cost, serial.cost);
      }
    }
  RelocalizerOptions bad;
  bad.search.threads = 0;
  EXPECT_EQ(ObjectRelocalizer(ObjectMap{}, K, bad).relocalize({}).status, RelocalizationStatus::InvalidInput);
}

TEST(ObjectRelocalizer, OaSlamPresetAlsoWorksOnBoxes) {
  std::mt19937 rng(85);
  const Intrinsics K = test::testIntrinsics();
  const Synthetic s = makeSceneSeeing(rng, 5, 10, 5);
  std::vector<Observation> boxes;
  for (const Observation& o : s.observations)
    boxes.push_back(*observationFromBox(o.category, 1.0, o.ellipse.boundingBox(), K.width, K.height));
  const RelocalizationResult r = ObjectRelocalizer(s.map, K, RelocalizerOptions::oaSlam()).relocalize(boxes);
  ASSERT_EQ(r.status, RelocalizationStatus::Success);
  EXPECT_FALSE(r.refined);
  EXPECT_LT(positionError(r.pose, s.truth), 0.3);
}

TEST(ObjectRelocalizer, SymmetricLayoutsAreExplainedAndBrokenByOneDistinctObject) {
  const Intrinsics K = test::testIntrinsics();
  // Four identical cups on the corners of a square: a quarter turn of the camera about the
  // square's axis explains the image equally well.
  ObjectMap map;
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  for (int k = 0; k < 4; ++k)
    map.objects.push_back(
        {k, 41, "cup", Ellipsoid({0.5 * (k & 1 ? 1 : -1), 0.5 * (k & 2 ? 1 : -1), 0.0}, {0.06, 0.06, 0.09}, I)});
  const Pose truth = Pose::fromCameraToWorld(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix(),
                                             Eigen::Vector3d(0.05, 0.02, 3.0));  // looking down the axis
  sim::MapObservationOptions every;
  every.inside_image_only = false;
  auto observe = [&](const ObjectMap& m) { return sim::observeMap(m, K, truth, every); };
  const RelocalizationResult sym = ObjectRelocalizer(map, K).relocalize(observe(map));
  ASSERT_EQ(sym.status, RelocalizationStatus::Success);
  EXPECT_EQ(sym.inliers.size(), 4u);  // some symmetric copy of the pose explains all four
  EXPECT_NEAR((sym.pose.center() - Eigen::Vector3d(0, 0, 0)).norm(), truth.center().norm(), 0.05);
  // A distinct object (a tv off the axis) breaks the symmetry: now the true pose wins.
  map.objects.push_back({9, 62, "tv", Ellipsoid({0.9, 0.2, 0.1}, {0.25, 0.03, 0.18}, I)});
  const RelocalizationResult r = ObjectRelocalizer(map, K).relocalize(observe(map));
  ASSERT_EQ(r.status, RelocalizationStatus::Success);
  EXPECT_LT((r.pose.center() - truth.center()).norm(), 0.01);
  EXPECT_LT(rotationErrorDeg(r.pose.rotation(), truth.rotation()), 0.2);
  for (const ObjectCorrespondence& c : r.inliers) EXPECT_EQ(c.object, c.observation);
}

namespace ellreloc {
namespace {

// A perturbed map (a mapper's centre, axis and yaw errors) limits what objects alone can do;
// keypoints matched to the map's points (20% wrong) pull the pose back to the truth.
TEST(ObjectRelocalizer, KeypointsMatchedToMapPointsImproveAccuracy) {
  const sim::Scene scene = sim::makeScene(sim::ScenePreset::Office, 7);
  const sim::NoiseModel noise = sim::NoiseModel::preset(sim::NoiseLevel::Realistic);
  const Intrinsics K(525.0, 525.0, 319.5, 239.5, 640, 480);
  const ObjectRelocalizer relocalizer(sim::perturbMap(scene.groundTruthMap(), noise, 8), K);
  ASSERT_FALSE(relocalizer.map().points.empty());
  std::mt19937_64 rng(9);
  std::vector<double> without, with;
  for (const Pose& truth : sim::queryTrajectory(scene, 12, 10)) {
    const sim::RenderedFrame frame = sim::render(scene, K, truth);
    const std::vector<Observation> observations =
        observeDetections(sim::detect(scene, frame, noise, rng), K.width, K.height);
    std::vector<Keypoint> keypoints = sim::keypoints(scene, frame, K, truth, noise, rng);
    const RelocalizationResult a = relocalizer.relocalize(observations);
    const RelocalizationResult b = relocalizer.relocalize(observations, keypoints);
    if (a.status != RelocalizationStatus::Success || b.status != RelocalizationStatus::Success) continue;
    without.push_back((a.pose.center() - truth.center()).norm());
    with.push_back((b.pose.center() - truth.center()).norm());
    // Keypoints that point nowhere are ignored, not a crash.
    keypoints.push_back({1 << 30, Eigen::Vector2d(1, 1)});
    keypoints.push_back({0, Eigen::Vector2d(std::nan(""), 1)});
    EXPECT_EQ(relocalizer.relocalize(observations, keypoints).status, RelocalizationStatus::Success);
  }
  ASSERT_GE(with.size(), 8u);
  std::sort(without.begin(), without.end());
  std::sort(with.begin(), with.end());
  EXPECT_LT(with[with.size() / 2], 0.6 * without[without.size() / 2]);
}

}  // namespace
}  // namespace ellreloc

// Two observations: the two-object solver gives the pose from the ellipses' shapes.
TEST(ObjectRelocalizer, TwoObservationsGiveThePose) {
  std::mt19937 rng(101);
  const Intrinsics K = test::testIntrinsics();
  int tried = 0, recovered = 0;
  for (int trial = 0; trial < 60 && tried < 30; ++trial) {
    Synthetic s = makeScene(rng, 12, 12, 0.0);  // one object per category: no ambiguity of labels
    if (s.observations.size() < 2) continue;
    s.observations.resize(2);
    ++tried;
    // Two objects never reach the default evidence: no search at all unless the acceptance test
    // is off (a host that checks poses itself); then the pose comes as Success.
    EXPECT_EQ(ObjectRelocalizer(s.map, K).relocalize(s.observations).status,
              RelocalizationStatus::NotEnoughObservations);
    RelocalizerOptions every_pose;
    every_pose.acceptance.enabled = false;
    const RelocalizationResult r = ObjectRelocalizer(s.map, K, every_pose).relocalize(s.observations);
    if (r.status == RelocalizationStatus::Success && positionError(r.pose, s.truth) < 0.02 &&
        rotationErrorDeg(r.pose.rotation(), s.truth.rotation()) < 0.5) {
      ++recovered;
      EXPECT_GT(r.few_object_hypotheses, 0);
      ASSERT_EQ(r.inliers.size(), 2u);
      for (const ObjectCorrespondence& c : r.inliers) EXPECT_EQ(c.object, s.object_of[c.observation]);
    }
  }
  EXPECT_EQ(tried, 30);
  // Measured 30 of 30; exact ellipses, but two small objects can fit a wrong pose too.
  EXPECT_GE(recovered, 27);
}

// One observation and gravity: a pose that reproduces the ellipse with the measured tilt.
// An ellipsoid looks the same from the opposite side of its vertical axis, so the pose is
// the true one or its mirror about that axis.
TEST(ObjectRelocalizer, OneObservationWithGravity) {
  std::mt19937 rng(102);
  const Intrinsics K = test::testIntrinsics();
  int tried = 0, recovered = 0;
  for (int trial = 0; trial < 60 && tried < 30; ++trial) {
    Synthetic s = makeScene(rng, 12, 12, 0.0);
    if (s.observations.empty()) continue;
    s.observations.resize(1);
    ++tried;
    RelocalizerOptions every_pose;  // one object never reaches the default evidence
    every_pose.acceptance.enabled = false;
    const ObjectRelocalizer reloc(s.map, K, every_pose);
    EXPECT_EQ(reloc.relocalize(s.observations).status, RelocalizationStatus::NotEnoughObservations);
    const GravityPrior g = GravityPrior::atPose(s.truth);
    EXPECT_EQ(ObjectRelocalizer(s.map, K).relocalize(s.observations, {}, g).status,
              RelocalizationStatus::NotEnoughObservations);
    const RelocalizationResult r = reloc.relocalize(s.observations, {}, g);
    if (r.status != RelocalizationStatus::Success) continue;
    const Ellipsoid& e = s.map.objects[s.object_of[0]].ellipsoid;
    const Eigen::Matrix3d mirror = Eigen::AngleAxisd(M_PI, e.rotation().col(2)).toRotationMatrix();
    const Pose mirrored(s.truth.rotation() * mirror.transpose(),
                        s.truth.translation() + s.truth.rotation() * (e.center() - mirror.transpose() * e.center()));
    const bool near_truth = positionError(r.pose, s.truth) < 0.02 || positionError(r.pose, mirrored) < 0.02;
    EXPECT_LT(g.errorDeg(r.pose), 0.5);
    recovered += near_truth;
  }
  EXPECT_EQ(tried, 30);
  EXPECT_GE(recovered, 27);  // measured 30 of 30
}

// A gravity prior drops every pose that tilts the camera against it.
TEST(ObjectRelocalizer, GravityPriorGatesHypotheses) {
  std::mt19937 rng(103);
  const Intrinsics K = test::testIntrinsics();
  const Synthetic s = makeSceneSeeing(rng, 5, 12, 6, 0.5);
  const ObjectRelocalizer reloc(s.map, K);
  const RelocalizationResult right = reloc.relocalize(s.observations, {}, GravityPrior::atPose(s.truth));
  ASSERT_EQ(right.status, RelocalizationStatus::Success) << right.reason;
  EXPECT_LT(positionError(right.pose, s.truth), 0.05);
  // Gravity 90 degrees off: no pose that explains the objects agrees with it.
  GravityPrior wrong = GravityPrior::atPose(s.truth);
  wrong.up_in_camera = s.truth.rotation() * Eigen::Vector3d::UnitX();
  const RelocalizationResult r = reloc.relocalize(s.observations, {}, wrong);
  if (r.status == RelocalizationStatus::Success) {
    EXPECT_LE(wrong.errorDeg(r.pose), reloc.options().gravity.gate_deg + 1e-9);
    EXPECT_GT(positionError(r.pose, s.truth), 0.05);
  }
}

// The gate's prepared bound says what errorDeg says, over random poses and bounds.
TEST(GravityPrior, BoundAdmitsWhatTheAngleSays) {
  std::mt19937 rng(43);
  std::normal_distribution<double> normal;
  GravityPrior prior;
  prior.up_in_camera = Eigen::Vector3d(0.1, -2.0, 0.3);  // not unit length: the bound normalises
  prior.up_in_map = Eigen::Vector3d(0.2, 0.1, 3.0);
  int admitted = 0, compared = 0;
  for (int i = 0; i < 20000; ++i) {
    const Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
    const Pose pose(q.normalized().toRotationMatrix(), Eigen::Vector3d(normal(rng), normal(rng), normal(rng)));
    const double max_deg = std::uniform_real_distribution<double>(0.0, 200.0)(rng);
    const double angle = prior.errorDeg(pose);
    if (std::abs(angle - max_deg) < 1e-6) continue;
    EXPECT_EQ(prior.bound(max_deg).admits(pose), angle <= max_deg) << "angle " << angle << " bound " << max_deg;
    admitted += angle <= max_deg;
    ++compared;
  }
  EXPECT_GT(admitted, 1000);  // both answers are exercised
  EXPECT_LT(admitted, compared - 1000);
}

// scorePose scores a given pose like relocalize() scores its own.
TEST(ObjectRelocalizer, ScoresAGivenPose) {
  std::mt19937 rng(104);
  const Intrinsics K = test::testIntrinsics();
  const Synthetic s = makeSceneSeeing(rng, 4, 12, 12, 0.0);
  const ObjectRelocalizer reloc(s.map, K);
  const RelocalizationResult at_truth = reloc.scorePose(s.observations, s.truth);
  EXPECT_EQ(at_truth.status, RelocalizationStatus::Success);
  ASSERT_EQ(at_truth.inliers.size(), s.observations.size());
  for (const ObjectCorrespondence& c : at_truth.inliers) {
    EXPECT_EQ(c.object, s.object_of[c.observation]);
    EXPECT_GT(c.overlap, 0.99);  // exact projections
  }
  EXPECT_NEAR(at_truth.cost, 0.0, 0.01 * s.observations.size());
  // Far off: nothing overlaps, every observation costs unmatched_cost.
  const Pose away = Pose::lookAt(s.truth.center(), s.truth.center() - 3.0 * s.truth.rotation().row(2).transpose());
  const RelocalizationResult r = reloc.scorePose(s.observations, away);
  EXPECT_EQ(r.status, RelocalizationStatus::NoConsistentHypothesis);
  EXPECT_TRUE(r.inliers.empty());
  EXPECT_DOUBLE_EQ(r.cost, reloc.options().scoring.unmatched_cost * s.observations.size());
  EXPECT_EQ(reloc.scorePose(s.observations, Pose(Eigen::Matrix3d::Zero(), Eigen::Vector3d::Zero())).status,
            RelocalizationStatus::InvalidInput);
}

// The pairs a host refines on: each observation's ellipse with its matched object's ellipsoid,
// a regular mask's fit weighed by regular_mask_sigma; refined from a perturbed truth they give
// the truth back (exact projections), and an index out of range is refused.
TEST(ObjectRelocalizer, RefinementMatchesArePairedAndWeighedAsTheRefinement) {
  std::mt19937 rng(105);
  const Intrinsics K = test::testIntrinsics();
  Synthetic s = makeSceneSeeing(rng, 4, 12, 12, 0.0);
  s.observations[0].source = EllipseSource::Mask;
  s.observations[0].regular = true;
  RelocalizerOptions options;
  options.refinement.regular_mask_sigma = 0.25;
  const ObjectRelocalizer reloc(s.map, K, options);
  const RelocalizationResult at_truth = reloc.scorePose(s.observations, s.truth);
  const std::vector<EllipseMatch> pairs = reloc.refinementMatches(s.observations, at_truth.inliers);
  ASSERT_EQ(pairs.size(), at_truth.inliers.size());
  for (size_t i = 0; i < pairs.size(); ++i) {
    const ObjectCorrespondence& c = at_truth.inliers[i];
    EXPECT_TRUE(pairs[i].observed.center().isApprox(s.observations[c.observation].ellipse.center()));
    EXPECT_TRUE(pairs[i].ellipsoid.center().isApprox(s.map.objects[c.object].ellipsoid.center()));
    EXPECT_DOUBLE_EQ(pairs[i].sigma, c.observation == 0 ? 0.25 : 1.0);
  }
  const Pose start(
      Eigen::AngleAxisd(0.03, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix() * s.truth.rotation(),
      s.truth.translation() + Eigen::Vector3d(0.05, -0.04, 0.03));
  const Pose refined = refinePose(K, start, pairs, {}, options.refinement.refiner).pose;
  EXPECT_LT(positionError(refined, s.truth), 0.01);
  std::vector<ObjectCorrespondence> bad = at_truth.inliers;
  bad[0].object = static_cast<int>(s.map.objects.size());
  EXPECT_THROW(reloc.refinementMatches(s.observations, bad), Error);
  bad = at_truth.inliers;
  bad[0].observation = -1;
  EXPECT_THROW(reloc.refinementMatches(s.observations, bad), Error);
}

// A match through a label the object carried in 10% of its detections is worth a fifth of one
// through its majority label (share / 0.5), unless weigh_minority_labels is off.
TEST(ObjectRelocalizer, MinorityLabelsWeighLess) {
  std::mt19937 rng(105);
  const Intrinsics K = test::testIntrinsics();
  Synthetic s = makeSceneSeeing(rng, 1, 12, 12, 0.0);
  const std::vector<Observation> one(s.observations.begin(), s.observations.begin() + 1);
  MapObject& object = s.map.objects[static_cast<size_t>(s.object_of[0])];
  object.category_counts = {{object.category, 9.0}, {77, 1.0}};
  std::vector<Observation> minority = one;
  minority[0].category = 77;
  const RelocalizationResult majority = ObjectRelocalizer(s.map, K).scorePose(one, s.truth);
  const RelocalizationResult weighed = ObjectRelocalizer(s.map, K).scorePose(minority, s.truth);
  RelocalizerOptions unweighted;
  unweighted.scoring.weigh_minority_labels = false;
  const RelocalizationResult plain = ObjectRelocalizer(s.map, K, unweighted).scorePose(minority, s.truth);
  ASSERT_EQ(majority.inliers.size(), 1u);
  ASSERT_EQ(weighed.inliers.size(), 1u);
  const double overlap = weighed.inliers[0].overlap;  // reported unweighted
  EXPECT_GT(overlap, 0.99);
  EXPECT_NEAR(majority.cost, 1.0 - overlap, 1e-9);
  EXPECT_NEAR(weighed.cost, 1.0 - 0.2 * overlap, 1e-9);
  EXPECT_NEAR(plain.cost, 1.0 - overlap, 1e-9);
}

// Objects a map cannot use (a collapsed axis, an absurd one) are never matched and said so;
// the pose still comes from the others.
TEST(ObjectRelocalizer, LeavesOutDegenerateMapObjects) {
  std::mt19937 rng(5);
  const Synthetic s = makeSceneSeeing(rng, 6, 12, 6);
  ObjectMap map = s.map;
  map.objects[static_cast<size_t>(s.object_of[0])].ellipsoid =
      Ellipsoid(map.objects[static_cast<size_t>(s.object_of[0])].ellipsoid.center(), {0.1, 1e-19, 0.1},
                Eigen::Matrix3d::Identity());
  map.objects[static_cast<size_t>(s.object_of[1])].ellipsoid =
      Ellipsoid({0, 0, 0}, {0.1, 25.0, 0.1}, Eigen::Matrix3d::Identity());
  const ObjectRelocalizer reloc(map, test::testIntrinsics());
  ASSERT_EQ(reloc.leftOut().size(), 2u);
  EXPECT_NE(reloc.leftOut()[0].find("below 1 mm"), std::string::npos) << reloc.leftOut()[0];
  const RelocalizationResult r = reloc.relocalize(s.observations);
  ASSERT_EQ(r.status, RelocalizationStatus::Success) << r.reason;
  EXPECT_LT(positionError(r.pose, s.truth), 0.05);
  for (const ObjectCorrespondence& m : r.inliers) {
    EXPECT_NE(m.object, s.object_of[0]);
    EXPECT_NE(m.object, s.object_of[1]);
  }
}

namespace {

/// The number of scenes among `scenes` whose result in the map of unit 16 m (a power of two: the
/// map's numbers scale exactly), its poses taken back to metres, differs from the metric map's:
/// pose, matches, alternatives or margin. Taken in metres, such a map's answers 30 cm apart are
/// 4.8 m apart in the room.
int scenesThatDifferInAnotherUnit(const std::vector<Synthetic>& scenes, bool give_the_unit,
                                  const RelocalizerOptions& options = {}) {
  const Intrinsics K = test::testIntrinsics();
  const double unit = 16.0;
  int differ = 0;
  for (const Synthetic& s : scenes) {
    ObjectMap scaled = test::mapInUnit(s.map, unit);
    if (!give_the_unit) scaled.unit_metres = 1.0;
    const RelocalizationResult metric = ObjectRelocalizer(s.map, K, options).relocalize(s.observations);
    const RelocalizationResult other = ObjectRelocalizer(scaled, K, options).relocalize(s.observations);
    // Within the refiner's convergence (a micrometre), which rounding moves.
    bool same = metric.status == other.status && metric.inliers.size() == other.inliers.size() &&
                metric.alternatives.size() == other.alternatives.size() &&
                (metric.pose.center() - unit * other.pose.center()).norm() < 1e-6 &&
                (metric.pose.rotation() - other.pose.rotation()).norm() < 1e-6 &&
                (metric.margin == other.margin || std::abs(metric.margin - other.margin) < 1e-6);
    for (size_t k = 0; same && k < metric.alternatives.size(); ++k)
      same = (metric.alternatives[k].pose.center() - unit * other.alternatives[k].pose.center()).norm() < 1e-6;
    differ += !same;
  }
  return differ;
}

}  // namespace

// A monocular system's map is in a unit of its own. Given the map's unit, the relocalizer finds
// the same poses in it as in metres (its distances in metres, the 5 cm of near-equal hypotheses
// and the 30 cm between distinct answers, are converted). Without it, the answers it tells apart
// change: a view of one of two identical desks 3 m apart has the other desk's view as its
// alternative, which, 0.19 units apart, no longer counts as another answer.
TEST(ObjectRelocalizer, AMapInAnotherUnitGivesTheSamePosesInThatUnit) {
  std::mt19937 rng(41);
  std::vector<Synthetic> scenes;
  for (int trial = 0; trial < 8; ++trial) scenes.push_back(makeSceneSeeing(rng, 4, 16, 3, 1.0));
  EXPECT_EQ(scenesThatDifferInAnotherUnit(scenes, true), 0);

  std::vector<Synthetic> desk_views;
  while (desk_views.size() < 3) {
    Synthetic view;
    view.map = test::twinDesks();
    view.truth = Pose::lookAt(Eigen::Vector3d(uniform(rng, -0.3, 0.3), uniform(rng, -1.3, -0.9), 0.6),
                              Eigen::Vector3d(0.0, 0.1, 0.1), Eigen::Vector3d::UnitZ());
    view.observations = sim::observeMap(view.map, test::testIntrinsics(), view.truth, sim::MapObservationOptions{},
                                        &rng, &view.object_of);
    if (view.observations.size() >= 4 && *std::max_element(view.object_of.begin(), view.object_of.end()) < 5)
      desk_views.push_back(view);
  }
  RelocalizerOptions every_triplet;  // both desks' views found, whatever the stopping rule
  every_triplet.search.sampler = HypothesisSampler::Exhaustive;
  const Eigen::Vector3d twin_offset(test::kTwinDeskOffset, 0.0, 0.0);
  for (const Synthetic& view : desk_views) {
    // The two views cost the same, and which one is chosen is a matter of rounding: each result
    // is asked whether the other view is among its other answers.
    const Pose twin = Pose::fromCameraToWorld(view.truth.inverse().rotation(), view.truth.center() + twin_offset);
    // `metres`: the length of one unit of the map's coordinates.
    const auto listsTheOtherView = [&](const ObjectMap& map, double metres) {
      const RelocalizationResult r =
          ObjectRelocalizer(map, test::testIntrinsics(), every_triplet).relocalize(view.observations);
      const bool chose_the_truth = (metres * r.pose.center() - view.truth.center()).norm() < 0.01;
      const Eigen::Vector3d other = chose_the_truth ? twin.center() : view.truth.center();
      return std::any_of(r.alternatives.begin(), r.alternatives.end(),
                         [&](const ScoredPose& a) { return (metres * a.pose.center() - other).norm() < 0.01; });
    };
    ObjectMap taken_in_metres = test::mapInUnit(view.map, 16.0);
    const ObjectMap in_unit = taken_in_metres;
    taken_in_metres.unit_metres = 1.0;
    EXPECT_TRUE(listsTheOtherView(view.map, 1.0));
    EXPECT_TRUE(listsTheOtherView(in_unit, 16.0));
    EXPECT_FALSE(listsTheOtherView(taken_in_metres, 16.0));
  }
}

// The same for frames of two objects, whose poses the two-object solver gives.
TEST(ObjectRelocalizer, AMapInAnotherUnitGivesTheSameTwoObjectPosesInThatUnit) {
  std::mt19937 rng(43);
  std::vector<Synthetic> scenes;
  for (int trial = 0; trial < 8; ++trial) {
    Synthetic s = makeSceneSeeing(rng, 2, 16, 3, 1.0);
    s.observations.resize(2);
    scenes.push_back(s);
  }
  RelocalizerOptions all;
  all.acceptance.enabled = false;  // frames of two observations are searched
  EXPECT_EQ(scenesThatDifferInAnotherUnit(scenes, true, all), 0);
  EXPECT_GT(scenesThatDifferInAnotherUnit(scenes, false, all), 0);
}

// The bounds on semi-axes (1 mm to 10 m) are in metres, whatever the map's unit.
TEST(ObjectRelocalizer, SemiAxisBoundsAreInMetresInAnyUnit) {
  MapObject o{1, 0, "", Ellipsoid({0, 0, 0}, {0.0004, 0.02, 0.05}, Eigen::Matrix3d::Identity())};
  EXPECT_NE(mapObjectProblem(o).find("below 1 mm"), std::string::npos);
  EXPECT_TRUE(mapObjectUsable(o, 10.0));  // 4 mm in a unit of 10 m
  const std::string problem = mapObjectProblem(o, 0.5);
  EXPECT_NE(problem.find("0.0004 (0.0002 m) is below 1 mm"), std::string::npos) << problem;
  o.ellipsoid = Ellipsoid({0, 0, 0}, {0.2, 1.5, 0.1}, Eigen::Matrix3d::Identity());
  EXPECT_TRUE(mapObjectUsable(o));
  EXPECT_NE(mapObjectProblem(o, 10.0).find("(15 m) is above 10 m"), std::string::npos);
}

// The envelope of the mapping keyframes: heights and tilts widened by the margins; the up
// direction defaults to the keyframes' mean image-up.
TEST(CameraEnvelope, FromKeyframesAndAdmits) {
  const Eigen::Vector3d target(0.0, 0.0, 0.8);
  const std::vector<Pose> keyframes = {Pose::lookAt({2.0, 0.0, 1.2}, target), Pose::lookAt({0.0, 2.0, 1.6}, target),
                                       Pose::lookAt({-2.0, 0.0, 1.4}, target)};
  const auto e = CameraEnvelope::fromKeyframes(keyframes, Eigen::Vector3d::UnitZ(), 0.5, 20.0);
  ASSERT_TRUE(e);
  EXPECT_NEAR(e->min_height, 0.7, 1e-9);
  EXPECT_NEAR(e->max_height, 2.1, 1e-9);
  const double steepest = std::atan2(0.8, 2.0) * 180.0 / M_PI;  // camera at 1.6 m looking 0.8 m down over 2 m
  EXPECT_NEAR(e->max_tilt_deg, steepest + 20.0, 1e-6);
  EXPECT_TRUE(e->admits(Pose::lookAt({1.0, 1.0, 1.3}, target)));
  EXPECT_FALSE(e->admits(Pose::lookAt({1.0, 1.0, -0.5}, target)));  // under the floor
  EXPECT_FALSE(e->admits(Pose::lookAt({0.1, 0.0, 2.0}, target)));   // looking straight down
  EXPECT_TRUE(e->isValid());
  EXPECT_FALSE(CameraEnvelope::fromKeyframes({keyframes[0]}));
  const auto estimated = CameraEnvelope::fromKeyframes(keyframes);  // up from the cameras
  ASSERT_TRUE(estimated);
  EXPECT_GT(estimated->up.z(), 0.9);
}

// An upright envelope bounds the tilt only: a level or a downward-looking camera at any height
// passes, one rolled upside down or turned more than max_tilt_deg away from up does not.
TEST(CameraEnvelope, UprightBoundsTheTiltAtAnyHeight) {
  const auto e = CameraEnvelope::upright(Eigen::Vector3d(0.0, 0.0, 2.0));  // normalised
  ASSERT_TRUE(e);
  EXPECT_TRUE(e->isValid());
  EXPECT_NEAR(e->up.z(), 1.0, 1e-12);
  const Eigen::Vector3d target(0.0, 0.0, 0.8);
  const Pose level = Pose::lookAt({2.0, 0.0, 0.8}, target);
  EXPECT_NEAR(CameraEnvelope::tiltDegOf(level, e->up), 0.0, 1e-9);
  EXPECT_TRUE(e->admits(level));
  EXPECT_TRUE(e->admits(Pose::lookAt({2.0, 0.0, 40.0}, target)));   // high above, looking down
  EXPECT_TRUE(e->admits(Pose::lookAt({2.0, 0.0, -30.0}, target)));  // far below, looking up
  // The level camera rolled half a turn about its optical axis: image-up points down.
  const Eigen::Matrix3d roll = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Pose upside_down(roll * level.rotation(), roll * level.translation());
  EXPECT_NEAR(upside_down.center().z(), 0.8, 1e-9);  // the same camera centre
  EXPECT_NEAR(CameraEnvelope::tiltDegOf(upside_down, e->up), 180.0, 1e-6);
  EXPECT_FALSE(e->admits(upside_down));
  // A quarter roll is 90 degrees of tilt: inside at 90, outside at 60.
  const Eigen::Matrix3d quarter = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Pose sideways(quarter * level.rotation(), quarter * level.translation());
  EXPECT_TRUE(e->admits(sideways));
  EXPECT_FALSE(CameraEnvelope::upright(Eigen::Vector3d::UnitZ(), 60.0)->admits(sideways));
  EXPECT_FALSE(CameraEnvelope::upright(Eigen::Vector3d::Zero()));
  EXPECT_FALSE(CameraEnvelope::upright(Eigen::Vector3d(0.0, NAN, 1.0)));
  EXPECT_FALSE(CameraEnvelope::upright(Eigen::Vector3d::UnitZ(), 0.0));
  EXPECT_FALSE(CameraEnvelope::upright(Eigen::Vector3d::UnitZ(), 181.0));
  EXPECT_FALSE(CameraEnvelope::upright(Eigen::Vector3d::UnitZ(), 90.0, 0.0));
  EXPECT_FALSE(CameraEnvelope::upright(Eigen::Vector3d::UnitZ(), 90.0, 91.0));
}

// A roll bound keeps the image rows near level: a camera looking down at 50 degrees passes at
// any heading, one rolled 30 degrees about its optical axis passes 45 but not 20.
TEST(CameraEnvelope, RollBoundsTheHorizon) {
  const auto e = CameraEnvelope::upright(Eigen::Vector3d::UnitZ(), 90.0, 45.0);
  ASSERT_TRUE(e);
  EXPECT_TRUE(e->isValid());
  for (double heading = 0.0; heading < 2 * M_PI; heading += 0.5) {
    const double rise = std::tan(50 * M_PI / 180);  // 50 degrees down from a metre away
    const Pose down = Pose::lookAt({std::cos(heading), std::sin(heading), 1.2 + rise}, {0, 0, 1.2});
    EXPECT_NEAR(CameraEnvelope::rollDegOf(down, e->up), 0.0, 1e-9);
    EXPECT_TRUE(e->admits(down));
  }
  const Pose level = Pose::lookAt({2.0, 0.0, 0.8}, {0.0, 0.0, 0.8});
  const Eigen::Matrix3d roll = Eigen::AngleAxisd(30 * M_PI / 180, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Pose rolled(roll * level.rotation(), roll * level.translation());
  EXPECT_NEAR(CameraEnvelope::rollDegOf(rolled, e->up), 30.0, 1e-9);
  EXPECT_NEAR(CameraEnvelope::tiltDegOf(rolled, e->up), 30.0, 1e-9);
  EXPECT_TRUE(e->admits(rolled));
  EXPECT_FALSE(CameraEnvelope::upright(Eigen::Vector3d::UnitZ(), 90.0, 20.0)->admits(rolled));
  EXPECT_TRUE(CameraEnvelope::upright(Eigen::Vector3d::UnitZ(), 90.0)->admits(rolled));
  CameraEnvelope bad = *e;
  bad.max_roll_deg = 0.0;
  EXPECT_FALSE(bad.isValid());
}

// admits() tests cosines and a sine prepared once; it says what the angles say, at any pose, and
// admitsRotation() what the tilt and roll say.
TEST(CameraEnvelope, AdmitsWhatItsAnglesAndHeightsSay) {
  CameraEnvelope e;
  e.up = Eigen::Vector3d(0.3, -0.2, 1.0).normalized();
  e.min_height = 0.5, e.max_height = 1.8;
  e.min_tilt_deg = 10.0, e.max_tilt_deg = 70.0, e.max_roll_deg = 30.0;
  ASSERT_TRUE(e.isValid());
  std::mt19937 rng(41);
  std::normal_distribution<double> normal;
  int admitted = 0, compared = 0;
  for (int i = 0; i < 20000; ++i) {
    const Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
    const Eigen::Matrix3d R = q.normalized().toRotationMatrix();
    const Eigen::Vector3d centre(normal(rng), normal(rng), 1.2 + normal(rng));
    const Pose pose(R, -R * centre);
    const double h = CameraEnvelope::heightOf(pose, e.up), t = CameraEnvelope::tiltDegOf(pose, e.up);
    const double r = CameraEnvelope::rollDegOf(pose, e.up);
    const auto near = [](double x, double bound) { return std::abs(x - bound) < 1e-6; };
    if (near(h, 0.5) || near(h, 1.8) || near(t, 10.0) || near(t, 70.0) || near(r, 30.0)) continue;
    const bool inside = h >= 0.5 && h <= 1.8 && t >= 10.0 && t <= 70.0 && r <= 30.0;
    EXPECT_EQ(e.admits(pose), inside) << "height " << h << " tilt " << t << " roll " << r;
    // The rotation alone: the tilt and roll bounds, whatever the height.
    EXPECT_EQ(e.prepared().admitsRotation(R), t >= 10.0 && t <= 70.0 && r <= 30.0) << "tilt " << t << " roll " << r;
    admitted += inside;
    ++compared;
  }
  EXPECT_GT(admitted, 100);  // both answers are exercised
  EXPECT_LT(admitted, compared - 100);
}

// Relocalization never returns a pose outside the envelope: with the true pose inside it, the
// pose is found; with an envelope that excludes it, the true pose is not returned.
TEST(ObjectRelocalizer, EnvelopeGatesPoses) {
  std::mt19937 rng(12);
  const Synthetic s = makeSceneSeeing(rng, 6, 12, 6);
  RelocalizerOptions options;
  options.envelope = CameraEnvelope::fromKeyframes({s.truth, s.truth}, Eigen::Vector3d::UnitZ(), 0.2, 5.0);
  ASSERT_TRUE(options.envelope);
  const RelocalizationResult inside =
      ObjectRelocalizer(s.map, test::testIntrinsics(), options).relocalize(s.observations);
  ASSERT_EQ(inside.status, RelocalizationStatus::Success) << inside.reason;
  EXPECT_LT(positionError(inside.pose, s.truth), 0.05);
  options.envelope->min_height += 1.0;  // the true camera is now 0.8 m below the envelope
  options.envelope->max_height += 1.0;
  const RelocalizationResult outside =
      ObjectRelocalizer(s.map, test::testIntrinsics(), options).relocalize(s.observations);
  if (outside.status == RelocalizationStatus::Success) EXPECT_GT(positionError(outside.pose, s.truth), 0.3);
  options.envelope->min_height = 5.0;  // empty range: an invalid option
  options.envelope->max_height = 4.0;
  EXPECT_EQ(ObjectRelocalizer(s.map, test::testIntrinsics(), options).relocalize(s.observations).status,
            RelocalizationStatus::InvalidInput);
}

// A map that records where it was made keeps the camera there unless the options give an
// envelope of their own or turn the map's off; the OA-SLAM preset ignores it.
TEST(ObjectRelocalizer, TheMapsEnvelopeGatesPosesByDefault) {
  std::mt19937 rng(12);
  Synthetic s = makeSceneSeeing(rng, 6, 12, 6);
  const auto around_truth = CameraEnvelope::fromKeyframes({s.truth, s.truth}, Eigen::Vector3d::UnitZ(), 0.2, 5.0);
  ASSERT_TRUE(around_truth);
  CameraEnvelope above = *around_truth;  // the true camera is 0.8 m below it
  above.min_height += 1.0, above.max_height += 1.0;
  s.map.camera_envelope = above;
  const auto relocalize = [&](const RelocalizerOptions& options) {
    return ObjectRelocalizer(s.map, test::testIntrinsics(), options).relocalize(s.observations);
  };
  const auto found = [&](const RelocalizationResult& r) {
    return r.status == RelocalizationStatus::Success && positionError(r.pose, s.truth) < 0.05;
  };
  RelocalizerOptions options;
  EXPECT_FALSE(found(relocalize(options)));
  EXPECT_EQ(ObjectRelocalizer(s.map, test::testIntrinsics(), options).options().envelope->min_height, above.min_height);
  options.map_envelope = false;
  EXPECT_TRUE(found(relocalize(options)));
  options.map_envelope = true;
  options.envelope = around_truth;  // the options' own envelope wins
  EXPECT_TRUE(found(relocalize(options)));
  s.map.camera_envelope = *around_truth;
  EXPECT_TRUE(found(relocalize(RelocalizerOptions{})));
  EXPECT_FALSE(RelocalizerOptions::oaSlam().map_envelope);
}

// A map without an envelope whose objects tell its up (estimateMapUp: office objects at their
// usual heights on a z-up floor) keeps the camera upright: a camera rolled upside down is never
// the answer, though its own detections would give it; turned off, it is found.
TEST(ObjectRelocalizer, KeepsTheCameraUprightAboutTheUpTheMapsObjectsTell) {
  std::mt19937 rng(13);
  const std::vector<int> categories = {56, 62, 66, 41, 73, 64, 39, 58};  // chair tv keyboard cup book mouse...
  ObjectMap map;
  for (int i = 0; i < 24; ++i) {
    const int c = categories[static_cast<size_t>(i) % categories.size()];
    map.objects.push_back({i, c, "",
                           Ellipsoid({uniform(rng, -2.0, 2.0), uniform(rng, -2.0, 2.0), typicalCentreHeight(c)},
                                     {0.15, 0.1, 0.08}, Eigen::Matrix3d::Identity())});
  }
  const Intrinsics K = test::testIntrinsics();
  const ObjectRelocalizer upright(map, K);
  ASSERT_TRUE(upright.upFromObjects());
  EXPECT_GT(upright.upFromObjects()->up.z(), 0.99);
  ASSERT_TRUE(upright.options().envelope);
  EXPECT_EQ(upright.options().envelope->max_tilt_deg, 90.0);
  EXPECT_EQ(upright.options().envelope->max_roll_deg, 45.0);
  EXPECT_LT((upright.options().envelope->up - upright.upFromObjects()->up).norm(), 1e-12);
  RelocalizerOptions anywhere;
  anywhere.map_envelope = false;
  EXPECT_FALSE(ObjectRelocalizer(map, K, anywhere).options().envelope);
  EXPECT_FALSE(ObjectRelocalizer(map, K, anywhere).upFromObjects());
  ObjectMap with_envelope = map;
  with_envelope.camera_envelope = CameraEnvelope::upright(Eigen::Vector3d::UnitY());
  EXPECT_FALSE(ObjectRelocalizer(with_envelope, K).upFromObjects());
  EXPECT_EQ(ObjectRelocalizer(with_envelope, K).options().envelope->up, Eigen::Vector3d::UnitY());

  const Pose level = Pose::lookAt({0.0, -4.5, 1.0}, {0.0, 0.0, 0.8});
  const Eigen::Matrix3d roll = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Pose upside_down(roll * level.rotation(), roll * level.translation());
  const std::vector<Observation> observations = sim::observeMap(map, K, upside_down, {}, &rng);
  ASSERT_GE(observations.size(), 6u);
  const RelocalizationResult free = ObjectRelocalizer(map, K, anywhere).relocalize(observations);
  ASSERT_EQ(free.status, RelocalizationStatus::Success) << free.reason;
  EXPECT_LT(positionError(free.pose, upside_down), 0.02);
  const RelocalizationResult kept = upright.relocalize(observations);
  EXPECT_NE(kept.status, RelocalizationStatus::Success);
  if (kept.status == RelocalizationStatus::LowEvidence)  // a withheld pose is upright too
    EXPECT_LE(CameraEnvelope::tiltDegOf(kept.pose, Eigen::Vector3d::UnitZ()), 90.0);
}
