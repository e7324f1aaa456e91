#pragma once
/// \file detections.hpp
/// Detection files (docs/formats.md): a JSON array of frames, each with a file name and its
/// detections (`bbox` required; optional `mask` as COCO RLE, `polygon`, `ellipse`,
/// `object_id`), and optional per-frame `keypoints` matched to the map's points.

#include <string>
#include <vector>

#include "ellreloc/core/detection.hpp"

namespace ellreloc {

namespace io {

/// Reads a detections file. Masks are checked for consistency (runs sum to height x width).
/// Throws ellreloc::Error naming the file and the field (e.g. [3].detections[1].bbox).
std::vector<DetectionFrame> readDetections(const std::string& path);
std::vector<DetectionFrame> parseDetectionsJson(const std::string& text, const std::string& source);

/// Writes a detections file atomically (masks as compressed COCO strings).
void writeDetections(const std::string& path, const std::vector<DetectionFrame>& frames);

}  // namespace io
}  // namespace ellreloc
