#include "ellreloc/sim/truth.hpp"

#include <algorithm>
#include <opencv2/imgproc.hpp>

#include "ellreloc/core/mask.hpp"
#include "ellreloc/core/projection.hpp"

namespace ellreloc::sim {

bool outlineIsConvexQuadrilateral(const RleMask& clean_mask) {
  const std::optional<BinaryMask> m = decodeMaskCrop(clean_mask);
  if (!m) return false;
  // One pixel of margin so that the outline of a crop is closed inside the image.
  cv::Mat img = cv::Mat::zeros(m->height + 2, m->width + 2, CV_8UC1);
  for (int y = 0; y < m->height; ++y)
    for (int x = 0; x < m->width; ++x) img.at<uint8_t>(y + 1, x + 1) = m->at(x, y) ? 255 : 0;
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(img, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
  if (contours.empty()) return false;
  const auto largest = std::max_element(contours.begin(), contours.end(), [](const auto& a, const auto& b) {
    return cv::contourArea(a) < cv::contourArea(b);
  });
  std::vector<cv::Point> polygon;
  cv::approxPolyDP(*largest, polygon, 0.02 * cv::arcLength(*largest, true), true);
  return polygon.size() == 4 && cv::isContourConvex(polygon);
}

std::vector<Detection> detectionTruth(const Scene& scene, const RenderedFrame& frame, const Intrinsics& K,
                                      const Pose& pose, const std::vector<Detection>& detections) {
  std::vector<Detection> truth;
  for (const Detection& d : detections) {
    if (!d.object_id) continue;
    const auto object = std::find_if(scene.objects.begin(), scene.objects.end(),
                                     [&d](const SimObject& o) { return o.id == *d.object_id; });
    if (object == scene.objects.end()) continue;
    const size_t index = static_cast<size_t>(object - scene.objects.begin());
    Detection t;
    t.bbox = d.bbox;
    t.score = d.score;
    t.category_id = object->category;
    t.object_id = object->id;
    if (const Projection p = project(object->ellipsoid(), K, pose)) t.ellipse = p.ellipse;
    t.regular = index < frame.masks.size() && outlineIsConvexQuadrilateral(frame.masks[index]);
    truth.push_back(std::move(t));
  }
  return truth;
}

}  // namespace ellreloc::sim
