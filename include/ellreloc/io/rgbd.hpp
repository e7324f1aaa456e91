#pragma once
/// \file rgbd.hpp
/// TUM RGB-D sequences: association files (`t_rgb rgb/X.png t_depth depth/Y.png`) and 16-bit
/// depth PNGs with 5000 units per metre (0 = no reading).

#include <cstdint>
#include <optional>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "ellreloc/core/depth_image.hpp"
#include "ellreloc/io/time_index.hpp"

namespace ellreloc::io {

struct Association {
  double rgb_time = 0.0;
  std::string rgb_path;  ///< resolved against the association file's folder
  double depth_time = 0.0;
  std::string depth_path;  ///< resolved against the association file's folder
};

/// Reads an association file; relative paths are made relative to the file's own folder.
/// `#` starts a comment. Throws ellreloc::Error naming the file and line on malformed input.
std::vector<Association> readAssociations(const std::string& path);

/// Each colour image's association in a sequence: the line naming the same image (paths
/// compared made absolute and normalised; of several, the last), else the line whose colour
/// image is nearest in time within `tolerance` seconds (of equally near, the last). Indexed
/// once, so that each of thousands of frames is found without reading every line.
class AssociationIndex {
 public:
  /// Throws ellreloc::Error for a tolerance that is negative or not finite.
  explicit AssociationIndex(std::vector<Association> associations, double tolerance = 0.02);
  /// nullptr when no line names the image and none is within the tolerance of `rgb_time`.
  const Association* find(const std::string& rgb_path, std::optional<double> rgb_time) const;

 private:
  std::vector<Association> associations_;
  double tolerance_;
  std::unordered_map<std::string, size_t> by_image_;
  TimeIndex by_time_;
};

/// TUM's scale: 5000 depth units per metre.
constexpr double kTumDepthUnitsPerMetre = 5000.0;

/// Reads a 16-bit single-channel depth PNG (units_per_metre units = 1 m). Throws
/// ellreloc::Error when the file is missing, not a PNG, or not 16-bit single-channel.
/// Depth images declaring more pixels than this in their header are refused before decoding
/// (a few hundred bytes of PNG can declare gigabytes); 64 Mpx is 8x a 4K depth map.
constexpr uint64_t kMaxDepthPixels = uint64_t{1} << 26;

DepthImage readDepthPng(const std::string& path, double units_per_metre = kTumDepthUnitsPerMetre);

/// Writes a 16-bit depth PNG (rounded; depths beyond 65535 units or invalid become 0), atomically.
void writeDepthPng(const std::string& path, const DepthImage& depth, double units_per_metre = kTumDepthUnitsPerMetre);

}  // namespace ellreloc::io
