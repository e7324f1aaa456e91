#pragma once
/// \file overlay.hpp
/// A picture of one relocalization: what the frame saw and where the map's objects land. On
/// the frame's image (or a blank canvas of the camera's size) it draws
///   - the observations: ellipse and box in green, "R" beside regular masks' boxes;
///   - the map ellipsoids projected with the returned pose in orange, each with its object id;
///   - the matches: a magenta segment from each observation's centre to its object's image;
///   - the map projected with the true pose, when given, in thin blue;
///   - text lines (status, inliers, score, time) at the top left.

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "ellreloc/core/camera.hpp"
#include "ellreloc/core/distortion.hpp"
#include "ellreloc/core/object_map.hpp"
#include "ellreloc/core/observation.hpp"
#include "ellreloc/core/pose.hpp"

namespace ellreloc::io {

struct OverlayContent {
  std::vector<Observation> observations;
  std::optional<Pose> pose;                  ///< the returned world->camera pose
  std::optional<Pose> truth;                 ///< the true world->camera pose
  std::vector<std::pair<int, int>> matches;  ///< (observation index, map object index) at `pose`
  std::vector<std::string> text;             ///< lines written at the top left
};

/// Draws `content` over the image at `background` (any format OpenCV reads; an image of
/// another size than the camera's is scaled to it) or, when `background` is empty, over a
/// blank canvas, and writes a PNG atomically. With a `lens`, the background is a raw image of
/// that distorted lens and is undistorted first, as the observations were (ObserveOptions::lens).
/// Throws ellreloc::Error naming the file when the background cannot be read or the PNG written.
void writeOverlay(const std::string& path, const Intrinsics& K, const ObjectMap& map, const OverlayContent& content,
                  const std::string& background = "", const Lens* lens = nullptr);

}  // namespace ellreloc::io
