// The mapper in both modes, fed keyframes built from the fuzzer's numbers: poses, boxes, masks
// (now and then of the wrong size) and depth images with any values (NaN, zero, negative):
// only ellreloc::Error escapes, and every object of the map holds a finite ellipsoid.
#include <cmath>

#include "ellreloc/core/mask.hpp"
#include "ellreloc/error.hpp"
#include "ellreloc/mapping/mapper.hpp"
#include "fuzz_input.hpp"

namespace {

using namespace ellreloc;

/// A rectangle of the image (corners from the fuzzer, clamped to it).
struct Rect {
  int x1, y1, x2, y2;
};
Rect rectOf(fuzz::Input& in, int width, int height) {
  const int x1 = in.small(width), y1 = in.small(height);
  return {x1, y1, std::min(width - 1, x1 + in.small(width)), std::min(height - 1, y1 + in.small(height))};
}

DepthImage depthOf(fuzz::Input& in, const Intrinsics& K, bool raw) {
  DepthImage d{K.width, K.height, {}};
  const auto value = [&] { return static_cast<float>(raw ? in.real() : in.scaled(0.2, 6.0)); };
  d.metres.assign(static_cast<size_t>(K.width * K.height), value());
  for (int patch = in.small(4); patch > 0; --patch) {  // objects in front of the background
    const Rect r = rectOf(in, K.width, K.height);
    const float z = value();
    for (int y = r.y1; y <= r.y2; ++y)
      for (int x = r.x1; x <= r.x2; ++x) d.metres[static_cast<size_t>(y * K.width + x)] = z;
  }
  return d;
}

Detection detectionOf(fuzz::Input& in, const Intrinsics& K, bool raw) {
  const auto num = [&](double lo, double hi) { return raw ? in.real() : in.scaled(lo, hi); };
  Detection d;
  d.category_id = in.small(3);
  d.score = num(0.0, 1.0);
  const Rect r = rectOf(in, K.width, K.height);
  d.bbox = Box(num(r.x1, r.x1 + 1), num(r.y1, r.y1 + 1), num(r.x2, r.x2 + 1), num(r.y2, r.y2 + 1));
  switch (in.small(4)) {
    case 0:  // a box only
      break;
    case 1: {  // a mask of another size than the camera's
      d.mask = encodeMask(BinaryMask(K.height - 1, K.width));
      break;
    }
    default: {
      BinaryMask mask(K.height, K.width);
      for (int y = r.y1; y <= r.y2; ++y)
        for (int x = r.x1; x <= r.x2; ++x) mask.at(x, y) = 1;
      d.mask = encodeMask(mask);
    }
  }
  return d;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fuzz::Input in(data, size);
  const bool raw = in.small(4) == 0;
  const auto num = [&](double lo, double hi) { return raw ? in.real() : in.scaled(lo, hi); };
  const Intrinsics K(40, 40, 31.5, 23.5, 64, 48);  // small images: many keyframes per second
  MapperOptions options;
  options.mode = in.small(2) == 0 ? MappingMode::Voxel : MappingMode::Boxes;
  options.min_observations = 1 + in.small(3);
  // Raw images through a lens (any coefficients: one that folds over is refused).
  if (in.small(3) == 0)
    options.lens = Lens{K, {num(-0.5, 0.5), num(-0.5, 0.5), num(-0.01, 0.01), num(-0.01, 0.01), num(-0.5, 0.5)}};
  if (options.lens && !options.lens->whyNotUsable().empty()) return 0;
  Mapper mapper(K, options);
  for (int k = 1 + in.small(6); k > 0; --k) {
    const Eigen::Vector3d axis(num(-1, 1), num(-1, 1), num(-1, 1));
    const Pose pose(Eigen::AngleAxisd(num(-0.5, 0.5), axis.normalized()).toRotationMatrix(),
                    {num(-0.3, 0.3), num(-0.3, 0.3), num(-0.3, 0.3)});
    std::vector<Detection> detections;
    for (int n = in.small(5); n > 0; --n) detections.push_back(detectionOf(in, K, raw));
    const DepthImage depth = depthOf(in, K, raw);
    try {
      mapper.addKeyframe(pose, detections, in.small(8) == 0 ? nullptr : &depth);
    } catch (const Error&) {  // a keyframe the mapper refuses, naming why: the map is unchanged
    }
  }
  mapper.finish();
  for (const MapObject& o : mapper.map().objects) {
    FUZZ_CHECK(o.ellipsoid.center().allFinite());
    FUZZ_CHECK(o.ellipsoid.axes().allFinite() && (o.ellipsoid.axes().array() > 0.0).all());
  }
  return 0;
}
