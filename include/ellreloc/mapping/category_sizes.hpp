#pragma once
/// \file category_sizes.hpp
/// Typical sizes of the COCO-80 categories (0-based ids, as the shipped detections use), the
/// size prior of box-only mapping: boxes seen from one side leave an object's depth along the
/// viewing direction unobserved, and that axis then falls back to the category's typical size
/// instead of collapsing to zero or running off to metres.
///
/// Sizes are the full extents, in metres, of a common instance (e.g. a 24" monitor, a mug, a
/// hardback book, an office chair), sorted smallest first, so they say nothing about the
/// object's orientation.

#include <Eigen/Core>
#include <algorithm>
#include <array>

namespace ellreloc {

/// The typical semi-axes of category `coco_id`, smallest first; a generic 30 cm object for an
/// id outside COCO-80.
inline Eigen::Vector3d typicalSemiAxes(int coco_id) {
  // clang-format off
  static constexpr std::array<std::array<double, 3>, 80> kExtents = {{
      {0.30, 0.50, 1.70}, {0.50, 1.00, 1.70}, {1.50, 1.80, 4.50}, {0.80, 1.10, 2.00},  // person bicycle car motorcycle
      {10.0, 30.0, 30.0}, {2.50, 3.00, 12.0}, {3.00, 4.00, 20.0}, {2.50, 3.00, 8.00},  // airplane bus train truck
      {1.50, 2.00, 5.00}, {0.40, 0.40, 1.00}, {0.40, 0.40, 0.80}, {0.05, 0.75, 0.75},  // boat traffic-light hydrant stop-sign
      {0.20, 0.30, 1.50}, {0.60, 0.80, 1.50}, {0.10, 0.20, 0.20}, {0.20, 0.30, 0.45},  // parking-meter bench bird cat
      {0.30, 0.60, 0.80}, {0.60, 1.60, 2.20}, {0.40, 0.90, 1.20}, {0.70, 1.40, 2.20},  // dog horse sheep cow
      {2.00, 3.00, 5.00}, {1.00, 1.20, 2.00}, {0.60, 1.40, 2.20}, {1.00, 3.00, 5.00},  // elephant bear zebra giraffe
      {0.20, 0.30, 0.45}, {0.90, 1.00, 1.00}, {0.15, 0.30, 0.35}, {0.02, 0.08, 0.50},  // backpack umbrella handbag tie
      {0.25, 0.45, 0.65}, {0.03, 0.25, 0.25}, {0.10, 0.10, 1.70}, {0.05, 0.30, 1.50},  // suitcase frisbee skis snowboard
      {0.22, 0.22, 0.22}, {0.10, 1.00, 1.00}, {0.07, 0.07, 0.85}, {0.12, 0.25, 0.30},  // ball kite bat glove
      {0.12, 0.20, 0.80}, {0.08, 0.55, 2.00}, {0.03, 0.30, 0.68}, {0.08, 0.08, 0.25},  // skateboard surfboard racket bottle
      {0.08, 0.08, 0.20}, {0.09, 0.09, 0.11}, {0.01, 0.03, 0.19}, {0.01, 0.03, 0.22},  // wine-glass cup fork knife
      {0.01, 0.04, 0.17}, {0.07, 0.16, 0.16}, {0.04, 0.04, 0.20}, {0.08, 0.08, 0.08},  // spoon bowl banana apple
      {0.06, 0.10, 0.12}, {0.08, 0.08, 0.08}, {0.15, 0.15, 0.15}, {0.03, 0.03, 0.18},  // sandwich orange broccoli carrot
      {0.05, 0.05, 0.18}, {0.03, 0.30, 0.30}, {0.04, 0.10, 0.10}, {0.10, 0.22, 0.22},  // hot-dog pizza donut cake
      {0.50, 0.50, 0.90}, {0.85, 0.90, 2.00}, {0.35, 0.35, 0.60}, {0.60, 1.60, 2.00},  // chair couch potted-plant bed
      {0.75, 0.80, 1.40}, {0.40, 0.70, 0.75}, {0.20, 0.45, 0.60}, {0.25, 0.25, 0.35},  // table toilet tv laptop
      {0.04, 0.07, 0.11}, {0.025, 0.05, 0.18}, {0.03, 0.15, 0.45}, {0.01, 0.075, 0.15},  // mouse remote keyboard phone
      {0.30, 0.40, 0.50}, {0.60, 0.60, 0.85}, {0.18, 0.20, 0.30}, {0.20, 0.45, 0.60},  // microwave oven toaster sink
      {0.70, 0.70, 1.80}, {0.04, 0.17, 0.24}, {0.05, 0.30, 0.30}, {0.15, 0.15, 0.30},  // refrigerator book clock vase
      {0.01, 0.08, 0.20}, {0.20, 0.30, 0.40}, {0.10, 0.25, 0.25}, {0.02, 0.02, 0.19},  // scissors teddy-bear hair-drier toothbrush
  }};
  // clang-format on
  if (coco_id < 0 || coco_id >= static_cast<int>(kExtents.size())) return Eigen::Vector3d::Constant(0.15);
  const auto& e = kExtents[static_cast<size_t>(coco_id)];
  return 0.5 * Eigen::Vector3d(e[0], e[1], e[2]);
}

}  // namespace ellreloc
