#pragma once
/// \file evaluation.hpp
/// The relocalization metrics of docs/formats.md and the paper's Table I, shared by the command
/// line, the benchmarks and the tests: the position and rotation error of a pose, the validity
/// rule (within 30 cm and 30 degrees), and a table row over every query frame.

#include <optional>
#include <vector>

#include "ellreloc/core/pose.hpp"
#include "ellreloc/core/statistics.hpp"

namespace ellreloc {

/// A relocalized pose is valid within these bounds of the truth (docs/formats.md).
constexpr double kValidPositionCm = 30.0;
constexpr double kValidRotationDeg = 30.0;

struct PoseError {
  double position_cm = 0.0;   ///< distance between the camera centres
  double rotation_deg = 0.0;  ///< angle of R_estimate^T R_truth
  bool valid() const { return position_cm < kValidPositionCm && rotation_deg < kValidRotationDeg; }
};

/// `unit_metres`: metres per unit of the poses' translations (1 for metric poses).
inline PoseError poseError(const Pose& estimate, const Pose& truth, double unit_metres = 1.0) {
  return {100.0 * unit_metres * (estimate.center() - truth.center()).norm(),
          rotationErrorDeg(estimate.rotation(), truth.rotation())};
}

/// A row of Table I: every query frame counts; the medians are over the valid frames.
struct RelocalizationSummary {
  int frames = 0;       ///< query frames
  int relocalized = 0;  ///< frames with a pose
  int valid = 0;        ///< frames with a valid pose
  double median_position_cm = 0.0;
  double median_rotation_deg = 0.0;
  double validPercent() const { return frames > 0 ? 100.0 * valid / frames : 0.0; }
};

/// One entry per query frame: its pose error, or nullopt when it got no pose.
inline RelocalizationSummary summarize(const std::vector<std::optional<PoseError>>& errors) {
  RelocalizationSummary s;
  s.frames = static_cast<int>(errors.size());
  std::vector<double> position, rotation;
  for (const std::optional<PoseError>& e : errors) {
    if (!e) continue;
    ++s.relocalized;
    if (!e->valid()) continue;
    ++s.valid;
    position.push_back(e->position_cm);
    rotation.push_back(e->rotation_deg);
  }
  s.median_position_cm = median(position);
  s.median_rotation_deg = median(rotation);
  return s;
}

}  // namespace ellreloc
