#pragma once
/// \file render.hpp
/// Ray-cast rendering of a synthetic scene for any camera: a z-buffered instance image (with
/// occlusion between objects and by furniture, clipped at the image border), the depth image
/// including floor and furniture, each object's instance mask as COCO run lengths and its box.

#include <cstdint>
#include <vector>

#include "ellreloc/core/box.hpp"
#include "ellreloc/core/camera.hpp"
#include "ellreloc/core/rle.hpp"
#include "ellreloc/sim/scene.hpp"

namespace ellreloc::sim {

/// Instance value of pixels that show no object (floor, furniture, nothing).
constexpr int16_t kNoObject = -1;

struct RenderedFrame {
  int width = 0;
  int height = 0;
  std::vector<float> depth;          ///< row-major, metres along the optical axis; 0 = no surface
  std::vector<int16_t> instance;     ///< row-major, index into scene.objects or kNoObject
  std::vector<RleMask> masks;        ///< per object (index into scene.objects); empty counts if unseen
  std::vector<Box> boxes;            ///< per object: its visible pixels' box (FORMATS convention)
  std::vector<long> visible_pixels;  ///< per object

  float depthAt(int x, int y) const { return depth[static_cast<size_t>(y) * width + x]; }
  int instanceAt(int x, int y) const { return instance[static_cast<size_t>(y) * width + x]; }
};

/// Renders the scene seen by a world->camera pose.
RenderedFrame render(const Scene& scene, const Intrinsics& K, const Pose& pose);

/// Depth of the nearest intersection of the camera ray through pixel (u, v) with a primitive,
/// or +infinity. Exposed for tests (an independent ray cast at sampled pixels).
double rayDepth(const Primitive& p, const Eigen::Vector3d& origin, const Eigen::Vector3d& direction);

}  // namespace ellreloc::sim
