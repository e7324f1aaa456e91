#pragma once
/// \file rle.hpp
/// COCO run-length masks, bit-exact with pycocotools: runs over the pixels in column-major
/// order (x outer, y inner), starting with a run of zeros; the compressed string form codes
/// each run (from the fourth on, minus the run two before) in 5-bit groups, 0x20 = "more",
/// offset by 48 (pycocotools' rleToString / rleFrString).

#include <algorithm>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace ellreloc {

struct RleMask {
  int height = 0;
  int width = 0;
  std::vector<uint32_t> counts;  ///< alternating runs of 0s and 1s, starting with 0s

  /// Sum of the runs; equals height * width for a consistent mask.
  uint64_t totalPixels() const {
    uint64_t n = 0;
    for (uint32_t c : counts) n += c;
    return n;
  }
  bool isConsistent() const {
    return height > 0 && width > 0 && totalPixels() == static_cast<uint64_t>(height) * static_cast<uint64_t>(width);
  }
};

/// Calls f(x, y0, length) for every vertical segment of ones of a consistent mask (runs split
/// where they wrap into the next column), in column-major order, walking the runs with
/// counters instead of a division per run.
template <typename F>
void forEachRunSegment(const RleMask& rle, F f) {
  if (rle.height <= 0) return;
  int x = 0, y = 0;
  const int h = rle.height;
  for (size_t i = 0; i < rle.counts.size(); ++i) {
    uint64_t remaining = rle.counts[i];
    if (i % 2 == 0) {  // zeros: just advance
      x += static_cast<int>(remaining / static_cast<uint64_t>(h));
      y += static_cast<int>(remaining % static_cast<uint64_t>(h));
      if (y >= h) y -= h, ++x;
      continue;
    }
    while (remaining > 0) {
      const int len = static_cast<int>(std::min<uint64_t>(remaining, static_cast<uint64_t>(h - y)));
      f(x, y, len);
      y += len;
      remaining -= static_cast<uint64_t>(len);
      if (y == h) y = 0, ++x;
    }
  }
}

/// The COCO run lengths of a height x width mask whose pixels outside columns [x_begin, x_end)
/// and rows [y_begin, y_end) are unset, and whose pixel (x, y) inside them is set when
/// is_set(x, y): only that window is visited, in column-major order, once each (the work is the
/// window's, not the image's). The window is cut to the image.
template <typename IsSet>
RleMask encodeRunsInWindow(int height, int width, int x_begin, int x_end, int y_begin, int y_end, IsSet is_set) {
  RleMask rle;
  rle.height = height;
  rle.width = width;
  height = std::max(height, 0), width = std::max(width, 0);
  x_begin = std::clamp(x_begin, 0, width), x_end = std::clamp(x_end, x_begin, width);
  y_begin = std::clamp(y_begin, 0, height), y_end = std::clamp(y_end, y_begin, height);
  bool current = false;
  uint32_t run = 0;
  const auto add = [&](bool on, uint64_t count) {
    if (count == 0) return;
    if (on != current) {
      rle.counts.push_back(run);
      run = 0;
      current = on;
    }
    run += static_cast<uint32_t>(count);
  };
  add(false, static_cast<uint64_t>(x_begin) * static_cast<uint64_t>(height));
  for (int x = x_begin; x < x_end; ++x) {
    add(false, static_cast<uint64_t>(y_begin));
    for (int y = y_begin; y < y_end; ++y) add(is_set(x, y), 1);
    add(false, static_cast<uint64_t>(height - y_end));
  }
  add(false, static_cast<uint64_t>(width - x_end) * static_cast<uint64_t>(height));
  rle.counts.push_back(run);
  return rle;
}

/// The COCO run lengths of a height x width mask with no pixel set (no pixel is visited).
inline RleMask emptyRle(int height, int width) {
  return encodeRunsInWindow(height, width, 0, 0, 0, 0, [](int, int) { return false; });
}

/// The COCO run lengths of a height x width mask whose pixel (x, y) is set when is_set(x, y):
/// the pixels are visited in column-major order, once each.
template <typename IsSet>
RleMask encodeRuns(int height, int width, IsSet is_set) {
  return encodeRunsInWindow(height, width, 0, width, 0, height, is_set);
}

/// Encodes run lengths as pycocotools' compressed string.
inline std::string encodeRleString(const std::vector<uint32_t>& counts) {
  std::string s;
  for (size_t i = 0; i < counts.size(); ++i) {
    long long x = counts[i];
    if (i > 2) x -= static_cast<long long>(counts[i - 2]);
    bool more = true;
    while (more) {
      char c = static_cast<char>(x & 0x1f);
      x >>= 5;  // arithmetic shift keeps the sign
      more = (c & 0x10) ? x != -1 : x != 0;
      if (more) c |= 0x20;
      s.push_back(static_cast<char>(c + 48));
    }
  }
  return s;
}

/// Decodes pycocotools' compressed string. nullopt when the string is malformed (a byte
/// outside the alphabet, a truncated group, or a run that comes out negative).
inline std::optional<std::vector<uint32_t>> decodeRleString(const std::string& s) {
  std::vector<uint32_t> counts;
  size_t p = 0;
  while (p < s.size()) {
    // Groups of 5 bits, least significant first; 8 groups (40 bits) hold any 32-bit run and
    // its difference, so longer groups are malformed (and would overflow the shifts).
    uint64_t bits = 0;
    int k = 0;
    bool more = true;
    while (more) {
      if (p >= s.size() || k >= 8) return std::nullopt;  // truncated or absurdly long group
      const int c = static_cast<unsigned char>(s[p]) - 48;
      if (c < 0 || c > 63) return std::nullopt;
      bits |= static_cast<uint64_t>(c & 0x1f) << (5 * k);
      more = (c & 0x20) != 0;
      ++p;
      ++k;
      if (!more && (c & 0x10)) bits |= ~uint64_t{0} << (5 * k);  // sign-extend
    }
    long long x = static_cast<long long>(bits);
    if (counts.size() > 2) x += counts[counts.size() - 2];
    if (x < 0 || x > 0xffffffffLL) return std::nullopt;
    counts.push_back(static_cast<uint32_t>(x));
  }
  return counts;
}

}  // namespace ellreloc
