#include "ellreloc/io/map.hpp"

#include <cmath>
#include <cstdlib>
#include <sstream>

#include "ellreloc/error.hpp"
#include "ellreloc/io/files.hpp"
#include "json_fields.hpp"

namespace ellreloc::io {

namespace {

using detail::json;
using detail::Where;

/// Rotations in files are rounded (float32 in OA-SLAM and GOReloc maps): accept them within
/// this tolerance and return the nearest exact rotation.
constexpr double kRotationTolerance = 1e-3;

/// An object that cannot be used: left out of the map with a warning naming it.
struct Unusable {
  std::string reason;
};

Ellipsoid ellipsoidFromDualQuadric(const Eigen::Matrix4d& Q, const std::string& where) {
  const auto e = Ellipsoid::fromDualQuadric(Q);
  if (!e) throw Unusable{where + ": the dual quadric is singular or not an ellipsoid"};
  return *e;
}

Ellipsoid parseObjectGeometry(const json& obj, const Where& where) {
  if (obj.contains("center") || !obj.contains("dual_quadric")) {
    const Eigen::Vector3d c = detail::vector<3>(detail::member(obj, "center", where), where["center"]);
    const Eigen::Vector3d axes = detail::vector<3>(detail::member(obj, "axes", where), where["axes"]);
    if (!(axes.minCoeff() > 0.0)) throw Unusable{where["axes"].path + ": semi-axes must be positive"};
    const json& rot = detail::member(obj, "rotation", where);
    if (!rot.is_array() || rot.size() != 3) where["rotation"].fail("expected 3 rows of 3 numbers");
    Eigen::Matrix3d R;
    for (size_t r = 0; r < 3; ++r)
      R.row(static_cast<int>(r)) = detail::vector<3>(rot[r], where["rotation"][r]).transpose();
    if (!isRotation(R, kRotationTolerance)) where["rotation"].fail("not a rotation matrix (orthonormal, det +1)");
    return Ellipsoid(c, axes, nearestRotation(R));
  }
  const json& q = obj["dual_quadric"];
  if (!q.is_array() || q.size() != 16) where["dual_quadric"].fail("expected 16 numbers (row-major)");
  Eigen::Matrix4d Q;
  for (size_t i = 0; i < 16; ++i)
    Q(static_cast<int>(i / 4), static_cast<int>(i % 4)) = detail::finiteNumber(q[i], where["dual_quadric"][i]);
  return ellipsoidFromDualQuadric(Q, where["dual_quadric"].path);
}

/// {"up": [x, y, z], "height": [min, max], "tilt_deg": [min, max]}: the heights (metres along
/// the unit `up`) and tilts of the map's keyframes (CameraEnvelope).
CameraEnvelope parseEnvelope(const json& e, const Where& where) {
  CameraEnvelope envelope;
  const Eigen::Vector3d up = detail::vector<3>(detail::member(e, "up", where), where["up"]);
  if (!(std::abs(up.norm() - 1.0) < 1e-6)) where["up"].fail("expected a unit vector");
  envelope.up = up;
  const Eigen::Vector2d height = detail::vector<2>(detail::member(e, "height", where), where["height"]);
  const Eigen::Vector2d tilt = detail::vector<2>(detail::member(e, "tilt_deg", where), where["tilt_deg"]);
  if (!(height(0) <= height(1))) where["height"].fail("expected [min, max] with min <= max");
  if (!(tilt(0) >= 0.0 && tilt(0) <= tilt(1) && tilt(1) <= 180.0))
    where["tilt_deg"].fail("expected [min, max] with 0 <= min <= max <= 180 degrees");
  envelope.min_height = height(0), envelope.max_height = height(1);
  envelope.min_tilt_deg = tilt(0), envelope.max_tilt_deg = tilt(1);
  return envelope;
}

/// Keeps `object` or, when unusable, leaves it out with a warning naming it.
void keepIfUsable(MapObject object, const std::string& problem, const std::string& source, ObjectMap* map,
                  std::vector<std::string>* warnings) {
  const std::string why = problem.empty() ? mapObjectProblem(object, map->unit_metres) : problem;
  if (why.empty()) {
    map->objects.push_back(std::move(object));
    return;
  }
  if (warnings) warnings->push_back(source + ": object " + std::to_string(object.id) + " left out: " + why);
}

/// No usable object is an error: relocalization against nothing cannot succeed.
void requireObjects(const ObjectMap& map, const std::vector<std::string>& left_out, const std::string& source) {
  if (!map.objects.empty()) return;
  if (left_out.empty()) throw Error(source + ": no objects found (empty or blank map file)");
  throw Error(left_out.front() + (left_out.size() > 1 ? " (and every other object)" : "") + "; no usable object");
}

}  // namespace

ObjectMap parseMapJson(const std::string& text, const std::string& source, std::vector<std::string>* warnings) {
  const json j = detail::parseJson(text, source);
  const Where top{source, ""};
  if (!j.is_object()) top.fail("expected a JSON object with \"objects\"");
  if (j.contains("ellreloc_map")) {
    const int version = detail::integer(j["ellreloc_map"], top["ellreloc_map"]);
    if (version != 1)
      top["ellreloc_map"].fail("unsupported version " + std::to_string(version) + " (this reader knows 1)");
  }
  const json& objects = detail::member(j, "objects", top);
  if (!objects.is_array()) top["objects"].fail("expected an array");
  ObjectMap map;
  if (j.contains("unit_metres")) {  // before the objects, whose semi-axes are checked in metres
    map.unit_metres = detail::finiteNumber(j["unit_metres"], top["unit_metres"]);
    if (!validUnitMetres(map.unit_metres)) top["unit_metres"].fail("expected a length of 1e-6 to 1e6 metres");
  }
  std::vector<std::string> left_out;
  for (size_t i = 0; i < objects.size(); ++i) {
    const Where where = top["objects"][i];
    const json& o = objects[i];
    if (!o.is_object()) where.fail("expected an object");
    MapObject obj;
    obj.id = detail::integer(detail::member(o, "id", where), where["id"]);
    obj.category = detail::integer(detail::member(o, "category", where), where["category"]);
    if (o.contains("label")) {
      if (!o["label"].is_string()) where["label"].fail("expected a string");
      obj.label = o["label"].get<std::string>();
    }
    std::string problem;
    try {
      obj.ellipsoid = parseObjectGeometry(o, where);
    } catch (const Unusable& u) {
      problem = u.reason;
    }
    if (o.contains("category_counts")) {
      const json& counts = o["category_counts"];
      const Where wc = where["category_counts"];
      if (!counts.is_object()) wc.fail("expected an object {\"category\": count}");
      for (const auto& [key, value] : counts.items()) {
        char* end = nullptr;
        const long c = std::strtol(key.c_str(), &end, 10);
        if (key.empty() || *end != '\0' || c < -2147483647L || c > 2147483647L)
          wc[key].fail("key is not an integer category");
        const double n = detail::finiteNumber(value, wc[key]);
        if (n < 0.0) wc[key].fail("count must be >= 0");
        obj.category_counts[static_cast<int>(c)] = n;
      }
    }
    keepIfUsable(std::move(obj), problem, source, &map, &left_out);
  }
  requireObjects(map, left_out, source);
  if (warnings) warnings->insert(warnings->end(), left_out.begin(), left_out.end());
  if (j.contains("points")) {
    const json& points = j["points"];
    if (!points.is_array()) top["points"].fail("expected an array of [x, y, z]");
    map.points.reserve(points.size());
    for (size_t i = 0; i < points.size(); ++i) map.points.push_back(detail::vector<3>(points[i], top["points"][i]));
  }
  if (j.contains("camera_envelope")) map.camera_envelope = parseEnvelope(j["camera_envelope"], top["camera_envelope"]);
  return map;
}

ObjectMap parseOaSlamMap(const std::string& text, const std::string& source, std::vector<std::string>* warnings) {
  ObjectMap map;
  std::vector<std::string> left_out;
  forEachDataLine(text, [&](int line_no, const std::string& line) {
    const Where where{source, "line " + std::to_string(line_no)};
    std::istringstream fields(line);
    long long id = 0, category = 0;
    if (!(fields >> id >> category)) where.fail("expected 'track_id category_id' then 16 numbers");
    Eigen::Matrix4d Q;
    for (int k = 0; k < 16; ++k) {
      double v = 0;
      if (!(fields >> v)) where.fail("expected 16 dual-quadric entries, found " + std::to_string(k));
      if (!std::isfinite(v)) where.fail("dual-quadric entry " + std::to_string(k) + " is not finite");
      Q(k % 4, k / 4) = v;  // column-major
    }
    std::string extra;
    if (fields >> extra) where.fail("unexpected trailing text '" + extra + "'");
    MapObject obj;
    obj.id = static_cast<int>(id);
    obj.category = static_cast<int>(category);
    std::string problem;
    try {
      obj.ellipsoid = ellipsoidFromDualQuadric(Q, where.path);
    } catch (const Unusable& u) {
      problem = u.reason;
    }
    keepIfUsable(std::move(obj), problem, source, &map, &left_out);
  });
  requireObjects(map, left_out, source);
  if (warnings) warnings->insert(warnings->end(), left_out.begin(), left_out.end());
  return map;
}

ObjectMap readMap(const std::string& path, std::vector<std::string>* warnings) {
  const std::string text = readTextFile(path);
  const size_t first = text.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) throw Error(path + ": empty file, expected a map");
  // An OA-SLAM text map starts with a number: any JSON (a detections file given by mistake, too)
  // goes to the JSON reader, which says what it expected.
  const bool json = text[first] == '{' || text[first] == '[';
  return json ? parseMapJson(text, path, warnings) : parseOaSlamMap(text, path, warnings);
}

void writeMap(const std::string& path, const ObjectMap& map) {
  json objects = json::array();
  for (const MapObject& o : map.objects) {
    if (!o.ellipsoid.isValid()) throw Error(path + ": object " + std::to_string(o.id) + " has an invalid ellipsoid");
    const Eigen::Matrix3d& R = o.ellipsoid.rotation();
    json obj = {{"id", o.id}, {"category", o.category}};
    if (!o.label.empty()) obj["label"] = o.label;
    obj["center"] = {o.ellipsoid.center()(0), o.ellipsoid.center()(1), o.ellipsoid.center()(2)};
    obj["axes"] = {o.ellipsoid.axes()(0), o.ellipsoid.axes()(1), o.ellipsoid.axes()(2)};
    obj["rotation"] = {{R(0, 0), R(0, 1), R(0, 2)}, {R(1, 0), R(1, 1), R(1, 2)}, {R(2, 0), R(2, 1), R(2, 2)}};
    if (!o.category_counts.empty()) {
      json counts = json::object();
      for (const auto& [c, n] : o.category_counts) counts[std::to_string(c)] = n;
      obj["category_counts"] = std::move(counts);
    }
    objects.push_back(std::move(obj));
  }
  if (!validUnitMetres(map.unit_metres)) throw Error(path + ": the map's unit_metres is not a length of 1e-6 to 1e6 m");
  json j = {{"ellreloc_map", 1}, {"objects", std::move(objects)}};
  if (map.unit_metres != 1.0) j["unit_metres"] = map.unit_metres;  // a metric map's file stays as it was
  if (!map.points.empty()) {
    json points = json::array();
    for (const auto& p : map.points) points.push_back({p(0), p(1), p(2)});
    j["points"] = std::move(points);
  }
  if (const auto& e = map.camera_envelope) {
    if (!e->isValid()) throw Error(path + ": the camera envelope is not valid (unit up, min <= max)");
    j["camera_envelope"] = {{"up", {e->up(0), e->up(1), e->up(2)}},
                            {"height", {e->min_height, e->max_height}},
                            {"tilt_deg", {e->min_tilt_deg, e->max_tilt_deg}}};
  }
  writeFileAtomically(path, j.dump(1) + "\n");
}

}  // namespace ellreloc::io
