#include "ellreloc/io/rgbd.hpp"

#include <cmath>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <system_error>

#include "ellreloc/error.hpp"
#include "ellreloc/io/files.hpp"
#include "ellreloc/io/image_codec.hpp"

namespace ellreloc::io {

namespace {

/// Each line's colour image time, in line order.
std::vector<double> rgbTimes(const std::vector<Association>& associations) {
  std::vector<double> times;
  times.reserve(associations.size());
  for (const Association& a : associations) times.push_back(a.rgb_time);
  return times;
}

/// The path made absolute (as given when it cannot be: empty, or no current directory) and normalised.
std::string absoluteNormal(const std::string& path) {
  std::error_code error;
  const std::filesystem::path absolute = std::filesystem::absolute(path, error);
  return (error ? std::filesystem::path(path) : absolute).lexically_normal().string();
}

std::string folderOf(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? std::string() : path.substr(0, slash + 1);
}

std::string resolve(const std::string& folder, const std::string& p) {
  return !p.empty() && p[0] == '/' ? p : folder + p;
}

}  // namespace

std::vector<Association> readAssociations(const std::string& path) {
  const std::string folder = folderOf(path);
  std::vector<Association> out;
  forEachDataLine(readTextFile(path), [&](int line_no, const std::string& line) {
    std::istringstream fields(line);
    Association a;
    if (!(fields >> a.rgb_time >> a.rgb_path >> a.depth_time >> a.depth_path) || !std::isfinite(a.rgb_time) ||
        !std::isfinite(a.depth_time))
      throw Error(path + ": line " + std::to_string(line_no) + ": expected 't_rgb rgb/X.png t_depth depth/Y.png'");
    a.rgb_path = resolve(folder, a.rgb_path);
    a.depth_path = resolve(folder, a.depth_path);
    out.push_back(std::move(a));
  });
  if (out.empty()) throw Error(path + ": no associations found (empty file)");
  return out;
}

AssociationIndex::AssociationIndex(std::vector<Association> associations, double tolerance)
    : associations_(std::move(associations)), tolerance_(tolerance), by_time_(rgbTimes(associations_)) {
  if (!(tolerance >= 0.0) || !std::isfinite(tolerance))
    throw Error("association index: the time tolerance must be finite and >= 0, got " + std::to_string(tolerance));
  for (size_t k = 0; k < associations_.size(); ++k) by_image_[absoluteNormal(associations_[k].rgb_path)] = k;
}

const Association* AssociationIndex::find(const std::string& rgb_path, std::optional<double> rgb_time) const {
  if (associations_.empty()) return nullptr;
  if (const auto named = by_image_.find(absoluteNormal(rgb_path)); named != by_image_.end())
    return &associations_[named->second];
  if (!rgb_time) return nullptr;
  const std::optional<size_t> nearest = by_time_.nearest(*rgb_time, tolerance_);
  return nearest ? &associations_[*nearest] : nullptr;
}

DepthImage readDepthPng(const std::string& path, double units_per_metre) {
  const std::string bytes = readTextFile(path);  // names the file when it is missing or unreadable
  // The decoder refuses an image declaring more than kMaxDepthPixels before decoding it, and
  // anything but a PNG or a JPEG; a JPEG, never 16-bit, fails the check below.
  const DecodedImage img = decodeImage(bytes, path, DecodeAs::Stored, kMaxDepthPixels);
  if (img.format != PixelFormat::Grey16) throw Error(path + ": expected a 16-bit single-channel depth PNG");
  DepthImage d;
  d.width = img.width;
  d.height = img.height;
  d.metres.resize(static_cast<size_t>(img.width) * img.height);
  const double scale = 1.0 / units_per_metre;
  for (size_t i = 0; i < d.metres.size(); ++i) {
    uint16_t units = 0;
    std::memcpy(&units, img.pixels.data() + 2 * i, 2);
    d.metres[i] = static_cast<float>(units * scale);
  }
  return d;
}

void writeDepthPng(const std::string& path, const DepthImage& depth, double units_per_metre) {
  if (depth.width <= 0 || depth.height <= 0 || depth.metres.size() != static_cast<size_t>(depth.width) * depth.height)
    throw Error(path + ": refusing to write a depth image whose size does not match its data");
  std::vector<uint16_t> units(depth.metres.size());
  for (size_t i = 0; i < units.size(); ++i) {
    const double u = std::round(static_cast<double>(depth.metres[i]) * units_per_metre);
    units[i] = std::isfinite(u) && u > 0 && u <= 65535 ? static_cast<uint16_t>(u) : 0;
  }
  writeFileAtomically(path, encodePng(units.data(), depth.width, depth.height, PixelFormat::Grey16,
                                      2 * static_cast<size_t>(depth.width)));
}

}  // namespace ellreloc::io
