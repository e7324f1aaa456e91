/// \file bind_data.cpp
/// The plain data types every component passes around: masks (COCO run lengths), detections,
/// keypoints, frames, observations, map objects and maps.

#include <pybind11/stl.h>

#include "bindings.hpp"
#include "convert.hpp"
#include "ellreloc/core/mask.hpp"
#include "ellreloc/core/object_map.hpp"

namespace ellreloc::python {
namespace {

RleMask maskFromCoco(const py::dict& d, const std::string& name) {
  if (!d.contains("size") || !d.contains("counts"))
    badArgument(name, "a COCO RLE dict needs 'size' ([height, width]) and 'counts'");
  RleMask rle;
  try {
    const auto size = d["size"].cast<std::vector<long long>>();
    if (size.size() != 2 || size[0] <= 0 || size[1] <= 0 || size[0] * size[1] > (1LL << 31))
      badArgument(name, "'size' must be [height, width], both positive");
    rle.height = static_cast<int>(size[0]);
    rle.width = static_cast<int>(size[1]);
    const py::object counts = d["counts"];
    if (py::isinstance<py::str>(counts) || py::isinstance<py::bytes>(counts)) {
      const std::string text =
          py::isinstance<py::bytes>(counts) ? counts.cast<py::bytes>().cast<std::string>() : counts.cast<std::string>();
      auto decoded = decodeRleString(text);
      if (!decoded) badArgument(name, "'counts' is a malformed compressed RLE string");
      rle.counts = std::move(*decoded);
    } else {
      for (const long long v : counts.cast<std::vector<long long>>()) {
        if (v < 0 || v > 0xffffffffLL) badArgument(name, "'counts' run lengths must be >= 0");
        rle.counts.push_back(static_cast<uint32_t>(v));
      }
    }
  } catch (const py::cast_error&) {
    badArgument(name, "'size' must be two integers and 'counts' a string, bytes or a list of integers");
  }
  return rle;
}

py::dict toCoco(const RleMask& m) {
  py::dict d;
  d["size"] = py::make_tuple(m.height, m.width);
  d["counts"] = encodeRleString(m.counts);
  return d;
}

py::array_t<bool> toBoolArray(const RleMask& rle) {
  if (!rle.isConsistent()) throw py::value_error("mask: its runs do not add up to height x width");
  py::array_t<bool> out({rle.height, rle.width});
  auto w = out.mutable_unchecked<2>();
  std::fill(out.mutable_data(), out.mutable_data() + out.size(), false);
  forEachRunSegment(rle, [&w](int x, int y0, int len) {
    for (int y = y0; y < y0 + len; ++y) w(y, x) = true;
  });
  return out;
}

void bindMask(py::module_& m) {
  py::class_<RleMask>(m, "RleMask",
                      "An instance mask as COCO run lengths: column-major runs of 0s and 1s, starting with 0s.")
      .def(py::init([](int height, int width, std::vector<uint32_t> counts) {
             RleMask r;
             r.height = height, r.width = width, r.counts = std::move(counts);
             if (!r.isConsistent()) throw py::value_error("RleMask: the runs do not add up to height x width");
             return r;
           }),
           py::arg("height"), py::arg("width"), py::arg("counts"))
      .def_static(
          "from_array", [](const py::handle& a) { return maskFromArray(a, "mask"); }, py::arg("mask"),
          "From a 2-D bool or uint8 numpy array (non-zero = object), read in place.")
      .def_static(
          "from_coco", [](const py::dict& d) { return maskFromCoco(d, "mask"); }, py::arg("rle"),
          "From a COCO RLE dict {'size': [h, w], 'counts': compressed str/bytes or a list of runs}.")
      .def_readonly("height", &RleMask::height)
      .def_readonly("width", &RleMask::width)
      .def_readonly("counts", &RleMask::counts)
      .def_property_readonly("area",
                             [](const RleMask& r) {
                               uint64_t n = 0;
                               for (size_t i = 1; i < r.counts.size(); i += 2) n += r.counts[i];
                               return n;
                             })
      .def("to_array", &toBoolArray, "A (height, width) bool array.")
      .def("to_coco", &toCoco, "A COCO RLE dict with the compressed counts string.")
      .def("__repr__", [](const RleMask& r) {
        return "RleMask(" + std::to_string(r.height) + "x" + std::to_string(r.width) + ", " +
               std::to_string(r.counts.size()) + " runs)";
      });
}

Detection makeDetection(int category, const py::handle& bbox, double score, const py::handle& mask,
                        const py::handle& polygon, const std::optional<Ellipse>& ellipse,
                        const std::optional<int>& object_id) {
  Detection d;
  d.category_id = category;
  d.bbox = boxFrom(bbox, "bbox");
  if (!std::isfinite(score)) badArgument("score", "must be finite");
  d.score = score;
  if (!mask.is_none()) d.mask = maskFromObject(mask, "mask");
  if (!polygon.is_none()) d.polygon = rows<2>(polygon, "polygon");
  d.ellipse = ellipse;
  d.object_id = object_id;
  return d;
}

void bindDetections(py::module_& m) {
  py::class_<Detection>(m, "Detection",
                        "One detected object: box, category, score, and optionally an instance mask (numpy array, "
                        "COCO RLE dict or RleMask), a polygon or a ready-made ellipse.")
      .def(py::init(&makeDetection), py::arg("category_id"), py::arg("bbox"), py::arg("score") = 1.0,
           py::arg("mask") = py::none(), py::arg("polygon") = py::none(), py::arg("ellipse") = py::none(),
           py::arg("object_id") = py::none())
      .def_readwrite("category_id", &Detection::category_id)
      .def_readwrite("score", &Detection::score)
      .def_readwrite("bbox", &Detection::bbox)
      .def_property(
          "mask", [](const Detection& d) { return d.mask; },
          [](Detection& d, const py::handle& h) {
            if (h.is_none())
              d.mask.reset();
            else
              d.mask = maskFromObject(h, "mask");
          })
      .def_property(
          "polygon", [](const Detection& d) { return rowsToArray<2>(d.polygon); },
          [](Detection& d, const py::handle& h) {
            d.polygon = h.is_none() ? decltype(d.polygon){} : rows<2>(h, "polygon");
          })
      .def_readwrite("ellipse", &Detection::ellipse)
      .def_readwrite("regular", &Detection::regular)
      .def_readwrite("object_id", &Detection::object_id)
      .def("__repr__", [](const Detection& d) {
        return "Detection(category_id=" + std::to_string(d.category_id) + ", score=" + std::to_string(d.score) +
               (d.mask ? ", mask" : "") + ")";
      });

  py::class_<Keypoint>(m, "Keypoint", "A 2D feature of the frame matched to map point `point_index`.")
      .def(py::init([](int index, const py::handle& uv) {
             Keypoint k;
             k.point_index = index;
             k.uv = vector<2>(uv, "uv");
             return k;
           }),
           py::arg("point_index"), py::arg("uv"))
      .def_readwrite("point_index", &Keypoint::point_index)
      .def_property(
          "uv", [](const Keypoint& k) { return toArray(k.uv); },
          [](Keypoint& k, const py::handle& h) { k.uv = vector<2>(h, "uv"); });

  py::class_<DetectionFrame>(
      m, "DetectionFrame",
      "One image's detections (and keypoints), named by its file. `detections` and `keypoints` return "
      "copies: assign a new list to change them.")
      .def(py::init([](std::string file_name, const py::handle& detections, const py::handle& keypoints) {
             DetectionFrame f;
             f.file_name = std::move(file_name);
             f.detections = detectionList(detections, "detections");
             f.keypoints = keypointsFrom(keypoints);
             return f;
           }),
           py::arg("file_name") = "", py::arg("detections") = py::list(), py::arg("keypoints") = py::list())
      .def_readwrite("file_name", &DetectionFrame::file_name)
      .def_readwrite("detections", &DetectionFrame::detections)
      .def_readwrite("keypoints", &DetectionFrame::keypoints)
      .def_property_readonly(
          "timestamp_text", &DetectionFrame::timestampText,
          "The file's base name without extension, under which `ellreloc relocalize` writes its pose.")
      .def_property_readonly("timestamp", &DetectionFrame::timestamp,
                             "The file's base name as a number (rgb/1311868164.36.png -> 1311868164.36), or None.")
      .def("__repr__", [](const DetectionFrame& f) {
        return "DetectionFrame('" + f.file_name + "', " + std::to_string(f.detections.size()) + " detections)";
      });
}

void bindObservationAndMap(py::module_& m) {
  py::enum_<EllipseSource>(m, "EllipseSource", "Where an observation's ellipse came from.")
      .value("box", EllipseSource::Box, "inscribed in the detection box (OA-SLAM's model)")
      .value("mask", EllipseSource::Mask, "fitted to the instance mask")
      .value("given", EllipseSource::Given, "the detection's own ellipse");

  py::class_<Observation>(m, "Observation", "A detected object of the query image as an ellipse, what relocalize uses.")
      .def(py::init([](int category, const Ellipse& ellipse, double score, const std::optional<Box>& box,
                       EllipseSource source) {
             if (!ellipse.isValid()) badArgument("ellipse", "is not a valid ellipse");
             Observation o;
             o.category = category, o.ellipse = ellipse, o.score = score, o.source = source;
             o.box = box ? *box : ellipse.boundingBox();
             return o;
           }),
           py::arg("category"), py::arg("ellipse"), py::arg("score") = 1.0, py::arg("box") = py::none(),
           py::arg("source") = EllipseSource::Given, "`box` defaults to the ellipse's bounding box.")
      .def_readwrite("category", &Observation::category)
      .def_readwrite("score", &Observation::score)
      .def_readwrite("ellipse", &Observation::ellipse)
      .def_readwrite("box", &Observation::box)
      .def_readwrite("source", &Observation::source)
      .def_readwrite("regular", &Observation::regular)
      .def_readwrite("truncated", &Observation::truncated)
      .def("__repr__", [](const Observation& o) {
        return "Observation(category=" + std::to_string(o.category) + ", " +
               std::string(py::repr(py::cast(o.ellipse))) + ")";
      });

  py::class_<MapObject>(m, "MapObject", "A mapped object: id, category (COCO-80, 0-based), label and ellipsoid.")
      .def(py::init(
               [](int id, int category, const Ellipsoid& ellipsoid, std::string label, std::map<int, double> counts) {
                 MapObject o;
                 o.id = id, o.category = category, o.ellipsoid = ellipsoid, o.label = std::move(label);
                 o.category_counts = std::move(counts);
                 return o;
               }),
           py::arg("id"), py::arg("category"), py::arg("ellipsoid"), py::arg("label") = "",
           py::arg("category_counts") = std::map<int, double>{})
      .def_readwrite("id", &MapObject::id)
      .def_readwrite("category", &MapObject::category)
      .def_readwrite("label", &MapObject::label)
      .def_readwrite("ellipsoid", &MapObject::ellipsoid)
      .def_readwrite("category_counts", &MapObject::category_counts,
                     "How often mapping saw each category for this object (empty: `category` only).")
      .def("problem", &mapObjectProblem, py::arg("unit_metres") = 1.0,
           "Why relocalization cannot use the object, or '' when it can (unit_metres: its map's).")
      .def("__repr__", [](const MapObject& o) {
        return "MapObject(id=" + std::to_string(o.id) + ", category=" + std::to_string(o.category) + ", " +
               std::string(py::repr(py::cast(o.ellipsoid))) + ")";
      });

  py::class_<ObjectMap>(m, "ObjectMap",
                        "Objects (ellipsoids with categories) and optional 3D points. `objects` returns a copy: "
                        "assign a new list to change it.")
      .def(py::init([](std::vector<MapObject> objects, const py::handle& points) {
             ObjectMap map;
             map.objects = std::move(objects);
             if (!points.is_none()) map.points = rows<3>(points, "points");
             return map;
           }),
           py::arg("objects") = std::vector<MapObject>{}, py::arg("points") = py::none())
      .def_readwrite("objects", &ObjectMap::objects)
      .def_property(
          "points", [](const ObjectMap& map) { return rowsToArray<3>(map.points); },
          [](ObjectMap& map, const py::handle& h) { map.points = rows<3>(h, "points"); }, "(n, 3) map points.")
      .def_readwrite("camera_envelope", &ObjectMap::camera_envelope,
                     "Where the map's keyframes were taken (a CameraEnvelope; maps built by a Mapper have one), or "
                     "None. The relocalizer keeps the camera within it unless told otherwise.")
      .def_property(
          "unit_metres", [](const ObjectMap& map) { return map.unit_metres; },
          [](ObjectMap& map, double unit) {
            if (!validUnitMetres(unit)) throw py::value_error("unit_metres: expected a length of 1e-6 to 1e6 metres");
            map.unit_metres = unit;
          },
          "Metres per unit of the map's coordinates: 1 for a metric map; a monocular system's map (MapperOptions."
          "unit_metres) is in its own unit.")
      .def("__len__", [](const ObjectMap& map) { return map.objects.size(); })
      .def("__repr__", [](const ObjectMap& map) {
        return "ObjectMap(" + std::to_string(map.objects.size()) + " objects, " + std::to_string(map.points.size()) +
               " points)";
      });
}

}  // namespace

RleMask maskFromObject(const py::handle& h, const std::string& name) {
  if (py::isinstance<RleMask>(h)) return h.cast<RleMask>();
  if (py::isinstance<py::dict>(h)) return maskFromCoco(h.cast<py::dict>(), name);
  return maskFromArray(h, name);
}

std::vector<Keypoint> keypointsFrom(const py::handle& h) {
  std::vector<Keypoint> out;
  if (py::isinstance<py::array>(h)) {
    for (const Eigen::Vector3d& row : rows<3>(h, "keypoints (point_index, u, v)")) {
      if (row(0) < 0 || row(0) != std::floor(row(0)))
        badArgument("keypoints", "point indices must be whole numbers >= 0");
      out.push_back({static_cast<int>(row(0)), row.tail<2>()});
    }
    return out;
  }
  if (py::isinstance<py::str>(h) || !py::hasattr(h, "__iter__"))
    badArgument("keypoints", "expected Keypoint items or an (n, 3) array, got " + describe(h));
  for (const py::handle& item : h) {
    if (!py::isinstance<Keypoint>(item))
      badArgument("keypoints", "expected Keypoint items or an (n, 3) array, found " + describe(item));
    out.push_back(item.cast<Keypoint>());
  }
  return out;
}

std::vector<Detection> detectionList(const py::handle& h, const std::string& name) {
  std::vector<Detection> out;
  if (py::isinstance<py::str>(h) || !py::hasattr(h, "__iter__"))
    badArgument(name, "expected a list of Detection, got " + describe(h));
  for (const py::handle& item : h) {
    if (!py::isinstance<Detection>(item)) badArgument(name, "expected a list of Detection, found " + describe(item));
    out.push_back(item.cast<Detection>());
  }
  return out;
}

void bindData(py::module_& m) {
  bindMask(m);
  bindDetections(m);
  bindObservationAndMap(m);
}

}  // namespace ellreloc::python
