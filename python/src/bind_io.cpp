/// \file bind_io.cpp
/// Files of docs/formats.md: cameras, maps, detections, TUM trajectories and depth PNGs. Paths
/// may be str or os.PathLike. Unreadable files raise OSError, malformed ones ValueError.

#include <pybind11/stl.h>

#include "bindings.hpp"
#include "convert.hpp"
#include "ellreloc/io/camera.hpp"
#include "ellreloc/io/detections.hpp"
#include "ellreloc/io/map.hpp"
#include "ellreloc/io/overlay.hpp"
#include "ellreloc/io/rgbd.hpp"
#include "ellreloc/io/trajectory.hpp"

namespace ellreloc::python {
namespace {

io::StampedPose stampedFrom(const py::handle& h) {
  if (py::isinstance<io::StampedPose>(h)) return h.cast<io::StampedPose>();
  if (py::isinstance<py::tuple>(h) && py::len(h) == 2) {
    const auto t = h.cast<py::tuple>();
    io::StampedPose p;
    p.pose = t[1].cast<Pose>();
    if (py::isinstance<py::str>(t[0])) {
      p.stamp = t[0].cast<std::string>();
      const std::optional<double> v = timestampFromText(p.stamp);
      if (!v) badArgument("poses", "timestamp '" + p.stamp + "' is not a finite number");
      p.timestamp = *v;
    } else {
      p.timestamp = t[0].cast<double>();
    }
    return p;
  }
  badArgument("poses", "expected StampedPose or (timestamp, Pose) items, found " + describe(h));
}

void bindTrajectory(py::module_& m) {
  py::class_<io::StampedPose>(m, "StampedPose", "A timestamped world->camera pose of a TUM trajectory.")
      .def(py::init([](double t, const Pose& p, std::string stamp) {
             return io::StampedPose{t, p, std::move(stamp)};
           }),
           py::arg("timestamp"), py::arg("pose"), py::arg("stamp") = "")
      .def_readwrite("timestamp", &io::StampedPose::timestamp)
      .def_readwrite("pose", &io::StampedPose::pose)
      .def_readwrite("stamp", &io::StampedPose::stamp,
                     "the timestamp's text as read ('' = write the shortest exact decimal)")
      .def("__repr__", [](const io::StampedPose& p) {
        return "StampedPose(" + (p.stamp.empty() ? std::to_string(p.timestamp) : p.stamp) + ", " +
               std::string(py::repr(py::cast(p.pose))) + ")";
      });
  m.def(
      "read_trajectory",
      [](const py::handle& path, bool allow_empty) { return io::readTumTrajectory(pathFrom(path), allow_empty); },
      py::arg("path"), py::arg("allow_empty") = false,
      "A TUM trajectory (camera->world on disk) as StampedPose items holding world->camera poses.");
  m.def(
      "write_trajectory",
      [](const py::handle& path, const py::handle& poses) {
        std::vector<io::StampedPose> list;
        for (const py::handle& item : poses) list.push_back(stampedFrom(item));
        io::writeTumTrajectory(pathFrom(path), list);
      },
      py::arg("path"), py::arg("poses"),
      "Writes StampedPose or (timestamp, Pose) items as a TUM trajectory, atomically; a str timestamp is "
      "written as given.");
  m.def("find_nearest", &io::findNearest, py::arg("poses"), py::arg("timestamp"), py::arg("tolerance") = 0.02,
        "Index of the pose nearest in time, if within `tolerance` seconds, else None (of equally near, the last). "
        "Reads every pose: for many lookups, time_index(poses).");
  py::class_<io::TimeIndex>(m, "TimeIndex", "Times indexed once for many lookups of the nearest.")
      .def(py::init<std::vector<double>>(), py::arg("times"))
      .def("nearest", &io::TimeIndex::nearest, py::arg("timestamp"), py::arg("tolerance") = 0.02,
           "Position of the time nearest to `timestamp`, if within `tolerance` seconds, else None (of equally "
           "near, the last).");
  m.def("time_index", &io::timeIndex, py::arg("poses"),
        "The poses' timestamps as a TimeIndex: index.nearest(t, tolerance) is find_nearest(poses, t, tolerance).");
}

void bindFiles(py::module_& m) {
  m.def(
      "read_camera", [](const py::handle& path) { return io::readCamera(pathFrom(path)); }, py::arg("path"),
      "Intrinsics from ORB-SLAM YAML or JSON.");
  m.def(
      "read_distortion", [](const py::handle& path) { return io::readDistortion(pathFrom(path)); }, py::arg("path"),
      "The lens distortion of a camera file (Camera.k1 ... or \"k1\" ...; 0 where left out).");
  m.def(
      "read_lens", [](const py::handle& path) { return io::readLens(pathFrom(path)); }, py::arg("path"),
      "Intrinsics and distortion of a camera file, for detections made on its raw images (ObserveOptions.lens).");
  m.def(
      "write_camera", [](const py::handle& path, const Intrinsics& K) { io::writeCamera(pathFrom(path), K); },
      py::arg("path"), py::arg("camera"), "JSON for a .json path, ORB-SLAM YAML otherwise.");
  m.def(
      "read_map",
      [](const py::handle& path) {
        std::vector<std::string> warnings;
        ObjectMap map = io::readMap(pathFrom(path), &warnings);
        const py::object warn = py::module_::import("warnings").attr("warn");
        for (const std::string& w : warnings) warn(w, py::module_::import("builtins").attr("UserWarning"), 2);
        return map;
      },
      py::arg("path"),
      "A JSON or OA-SLAM text map. Objects that cannot be used are left out with a UserWarning naming them.");
  m.def(
      "write_map", [](const py::handle& path, const ObjectMap& map) { io::writeMap(pathFrom(path), map); },
      py::arg("path"), py::arg("map"), "Writes the JSON map atomically.");
  m.def(
      "read_detections",
      [](const py::handle& path) {
        const std::string p = pathFrom(path);
        py::gil_scoped_release release;
        return io::readDetections(p);
      },
      py::arg("path"), "A detections file as a list of DetectionFrame.");
  m.def(
      "write_detections",
      [](const py::handle& path, const std::vector<DetectionFrame>& frames) {
        io::writeDetections(pathFrom(path), frames);
      },
      py::arg("path"), py::arg("frames"), "Writes a detections file atomically (masks as compressed COCO strings).");
  m.def(
      "read_depth_png",
      [](const py::handle& path, double units_per_metre) {
        DepthImage d = io::readDepthPng(pathFrom(path), units_per_metre);
        return adoptVector(std::move(d.metres), {d.height, d.width});
      },
      py::arg("path"), py::arg("units_per_metre") = io::kTumDepthUnitsPerMetre,
      "A 16-bit depth PNG as a (height, width) float32 array in metres (0 = no reading).");
  m.def(
      "write_overlay",
      [](const py::handle& path, const Intrinsics& K, const ObjectMap& map, std::vector<Observation> observations,
         const std::optional<Pose>& pose, const std::optional<Pose>& truth, std::vector<std::pair<int, int>> matches,
         std::vector<std::string> text, const py::handle& background, const std::optional<Lens>& lens) {
        io::OverlayContent c{std::move(observations), pose, truth, std::move(matches), std::move(text)};
        const std::string out = pathFrom(path), image = background.is_none() ? "" : pathFrom(background);
        py::gil_scoped_release release;
        io::writeOverlay(out, K, map, c, image, lens ? &*lens : nullptr);
      },
      py::arg("path"), py::arg("camera"), py::arg("map"), py::arg("observations"), py::arg("pose") = py::none(),
      py::arg("truth") = py::none(), py::arg("matches") = std::vector<std::pair<int, int>>{},
      py::arg("text") = std::vector<std::string>{}, py::arg("background") = py::none(), py::arg("lens") = py::none(),
      "A PNG picture of one relocalization (what `ellreloc relocalize --overlays` draws): observations in green, "
      "the map projected with `pose` in orange, `matches` ((observation, object index) pairs, e.g. "
      "[(m.observation, m.object) for m in result.matches]) in magenta, the map at `truth` in blue, `text` at "
      "the top left, over the `background` image or a blank canvas; with a `lens`, the background is a raw image "
      "of it and is undistorted first.");
  py::class_<io::Association>(m, "Association", "A line of a TUM association file.")
      .def_readonly("rgb_time", &io::Association::rgb_time)
      .def_readonly("rgb_path", &io::Association::rgb_path)
      .def_readonly("depth_time", &io::Association::depth_time)
      .def_readonly("depth_path", &io::Association::depth_path);
  m.def(
      "read_associations", [](const py::handle& path) { return io::readAssociations(pathFrom(path)); }, py::arg("path"),
      "A TUM association file; paths resolved against the file's folder.");
  py::class_<io::AssociationIndex>(m, "AssociationIndex",
                                   "Finds a colour image's line of an association file: the line naming it, else "
                                   "the one nearest in time within `tolerance` seconds (what `ellreloc map` does).")
      .def(py::init<std::vector<io::Association>, double>(), py::arg("associations"), py::arg("tolerance") = 0.02)
      .def(
          "find",
          [](const io::AssociationIndex& index, const py::handle& rgb_path, std::optional<double> rgb_time) {
            const io::Association* a = index.find(pathFrom(rgb_path), rgb_time);
            return a ? std::optional<io::Association>(*a) : std::nullopt;
          },
          py::arg("rgb_path"), py::arg("rgb_time") = py::none(),
          "The association of a colour image (its path, and its time when known); None when there is none.");
}

}  // namespace

void bindIo(py::module_& m) {
  bindTrajectory(m);
  bindFiles(m);
}

}  // namespace ellreloc::python
