/// \file bind_sim.cpp
/// `ellreloc.sim`: seeded synthetic scenes, rendering, detector and mapper noise, and whole
/// simulated sequences on disk, so a notebook can make data with known answers.

#include <pybind11/stl.h>

#include <random>

#include "bindings.hpp"
#include "convert.hpp"
#include "ellreloc/sim/map_observations.hpp"
#include "ellreloc/sim/noise.hpp"
#include "ellreloc/sim/render.hpp"
#include "ellreloc/sim/scene.hpp"
#include "ellreloc/sim/writer.hpp"

namespace ellreloc::python {
namespace {

sim::ScenePreset presetFrom(const py::handle& h) {
  if (py::isinstance<sim::ScenePreset>(h)) return h.cast<sim::ScenePreset>();
  sim::ScenePreset p;
  if (py::isinstance<py::str>(h) && sim::parsePreset(h.cast<std::string>(), &p)) return p;
  badArgument("preset", "expected 'office', 'cluttered' or 'sparse', got " + std::string(py::repr(h)));
}

sim::NoiseLevel noiseLevelFrom(const py::handle& h) {
  if (py::isinstance<sim::NoiseLevel>(h)) return h.cast<sim::NoiseLevel>();
  sim::NoiseLevel n;
  if (py::isinstance<py::str>(h) && sim::parseNoiseLevel(h.cast<std::string>(), &n)) return n;
  badArgument("noise", "expected 'none', 'realistic' or 'hard', got " + std::string(py::repr(h)));
}

sim::NoiseModel noiseFrom(const py::handle& h) {
  if (py::isinstance<sim::NoiseModel>(h)) return h.cast<sim::NoiseModel>();
  return sim::NoiseModel::preset(noiseLevelFrom(h));
}

/// An array that shares the frame's memory (its base keeps the frame alive), made read-only.
template <typename T>
py::array_t<T> readOnlyView(py::array_t<T> view) {
  view.attr("setflags")(py::arg("write") = false);
  return view;
}

void bindScene(py::module_& s) {
  py::enum_<sim::ScenePreset>(s, "ScenePreset")
      .value("office", sim::ScenePreset::Office, "~20 objects of varied categories")
      .value("cluttered", sim::ScenePreset::Cluttered, "~40 objects, many of one category")
      .value("sparse", sim::ScenePreset::Sparse, "~6 objects");
  py::class_<sim::Scene>(s, "Scene", "A synthetic room: objects on the floor, tables and a shelf (z up, floor z = 0).")
      .def("ground_truth_map", &sim::Scene::groundTruthMap,
           "The true ellipsoids (inscribed in the objects' cuboids), categories and points.")
      .def_property_readonly("object_count", [](const sim::Scene& sc) { return sc.objects.size(); })
      .def_property_readonly("points", [](const sim::Scene& sc) { return rowsToArray<3>(sc.points); })
      .def_readonly("room_half_size", &sim::Scene::room_half_size);
  s.def(
      "make_scene", [](const py::handle& preset, uint64_t seed) { return sim::makeScene(presetFrom(preset), seed); },
      py::arg("preset") = "office", py::arg("seed") = 0,
      "A scene for a preset name; same preset and seed, same scene.");
  s.def("mapping_trajectory", &sim::mappingTrajectory, py::arg("scene"), py::arg("frames"),
        "World->camera poses of a loop around the room at eye height, looking in.");
  s.def("query_trajectory", &sim::queryTrajectory, py::arg("scene"), py::arg("frames"), py::arg("seed") = 0,
        "World->camera poses with strong changes of viewpoint from the mapping loop.");
}

void bindRendering(py::module_& s) {
  py::class_<sim::RenderedFrame>(s, "RenderedFrame")
      .def_readonly("width", &sim::RenderedFrame::width)
      .def_readonly("height", &sim::RenderedFrame::height)
      .def_property_readonly(
          "depth",
          [](const py::object& self) {
            const auto& f = self.cast<const sim::RenderedFrame&>();
            return readOnlyView(py::array_t<float>({f.height, f.width}, f.depth.data(), self));
          },
          "(height, width) float32 metres along the optical axis; 0 = no surface. A read-only view of the frame.")
      .def_property_readonly(
          "instance",
          [](const py::object& self) {
            const auto& f = self.cast<const sim::RenderedFrame&>();
            return readOnlyView(py::array_t<int16_t>({f.height, f.width}, f.instance.data(), self));
          },
          "(height, width) int16: the object index of each pixel, -1 for none. A read-only view of the frame.")
      .def_readonly("masks", &sim::RenderedFrame::masks, "per object: its visible pixels as an RleMask")
      .def_readonly("boxes", &sim::RenderedFrame::boxes, "per object: the box of its visible pixels")
      .def_readonly("visible_pixels", &sim::RenderedFrame::visible_pixels);
  s.def("render", &sim::render, py::arg("scene"), py::arg("camera"), py::arg("pose"),
        py::call_guard<py::gil_scoped_release>(), "Ray-casts the scene from a world->camera pose.");

  py::enum_<sim::NoiseLevel>(s, "NoiseLevel")
      .value("none", sim::NoiseLevel::None)
      .value("realistic", sim::NoiseLevel::Realistic)
      .value("hard", sim::NoiseLevel::Hard);
  py::class_<sim::NoiseModel>(s, "NoiseModel", "A detector's, a depth sensor's and a mapper's errors.")
      .def(py::init<>())
      .def_static(
          "preset", [](const py::handle& level) { return sim::NoiseModel::preset(noiseLevelFrom(level)); },
          py::arg("level"))
      .def_readwrite("mask_boundary_px", &sim::NoiseModel::mask_boundary_px)
      .def_readwrite("mask_flip_rate", &sim::NoiseModel::mask_flip_rate)
      .def_readwrite("box_jitter_px", &sim::NoiseModel::box_jitter_px)
      .def_readwrite("miss_rate", &sim::NoiseModel::miss_rate)
      .def_readwrite("false_positives", &sim::NoiseModel::false_positives)
      .def_readwrite("label_confusion", &sim::NoiseModel::label_confusion)
      .def_readwrite("depth_sigma_at_2m", &sim::NoiseModel::depth_sigma_at_2m)
      .def_readwrite("min_visible_pixels", &sim::NoiseModel::min_visible_pixels)
      .def_readwrite("keypoint_sigma_px", &sim::NoiseModel::keypoint_sigma_px)
      .def_readwrite("keypoint_outliers", &sim::NoiseModel::keypoint_outliers)
      .def_readwrite("map_centre_sigma", &sim::NoiseModel::map_centre_sigma)
      .def_readwrite("map_axis_sigma", &sim::NoiseModel::map_axis_sigma)
      .def_readwrite("map_yaw_sigma_deg", &sim::NoiseModel::map_yaw_sigma_deg);
}

void bindNoise(py::module_& s) {
  s.def(
      "detect",
      [](const sim::Scene& scene, const sim::RenderedFrame& frame, const py::handle& noise, uint64_t seed) {
        const sim::NoiseModel n = noiseFrom(noise);
        std::mt19937_64 rng(seed);
        return sim::detect(scene, frame, n, rng);
      },
      py::arg("scene"), py::arg("frame"), py::arg("noise") = "realistic", py::arg("seed") = 0,
      "Detections (box + mask, object_id = the object's index) of a rendered frame, with noise.");
  s.def(
      "keypoints",
      [](const sim::Scene& scene, const sim::RenderedFrame& frame, const Intrinsics& K, const Pose& pose,
         const py::handle& noise, uint64_t seed) {
        const sim::NoiseModel n = noiseFrom(noise);
        std::mt19937_64 rng(seed);
        return sim::keypoints(scene, frame, K, pose, n, rng);
      },
      py::arg("scene"), py::arg("frame"), py::arg("camera"), py::arg("pose"), py::arg("noise") = "realistic",
      py::arg("seed") = 0, "Keypoints matched to the scene's points, with pixel noise and outliers.");
  s.def(
      "noisy_depth",
      [](const sim::RenderedFrame& frame, const py::handle& noise, uint64_t seed) {
        const sim::NoiseModel n = noiseFrom(noise);
        std::mt19937_64 rng(seed);
        DepthImage d = sim::noisyDepth(frame, n, rng);
        return adoptVector(std::move(d.metres), {d.height, d.width});
      },
      py::arg("frame"), py::arg("noise") = "realistic", py::arg("seed") = 0,
      "The frame's depth with noise, (height, width) float32 metres.");
  s.def(
      "perturb_map",
      [](const ObjectMap& map, const py::handle& noise, uint64_t seed) {
        return sim::perturbMap(map, noiseFrom(noise), seed);
      },
      py::arg("map"), py::arg("noise") = "realistic", py::arg("seed") = 0,
      "The map with a mapper's errors (centre, axes, yaw).");
  s.def(
      "observe_map",
      [](const ObjectMap& map, const Intrinsics& K, const Pose& pose, double centre_sigma_px, double axis_sigma,
         bool inside_image_only, int max_observations, uint64_t seed) {
        sim::MapObservationOptions o;
        o.centre_sigma_px = centre_sigma_px, o.axis_sigma = axis_sigma;
        o.inside_image_only = inside_image_only, o.max_observations = max_observations;
        std::mt19937 rng(static_cast<std::mt19937::result_type>(seed));
        std::vector<int> objects;
        std::vector<Observation> obs = sim::observeMap(map, K, pose, o, &rng, &objects);
        return py::make_tuple(obs, objects);
      },
      py::arg("map"), py::arg("camera"), py::arg("pose"), py::arg("centre_sigma_px") = 0.0, py::arg("axis_sigma") = 0.0,
      py::arg("inside_image_only") = true, py::arg("max_observations") = 0, py::arg("seed") = 0,
      "(observations, object indices): the projected ellipses of the map's objects seen from `pose`, with "
      "optional Gaussian noise on centres (px) and axes (relative).");
}

void bindWriter(py::module_& s) {
  py::class_<sim::SimulationSummary>(s, "SimulationSummary")
      .def_readonly("files", &sim::SimulationSummary::files)
      .def_readonly("objects", &sim::SimulationSummary::objects)
      .def_readonly("mapping_frames", &sim::SimulationSummary::mapping_frames)
      .def_readonly("query_frames", &sim::SimulationSummary::query_frames)
      .def_readonly("query_detections", &sim::SimulationSummary::query_detections);
  s.def(
      "write_simulation",
      [](const py::handle& dir, const py::handle& preset, uint64_t seed, const py::handle& noise, int mapping_frames,
         int query_frames, bool write_rgb) {
        sim::SimulationOptions o;
        o.preset = presetFrom(preset), o.seed = seed, o.noise = noiseLevelFrom(noise);
        if (mapping_frames < 1 || query_frames < 1) badArgument("mapping_frames, query_frames", "must be at least 1");
        o.mapping_frames = mapping_frames, o.query_frames = query_frames, o.write_rgb = write_rgb;
        const std::string path = pathFrom(dir);
        py::gil_scoped_release release;
        return sim::writeSimulation(path, o);
      },
      py::arg("dir"), py::arg("preset") = "office", py::arg("seed") = 0, py::arg("noise") = "realistic",
      py::arg("mapping_frames") = 60, py::arg("query_frames") = 100, py::arg("write_rgb") = true,
      "Writes a simulated sequence as `ellreloc simulate` does (camera, maps, mapping and query folders).");
}

}  // namespace

void bindSim(py::module_& s) {
  bindScene(s);
  bindRendering(s);
  bindNoise(s);
  bindWriter(s);
}

}  // namespace ellreloc::python
