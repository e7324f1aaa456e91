#pragma once
/// \file map_quality.hpp
/// How well a map explains boxes it was not built from: for each detection box of a frame
/// with a known pose, the best IoU between the box and the bounding box of the projection of
/// a map object of the box's category (0 when no such object projects into the frame). The
/// median over all boxes is the map quality `ellreloc map --holdout-every` prints: a map with
/// a missing, misplaced or degenerate object lowers it.

#include <algorithm>
#include <vector>

#include "ellreloc/core/camera.hpp"
#include "ellreloc/core/detection.hpp"
#include "ellreloc/core/object_map.hpp"
#include "ellreloc/core/pose.hpp"
#include "ellreloc/core/projection.hpp"
#include "ellreloc/core/statistics.hpp"

namespace ellreloc {

/// A frame's detections with its true world->camera pose.
struct PosedDetections {
  Pose pose;
  std::vector<Detection> detections;
};

struct MapQuality {
  size_t frames = 0;
  size_t boxes = 0;      ///< boxes measured
  size_t explained = 0;  ///< boxes that overlap the projection of an object of their category
  double median_best_iou = 0.0;
  double mean_best_iou = 0.0;
};

/// The best same-category IoU of each box (in frame order), as measureMapQuality uses them.
inline std::vector<double> bestCategoryIoUs(const ObjectMap& map, const Intrinsics& K, const PosedDetections& frame,
                                            double min_score = 0.0) {
  std::vector<double> best;
  std::vector<Box> projected(map.objects.size());
  std::vector<bool> visible(map.objects.size(), false);
  for (size_t i = 0; i < map.objects.size(); ++i) {
    const Projection p = project(map.objects[i].ellipsoid, K, frame.pose);
    if (!p) continue;
    projected[i] = p.ellipse.boundingBox().intersection(Box(-0.5, -0.5, K.width - 0.5, K.height - 0.5));
    visible[i] = projected[i].area() > 0.0;
  }
  for (const Detection& d : frame.detections) {
    if (!(d.score >= min_score) || !d.bbox.isValid()) continue;
    double iou = 0.0;
    for (size_t i = 0; i < map.objects.size(); ++i)
      if (visible[i] && map.objects[i].category == d.category_id) iou = std::max(iou, boxIoU(projected[i], d.bbox));
    best.push_back(iou);
  }
  return best;
}

/// The quality of `map` on frames with known poses (detections below min_score are skipped).
inline MapQuality measureMapQuality(const ObjectMap& map, const Intrinsics& K,
                                    const std::vector<PosedDetections>& frames, double min_score = 0.0) {
  MapQuality q;
  std::vector<double> all;
  for (const PosedDetections& f : frames) {
    const std::vector<double> best = bestCategoryIoUs(map, K, f, min_score);
    all.insert(all.end(), best.begin(), best.end());
    ++q.frames;
  }
  q.boxes = all.size();
  if (all.empty()) return q;
  double sum = 0.0;
  for (double v : all) sum += v, q.explained += v > 0.0 ? 1 : 0;
  q.mean_best_iou = sum / static_cast<double>(all.size());
  q.median_best_iou = median(all);
  return q;
}

}  // namespace ellreloc
