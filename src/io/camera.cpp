#include "ellreloc/io/camera.hpp"

#include <cmath>
#include <cstdlib>
#include <map>
#include <sstream>

#include "ellreloc/error.hpp"
#include "ellreloc/io/files.hpp"
#include "json_fields.hpp"

namespace ellreloc::io {

namespace {

bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

void checkIntrinsics(const Intrinsics& K, const std::string& path) {
  if (!(K.fx > 0) || !(K.fy > 0)) throw Error(path + ": focal lengths fx, fy must be positive");
  if (!(K.width > 0) || !(K.height > 0)) throw Error(path + ": width and height must be positive");
}

Intrinsics intrinsicsFromJson(const detail::json& j, const std::string& path) {
  using namespace detail;
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

/// The top-level `key: value` lines of an ORB-SLAM style YAML file. OpenCV's FileStorage is
/// not used: it aborts the process on some malformed documents (found by fuzzing). Indented
/// lines (nested maps, matrices), comments, directives and document markers are skipped.
std::map<std::string, std::string> yamlTopLevel(const std::string& text, const std::string& path) {
  std::map<std::string, std::string> values;
  int line_number = 0;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == ' ' || line[0] == '\t' || line[0] == '#' || line[0] == '%' ||
        line.rfind("---", 0) == 0 || line.rfind("...", 0) == 0)
      continue;
    const size_t colon = line.find(':');
    if (colon == std::string::npos)
      throw Error(path + ": line " + std::to_string(line_number) + ": expected key: value");
    const std::string key = line.substr(0, colon);
    std::string value = line.substr(colon + 1);
    if (const size_t hash = value.find(" #"); hash != std::string::npos) value.resize(hash);
    const size_t first = value.find_first_not_of(" \t"), last = value.find_last_not_of(" \t");
    value = first == std::string::npos ? "" : value.substr(first, last - first + 1);
    if (!values.emplace(key, value).second)
      throw Error(path + ": line " + std::to_string(line_number) + ": " + key + " given twice");
  }
  return values;
}

double yamlNumber(const std::map<std::string, std::string>& values, const std::string& key, const std::string& path) {
  const auto it = values.find(key);
  if (it == values.end() || it->second.empty()) throw Error(path + ": " + key + ": missing");
  const char* begin = it->second.c_str();
  char* end = nullptr;
  const double v = std::strtod(begin, &end);
  if (end == begin || *end != '\0') throw Error(path + ": " + key + ": expected a number");
  if (!std::isfinite(v)) throw Error(path + ": " + key + ": not a finite number");
  return v;
}

int yamlInteger(const std::map<std::string, std::string>& values, const std::string& key, const std::string& path) {
  const double v = yamlNumber(values, key, path);
  if (v != std::floor(v) || std::abs(v) > 1e9) throw Error(path + ": " + key + ": expected an integer");
  return static_cast<int>(v);
}

std::map<std::string, std::string> yamlValues(const std::string& path) {
  const std::string text = readTextFile(path);  // names the file if it does not exist
  if (text.find_first_not_of(" \t\r\n") == std::string::npos) throw Error(path + ": empty file, expected a camera");
  return yamlTopLevel(text, path);
}

Intrinsics intrinsicsFromYaml(const std::map<std::string, std::string>& values, const std::string& path) {
  Intrinsics K;
  K.fx = yamlNumber(values, "Camera.fx", path);
  K.fy = yamlNumber(values, "Camera.fy", path);
  K.cx = yamlNumber(values, "Camera.cx", path);
  K.cy = yamlNumber(values, "Camera.cy", path);
  K.width = yamlInteger(values, "Camera.width", path);
  K.height = yamlInteger(values, "Camera.height", path);
  return K;
}

/// The distortion keys, in the order of Distortion's fields; a key left out is 0.
constexpr const char* kDistortionKeys[5] = {"k1", "k2", "p1", "p2", "k3"};

Distortion distortionFromYaml(const std::map<std::string, std::string>& values, const std::string& path) {
  double k[5] = {0, 0, 0, 0, 0};
  for (int i = 0; i < 5; ++i) {
    const std::string key = std::string("Camera.") + kDistortionKeys[i];
    if (values.count(key)) k[i] = yamlNumber(values, key, path);
  }
  return {k[0], k[1], k[2], k[3], k[4]};
}

Distortion distortionFromJson(const detail::json& j, const std::string& path) {
  using namespace detail;
  const Where where{path, ""};
  if (!j.is_object()) where.fail("expected an object");
  double k[5] = {0, 0, 0, 0, 0};
  for (int i = 0; i < 5; ++i)
    if (j.contains(kDistortionKeys[i])) k[i] = finiteNumber(j.at(kDistortionKeys[i]), where[kDistortionKeys[i]]);
  return {k[0], k[1], k[2], k[3], k[4]};
}

/// A camera file read and parsed once: its JSON document, or its YAML top-level values.
struct CameraFile {
  std::string path;
  bool json = false;
  detail::json document;
  std::map<std::string, std::string> yaml;

  explicit CameraFile(const std::string& p) : path(p), json(endsWith(p, ".json")) {
    if (json)
      document = detail::parseJson(readTextFile(path), path);
    else
      yaml = yamlValues(path);
  }
  Intrinsics intrinsics() const {
    const Intrinsics K = json ? intrinsicsFromJson(document, path) : intrinsicsFromYaml(yaml, path);
    checkIntrinsics(K, path);
    return K;
  }
  Distortion distortion() const { return json ? distortionFromJson(document, path) : distortionFromYaml(yaml, path); }
};

}  // namespace

Distortion readDistortion(const std::string& path) { return CameraFile(path).distortion(); }

Lens readLens(const std::string& path) {
  const CameraFile file(path);
  const Intrinsics K = file.intrinsics();  // the intrinsics' errors first
  const Lens lens{K, file.distortion()};
  if (const std::string why = lens.whyNotUsable(); !why.empty()) throw Error(path + ": " + why);
  return lens;
}

Intrinsics readCamera(const std::string& path) { return CameraFile(path).intrinsics(); }

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
