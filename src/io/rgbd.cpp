#include "ellreloc/io/rgbd.hpp"

#include <cmath>
#include <cstring>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "ellreloc/error.hpp"
#include "ellreloc/io/files.hpp"

namespace ellreloc::io {

namespace {

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

DepthImage readDepthPng(const std::string& path, double units_per_metre) {
  const std::string bytes = readTextFile(path);  // names the file when it is missing or unreadable
  // The size from the PNG header (IHDR) before decoding: a small file can declare a huge image.
  static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (bytes.size() < 24 || std::memcmp(bytes.data(), kSignature, 8) != 0 || bytes.compare(12, 4, "IHDR") != 0)
    throw Error(path + ": not a PNG image");
  const auto be32 = [&](size_t at) {
    return (static_cast<uint32_t>(static_cast<unsigned char>(bytes[at])) << 24) |
           (static_cast<uint32_t>(static_cast<unsigned char>(bytes[at + 1])) << 16) |
           (static_cast<uint32_t>(static_cast<unsigned char>(bytes[at + 2])) << 8) |
           static_cast<uint32_t>(static_cast<unsigned char>(bytes[at + 3]));
  };
  const uint64_t width = be32(16), height = be32(20);
  if (width == 0 || height == 0 || width * height > kMaxDepthPixels)
    throw Error(path + ": declares a " + std::to_string(width) + "x" + std::to_string(height) +
                " image; depth images are limited to " + std::to_string(kMaxDepthPixels) + " pixels");
  cv::Mat img;
  try {
    img = cv::imdecode(cv::Mat(1, static_cast<int>(bytes.size()), CV_8UC1, const_cast<char*>(bytes.data())),
                       cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    throw Error(path + ": cannot decode image (" + e.msg + ")");
  }
  if (img.empty()) throw Error(path + ": not a readable image");
  if (img.type() != CV_16UC1) throw Error(path + ": expected a 16-bit single-channel depth PNG");
  DepthImage d;
  d.width = img.cols;
  d.height = img.rows;
  d.metres.resize(static_cast<size_t>(img.rows) * img.cols);
  const double scale = 1.0 / units_per_metre;
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x)
      d.metres[static_cast<size_t>(y) * img.cols + x] = static_cast<float>(img.at<uint16_t>(y, x) * scale);
  return d;
}

void writeDepthPng(const std::string& path, const DepthImage& depth, double units_per_metre) {
  if (depth.width <= 0 || depth.height <= 0 || depth.metres.size() != static_cast<size_t>(depth.width) * depth.height)
    throw Error(path + ": refusing to write a depth image whose size does not match its data");
  cv::Mat img(depth.height, depth.width, CV_16UC1);
  for (int y = 0; y < depth.height; ++y)
    for (int x = 0; x < depth.width; ++x) {
      const double units = std::round(depth.at(x, y) * units_per_metre);
      img.at<uint16_t>(y, x) = std::isfinite(units) && units > 0 && units <= 65535 ? static_cast<uint16_t>(units) : 0;
    }
  std::vector<uchar> png;
  if (!cv::imencode(".png", img, png)) throw Error(path + ": PNG encoding failed");
  writeFileAtomically(path, std::string(png.begin(), png.end()));
}

}  // namespace ellreloc::io
