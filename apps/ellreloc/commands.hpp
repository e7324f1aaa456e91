#pragma once
// The `ellreloc` subcommands, one file each: add<Name>Command registers the options, the plain
// function runs it (so that `demo` can chain them). Each throws ellreloc::Error on bad input
// (main turns it into one line and exit code 2).

#include <optional>
#include <string>
#include <vector>

#include "ellreloc/core/evaluation.hpp"
#include "ellreloc/core/object_map.hpp"
#include "ellreloc/error.hpp"
#include "ellreloc/observe/observe.hpp"
#include "ellreloc/pose/pose_region.hpp"
#include "ellreloc/pose/relocalizer_options.hpp"
#include "ellreloc/pose/track_relocalizer.hpp"
#include "figure.hpp"

namespace CLI {
class App;
}

namespace ellreloc::cli {

/// Where progress goes: a bar on a terminal, nothing when quiet.
struct Console {
  bool quiet = false;
  /// A progress bar on stderr, only when stderr is a terminal and not quiet.
  void progress(const char* what, size_t done, size_t total) const;
  void endProgress() const;
};

/// A path given to an option, for messages.
struct NamedPath {
  std::string option, path;
};

/// Before any work: refuses (Error) an output that is the same file as an input or another
/// output (same device and inode, or the same resolved path when it does not exist yet), or
/// that exists and is not a regular file, or whose folder does not exist or cannot be written.
/// Empty paths are skipped.
void checkPaths(const std::vector<NamedPath>& outputs, const std::vector<NamedPath>& inputs);

/// For a command run without --undistort: says so when the camera file gives a lens distortion
/// (the detections may have been made on its raw images). Prints nothing for a camera without
/// one, or whose distortion keys do not read (they are not used).
void mentionTheLens(const std::string& camera);

struct SimulateArgs {
  std::string preset = "office", noise = "realistic", out;
  unsigned long seed = 1;
  int mapping_frames = 60, query_frames = 100;
};
CLI::App* addSimulateCommand(CLI::App& app, SimulateArgs& a);
void simulate(const SimulateArgs& a, const Console& console);

struct ObserveArgs {
  std::string camera, detections, policy = "solid", out;
};
CLI::App* addObserveCommand(CLI::App& app, ObserveArgs& a);
void observe(const ObserveArgs& a, const Console& console);
/// solid, paper, bbox, mask or given; anything else is an Error naming --policy.
ObservationPolicy parsePolicy(const std::string& name);

struct MapArgs {
  std::string camera, associations, trajectory, detections, mode = "voxel", out;
  int holdout_every = 0;   ///< every N-th frame is left out of the map and measures its quality
  std::string holdout;     ///< detections of frames left out of the map, to measure its quality
  std::vector<double> up;  ///< the world's up direction, when known
  bool undistort = false;  ///< the detections and depth images are raw images of the camera's distorted lens
  std::string unit_metres = "1";  ///< boxes mode: the trajectory's unit in metres, or "auto"
  std::string detections_out;     ///< the detections again, each with the map object it joined
};
CLI::App* addMapCommand(CLI::App& app, MapArgs& a);
void map(const MapArgs& a, const Console& console);

struct RelocalizeArgs {
  std::string camera, map, detections, method = "ours", out, report, policy;
  std::string reference;         ///< TUM poses to diagnose each frame against (search or scoring failure)
  std::string envelope;          ///< TUM trajectory of the mapping keyframes: poses outside their envelope are dropped
  bool no_map_envelope = false;  ///< ignore the map's own camera envelope
  double max_tilt_deg = -1.0;    ///< with map_up: the camera's image-up within this of up (< 0: not given)
  double max_roll_deg = 90.0;    ///< with max_tilt_deg: the camera's image rows within this of level
  bool use_points = false;       ///< refine with the frames' keypoints matched to the map's points
  std::string points;            ///< a file with the keypoints; empty: the detections file's own
  int threads = 1;
  double max_time_ms = 0.0;  ///< wall-clock budget of each frame's search; 0: none
  double min_evidence = AcceptanceOptions().min_evidence;
  double min_margin = AcceptanceOptions().min_margin;
  bool accept_all = false;
  /// A gravity prior for every frame when both are given; map_up is also the up of --envelope and
  /// --max-tilt.
  std::vector<double> camera_up, map_up;
  double gravity_sigma_deg = 2.0;
  std::string overlays;  ///< a folder for one PNG per frame (io/overlay.hpp); empty: none
  /// TUM poses the camera was last tracked at: each frame is searched within near_radius_m and
  /// near_angle_deg of the latest one at or before its timestamp (a PoseRegion); empty: none.
  std::string near;
  double near_radius_m = PoseRegion().radius_m;
  double near_angle_deg = PoseRegion().max_rotation_deg;
  /// TUM poses from the host's own odometry (camera->world in its frame): the frames are
  /// relocalized in timestamp order as one track (TrackRelocalizer); a frame without a pose within
  /// 20 ms of its timestamp is relocalized alone and starts the track again. Empty: none.
  std::string track;
  int track_frames = TrackOptions().max_frames;
  /// The --track odometry's scale is unknown (a monocular host's): the track estimates it.
  bool track_scale_unknown = false;
  /// The detections (and keypoints) were made on the raw images of the --camera file's
  /// distorted lens: undistort them (ObserveOptions::lens).
  bool undistort = false;
};
/// `use_points` is set after parsing, from whether --points was given.
CLI::App* addRelocalizeCommand(CLI::App& app, RelocalizeArgs& a);
/// Returns the number of frames relocalized.
int relocalize(const RelocalizeArgs& a, const Console& console);

struct EvaluateArgs {
  std::string groundtruth;
  std::vector<std::string> estimates;  ///< FILE or FILE:LABEL
  std::string detections, plot, map, per_frame;
  double unit_metres = 0.0;  ///< metres per unit of the trajectories; 0: the --map's unit_metres, else 1
};
/// One method's errors on the query frames.
struct MethodEvaluation {
  std::string label, path;
  std::vector<std::optional<PoseError>> errors;         ///< per query frame; nullopt: no pose
  std::vector<std::optional<Eigen::Vector3d>> centres;  ///< per query frame: the estimated camera centre
  RelocalizationSummary summary;
};
struct Evaluation {
  std::vector<std::string> frames;     ///< the query frames' timestamps as written
  std::vector<Eigen::Vector3d> truth;  ///< their true camera centres
  std::vector<MethodEvaluation> methods;
};
CLI::App* addEvaluateCommand(CLI::App& app, EvaluateArgs& a);
/// Reads and scores every estimate; writes no file (a warning on stderr names the estimates with
/// poses at no frame's time).
Evaluation evaluateEstimates(const EvaluateArgs& a);
/// evaluateEstimates, then --plot and --per-frame.
Evaluation evaluate(const EvaluateArgs& a);
/// A frame's status in a method's results: "valid", "wrong" (a pose beyond 30 cm or 30 degrees)
/// or "no pose".
const char* frameStatus(const std::optional<PoseError>& error);
/// The Table-I rows, one per method (the method is the last column).
void printEvaluation(const Evaluation& e);
/// Cumulative position and rotation error curves of every method and a top view (plots.cpp).
Figure comparisonFigure(const Evaluation& e, const ObjectMap* map);

struct ReportArgs {
  std::string groundtruth;
  std::vector<std::string> estimates;  ///< FILE or FILE:LABEL
  std::string detections, map, overlays, out;
  int worst = 6;
};
CLI::App* addReportCommand(CLI::App& app, ReportArgs& a);
void report(const ReportArgs& a, const Console& console);

struct DemoArgs {
  std::string out;
  unsigned long seed = 1;
  int threads = 2;
};
CLI::App* addDemoCommand(CLI::App& app, DemoArgs& a);
void demo(const DemoArgs& a, const Console& console);

}  // namespace ellreloc::cli
