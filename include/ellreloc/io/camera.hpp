#pragma once
/// \file camera.hpp
/// Camera files: ORB-SLAM style YAML (OpenCV FileStorage keys Camera.fx, Camera.fy, Camera.cx,
/// Camera.cy, Camera.width, Camera.height, and the distortion's Camera.k1 ...) or JSON
/// {"fx","fy","cx","cy","width","height"} (and "k1" ...).

#include <string>

#include "ellreloc/core/camera.hpp"
#include "ellreloc/core/distortion.hpp"

namespace ellreloc::io {

/// Reads a camera file; the format is chosen by extension (.json, else YAML). Distortion keys
/// may be present and are ignored here (v1 assumes undistorted detections; readLens reads them).
/// Throws ellreloc::Error naming the file and the key on malformed input.
Intrinsics readCamera(const std::string& path);

/// The lens distortion of a camera file: Camera.k1, Camera.k2, Camera.p1, Camera.p2, Camera.k3
/// (YAML) or "k1", "k2", "p1", "p2", "k3" (JSON), each 0 when left out. Throws ellreloc::Error
/// naming the file and the key when one is not a finite number.
Distortion readDistortion(const std::string& path);

/// readCamera and readDistortion together, for detections made on the raw images
/// (ObserveOptions::lens). Throws ellreloc::Error naming the file when the distortion cannot be
/// undone over the image (Distortion::whyNotInvertible).
Lens readLens(const std::string& path);

/// Writes JSON for a .json path, ORB-SLAM YAML otherwise.
void writeCamera(const std::string& path, const Intrinsics& K);

}  // namespace ellreloc::io
