#pragma once
/// \file mask.hpp
/// Binary instance masks: decoding and encoding COCO run-length masks, and their moments.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include "ellreloc/core/box.hpp"
#include "ellreloc/core/rle.hpp"

namespace ellreloc {

/// A row-major 0/1 mask of width x height pixels. It may be a crop: then its pixel (0, 0) is
/// pixel (x0, y0) of an image of image_width x image_height, and everything outside is 0.
struct BinaryMask {
  int height = 0;
  int width = 0;
  std::vector<uint8_t> data;
  int x0 = 0, y0 = 0;
  int image_width = 0, image_height = 0;

  BinaryMask() = default;
  BinaryMask(int h, int w)
      : height(h),
        width(w),
        data(static_cast<size_t>(h) * static_cast<size_t>(w), 0),
        image_width(w),
        image_height(h) {}

  uint8_t at(int x, int y) const { return data[static_cast<size_t>(y) * width + x]; }
  uint8_t& at(int x, int y) { return data[static_cast<size_t>(y) * width + x]; }
  bool inside(int x, int y) const { return x >= 0 && y >= 0 && x < width && y < height; }
  long count() const {
    long n = 0;
    for (uint8_t v : data) n += v != 0;
    return n;
  }
};

/// Decodes a COCO run-length mask (column-major runs starting with zeros) into a full-image
/// mask. nullopt when its runs do not add up to height x width.
inline std::optional<BinaryMask> decodeMask(const RleMask& rle) {
  if (!rle.isConsistent()) return std::nullopt;
  BinaryMask m(rle.height, rle.width);
  forEachRunSegment(rle, [&m](int x, int y0, int len) {
    for (int y = y0; y < y0 + len; ++y) m.at(x, y) = 1;
  });
  return m;
}

/// The first and last column and row with a pixel of the mask.
struct PixelBounds {
  int xmin = 0, xmax = 0, ymin = 0, ymax = 0;
};

/// The pixel bounds of a run-length mask (from its runs, no decoding); nullopt when it is
/// inconsistent or empty.
inline std::optional<PixelBounds> maskPixelBounds(const RleMask& rle) {
  if (!rle.isConsistent()) return std::nullopt;
  PixelBounds b{rle.width, -1, rle.height, -1};
  forEachRunSegment(rle, [&](int x, int y0, int len) {
    b.xmin = std::min(b.xmin, x), b.xmax = std::max(b.xmax, x);
    b.ymin = std::min(b.ymin, y0), b.ymax = std::max(b.ymax, y0 + len - 1);
  });
  if (b.xmax < 0) return std::nullopt;
  return b;
}

/// The box of a mask's pixels in the convention of docs/formats.md (pixel centres at integers,
/// so the box runs along the outer pixel edges); nullopt when inconsistent or empty.
inline std::optional<Box> maskBox(const RleMask& rle) {
  const std::optional<PixelBounds> b = maskPixelBounds(rle);
  if (!b) return std::nullopt;
  return Box(b->xmin - 0.5, b->ymin - 0.5, b->xmax + 0.5, b->ymax + 0.5);
}

/// Decodes only the bounding box of a run-length mask's pixels, grown by `margin` pixels on
/// every side and cut to the image, as a crop (BinaryMask::x0, y0): the work is proportional to
/// the object, not to the image. nullopt when inconsistent or empty.
inline std::optional<BinaryMask> decodeMaskCrop(const RleMask& rle, int margin = 0) {
  const std::optional<PixelBounds> bounds = maskPixelBounds(rle);
  if (!bounds) return std::nullopt;
  margin = std::clamp(margin, 0, std::max(rle.width, rle.height));  // no overflow below
  // Plain copies, not a structured binding: C++17 lambdas cannot capture those.
  const int xmin = std::max(bounds->xmin - margin, 0), xmax = std::min(bounds->xmax + margin, rle.width - 1);
  const int ymin = std::max(bounds->ymin - margin, 0), ymax = std::min(bounds->ymax + margin, rle.height - 1);
  BinaryMask m(ymax - ymin + 1, xmax - xmin + 1);
  m.x0 = xmin;
  m.y0 = ymin;
  m.image_width = rle.width;
  m.image_height = rle.height;
  forEachRunSegment(rle, [&](int x, int y0, int len) {
    for (int y = y0; y < y0 + len; ++y) m.at(x - xmin, y - ymin) = 1;
  });
  return m;
}

/// Encodes a mask (of the whole image, for a crop) as COCO run lengths. Only the crop's pixels
/// are visited: the runs beyond it are counted, not scanned.
inline RleMask encodeMask(const BinaryMask& m) {
  return encodeRunsInWindow(m.image_height, m.image_width, m.x0, m.x0 + m.width, m.y0, m.y0 + m.height,
                            [&m](int x, int y) { return m.at(x - m.x0, y - m.y0) != 0; });
}

/// The run-length mask of a polygon (even-odd rule): pixel (x, y) is set when its centre lies
/// inside. Only the columns the polygon spans are visited, each against every edge, so the work
/// is the polygon's width in pixels times its vertex count. Non-finite vertices give an empty
/// mask; an image of more than 2^32 - 1 pixels, whose runs do not fit the format, no runs.
inline RleMask polygonMask(const std::vector<Eigen::Vector2d>& polygon, int height, int width) {
  RleMask rle;
  rle.height = height;
  rle.width = width;
  const uint64_t total = static_cast<uint64_t>(std::max(height, 0)) * static_cast<uint64_t>(std::max(width, 0));
  double xmin = INFINITY, xmax = -INFINITY;
  bool finite = polygon.size() >= 3;
  for (const Eigen::Vector2d& p : polygon) {
    finite = finite && p.allFinite();
    xmin = std::min(xmin, p.x()), xmax = std::max(xmax, p.x());
  }
  uint64_t pos = 0;  // the first pixel not yet covered by a run
  const auto addOnes = [&](uint64_t start, uint64_t length) {
    if (!rle.counts.empty() && start == pos) {  // continues the previous run of ones
      rle.counts.back() += static_cast<uint32_t>(length);
    } else {
      rle.counts.push_back(static_cast<uint32_t>(start - pos));
      rle.counts.push_back(static_cast<uint32_t>(length));
    }
    pos = start + length;
  };
  if (total > UINT32_MAX) return rle;
  if (finite && total > 0) {
    const int x0 = static_cast<int>(std::max(0.0, std::ceil(xmin)));
    const int x1 = static_cast<int>(std::min(width - 1.0, std::floor(xmax)));
    std::vector<double> crossings;
    for (int x = x0; x <= x1; ++x) {
      crossings.clear();
      for (size_t i = 0; i < polygon.size(); ++i) {
        const Eigen::Vector2d& a = polygon[i];
        const Eigen::Vector2d& b = polygon[(i + 1) % polygon.size()];
        // Half-open in x, so a vertex on the column counts once.
        if ((a.x() <= x) != (b.x() <= x)) crossings.push_back(a.y() + (x - a.x()) * (b.y() - a.y()) / (b.x() - a.x()));
      }
      std::sort(crossings.begin(), crossings.end());
      for (size_t k = 0; k + 1 < crossings.size(); k += 2) {
        // Pixel centres y with crossings[k] <= y < crossings[k + 1], inside the image.
        const double y0 = std::max(0.0, std::ceil(crossings[k]));
        const double y1 = std::min(static_cast<double>(height), std::ceil(crossings[k + 1]));
        if (y1 > y0)
          addOnes(static_cast<uint64_t>(x) * static_cast<uint64_t>(height) + static_cast<uint64_t>(y0),
                  static_cast<uint64_t>(y1 - y0));
      }
    }
  }
  if (total - pos > 0 || rle.counts.empty()) rle.counts.push_back(static_cast<uint32_t>(total - pos));
  return rle;
}

/// First and second moments of a mask's pixels, each pixel a unit square centred on its
/// integer coordinates.
struct MaskMoments {
  double area = 0.0;  ///< pixel count
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
  Box bounds;  ///< outer pixel edges of the mask, FORMATS convention
};

/// Moments straight from the runs, without decoding: a segment of ones in column x from y0 to
/// y1 adds n = y1 - y0 + 1 pixels with known sums of y and y^2. O(number of runs).
inline std::optional<MaskMoments> rleMoments(const RleMask& rle) {
  if (!rle.isConsistent()) return std::nullopt;
  long double n = 0, sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
  double x1 = 1e300, y1 = 1e300, x2 = -1e300, y2 = -1e300;
  forEachRunSegment(rle, [&](int xi, int y0, int len) {
    const long double x = xi, a = y0, b = y0 + len - 1, cnt = len;
    const long double sum_y = cnt * (a + b) / 2;
    const long double sum_y2 = (b * (b + 1) * (2 * b + 1) - (a - 1) * a * (2 * a - 1)) / 6;
    n += cnt;
    sx += cnt * x;
    sxx += cnt * x * x;
    sy += sum_y;
    syy += sum_y2;
    sxy += x * sum_y;
    x1 = std::min(x1, static_cast<double>(x));
    x2 = std::max(x2, static_cast<double>(x));
    y1 = std::min(y1, static_cast<double>(a));
    y2 = std::max(y2, static_cast<double>(b));
  });
  if (n <= 0) return std::nullopt;
  MaskMoments m;
  m.area = static_cast<double>(n);
  m.mean = Eigen::Vector2d(static_cast<double>(sx / n), static_cast<double>(sy / n));
  // Pixel centres' covariance plus that of a unit square (1/12 on each axis).
  m.covariance(0, 0) = static_cast<double>(sxx / n) - m.mean(0) * m.mean(0) + 1.0 / 12.0;
  m.covariance(1, 1) = static_cast<double>(syy / n) - m.mean(1) * m.mean(1) + 1.0 / 12.0;
  m.covariance(0, 1) = m.covariance(1, 0) = static_cast<double>(sxy / n) - m.mean(0) * m.mean(1);
  m.bounds = Box(x1 - 0.5, y1 - 0.5, x2 + 0.5, y2 + 0.5);
  return m;
}

}  // namespace ellreloc
