#pragma once
/// \file depth_image.hpp
/// A depth image in metres, as the mapper consumes it (io::readDepthPng reads TUM's PNGs).

#include <cstddef>
#include <vector>

namespace ellreloc {

/// A depth image in metres, row-major; 0 where there is no reading.
struct DepthImage {
  int width = 0;
  int height = 0;
  std::vector<float> metres;
  float at(int x, int y) const { return metres[static_cast<size_t>(y) * width + x]; }
};

}  // namespace ellreloc
