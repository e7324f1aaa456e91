#include "ellreloc/io/detections.hpp"

#include <cstdlib>
#include <unordered_map>

#include "ellreloc/error.hpp"
#include "ellreloc/io/files.hpp"
#include "json_fields.hpp"

namespace ellreloc {

namespace io {

namespace {

using detail::json;
using detail::Where;

RleMask parseMask(const json& m, const Where& where) {
  RleMask mask;
  const json& size = detail::member(m, "size", where);
  if (!size.is_array() || size.size() != 2) where["size"].fail("expected [height, width]");
  mask.height = detail::integer(size[0], where["size"][0]);
  mask.width = detail::integer(size[1], where["size"][1]);
  if (mask.height <= 0 || mask.width <= 0) where["size"].fail("height and width must be positive");
  if (static_cast<long long>(mask.height) * mask.width > (1LL << 31)) where["size"].fail("mask too large");
  const json& counts = detail::member(m, "counts", where);
  if (counts.is_string()) {
    auto decoded = decodeRleString(counts.get<std::string>());
    if (!decoded) where["counts"].fail("malformed compressed RLE string");
    mask.counts = std::move(*decoded);
  } else if (counts.is_array()) {
    mask.counts.reserve(counts.size());
    for (size_t i = 0; i < counts.size(); ++i) {
      const int c = detail::integer(counts[i], where["counts"][i]);
      if (c < 0) where["counts"][i].fail("run lengths must be >= 0");
      mask.counts.push_back(static_cast<uint32_t>(c));
    }
  } else {
    where["counts"].fail("expected a compressed RLE string or a list of run lengths");
  }
  if (!mask.isConsistent())
    where["counts"].fail("runs sum to " + std::to_string(mask.totalPixels()) + ", expected height x width = " +
                         std::to_string(static_cast<long long>(mask.height) * mask.width));
  return mask;
}

Detection parseDetection(const json& d, const Where& where) {
  if (!d.is_object()) where.fail("expected an object");
  Detection det;
  det.category_id = detail::integer(detail::member(d, "category_id", where), where["category_id"]);
  if (d.contains("detection_score")) {
    det.score = detail::finiteNumber(d["detection_score"], where["detection_score"]);
    if (det.score < 0.0) where["detection_score"].fail("must be >= 0");
  }
  const Eigen::Vector4d b = detail::vector<4>(detail::member(d, "bbox", where), where["bbox"]);
  det.bbox = Box(b(0), b(1), b(2), b(3));
  if (!(b(0) < b(2)) || !(b(1) < b(3))) where["bbox"].fail("expected [x1, y1, x2, y2] with x1 < x2 and y1 < y2");
  if (d.contains("mask") && !d["mask"].is_null()) det.mask = parseMask(d["mask"], where["mask"]);
  if (d.contains("polygon")) {
    const json& poly = d["polygon"];
    if (!poly.is_array() || poly.size() < 3) where["polygon"].fail("expected at least 3 [x, y] vertices");
    for (size_t i = 0; i < poly.size(); ++i) det.polygon.push_back(detail::vector<2>(poly[i], where["polygon"][i]));
  }
  if (d.contains("ellipse") && !d["ellipse"].is_null()) {
    const json& e = d["ellipse"];
    const Where we = where["ellipse"];
    const Eigen::Vector2d c = detail::vector<2>(detail::member(e, "center", we), we["center"]);
    const Eigen::Vector2d axes = detail::vector<2>(detail::member(e, "axes", we), we["axes"]);
    if (axes.minCoeff() <= 0.0) we["axes"].fail("semi-axes must be positive");
    det.ellipse = Ellipse(c, axes, detail::finiteNumber(detail::member(e, "angle", we), we["angle"]));
  }
  if (d.contains("regular")) {
    if (!d["regular"].is_boolean()) where["regular"].fail("expected true or false");
    det.regular = d["regular"].get<bool>();
  }
  if (d.contains("object_id") && !d["object_id"].is_null())
    det.object_id = detail::integer(d["object_id"], where["object_id"]);
  return det;
}

}  // namespace

std::vector<DetectionFrame> parseDetectionsJson(const std::string& text, const std::string& source) {
  const json j = detail::parseJson(text, source);
  const Where top{source, ""};
  if (!j.is_array()) top.fail("expected an array of frames");
  std::vector<DetectionFrame> frames;
  frames.reserve(j.size());
  std::unordered_map<std::string, size_t> seen;  // file name -> its frame's index
  for (size_t f = 0; f < j.size(); ++f) {
    const Where where = top[f];
    const json& fr = j[f];
    if (!fr.is_object()) where.fail("expected an object with file_name and detections");
    DetectionFrame frame;
    const json& name = detail::member(fr, "file_name", where);
    if (!name.is_string() || name.get<std::string>().empty()) where["file_name"].fail("expected a non-empty string");
    frame.file_name = name.get<std::string>();
    if (const auto [it, fresh] = seen.emplace(frame.file_name, f); !fresh)
      where["file_name"].fail("'" + frame.file_name + "' repeats frame [" + std::to_string(it->second) + "]");
    const json& dets = detail::member(fr, "detections", where);
    if (!dets.is_array()) where["detections"].fail("expected an array");
    for (size_t i = 0; i < dets.size(); ++i)
      frame.detections.push_back(parseDetection(dets[i], where["detections"][i]));
    if (fr.contains("keypoints")) {
      const json& kps = fr["keypoints"];
      if (!kps.is_array()) where["keypoints"].fail("expected an array of [point_index, u, v]");
      for (size_t i = 0; i < kps.size(); ++i) {
        const Where wk = where["keypoints"][i];
        if (!kps[i].is_array() || kps[i].size() != 3) wk.fail("expected [point_index, u, v]");
        Keypoint kp;
        kp.point_index = detail::integer(kps[i][0], wk[0]);
        if (kp.point_index < 0) wk[0].fail("point index must be >= 0");
        kp.uv = Eigen::Vector2d(detail::finiteNumber(kps[i][1], wk[1]), detail::finiteNumber(kps[i][2], wk[2]));
        frame.keypoints.push_back(kp);
      }
    }
    frames.push_back(std::move(frame));
  }
  return frames;
}

std::vector<DetectionFrame> readDetections(const std::string& path) {
  return parseDetectionsJson(readTextFile(path), path);
}

void writeDetections(const std::string& path, const std::vector<DetectionFrame>& frames) {
  json out = json::array();
  for (const DetectionFrame& frame : frames) {
    json dets = json::array();
    for (const Detection& d : frame.detections) {
      json jd = {{"category_id", d.category_id},
                 {"detection_score", d.score},
                 {"bbox", {d.bbox.x1, d.bbox.y1, d.bbox.x2, d.bbox.y2}}};
      if (d.mask) jd["mask"] = {{"size", {d.mask->height, d.mask->width}}, {"counts", encodeRleString(d.mask->counts)}};
      if (!d.polygon.empty()) {
        json poly = json::array();
        for (const auto& p : d.polygon) poly.push_back({p(0), p(1)});
        jd["polygon"] = std::move(poly);
      }
      if (d.ellipse) {
        if (!d.ellipse->isValid()) throw Error(path + ": refusing to write an invalid ellipse");
        jd["ellipse"] = {{"center", {d.ellipse->center()(0), d.ellipse->center()(1)}},
                         {"axes", {d.ellipse->axes()(0), d.ellipse->axes()(1)}},
                         {"angle", d.ellipse->angle()}};
      }
      if (d.regular) jd["regular"] = *d.regular;
      if (d.object_id) jd["object_id"] = *d.object_id;
      dets.push_back(std::move(jd));
    }
    json jf = {{"file_name", frame.file_name}, {"detections", std::move(dets)}};
    if (!frame.keypoints.empty()) {
      json kps = json::array();
      for (const Keypoint& k : frame.keypoints) kps.push_back({k.point_index, k.uv(0), k.uv(1)});
      jf["keypoints"] = std::move(kps);
    }
    out.push_back(std::move(jf));
  }
  writeFileAtomically(path, out.dump(1) + "\n");
}

}  // namespace io
}  // namespace ellreloc
