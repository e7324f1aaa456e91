// `ellreloc evaluate`.

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "commands.hpp"
#include "ellreloc/io/detections.hpp"
#include "ellreloc/io/files.hpp"
#include "ellreloc/io/map.hpp"
#include "ellreloc/io/trajectory.hpp"

namespace ellreloc::cli {

CLI::App* addEvaluateCommand(CLI::App& app, EvaluateArgs& a) {
  CLI::App* e = app.add_subcommand(
      "evaluate", "Table I rows: median errors and valid % of one or more methods (definitions in docs/formats.md)");
  e->add_option("--groundtruth", a.groundtruth, "TUM trajectory of the true camera poses")
      ->required()
      ->check(CLI::ExistingFile);
  e->add_option("--estimate", a.estimates,
                "TUM poses written by `ellreloc relocalize`, as FILE or FILE:LABEL (the label names the method in "
                "the table and the plots; default: the file's name); repeat it to compare methods")
      ->required();
  e->add_option("--detections", a.detections, "the query frames (default: every ground-truth pose)")
      ->check(CLI::ExistingFile);
  e->add_option("--map", a.map, "map JSON or OA-SLAM text map: its objects' footprints in the plot's top view")
      ->check(CLI::ExistingFile);
  e->add_option("--unit-metres", a.unit_metres,
                "metres per unit of the trajectories, for poses of a monocular SLAM system's map (default: the --map's "
                "unit_metres, else 1)");
  e->add_option("--plot", a.plot,
                "cumulative error curves and a top view of every method: SVG for a .svg name (text stays text), "
                "else PNG");
  e->add_option("--per-frame", a.per_frame,
                "CSV of every query frame's errors and status for every method (frame,method,status,position_cm,"
                "rotation_deg)");
  e->footer(
      "Example: ellreloc evaluate --groundtruth G.txt --estimate ours.txt:ours --estimate oaslam.txt:OA-SLAM "
      "--detections D.json --map map.json --plot compare.svg --per-frame frames.csv");
  return e;
}

namespace {

/// An estimate's pose belongs to a query frame when their times are this close (seconds):
/// `ellreloc relocalize` writes each frame's own timestamp.
constexpr double kSameTime = 1e-4;

/// FILE:LABEL -> {FILE, LABEL}; an existing file keeps its colons, and the label defaults to
/// the file's name without extension.
std::pair<std::string, std::string> fileAndLabel(const std::string& arg) {
  std::error_code ec;
  const size_t colon = arg.rfind(':');
  if (colon == std::string::npos || std::filesystem::exists(arg, ec))
    return {arg, std::filesystem::path(arg).stem().string()};
  const std::string label = arg.substr(colon + 1);
  if (label.empty()) throw Error("--estimate: '" + arg + "' has an empty label after ':'");
  return {arg.substr(0, colon), label};
}

std::string csvField(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

void writePerFrame(const std::string& path, const Evaluation& e) {
  std::string csv = "frame,method,status,position_cm,rotation_deg\n";
  char numbers[64];
  for (size_t i = 0; i < e.frames.size(); ++i)
    for (const MethodEvaluation& m : e.methods) {
      const std::optional<PoseError>& err = m.errors[i];
      numbers[0] = ',', numbers[1] = '\0';  // no pose: empty errors
      if (err) std::snprintf(numbers, sizeof numbers, "%.3f,%.3f", err->position_cm, err->rotation_deg);
      csv += csvField(e.frames[i]) + "," + csvField(m.label) + "," + frameStatus(err) + "," + numbers + "\n";
    }
  io::writeFileAtomically(path, csv);
}

}  // namespace

const char* frameStatus(const std::optional<PoseError>& error) {
  return !error ? "no pose" : error->valid() ? "valid" : "wrong";
}

Evaluation evaluateEstimates(const EvaluateArgs& a) {
  std::vector<std::pair<std::string, std::string>> estimates;
  std::vector<NamedPath> inputs = {{"--groundtruth", a.groundtruth}, {"--detections", a.detections}, {"--map", a.map}};
  for (const std::string& arg : a.estimates) {
    estimates.push_back(fileAndLabel(arg));
    inputs.push_back({"--estimate", estimates.back().first});
    for (size_t k = 0; k + 1 < estimates.size(); ++k)
      if (estimates[k].second == estimates.back().second)
        throw Error("--estimate: two methods are labelled '" + estimates.back().second + "'; give FILE:LABEL");
  }
  if (estimates.empty()) throw Error("--estimate: give at least one");
  checkPaths({{"--plot", a.plot}, {"--per-frame", a.per_frame}}, inputs);
  if (!(a.unit_metres == 0.0 || validUnitMetres(a.unit_metres)))
    throw Error("--unit-metres: expected a length of 1e-6 to 1e6 metres");
  const double unit = a.unit_metres > 0.0 ? a.unit_metres : a.map.empty() ? 1.0 : io::readMap(a.map).unit_metres;
  const std::vector<io::StampedPose> gt = io::readTumTrajectory(a.groundtruth);
  // The query frames: those of the detections file when given, else every ground-truth pose.
  Evaluation e;
  std::vector<double> times;        // each query frame's time, under which the estimates write its pose
  std::vector<size_t> truth_index;  // its ground-truth pose
  std::vector<double> frame_times;  // every frame's time, with a ground-truth pose or not
  if (!a.detections.empty()) {
    const io::TimeIndex truth_by_time = io::timeIndex(gt);
    for (const DetectionFrame& f : io::readDetections(a.detections))
      if (const auto t = f.timestamp()) {
        frame_times.push_back(*t);
        if (const auto g = truth_by_time.nearest(*t))
          e.frames.push_back(f.timestampText()), times.push_back(*t), truth_index.push_back(*g);
      }
  } else {
    for (size_t g = 0; g < gt.size(); ++g) {
      char text[32];
      std::snprintf(text, sizeof text, "%.6f", gt[g].timestamp);
      e.frames.push_back(gt[g].stamp.empty() ? text : gt[g].stamp);
      times.push_back(gt[g].timestamp);
      frame_times.push_back(gt[g].timestamp);
      truth_index.push_back(g);
    }
  }
  if (e.frames.empty()) throw Error(a.groundtruth + ": no query frame has a ground-truth pose");
  for (size_t g : truth_index) e.truth.push_back(gt[g].pose.center());
  const io::TimeIndex frames_by_time(frame_times);
  for (const auto& [path, label] : estimates) {
    // An estimate without poses is a run that relocalized nothing: 0% valid, not an error.
    const std::vector<io::StampedPose> est = io::readTumTrajectory(path, /*allow_empty=*/true);
    MethodEvaluation m{label, path, {}, {}, {}};
    const io::TimeIndex by_time = io::timeIndex(est);
    for (size_t i = 0; i < e.frames.size(); ++i) {
      const auto k = by_time.nearest(times[i], kSameTime);
      m.errors.push_back(k ? std::optional(poseError(est[*k].pose, gt[truth_index[i]].pose, unit)) : std::nullopt);
      m.centres.push_back(k ? std::optional(est[*k].pose.center()) : std::nullopt);
    }
    m.summary = summarize(m.errors);
    e.methods.push_back(std::move(m));
    // Poses at no frame's time are left out of every figure: say so, e.g. when the ground truth
    // is a motion-capture trajectory sampled apart from the camera's frames.
    const auto unmatched = static_cast<size_t>(
        std::count_if(est.begin(), est.end(), [&](const io::StampedPose& p) {
          return !frames_by_time.nearest(p.timestamp, kSameTime);
        }));
    if (unmatched > 0)
      std::fprintf(stderr, "warning: %s: %zu of its %zu poses are at no frame's time (within 0.1 ms)%s\n", path.c_str(),
                   unmatched, est.size(),
                   a.detections.empty() ? "; without --detections the query frames are the ground-truth poses" : "");
  }
  return e;
}

Evaluation evaluate(const EvaluateArgs& a) {
  const Evaluation e = evaluateEstimates(a);
  if (!a.plot.empty()) {
    const std::optional<ObjectMap> map = a.map.empty() ? std::nullopt : std::optional(io::readMap(a.map));
    const Figure figure = comparisonFigure(e, map ? &*map : nullptr);
    const bool svg = std::filesystem::path(a.plot).extension() == ".svg";
    io::writeFileAtomically(a.plot, svg ? figure.svg() : figure.png());
  }
  if (!a.per_frame.empty()) writePerFrame(a.per_frame, e);
  return e;
}

void printEvaluation(const Evaluation& e) {
  std::printf("| median position error (cm) | median rotation error (deg) | valid %% | relocalized | method |\n");
  std::printf("| --- | --- | --- | --- | --- |\n");
  for (const MethodEvaluation& m : e.methods) {
    const RelocalizationSummary& s = m.summary;
    if (s.valid == 0)  // no valid frame: no median error to show
      std::printf("| - | - | %.1f | %d / %d | %s |\n", s.validPercent(), s.relocalized, s.frames, m.label.c_str());
    else
      std::printf("| %.1f | %.2f | %.1f | %d / %d | %s |\n", s.median_position_cm, s.median_rotation_deg,
                  s.validPercent(), s.relocalized, s.frames, m.label.c_str());
  }
}

}  // namespace ellreloc::cli
