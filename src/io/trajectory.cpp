#include "ellreloc/io/trajectory.hpp"

#include <Eigen/Geometry>
#include <charconv>
#include <cmath>
#include <iomanip>
#include <map>
#include <set>
#include <sstream>

#include "ellreloc/core/detection.hpp"
#include "ellreloc/error.hpp"
#include "ellreloc/io/files.hpp"

namespace ellreloc::io {

std::vector<StampedPose> readTumTrajectory(const std::string& path, bool allow_empty) {
  std::vector<StampedPose> poses;
  std::map<double, int> first_line;  // timestamp -> the line that gave it
  forEachDataLine(readTextFile(path), [&](int line_no, const std::string& line) {
    const std::string where = path + ": line " + std::to_string(line_no) + ": ";
    std::istringstream fields(line);
    std::string stamp;
    fields >> stamp;
    const std::optional<double> t = timestampFromText(stamp);
    if (!t) throw Error(where + "timestamp '" + stamp + "' is not a finite number");
    double v[8] = {*t};
    for (int k = 1; k < 8; ++k) {
      if (!(fields >> v[k])) throw Error(where + "expected 'timestamp tx ty tz qx qy qz qw'");
      if (!std::isfinite(v[k])) throw Error(where + "value " + std::to_string(k + 1) + " is not finite");
    }
    std::string extra;
    if (fields >> extra) throw Error(where + "unexpected trailing text '" + extra + "'");
    Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    if (!(q.norm() > 1e-6)) throw Error(where + "zero quaternion");
    q.normalize();
    if (const auto [it, fresh] = first_line.emplace(v[0], line_no); !fresh)
      throw Error(where + "timestamp " + stamp + " repeats line " + std::to_string(it->second));
    poses.push_back({v[0], Pose::fromCameraToWorld(q.toRotationMatrix(), Eigen::Vector3d(v[1], v[2], v[3])), stamp});
  });
  if (poses.empty() && !allow_empty) throw Error(path + ": no poses found (empty trajectory)");
  return poses;
}

void writeTumTrajectory(const std::string& path, const std::vector<StampedPose>& poses) {
  std::ostringstream out;
  out << "# timestamp tx ty tz qx qy qz qw (camera->world)\n" << std::setprecision(17);
  std::set<double> written;
  for (const StampedPose& p : poses) {
    if (!p.pose.isValid() || !std::isfinite(p.timestamp)) throw Error(path + ": refusing to write an invalid pose");
    std::string stamp = p.stamp;
    if (stamp.empty()) {
      char text[64];
      const auto [end, ec] = std::to_chars(text, text + sizeof text, p.timestamp);  // shortest round trip
      stamp.assign(text, end);
    }
    const std::optional<double> t_read = timestampFromText(stamp);
    if (!t_read) throw Error(path + ": refusing to write the timestamp '" + stamp + "': not a finite number");
    if (!written.insert(*t_read).second) throw Error(path + ": refusing to write two poses at timestamp " + stamp);
    const Pose inv = p.pose.inverse();  // camera->world
    const Eigen::Quaterniond q(inv.rotation());
    const Eigen::Vector3d& t = inv.translation();
    out << stamp << ' ' << t(0) << ' ' << t(1) << ' ' << t(2) << ' ' << q.x() << ' ' << q.y() << ' ' << q.z() << ' '
        << q.w() << '\n';
  }
  writeFileAtomically(path, out.str());
}

std::optional<size_t> findNearest(const std::vector<StampedPose>& poses, double t, double tolerance) {
  std::optional<size_t> best;
  double best_dt = tolerance;
  for (size_t i = 0; i < poses.size(); ++i) {
    const double dt = std::abs(poses[i].timestamp - t);
    if (dt <= best_dt) best = i, best_dt = dt;
  }
  return best;
}

TimeIndex timeIndex(const std::vector<StampedPose>& poses) {
  std::vector<double> times;
  times.reserve(poses.size());
  for (const StampedPose& p : poses) times.push_back(p.timestamp);
  return TimeIndex(times);
}

const Pose* framePose(const std::vector<StampedPose>& poses, const DetectionFrame& frame, double tolerance) {
  const std::optional<double> t = frame.timestamp();
  const std::optional<size_t> k = t ? findNearest(poses, *t, tolerance) : std::nullopt;
  return k ? &poses[*k].pose : nullptr;
}

const Pose* framePose(const std::vector<StampedPose>& poses, const TimeIndex& by_time, const DetectionFrame& frame,
                      double tolerance) {
  const std::optional<double> t = frame.timestamp();
  const std::optional<size_t> k = t ? by_time.nearest(*t, tolerance) : std::nullopt;
  return k ? &poses[*k].pose : nullptr;
}

}  // namespace ellreloc::io
