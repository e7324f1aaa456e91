#include "ellreloc/io/camera.hpp"

#include "ellreloc/error.hpp"
#include "ellreloc/io/files.hpp"
#include "json_fields.hpp"

#include <opencv2/core.hpp>

#include <cmath>
#include <sstream>

namespace ellreloc::io {

namespace {

bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

void checkIntrinsics(const Intrinsics& K, const std::string& path) {
  if (!(K.fx > 0) || !(K.fy > 0)) throw Error(path + ": focal lengths fx, fy must be positive");
  if (!(K.width > 0) || !(K.height > 0)) throw Error(path + ": width and height must be positive");
}

Intrinsics readJson(const std::string& path) {
  using namespace detail;
  const json j = parseJson(readTextFile(path), path);
  const Where where{path, ""};
  Intrinsics K;
  K.fx = finiteNumber(member(j, "fx", where), where["fx"]);
  K.fy = finiteNumber(member(j, "fy", where), where["fy"]);
  K.cx = finiteNumber(member(j, "cx", where), where["cx"]);
  K.cy = finiteNumber(member(j, "cy", where), where["cy"]);
  K.width = integer(member(j, "width", where), where["width"]);
  K.height = integer(member(j, "height", where), where["height"]);
  return K;
}

double yamlNumber(const cv::FileStorage& fs, const std::string& key, const std::string& path) {
  const cv::FileNode node = fs[key];
  if (node.empty() || node.isNone()) throw Error(path + ": " + key + ": missing");
  if (!node.isReal() && !node.isInt()) throw Error(path + ": " + key + ": expected a number");
  const double v = node.real();
  if (!std::isfinite(v)) throw Error(path + ": " + key + ": not a finite number");
  return v;
}

int yamlInteger(const cv::FileStorage& fs, const std::string& key, const std::string& path) {
  const double v = yamlNumber(fs, key, path);
  if (v != std::floor(v) || std::abs(v) > 1e9) throw Error(path + ": " + key + ": expected an integer");
  return static_cast<int>(v);
}

Intrinsics readYaml(const std::string& path) {
  const std::string text = readTextFile(path);  // names the file if it does not exist
  if (text.find_first_not_of(" \t\r\n") == std::string::npos) throw Error(path + ": empty file, expected a camera");
  cv::FileStorage fs;
  try {
    // OpenCV's YAML parser wants the %YAML header; ORB-SLAM files have it, hand-written ones may not.
    const std::string content = text.rfind("%YAML", 0) == 0 ? text : "%YAML:1.0\n" + text;
    fs.open(content, cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
  } catch (const cv::Exception& e) {
    throw Error(path + ": invalid YAML (" + e.msg + ")");
  }
  if (!fs.isOpened()) throw Error(path + ": invalid YAML");
  Intrinsics K;
  K.fx = yamlNumber(fs, "Camera.fx", path);
  K.fy = yamlNumber(fs, "Camera.fy", path);
  K.cx = yamlNumber(fs, "Camera.cx", path);
  K.cy = yamlNumber(fs, "Camera.cy", path);
  K.width = yamlInteger(fs, "Camera.width", path);
  K.height = yamlInteger(fs, "Camera.height", path);
  return K;
}

}  // namespace

Intrinsics readCamera(const std::string& path) {
  const Intrinsics K = endsWith(path, ".json") ? readJson(path) : readYaml(path);
  checkIntrinsics(K, path);
  return K;
}

void writeCamera(const std::string& path, const Intrinsics& K) {
  if (!K.isValid()) throw Error(path + ": refusing to write invalid intrinsics");
  std::ostringstream out;
  out.precision(17);
  if (endsWith(path, ".json")) {
    detail::json j = {{"fx", K.fx}, {"fy", K.fy}, {"cx", K.cx}, {"cy", K.cy}, {"width", K.width}, {"height", K.height}};
    out << j.dump(2) << "\n";
  } else {
    out << "%YAML:1.0\n\nCamera.fx: " << K.fx << "\nCamera.fy: " << K.fy << "\nCamera.cx: " << K.cx
        << "\nCamera.cy: " << K.cy << "\n\nCamera.width: " << K.width << "\nCamera.height: " << K.height << "\n";
  }
  writeFileAtomically(path, out.str());
}

}  // namespace ellreloc::io
