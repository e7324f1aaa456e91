// `ellreloc evaluate`.

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "commands.hpp"
#include "ellreloc/io/detections.hpp"
#include "ellreloc/io/files.hpp"
#include "ellreloc/io/trajectory.hpp"

namespace ellreloc::cli {

CLI::App* addEvaluateCommand(CLI::App& app, EvaluateArgs& a) {
  CLI::App* e =
      app.add_subcommand("evaluate", "Table I row: median errors and valid % (definitions in docs/formats.md)");
  e->add_option("--groundtruth", a.groundtruth, "TUM trajectory of the true camera poses")
      ->required()
      ->check(CLI::ExistingFile);
  e->add_option("--estimate", a.estimate, "TUM poses written by `ellreloc relocalize`")
      ->required()
      ->check(CLI::ExistingFile);
  e->add_option("--detections", a.detections, "the query frames (default: every ground-truth pose)")
      ->check(CLI::ExistingFile);
  e->add_option("--plot", a.plot, "PNG: top view and cumulative error curves");
  e->footer("Example: ellreloc evaluate --groundtruth G.txt --estimate poses.txt --detections D.json --plot out.png");
  return e;
}

namespace {

/// A top view of the ground truth with the relocalized positions coloured by error, and the
/// cumulative error curves (the paper's Figs. 6 and 7), side by side.
void writePlot(const std::string& path, const std::vector<io::StampedPose>& gt,
               const std::vector<std::pair<Eigen::Vector3d, double>>& estimates, const std::vector<double>& pos_cm,
               const std::vector<double>& rot_deg, int frames) {
  const int size = 480;
  cv::Mat img(size, 2 * size, CV_8UC3, cv::Scalar(255, 255, 255));
  Eigen::AlignedBox2d box;
  for (const auto& p : gt) box.extend(p.pose.center().head<2>());
  for (const auto& [c, e] : estimates) box.extend(c.head<2>());
  const double span = std::max(1e-3, box.sizes().maxCoeff()) * 1.1;
  const Eigen::Vector2d mid = box.center();
  const auto px = [&](const Eigen::Vector3d& c) {
    return cv::Point(static_cast<int>(size / 2 + (c.x() - mid.x()) / span * (size - 40)),
                     static_cast<int>(size / 2 - (c.y() - mid.y()) / span * (size - 40)));
  };
  for (size_t i = 1; i < gt.size(); ++i)
    cv::line(img, px(gt[i - 1].pose.center()), px(gt[i].pose.center()), cv::Scalar(160, 160, 160), 1, cv::LINE_AA);
  for (const auto& [c, err_cm] : estimates) {
    const double s = std::min(1.0, err_cm / 30.0);  // green (0 cm) to red (>= 30 cm)
    cv::circle(img, px(c), 4, cv::Scalar(0, 255 * (1 - s), 255 * s), cv::FILLED, cv::LINE_AA);
  }
  cv::putText(img, "top view: ground truth (grey), relocalized (green 0 -> red 30 cm)", {8, 16},
              cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  // Cumulative curves: share of all frames with error below x (x from 0 to 30 cm / degrees).
  const cv::Point origin(size + 40, size - 40);
  const int w = size - 70, h = size - 90;
  cv::rectangle(img, origin, origin + cv::Point(w, -h), cv::Scalar(0, 0, 0));
  const auto curve = [&](std::vector<double> v, const cv::Scalar& colour) {
    std::sort(v.begin(), v.end());
    cv::Point last = origin;
    for (int x = 0; x <= w; ++x) {
      const double limit = 30.0 * x / w;
      const double share = static_cast<double>(std::upper_bound(v.begin(), v.end(), limit) - v.begin()) / frames;
      const cv::Point p(origin.x + x, origin.y - static_cast<int>(share * h));
      if (x > 0) cv::line(img, last, p, colour, 2, cv::LINE_AA);
      last = p;
    }
  };
  curve(pos_cm, cv::Scalar(200, 80, 0));
  curve(rot_deg, cv::Scalar(0, 120, 0));
  cv::putText(img, "cumulative share of frames: position error (cm, blue), rotation error (deg, green)", {size + 8, 16},
              cv::FONT_HERSHEY_SIMPLEX, 0.35, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  cv::putText(img, "0", origin + cv::Point(-4, 16), cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(0, 0, 0));
  cv::putText(img, "30", origin + cv::Point(w - 8, 16), cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(0, 0, 0));
  cv::putText(img, "100%", origin + cv::Point(-36, -h + 4), cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(0, 0, 0));
  std::vector<uchar> png;
  if (!cv::imencode(".png", img, png)) throw Error(path + ": could not encode the plot");
  io::writeFileAtomically(path, std::string(png.begin(), png.end()));
}

}  // namespace

RelocalizationSummary evaluate(const EvaluateArgs& a) {
  checkPaths({{"--plot", a.plot}},
             {{"--groundtruth", a.groundtruth}, {"--estimate", a.estimate}, {"--detections", a.detections}});
  const std::vector<io::StampedPose> gt = io::readTumTrajectory(a.groundtruth);
  // An estimate without poses is a run that relocalized nothing: 0% valid, not an error.
  const std::vector<io::StampedPose> est = io::readTumTrajectory(a.estimate, /*allow_empty=*/true);
  // The query frames: those of the detections file when given, else every ground-truth pose.
  std::vector<double> queries;
  if (!a.detections.empty()) {
    for (const DetectionFrame& f : io::readDetections(a.detections))
      if (const auto t = f.timestamp(); t && io::findNearest(gt, *t)) queries.push_back(*t);
  } else {
    for (const io::StampedPose& p : gt) queries.push_back(p.timestamp);
  }
  if (queries.empty()) throw Error(a.groundtruth + ": no query frame has a ground-truth pose");
  std::vector<std::optional<PoseError>> errors;
  std::vector<double> pos_cm, rot_deg;
  std::vector<std::pair<Eigen::Vector3d, double>> estimates;
  for (double t : queries) {
    const auto g = io::findNearest(gt, t);
    const auto k = io::findNearest(est, t, 1e-4);
    errors.push_back(g && k ? std::optional(poseError(est[*k].pose, gt[*g].pose)) : std::nullopt);
    if (!errors.back()) continue;
    pos_cm.push_back(errors.back()->position_cm);
    rot_deg.push_back(errors.back()->rotation_deg);
    estimates.emplace_back(est[*k].pose.center(), errors.back()->position_cm);
  }
  const RelocalizationSummary summary = summarize(errors);
  if (!a.plot.empty()) writePlot(a.plot, gt, estimates, pos_cm, rot_deg, summary.frames);
  return summary;
}

void printEvaluation(const RelocalizationSummary& e) {
  std::printf("| median position error (cm) | median rotation error (deg) | valid %% | relocalized |\n");
  std::printf("| --- | --- | --- | --- |\n");
  if (e.valid == 0) {  // no valid frame: no median error to show
    std::printf("| - | - | %.1f | %d / %d |\n", e.validPercent(), e.relocalized, e.frames);
    return;
  }
  std::printf("| %.1f | %.2f | %.1f | %d / %d |\n", e.median_position_cm, e.median_rotation_deg, e.validPercent(),
              e.relocalized, e.frames);
}

}  // namespace ellreloc::cli
