#pragma once
/// \file track_relocalizer.hpp
/// Relocalization over a short track: the frames a host followed since it lost the map, with
/// their camera poses from its own odometry (visual-inertial, stereo or RGB-D odometry, wheel
/// odometry, or the new map a SLAM system starts when it loses the old one). One frame's
/// objects may fit look-alikes elsewhere in the map (the other desk's monitor and keyboard)
/// as well as the right ones; a few frames seen from elsewhere along the track rarely all do.
/// Every frame is relocalized on its own once, as it comes; the poses each search found (its
/// pose and its alternatives) are carried to the newest frame by the odometry and ranked by the
/// sum of their costs over all the track's frames; the best is refined on the newest frame.
/// A monocular host's odometry has a scale of its own: the track estimates it
/// (TrackOptions::metric_odometry).

#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ellreloc/core/observation.hpp"
#include "ellreloc/core/pose.hpp"
#include "ellreloc/pose/gravity_prior.hpp"
#include "ellreloc/pose/object_relocalizer.hpp"

namespace ellreloc {

struct TrackOptions {
  /// The newest frames kept in the track. A longer track sees more of the room, but carries the
  /// poses further on the odometry's drift; a frame's work grows with it (its poses are scored
  /// on every frame, every kept pose on it), and the memory with its square. At most 100.
  int max_frames = 10;
  /// With the relocalizer's acceptance test on (acceptance.enabled), a pose is Success only when
  /// the track's frames' evidence at it sums to acceptance.min_evidence and averages at least
  /// `min_mean_evidence` per frame (a look-alike pose explains a few of each frame's
  /// observations, the right one most of them), and when the best other pose the track's frames
  /// found (30 cm or 30 degrees away) costs at least `min_margin` more over the track. Chosen on
  /// fr2_desk and nine fr3 splits, tracks of 3-20 frames: no more wrong poses than each frame
  /// alone on any of them, and more right ones (docs/benchmarks.md, "Over a track").
  double min_mean_evidence = 1.5;
  double min_margin = 0.5;
  /// The odometry is metric (visual-inertial, stereo or RGB-D odometry, wheels). A monocular
  /// host's odometry (the new map a monocular SLAM system starts after a loss) has a scale of its
  /// own, unknown and drifting: false, and the track estimates the map's units per odometry
  /// unit at each frame. Pairs of frames whose own poses turn and move as the odometry does
  /// propose a scale; the scale, within a factor 1.5 of theirs, at which the track's best pose
  /// costs least is taken (TrackResult::scale). Until a first proposal, the newest frame's own
  /// poses are ranked on it alone.
  bool metric_odometry = true;
  /// Why the options are unusable, or empty.
  std::string validate() const;
};

struct TrackResult {
  /// The newest frame's answer. `pose` is the track's best pose refined on this frame (world ->
  /// camera); `inliers`, `cost`, `mean_overlap` and `evidence` are this frame's at it; `margin`,
  /// `rival` and `alternatives` compare track costs (the other answers the frames' searches
  /// found, carried to this frame); `hypotheses` and `iterations` are this frame's own search's.
  /// Success needs the track's evidence and margin to pass TrackOptions' test; without any pose
  /// found, this frame's own status.
  RelocalizationResult result;
  double track_cost = 0.0;      ///< the sum over the track's frames of their cost at the pose
  double track_evidence = 0.0;  ///< the sum over the track's frames of their evidence at the pose
  int track_matches = 0;        ///< observations explained over the track's frames
  int frames = 0;               ///< frames whose observations ranked the poses, this one included
  int candidates = 0;           ///< distinct poses ranked
  int found_by = -1;            ///< whose search found the pose: 0 this frame, 1 the one before, ...
  /// Map units per odometry unit with which the poses were carried (map metres when the map is
  /// metric): 1 / the map's unit_metres with metric odometry, the estimate otherwise (0 while
  /// there is none).
  double scale = 1.0;
};

/// Keeps the last frames of a track and relocalizes each new one with their help. Holds a
/// reference to `relocalizer`, which must outlive it. Not thread-safe (one per track); the
/// relocalizer itself may serve other threads meanwhile.
class TrackRelocalizer {
 public:
  TrackRelocalizer(const ObjectRelocalizer& relocalizer, TrackOptions options = {});
  ~TrackRelocalizer();
  TrackRelocalizer(const TrackRelocalizer&) = delete;
  TrackRelocalizer& operator=(const TrackRelocalizer&) = delete;

  /// Adds a frame: its observations and its camera pose in the odometry's frame (world ->
  /// camera; metric unless TrackOptions::metric_odometry is false), the oldest frame dropped beyond
  /// max_frames; relocalizes it (with `gravity`, as ObjectRelocalizer::relocalize) and ranks
  /// every pose the track's frames found. An invalid odometry pose or options, or input the
  /// relocalizer turns down (InvalidInput), leaves the track unchanged.
  TrackResult add(const std::vector<Observation>& observations, const Pose& odometry_pose,
                  const std::optional<GravityPrior>& gravity = std::nullopt);
  /// Forgets every frame: when the host's odometry restarts, or tracking on the map resumes.
  void reset();
  /// Frames held.
  int size() const { return static_cast<int>(frames_.size()); }

 private:
  struct Frame;  // a frame's observations, odometry pose, scorer and own poses
  /// A pose a frame's search found, carried to the newest frame.
  struct Carried {
    Pose pose;     // world -> the newest frame's camera
    int found_by;  // 0 the newest frame, 1 the one before, ...
    double cost;   // over the frames ranked
  };
  /// How the poses are carried: the odometry's translations times base * exp(kScaleStep *
  /// scale_step), read from the track's frames from `first` (an index into frames_) to the
  /// newest. `base`: map units per odometry unit at step 0, 1 / the map's unit_metres for metric
  /// odometry, else 1.
  struct Carrying {
    int scale_step = 0;
    int first = 0;
    bool known = true;  // false: no scale yet, the newest frame alone
    double base = 1.0;
    double scale() const;
  };
  /// The cost of the newest frame's pose `pose` over the frames carried (each at the pose the
  /// odometry gives it), and with `with_evidence` their evidence and matches (at the report's
  /// precision).
  struct TrackScore {
    double cost = 0.0, evidence = 0.0;
    int matches = 0;
  };
  TrackScore score(const Pose& pose, bool with_evidence, const Carrying& carrying) const;
  /// The frame joins the track, with the poses its own search found (`own`).
  void join(const std::vector<Observation>& observations, const Pose& odometry_pose, const RelocalizationResult& own);
  /// Every carried frame's poses, carried to the newest frame, each once (5 cm, 3 degrees),
  /// cheapest first.
  std::vector<Carried> rankedPoses(const Carrying& carrying) const;
  /// Metric odometry: the map's units per metre over the whole track. Otherwise the scale step,
  /// near the scale the frames' poses propose (or the last one chosen), whose best pose costs
  /// least; without either, the newest frame alone. Fills `ranked` with that carrying's poses.
  Carrying chooseCarrying(std::vector<Carried>* ranked);
  /// The scale (map units per odometry unit) pairs of the track's frames propose, or 0.
  double proposedScale() const;
  /// Fills the result at the chosen pose: this frame's matches, the track's cost and evidence,
  /// the other answers and the status.
  void report(const std::vector<Observation>& observations, const Pose& pose, const std::vector<Carried>& ranked,
              const Carrying& carrying, TrackResult* out) const;

  const ObjectRelocalizer& relocalizer_;
  TrackOptions options_;
  std::deque<std::unique_ptr<Frame>> frames_;  // oldest first
  long next_serial_ = 0;
  std::optional<int> last_scale_step_;  // with an unknown scale, the step chosen last
};

}  // namespace ellreloc
