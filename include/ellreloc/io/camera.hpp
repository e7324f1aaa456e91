#pragma once
/// \file camera.hpp
/// Camera files: ORB-SLAM style YAML (OpenCV FileStorage keys Camera.fx, Camera.fy, Camera.cx,
/// Camera.cy, Camera.width, Camera.height) or JSON {"fx","fy","cx","cy","width","height"}.

#include "ellreloc/core/camera.hpp"

#include <string>

namespace ellreloc::io {

/// Reads a camera file; the format is chosen by extension (.json, else YAML). Distortion keys
/// may be present and are ignored (v1 assumes undistorted detections).
/// Throws ellreloc::Error naming the file and the key on malformed input.
Intrinsics readCamera(const std::string& path);

/// Writes JSON for a .json path, ORB-SLAM YAML otherwise.
void writeCamera(const std::string& path, const Intrinsics& K);

}  // namespace ellreloc::io
