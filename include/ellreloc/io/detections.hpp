#pragma once
/// \file detections.hpp
/// Detection files (FORMATS.md): a JSON array of frames, each with a file name and its
/// detections (`bbox` required; optional `mask` as COCO RLE, `polygon`, `ellipse`,
/// `object_id`), and optional per-frame `keypoints` matched to the map's points.

#include "ellreloc/core/box.hpp"
#include "ellreloc/core/ellipse.hpp"
#include "ellreloc/observe/rle.hpp"

#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

namespace ellreloc {

struct Detection {
  int category_id = 0;
  double score = 1.0;
  Box bbox;
  std::optional<RleMask> mask;
  std::vector<Eigen::Vector2d> polygon;  ///< empty when not given
  std::optional<Ellipse> ellipse;        ///< an observation ellipse someone already computed
  std::optional<bool> regular;           ///< the regular-mask verdict, when written by `observe`
  std::optional<int> object_id;          ///< ground-truth association, when the file has one
};

/// A 2D feature of the frame matched to the map's points list.
struct Keypoint {
  int point_index = 0;
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();
};

struct DetectionFrame {
  std::string file_name;
  std::vector<Detection> detections;
  std::vector<Keypoint> keypoints;

  /// The base name without extension ("rgb/1311868164.363181.png" -> "1311868164.363181").
  std::string timestampText() const;
  /// timestampText() as a number; nullopt when it is not one.
  std::optional<double> timestamp() const;
};

namespace io {

/// Reads a detections file. Masks are checked for consistency (runs sum to height x width).
/// Throws ellreloc::Error naming the file and the field (e.g. [3].detections[1].bbox).
std::vector<DetectionFrame> readDetections(const std::string& path);
std::vector<DetectionFrame> parseDetectionsJson(const std::string& text, const std::string& source);

/// Writes a detections file atomically (masks as compressed COCO strings).
void writeDetections(const std::string& path, const std::vector<DetectionFrame>& frames);

}  // namespace io
}  // namespace ellreloc
