#pragma once
/// \file camera_envelope.hpp
/// Where a camera can plausibly be: the heights and tilts at which the map's keyframes were
/// taken, widened by margins. A hand-held or robot camera that mapped a room from 1.2-1.7 m,
/// looking 20-45 degrees down, does not come back upside down or under the floor, yet two boxes
/// matched to two look-alike objects can be explained by such a pose as well as by the true
/// one. Poses outside the envelope are never hypotheses (RelocalizerOptions::envelope).

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "ellreloc/core/pose.hpp"

namespace ellreloc {

struct CameraEnvelope {
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();  ///< world frame, unit length
  double min_height = -1e9, max_height = 1e9;     ///< camera centre along `up`, metres
  /// Angle between the camera's image-up direction (-y) and `up`: 0 for a level camera, 90 for
  /// one looking straight down or up.
  double min_tilt_deg = 0.0, max_tilt_deg = 180.0;
  /// Angle between the camera's image rows (+x) and the plane normal to `up`: 0 for a level
  /// horizon, 90 (no bound) for a camera on its side. Not stored in map files.
  double max_roll_deg = 90.0;

  bool isValid() const {
    return up.allFinite() && std::abs(up.norm() - 1.0) < 1e-6 && std::isfinite(min_height) &&
           std::isfinite(max_height) && min_height <= max_height && std::isfinite(min_tilt_deg) &&
           std::isfinite(max_tilt_deg) && min_tilt_deg <= max_tilt_deg && max_roll_deg > 0.0 && max_roll_deg <= 90.0;
  }

  static double heightOf(const Pose& pose, const Eigen::Vector3d& up) { return up.dot(pose.center()); }
  static double tiltDegOf(const Pose& pose, const Eigen::Vector3d& up) {
    const Eigen::Vector3d image_up = -pose.rotation().transpose().col(1);  // camera -y in the world
    return std::acos(std::clamp(image_up.dot(up), -1.0, 1.0)) * 180.0 / M_PI;
  }
  static double rollDegOf(const Pose& pose, const Eigen::Vector3d& up) {
    const Eigen::Vector3d image_right = pose.rotation().row(0).transpose();  // camera +x in the world
    return std::abs(std::asin(std::clamp(image_right.dot(up), -1.0, 1.0))) * 180.0 / M_PI;
  }

  /// The bounds as a pose is tested against them: the tilts as cosines and the roll as a sine,
  /// computed once for the many poses of a search instead of an arc cosine per pose.
  struct Prepared {
    Eigen::Vector3d up;
    double min_height, max_height;
    double min_up_cos, max_up_cos;  // image-up . up: cos(max_tilt) .. cos(min_tilt)
    double max_right_sin;           // |image-right . up| <= sin(max_roll); above 1 without a bound
    bool admits(const Pose& pose) const {
      const double h = heightOf(pose, up);
      return h >= min_height && h <= max_height && admitsRotation(pose.rotation());
    }
    /// The tilt and roll bounds alone, for a world->camera rotation whose translation is not
    /// known yet.
    bool admitsRotation(const Eigen::Matrix3d& R_cw) const {
      const double c = -R_cw.row(1).dot(up);
      return c >= min_up_cos && c <= max_up_cos && std::abs(R_cw.row(0).dot(up)) <= max_right_sin;
    }
  };
  Prepared prepared() const {
    const double deg = M_PI / 180.0;
    return {up,
            min_height,
            max_height,
            max_tilt_deg >= 180.0 ? -2.0 : std::cos(max_tilt_deg * deg),
            min_tilt_deg <= 0.0 ? 2.0 : std::cos(min_tilt_deg * deg),
            max_roll_deg >= 90.0 ? 2.0 : std::sin(max_roll_deg * deg)};
  }

  /// The world->camera pose lies within the envelope.
  bool admits(const Pose& pose) const { return prepared().admits(pose); }

  /// A camera at any height whose image-up stays within `max_tilt_deg` of the world's `up`, and
  /// whose image rows stay within `max_roll_deg` of level: for a host that knows which way is up
  /// in its map but has no mapping poses (90 and 90: the camera is never upside down). A roll
  /// bound needs `up` close to the vertical: about a tilted one a level camera looking another
  /// way rolls. nullopt for a zero or non-finite `up`, a tilt outside (0, 180] or a roll outside
  /// (0, 90].
  static std::optional<CameraEnvelope> upright(const Eigen::Vector3d& up, double max_tilt_deg = 90.0,
                                               double max_roll_deg = 90.0) {
    if (!up.allFinite() || !(up.norm() > 1e-9) || !(max_tilt_deg > 0.0 && max_tilt_deg <= 180.0) ||
        !(max_roll_deg > 0.0 && max_roll_deg <= 90.0))
      return std::nullopt;
    CameraEnvelope e;
    e.up = up.normalized();
    e.max_tilt_deg = max_tilt_deg;
    e.max_roll_deg = max_roll_deg;
    return e;
  }

  /// The envelope of mapping keyframes (world->camera poses): their range of heights widened by
  /// `height_margin` metres and of tilts by `tilt_margin_deg`. `up`: the world's up when known;
  /// nullopt takes the mean image-up direction of the keyframes (hand-held and robot cameras
  /// keep their roll small), so heights and tilts are measured consistently, if not from true
  /// vertical. nullopt for fewer than 2 valid poses.
  static std::optional<CameraEnvelope> fromKeyframes(const std::vector<Pose>& keyframes,
                                                     std::optional<Eigen::Vector3d> up = std::nullopt,
                                                     double height_margin = 0.5, double tilt_margin_deg = 20.0) {
    std::vector<Pose> valid;
    for (const Pose& p : keyframes)
      if (p.isValid()) valid.push_back(p);
    if (valid.size() < 2) return std::nullopt;
    if (!up) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (const Pose& p : valid) sum -= p.rotation().transpose().col(1);
      if (!(sum.norm() > 1e-9)) return std::nullopt;
      up = sum;
    }
    if (!up->allFinite() || !(up->norm() > 1e-9)) return std::nullopt;
    CameraEnvelope e;
    e.up = up->normalized();
    e.min_height = e.min_tilt_deg = 1e300;
    e.max_height = e.max_tilt_deg = -1e300;
    for (const Pose& p : valid) {
      const double h = heightOf(p, e.up), t = tiltDegOf(p, e.up);
      e.min_height = std::min(e.min_height, h), e.max_height = std::max(e.max_height, h);
      e.min_tilt_deg = std::min(e.min_tilt_deg, t), e.max_tilt_deg = std::max(e.max_tilt_deg, t);
    }
    e.min_height -= height_margin, e.max_height += height_margin;
    e.min_tilt_deg = std::max(0.0, e.min_tilt_deg - tilt_margin_deg);
    e.max_tilt_deg = std::min(180.0, e.max_tilt_deg + tilt_margin_deg);
    return e;
  }
};

}  // namespace ellreloc
