#include "ellreloc/observe/regular_mask.hpp"

#include <cmath>
#include <opencv2/imgproc.hpp>

namespace ellreloc {

namespace {

/// Area of a polygon of pixel-centre vertices, grown by half a pixel all round: masks count
/// whole pixels, contours run through pixel centres.
double pixelArea(const std::vector<cv::Point>& poly) {
  return std::abs(cv::contourArea(poly)) + 0.5 * cv::arcLength(poly, true) + 1.0;
}

}  // namespace

RegularVerdict testRegularMask(const BinaryMask& mask, const RegularMaskOptions& options) {
  RegularVerdict v;
  if (mask.width <= 0 || mask.height <= 0 || mask.data.size() != static_cast<size_t>(mask.width) * mask.height)
    return v;
  // Work on the mask's bounding box (plus a one-pixel frame so contours close).
  int x1 = mask.width, y1 = mask.height, x2 = -1, y2 = -1;
  long area = 0;
  for (int y = 0; y < mask.height; ++y)
    for (int x = 0; x < mask.width; ++x)
      if (mask.at(x, y)) x1 = std::min(x1, x), x2 = std::max(x2, x), y1 = std::min(y1, y), y2 = std::max(y2, y), ++area;
  if (area < options.min_pixels) return v;
  v.touches_border = x1 + mask.x0 == 0 || y1 + mask.y0 == 0 || x2 + mask.x0 == mask.image_width - 1 ||
                     y2 + mask.y0 == mask.image_height - 1;
  cv::Mat roi = cv::Mat::zeros(y2 - y1 + 3, x2 - x1 + 3, CV_8U);
  for (int y = y1; y <= y2; ++y)
    for (int x = x1; x <= x2; ++x) roi.at<uint8_t>(y - y1 + 1, x - x1 + 1) = mask.at(x, y) ? 255 : 0;
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(roi, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
  if (contours.empty()) return v;
  // All outer contours together: a mask split in pieces is judged by its overall hull.
  std::vector<cv::Point> all;
  for (const auto& c : contours) all.insert(all.end(), c.begin(), c.end());
  std::vector<cv::Point> hull;
  cv::convexHull(all, hull);
  v.hull_vertices = static_cast<int>(hull.size());
  v.solidity = static_cast<double>(area) / pixelArea(hull);
  const double perimeter = cv::arcLength(hull, true);
  std::vector<cv::Point> quad;
  // Simplify with a growing tolerance until four corners remain (or the tolerance is used up).
  for (double k = 0.005; k <= options.max_simplification + 1e-12; k *= 1.25) {
    cv::approxPolyDP(hull, quad, k * perimeter, true);
    if (quad.size() <= 4) break;
  }
  v.quad_vertices = static_cast<int>(quad.size());
  if (quad.size() != 4) return v;
  v.fill = static_cast<double>(area) / pixelArea(quad);
  // A noisy triangle can reach four corners first (one cut off); it is a triangle when three
  // corners already enclose the mask as tightly as the regular range of fills allows.
  std::vector<cv::Point> tri = quad;
  for (double k = 0.005; tri.size() > 3 && k < 0.5; k *= 1.25) cv::approxPolyDP(hull, tri, k * perimeter, true);
  if (tri.size() == 3) v.triangle_fill = static_cast<double>(area) / pixelArea(tri);
  v.min_corner_angle_deg = 180.0;
  for (int i = 0; i < 4; ++i) {
    const cv::Point2d p(quad[(i + 3) % 4]), c(quad[i]), n(quad[(i + 1) % 4]);
    const cv::Point2d a = p - c, b = n - c;
    const double ang =
        std::acos(std::clamp(a.dot(b) / (std::hypot(a.x, a.y) * std::hypot(b.x, b.y) + 1e-12), -1.0, 1.0));
    v.max_corner_angle_deg = std::max(v.max_corner_angle_deg, ang * 180.0 / M_PI);
    v.min_corner_angle_deg = std::min(v.min_corner_angle_deg, ang * 180.0 / M_PI);
    // Contours run through pixel centres: move the corner out so that both sides move out by
    // half a pixel, onto the mask's outer edge (distance 0.5 / sin(angle / 2) on the bisector).
    const cv::Point2d bis = -(a / std::hypot(a.x, a.y) + b / std::hypot(b.x, b.y));
    const double bn = std::hypot(bis.x, bis.y);
    const cv::Point2d out = bn > 1e-9 ? bis * (0.5 / std::sin(0.5 * ang) / bn) : cv::Point2d(0, 0);
    v.corners[i] = Eigen::Vector2d(c.x + out.x + x1 - 1 + mask.x0, c.y + out.y + y1 - 1 + mask.y0);
  }
  const bool triangle = v.triangle_fill >= options.min_fill && v.triangle_fill <= options.max_fill;
  v.regular = !triangle && v.solidity >= options.min_solidity && v.fill >= options.min_fill &&
              v.fill <= options.max_fill && v.max_corner_angle_deg <= options.max_corner_angle_deg &&
              v.min_corner_angle_deg >= options.min_corner_angle_deg;
  return v;
}

}  // namespace ellreloc
