#pragma once
/// \file detection.hpp
/// What a detector reports for one image: boxes with category and score, optional instance
/// masks (COCO RLE), polygons or ready-made ellipses, and keypoints matched to the map's points.

#include <Eigen/Core>
#include <charconv>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "ellreloc/core/box.hpp"
#include "ellreloc/core/ellipse.hpp"
#include "ellreloc/core/rle.hpp"

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

/// A timestamp written as text (a TUM file's first field, an image's base name): a plain
/// decimal number, finite, and nothing else; nullopt otherwise.
inline std::optional<double> timestampFromText(const std::string& text) {
  double t = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), t);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size() || !std::isfinite(t)) return std::nullopt;
  return t;
}

struct DetectionFrame {
  std::string file_name;
  std::vector<Detection> detections;
  std::vector<Keypoint> keypoints;

  /// The base name without extension ("rgb/1311868164.363181.png" -> "1311868164.363181").
  std::string timestampText() const {
    const size_t slash = file_name.find_last_of("/\\");
    std::string base = slash == std::string::npos ? file_name : file_name.substr(slash + 1);
    const size_t dot = base.find_last_of('.');
    // "1311868164.363181.png": only the last dot starts the extension.
    if (dot != std::string::npos && dot > 0) base = base.substr(0, dot);
    return base;
  }
  /// timestampText() as a number (timestampFromText); nullopt when it is not one.
  std::optional<double> timestamp() const { return timestampFromText(timestampText()); }
};

}  // namespace ellreloc
