#pragma once
/// \file trajectory.hpp
/// TUM trajectories (`timestamp tx ty tz qx qy qz qw`, camera->world on disk; world->camera
/// Pose in memory) and TUM association files.

#include <optional>
#include <string>
#include <vector>

#include "ellreloc/core/camera.hpp"
#include "ellreloc/core/detection.hpp"
#include "ellreloc/io/time_index.hpp"

namespace ellreloc::io {

struct StampedPose {
  double timestamp = 0.0;
  Pose pose;          ///< world->camera
  std::string stamp;  ///< the timestamp's text as read or to be written; empty: `timestamp` decides
};

/// Reads a TUM trajectory; `#` starts a comment. Quaternions are normalised; a zero or
/// non-finite one is an error naming the line, and so is a timestamp equal to an earlier line's.
/// Throws ellreloc::Error on malformed input, and on a file without poses unless `allow_empty`
/// (a run that relocalized no frame writes one).
std::vector<StampedPose> readTumTrajectory(const std::string& path, bool allow_empty = false);

/// Writes camera->world lines atomically: each timestamp as its `stamp` text when there is one
/// (so "1311868164.3631811" stays that), else the shortest decimal that reads back as the same
/// double; poses with full precision. Throws on an invalid pose, a non-finite or malformed
/// timestamp and two poses at the same timestamp.
void writeTumTrajectory(const std::string& path, const std::vector<StampedPose>& poses);

/// Index of the pose whose timestamp is nearest to t, if within `tolerance` seconds; of several
/// equally near, the last. Reads every pose: to find many frames' poses, index them once
/// (timeIndex).
std::optional<size_t> findNearest(const std::vector<StampedPose>& poses, double t, double tolerance = 0.02);

/// The poses' timestamps indexed for many lookups: nearest(t, tolerance) is findNearest's answer.
TimeIndex timeIndex(const std::vector<StampedPose>& poses);

/// The pose of a detection frame: the trajectory's pose nearest to the timestamp of the frame's
/// file name, within `tolerance` seconds; nullptr when there is none (or no timestamp).
const Pose* framePose(const std::vector<StampedPose>& poses, const DetectionFrame& frame, double tolerance = 0.02);
/// The same with the poses' timeIndex, for many frames.
const Pose* framePose(const std::vector<StampedPose>& poses, const TimeIndex& by_time, const DetectionFrame& frame,
                      double tolerance = 0.02);

}  // namespace ellreloc::io
