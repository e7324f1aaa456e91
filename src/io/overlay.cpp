#include "ellreloc/io/overlay.hpp"

#include <cstdio>
#include <memory>
#include <mutex>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "ellreloc/core/projection.hpp"
#include "ellreloc/error.hpp"
#include "ellreloc/io/files.hpp"
#include "ellreloc/io/image_codec.hpp"

namespace ellreloc::io {

namespace {

// BGR.
const cv::Scalar kObservation(60, 180, 60), kEstimate(0, 140, 255), kTruth(230, 120, 30), kMatch(200, 0, 200);

cv::Point pixel(const Eigen::Vector2d& p) {
  return {static_cast<int>(std::lround(p.x() * 4)), static_cast<int>(std::lround(p.y() * 4))};  // 2 fractional bits
}

void drawEllipse(cv::Mat& img, const Ellipse& e, const cv::Scalar& colour, int thickness) {
  // OpenCV draws with sub-pixel accuracy given `shift` fractional bits; huge ellipses are clipped.
  const double limit = 4.0 * (img.cols + img.rows);
  if (!e.isValid() || e.axes().maxCoeff() > limit || e.center().cwiseAbs().maxCoeff() > limit) return;
  cv::ellipse(img, pixel(e.center()), cv::Size(static_cast<int>(e.axes()(0) * 4), static_cast<int>(e.axes()(1) * 4)),
              e.angle() * 180.0 / M_PI, 0, 360, colour, thickness, cv::LINE_AA, 2);
}

void label(cv::Mat& img, const std::string& text, cv::Point at, const cv::Scalar& colour, double scale = 0.45) {
  cv::putText(img, text, at, cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(255, 255, 255), 3, cv::LINE_AA);
  cv::putText(img, text, at, cv::FONT_HERSHEY_SIMPLEX, scale, colour, 1, cv::LINE_AA);
}

/// Each map object's image at `pose` (nullopt when it has none or lies far outside the image).
std::vector<std::optional<Ellipse>> projectMap(const ObjectMap& map, const Intrinsics& K, const Pose& pose) {
  std::vector<std::optional<Ellipse>> out(map.objects.size());
  for (size_t i = 0; i < map.objects.size(); ++i)
    if (const Projection p = project(map.objects[i].ellipsoid, K, pose); p) out[i] = p.ellipse;
  return out;
}

/// Where each pinhole pixel of a lens's image lies in the raw image.
struct LensRemap {
  Lens lens;
  cv::Mat map_x, map_y;
};

/// The remap of `lens` over a rows x cols image. The pictures of a sequence share one lens, and
/// a 640x480 map costs several milliseconds, as much as the rest of a picture: the last one made
/// is kept for the next picture (shared between threads, so one being drawn keeps its own).
std::shared_ptr<const LensRemap> remapOf(const Lens& lens, int rows, int cols) {
  static std::mutex mutex;
  static std::shared_ptr<const LensRemap> last;
  const std::lock_guard<std::mutex> lock(mutex);
  if (last && last->lens == lens && last->map_x.rows == rows && last->map_x.cols == cols) return last;
  auto made = std::make_shared<LensRemap>();
  made->lens = lens;
  made->map_x.create(rows, cols, CV_32FC1);
  made->map_y.create(rows, cols, CV_32FC1);
  for (int y = 0; y < rows; ++y)
    for (int x = 0; x < cols; ++x) {
      const Eigen::Vector2d p = lens.distortion.distortPixel(lens.intrinsics, {x, y});
      made->map_x.at<float>(y, x) = static_cast<float>(p.x());
      made->map_y.at<float>(y, x) = static_cast<float>(p.y());
    }
  last = made;
  return last;
}

/// The raw image resampled as the pinhole camera of the same intrinsics sees it.
cv::Mat undistorted(const cv::Mat& raw, const Lens& lens) {
  const std::shared_ptr<const LensRemap> remap = remapOf(lens, raw.rows, raw.cols);
  cv::Mat out;
  cv::remap(raw, out, remap->map_x, remap->map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0, 0, 0));
  return out;
}

cv::Mat canvas(const Intrinsics& K, const std::string& background, const Lens* lens) {
  if (background.empty()) return cv::Mat(K.height, K.width, CV_8UC3, cv::Scalar(245, 245, 245));
  const std::string bytes = readTextFile(background);
  DecodedImage decoded = decodeImage(bytes, background, DecodeAs::Bgr8);
  cv::Mat img(decoded.height, decoded.width, CV_8UC3, decoded.pixels.data());
  if (img.cols != K.width || img.rows != K.height) cv::resize(img, img, cv::Size(K.width, K.height));
  if (lens && !lens->distortion.isZero()) img = undistorted(img, *lens);
  // Lighter, so that the drawing stands out (into a new matrix: `img` may view `decoded`).
  cv::Mat lighter;
  img.convertTo(lighter, -1, 0.6, 90);
  return lighter;
}

}  // namespace

void writeOverlay(const std::string& path, const Intrinsics& K, const ObjectMap& map, const OverlayContent& content,
                  const std::string& background, const Lens* lens) {
  cv::Mat img = canvas(K, background, lens);
  if (content.truth)
    for (const std::optional<Ellipse>& e : projectMap(map, K, *content.truth))
      if (e) drawEllipse(img, *e, kTruth, 1);
  for (const Observation& o : content.observations) {
    cv::rectangle(img, cv::Point2d(o.box.x1, o.box.y1), cv::Point2d(o.box.x2, o.box.y2), kObservation, 1, cv::LINE_AA);
    drawEllipse(img, o.ellipse, kObservation, 2);
    if (o.regular.value_or(false))
      label(img, "R", cv::Point(static_cast<int>(o.box.x1) + 2, static_cast<int>(o.box.y1) + 14), kObservation);
  }
  if (content.pose) {
    const std::vector<std::optional<Ellipse>> projected = projectMap(map, K, *content.pose);
    for (size_t i = 0; i < projected.size(); ++i) {
      if (!projected[i]) continue;
      drawEllipse(img, *projected[i], kEstimate, 2);
      const Eigen::Vector2d c = projected[i]->center();
      if (c.x() >= 0 && c.y() >= 0 && c.x() < K.width && c.y() < K.height)
        label(img, std::to_string(map.objects[i].id), cv::Point(static_cast<int>(c.x()) + 4, static_cast<int>(c.y())),
              kEstimate, 0.4);
    }
    for (const auto& [observation, object] : content.matches) {
      if (observation < 0 || observation >= static_cast<int>(content.observations.size()) || object < 0 ||
          object >= static_cast<int>(projected.size()) || !projected[static_cast<size_t>(object)])
        continue;
      cv::line(img, pixel(content.observations[static_cast<size_t>(observation)].ellipse.center()),
               pixel(projected[static_cast<size_t>(object)]->center()), kMatch, 2, cv::LINE_AA, 2);
    }
  }
  int y = 18;
  for (const std::string& line : content.text) {
    label(img, line, cv::Point(8, y), cv::Scalar(0, 0, 0), 0.5);
    y += 20;
  }
  const char* legend = content.truth ? "green: detections  orange: map at the pose  blue: at the true pose  magenta: "
                                       "matches"
                                     : "green: detections  orange: map at the pose  magenta: matches";
  label(img, legend, cv::Point(8, K.height - 8), cv::Scalar(60, 60, 60), 0.4);
  writeFileAtomically(path, encodePng(img.data, img.cols, img.rows, PixelFormat::Bgr8, img.step, 6));
}

}  // namespace ellreloc::io
