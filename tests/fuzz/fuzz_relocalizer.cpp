// The relocalizer with a small map and observations built from the fuzzer's numbers (and maybe
// a gravity prior and a pose region, or a track of two frames along odometry poses from the
// numbers): a status, never a crash, and a successful pose is a valid rigid transform, within
// the region when there is one.
#include <cmath>

#include "ellreloc/pose/object_relocalizer.hpp"
#include "ellreloc/pose/track_relocalizer.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace ellreloc;
  fuzz::Input in(data, size);
  const bool raw = in.small(4) == 0;
  const auto num = [&](double lo, double hi) { return raw ? in.real() : in.scaled(lo, hi); };
  ObjectMap map;
  const int objects = 1 + in.small(8);
  for (int i = 0; i < objects; ++i) {
    MapObject o;
    o.id = i;
    o.category = in.small(3);
    o.ellipsoid = Ellipsoid({num(-2, 2), num(-2, 2), num(0, 1)}, {num(0.01, 0.5), num(0.01, 0.5), num(0.01, 0.5)},
                            Eigen::AngleAxisd(num(-4, 4), Eigen::Vector3d::UnitZ()).toRotationMatrix());
    map.objects.push_back(o);
  }
  if (in.small(4) == 0) map.unit_metres = raw ? in.real() : std::exp(in.scaled(-8, 8));  // a monocular map's unit
  std::vector<Observation> observations;
  const int n = in.small(10);
  for (int i = 0; i < n; ++i) {
    Observation o;
    o.category = in.small(3);
    o.score = num(0, 1);
    o.ellipse = Ellipse({num(0, 640), num(0, 480)}, {num(1, 200), num(1, 200)}, num(-2, 2));
    o.box = o.ellipse.boundingBox();
    observations.push_back(o);
  }
  std::optional<GravityPrior> gravity;
  if (in.small(2) == 1)
    gravity = GravityPrior{{num(-1, 1), num(-1, 1), num(-1, 1)}, {num(-1, 1), num(-1, 1), num(-1, 1)}, num(0.1, 10)};
  std::optional<PoseRegion> region;
  if (in.small(2) == 1)
    region = PoseRegion{Pose::lookAt({num(-3, 3), num(-3, 3), num(0, 2)}, {num(-1, 1), num(-1, 1), num(0, 1)}),
                        num(0.05, 3), num(1, 180)};
  RelocalizerOptions options;
  options.search.budget.max_hypotheses = 200;  // keep each run short
  options.few_objects.max_pair_hypotheses = 20;
  options.few_objects.solver.angle_steps = 8;  // coarse sweeps: the paths matter here, not the accuracy
  options.few_objects.solver.axis_step_deg = 60.0;
  const ObjectRelocalizer relocalizer(map, Intrinsics(525, 525, 319.5, 239.5, 640, 480), options);
  const RelocalizationResult r = relocalizer.relocalize(observations, {}, gravity, region);
  FUZZ_CHECK(r.status != RelocalizationStatus::Success || r.pose.isValid());
  FUZZ_CHECK(validUnitMetres(map.unit_metres) || r.status == RelocalizationStatus::InvalidInput);
  // A pose found in a region lies in it; an invalid region is a status.
  FUZZ_CHECK(!region || !region->isValid() || r.status != RelocalizationStatus::Success || region->admits(r.pose));
  FUZZ_CHECK(!region || region->isValid() || r.status == RelocalizationStatus::InvalidInput);
  // The budgets hold: triplets, and up to max_poses poses per pair (or single object).
  FUZZ_CHECK(r.hypotheses - r.few_object_hypotheses <= options.search.budget.max_hypotheses + 4);
  FUZZ_CHECK(r.few_object_hypotheses <= options.few_objects.max_pair_hypotheses * options.few_objects.solver.max_poses);
  if (in.small(2) == 1) {  // the frame twice along a track, the odometry poses from the numbers
    TrackOptions track_options;
    track_options.max_frames = 1 + in.small(2);
    track_options.metric_odometry = in.small(2) == 0;
    TrackRelocalizer track(relocalizer, track_options);
    for (int k = 0; k < 2; ++k) {
      const Pose odometry(Eigen::AngleAxisd(num(-4, 4), Eigen::Vector3d::UnitY()).toRotationMatrix(),
                          Eigen::Vector3d(num(-3, 3), num(-3, 3), num(-3, 3)));
      const int before = track.size();
      const TrackResult t = track.add(observations, odometry, gravity);
      FUZZ_CHECK(t.result.status != RelocalizationStatus::Success || t.result.pose.isValid());
      FUZZ_CHECK(odometry.isValid() ||
                 (t.result.status == RelocalizationStatus::InvalidInput && track.size() == before));
      FUZZ_CHECK(track.size() <= track_options.max_frames);
      FUZZ_CHECK(std::isfinite(t.scale) && t.scale >= 0.0 &&
                 (!track_options.metric_odometry || t.result.status == RelocalizationStatus::InvalidInput ||
                  t.scale == 1.0 / map.unit_metres));
    }
  }
  return 0;
}
