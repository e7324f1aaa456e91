/// \file bind_mapping.cpp
/// The object mapper (RGB-D keyframes with masks, or boxes and poses) and the map quality
/// measure. The GIL is released while keyframes are integrated and maps built.

#include <pybind11/stl.h>

#include <array>
#include <vector>

#include "bindings.hpp"
#include "convert.hpp"
#include "ellreloc/mapping/map_quality.hpp"
#include "ellreloc/mapping/mapper.hpp"

namespace ellreloc::python {
namespace {

/// A depth image in metres from a (height, width) numpy array: uint16 in `units_per_metre`
/// units (TUM: 5000), or float32/float64 already in metres; 0 = no reading.
DepthImage depthFrom(const py::handle& h, const Intrinsics& K, double units_per_metre) {
  if (!py::isinstance<py::array>(h))
    badArgument("depth", "expected a 2-D uint16 or float numpy array, got " + describe(h));
  const auto a = py::reinterpret_borrow<py::array>(h);
  const char kind = a.dtype().kind();
  const bool units = kind == 'u' && a.dtype().itemsize() == 2;
  if ((!units && kind != 'f') || a.ndim() != 2)
    badArgument("depth", "expected a 2-D uint16 or float numpy array, got " + describe(h));
  if (a.shape(0) != K.height || a.shape(1) != K.width)
    badArgument("depth", "is " + std::to_string(a.shape(1)) + "x" + std::to_string(a.shape(0)) +
                             " pixels, the camera " + std::to_string(K.width) + "x" + std::to_string(K.height));
  if (!(units_per_metre > 0) || !std::isfinite(units_per_metre)) badArgument("depth_scale", "must be positive");
  DepthImage d;
  d.width = K.width, d.height = K.height;
  d.metres.resize(static_cast<size_t>(K.width) * K.height);
  if (units) {
    const auto v = py::array_t<uint16_t, py::array::forcecast>::ensure(a).unchecked<2>();
    for (int y = 0; y < d.height; ++y)
      for (int x = 0; x < d.width; ++x) d.metres[static_cast<size_t>(y) * d.width + x] = v(y, x) / units_per_metre;
  } else {
    const auto v = py::array_t<float, py::array::forcecast>::ensure(a).unchecked<2>();
    for (int y = 0; y < d.height; ++y)
      for (int x = 0; x < d.width; ++x) {
        const float z = v(y, x);
        d.metres[static_cast<size_t>(y) * d.width + x] = std::isfinite(z) && z > 0 ? z : 0.0f;
      }
  }
  return d;
}

void bindMapperOptions(py::module_& m) {
  py::enum_<MappingMode>(m, "MappingMode")
      .value("voxel", MappingMode::Voxel, "RGB-D keyframes with masks (the paper)")
      .value("boxes", MappingMode::Boxes, "boxes and poses only (monocular)");
  py::class_<VoxelOptions>(m, "VoxelOptions")
      .def(py::init<>())
      .def_readwrite("voxel_size", &VoxelOptions::voxel_size)
      .def_readwrite("hit_probability", &VoxelOptions::hit_probability)
      .def_readwrite("miss_probability", &VoxelOptions::miss_probability)
      .def_readwrite("occupied_probability", &VoxelOptions::occupied_probability)
      .def_readwrite("depth_tolerance", &VoxelOptions::depth_tolerance)
      .def_readwrite("min_depth", &VoxelOptions::min_depth)
      .def_readwrite("max_depth", &VoxelOptions::max_depth)
      .def_readwrite("pixel_stride", &VoxelOptions::pixel_stride)
      .def_readwrite("max_voxels", &VoxelOptions::max_voxels);
  py::class_<TrackingOptions>(m, "TrackingOptions")
      .def(py::init<>())
      .def_readwrite("label_weight", &TrackingOptions::label_weight)
      .def_readwrite("iou_weight", &TrackingOptions::iou_weight)
      .def_readwrite("min_iou", &TrackingOptions::min_iou)
      .def_readwrite("min_iou_other_label", &TrackingOptions::min_iou_other_label)
      .def_readwrite("depth_margin", &TrackingOptions::depth_margin)
      .def_readwrite("match_radius", &TrackingOptions::match_radius)
      .def_readwrite("match_ratio", &TrackingOptions::match_ratio);
  py::enum_<YawMethod>(m, "YawMethod")
      .value("min_area_rectangle", YawMethod::MinAreaRectangle, "the smallest rectangle around the footprint (default)")
      .value("pca", YawMethod::Pca, "the main axis of the footprint's PCA (the paper)");
  py::class_<EllipsoidBuilderOptions>(m, "EllipsoidBuilderOptions",
                                      "How a voxel object becomes an upright ellipsoid (mapping/ellipsoid_builder.hpp).")
      .def(py::init<>())
      .def_property(
          "up", [](const EllipsoidBuilderOptions& o) { return toArray(o.up); },
          [](EllipsoidBuilderOptions& o, const py::handle& up) { o.up = vector<3>(up, "up"); },
          "against gravity, in world coordinates")
      .def_readwrite("yaw", &EllipsoidBuilderOptions::yaw)
      .def_readwrite("low_percentile", &EllipsoidBuilderOptions::low_percentile)
      .def_readwrite("high_percentile", &EllipsoidBuilderOptions::high_percentile)
      .def_readwrite("extent_padding", &EllipsoidBuilderOptions::extent_padding)
      .def_readwrite("min_points", &EllipsoidBuilderOptions::min_points);
  py::class_<MapperOptions>(m, "MapperOptions", "The mapper's options (mapping/mapper.hpp documents each).")
      .def(py::init<>())
      .def_readwrite("mode", &MapperOptions::mode)
      .def_readwrite("voxels", &MapperOptions::voxels)
      .def_readwrite("tracking", &MapperOptions::tracking)
      .def_readwrite("ellipsoid", &MapperOptions::ellipsoid)
      .def_readwrite("min_observations", &MapperOptions::min_observations)
      .def_readwrite("prune_probability", &MapperOptions::prune_probability)
      .def_readwrite("ellipsoid_min_probability", &MapperOptions::ellipsoid_min_probability)
      .def_readwrite("track_window", &MapperOptions::track_window)
      .def_readwrite("candidate_lifetime", &MapperOptions::candidate_lifetime)
      .def_readwrite("min_score", &MapperOptions::min_score)
      .def_readwrite("estimate_up_from_floor", &MapperOptions::estimate_up_from_floor)
      .def_readwrite("min_mask_pixels", &MapperOptions::min_mask_pixels)
      .def_readwrite("unit_metres", &MapperOptions::unit_metres,
                     "boxes mode: the length of the keyframe poses' unit in metres (a monocular SLAM map's own)")
      .def_readwrite("lens", &MapperOptions::lens,
                     "the Lens of the keyframes' raw images: boxes undistorted, masks and depth images resampled")
      .def("validate", &MapperOptions::validate);
}

void bindMapperClass(py::module_& m) {
  py::class_<KeyframeReport>(m, "KeyframeReport", "What one keyframe did.")
      .def_readonly("used", &KeyframeReport::used)
      .def_readonly("tracked_2d", &KeyframeReport::tracked_2d)
      .def_readonly("matched_3d", &KeyframeReport::matched_3d)
      .def_readonly("new_objects", &KeyframeReport::new_objects)
      .def_readonly("ignored", &KeyframeReport::ignored)
      .def_readonly("object_ids", &KeyframeReport::object_ids,
                    "For each detection, in the order given: the id of the object it joined (as map() names it once "
                    "it is in the map), or -1 when ignored; Mapper.current_object_id follows later joins.");
  py::class_<Cuboid>(m, "Cuboid", "The yaw-aligned cuboid a voxel object's ellipsoid is inscribed in.")
      .def_property_readonly("center", [](const Cuboid& c) { return toArray(c.center); })
      .def_property_readonly(
          "half", [](const Cuboid& c) { return toArray(c.half); }, "half extents")
      .def_property_readonly(
          "rotation", [](const Cuboid& c) { return toArray(c.rotation); }, "its axes, as columns")
      .def(
          "corners",
          [](const Cuboid& c) {
            const std::array<Eigen::Vector3d, 8> k = c.corners();
            return rowsToArray(std::vector<Eigen::Vector3d>(k.begin(), k.end()));
          },
          "the eight corners, (8, 3)");
  py::class_<MappedObject>(m, "MappedObject", "A mapped object with what the mapper knows about it.")
      .def_readonly("object", &MappedObject::object, "id, category, label histogram, ellipsoid")
      .def_readonly("cuboid", &MappedObject::cuboid, "voxel mode: the cuboid its ellipsoid is inscribed in")
      .def_readonly("observations", &MappedObject::observations)
      .def_readonly("depth_from_size", &MappedObject::depth_from_size,
                    "boxes mode: placed by its category's typical size (too narrow a baseline)")
      .def_readonly("voxels", &MappedObject::voxels)
      .def_readonly("memory_bytes", &MappedObject::memory_bytes);
  py::class_<MapperStats>(m, "MapperStats")
      .def_readonly("keyframes", &MapperStats::keyframes)
      .def_property_readonly("up", [](const MapperStats& s) { return toArray(s.up); })
      .def_readonly("objects", &MapperStats::objects)
      .def_readonly("candidates", &MapperStats::candidates)
      .def_readonly("placed_by_size", &MapperStats::placed_by_size)
      .def_readonly("voxels", &MapperStats::voxels)
      .def_readonly("memory_bytes", &MapperStats::memory_bytes);
  py::class_<Mapper>(m, "Mapper",
                     "Builds an object map from keyframes: voxel mode (depth + masks, the paper) or boxes mode "
                     "(boxes and poses).")
      .def(py::init([](const Intrinsics& K, const std::optional<MapperOptions>& options, const py::handle& mode) {
             MapperOptions o = options.value_or(MapperOptions{});
             if (!mode.is_none()) {
               if (py::isinstance<MappingMode>(mode))
                 o.mode = mode.cast<MappingMode>();
               else if (!py::isinstance<py::str>(mode) || !parseMappingMode(mode.cast<std::string>(), &o.mode))
                 badArgument("mode", "expected 'voxel' or 'boxes', got " + std::string(py::repr(mode)));
             }
             return std::make_unique<Mapper>(K, o);
           }),
           py::arg("camera"), py::arg("options") = py::none(), py::arg("mode") = py::none())
      .def(
          "add_keyframe",
          [](Mapper& mapper, const Pose& pose, const py::handle& detections, const py::handle& depth,
             double depth_scale) {
            const std::vector<Detection> dets = detectionList(detections, "detections");
            std::optional<DepthImage> d;
            if (!depth.is_none()) d = depthFrom(depth, mapper.intrinsics(), depth_scale);
            py::gil_scoped_release release;
            return mapper.addKeyframe(pose, dets, d ? &*d : nullptr);
          },
          py::arg("pose"), py::arg("detections"), py::arg("depth") = py::none(), py::arg("depth_scale") = 5000.0,
          "Adds a keyframe: world->camera pose, detections, and (voxel mode) the depth image, (height, width) "
          "uint16 in depth_scale units per metre (TUM: 5000) or float metres. On error the map is unchanged.")
      .def("finish", &Mapper::finish, py::call_guard<py::gil_scoped_release>(),
           "Boxes mode: refits every object whose views grew. Call after the last keyframe.")
      .def("update_keyframe_poses", &Mapper::updateKeyframePoses, py::call_guard<py::gil_scoped_release>(),
           py::arg("poses"),
           "The host moved its keyframes (bundle adjustment, loop closure): the world->camera pose of every "
           "keyframe added so far, in order. Boxes mode refits every object at the new poses; voxel mode moves "
           "each object with the keyframe that saw it last; objects that now coincide are joined. On error the map "
           "is unchanged.")
      .def("current_object_id", &Mapper::currentObjectId, py::arg("id"),
           "The id an object a KeyframeReport named has now (objects found to be one are joined, the younger "
           "into the older), or None for a candidate forgotten before it was confirmed.")
      .def("estimated_unit_metres", &Mapper::estimatedUnitMetres, py::arg("min_objects") = 5,
           "Boxes mode: the poses' unit in metres that the triangulated objects' sizes tell (None with fewer than "
           "min_objects of them): map again with it as MapperOptions.unit_metres until it settles.")
      .def("map", &Mapper::map, py::call_guard<py::gil_scoped_release>(), "The current object map.")
      .def("objects", &Mapper::objects, py::call_guard<py::gil_scoped_release>(),
           "The objects in the map with what the mapper knows about each (MappedObject), in map order.")
      .def_property_readonly("stats", &Mapper::stats)
      .def_property_readonly("camera", &Mapper::intrinsics)
      .def_property_readonly("options", &Mapper::options, "A copy.");
}

}  // namespace

void bindMapping(py::module_& m) {
  bindMapperOptions(m);
  bindMapperClass(m);
  py::class_<MapQuality>(m, "MapQuality")
      .def_readonly("frames", &MapQuality::frames)
      .def_readonly("boxes", &MapQuality::boxes)
      .def_readonly("explained", &MapQuality::explained)
      .def_readonly("median_best_iou", &MapQuality::median_best_iou)
      .def_readonly("mean_best_iou", &MapQuality::mean_best_iou);
  m.def(
      "map_quality",
      [](const ObjectMap& map, const Intrinsics& K, const py::handle& frames, double min_score) {
        std::vector<PosedDetections> posed;
        for (const py::handle& item : frames) {
          if (!py::isinstance<py::tuple>(item) || py::len(item) != 2)
            badArgument("frames", "expected (Pose, [Detection]) pairs, found " + describe(item));
          const auto pair = item.cast<py::tuple>();
          posed.push_back({pair[0].cast<Pose>(), detectionList(pair[1], "frames")});
        }
        py::gil_scoped_release release;
        return measureMapQuality(map, K, posed, min_score);
      },
      py::arg("map"), py::arg("camera"), py::arg("frames"), py::arg("min_score") = 0.0,
      "How well a map explains held-out boxes: for each box of each (pose, detections) frame, the best IoU "
      "with the bounding box of a projected object of its category; the median is `ellreloc map`'s quality.");
}

}  // namespace ellreloc::python
