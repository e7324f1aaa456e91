#pragma once
/// \file bindings.hpp
/// One function per library component adds its classes and functions to the module; module.cpp
/// calls them in dependency order (core first: the others' signatures use its types).

#include <pybind11/pybind11.h>

#include <string>
#include <vector>

#include "ellreloc/core/detection.hpp"
#include "ellreloc/core/observation.hpp"
#include "ellreloc/observe/observe.hpp"

namespace ellreloc::python {

namespace py = pybind11;

void bindCore(py::module_& m);
void bindData(py::module_& m);
void bindObserve(py::module_& m);
void bindPose(py::module_& m);
void bindMapping(py::module_& m);
void bindIo(py::module_& m);
void bindSim(py::module_& sim);

/// A Box, or (x1, y1, x2, y2) as any array-like; ValueError naming `name` otherwise (bind_core.cpp).
Box boxFrom(const py::handle& h, const std::string& name);

/// A mask given as a 2-D bool/uint8 numpy array, a COCO RLE dict ({"size": [h, w], "counts":
/// str, bytes or list}) or an RleMask; ValueError naming `name` otherwise (bind_data.cpp).
RleMask maskFromObject(const py::handle& h, const std::string& name);

/// Keypoints from Keypoint items or an (n, 3) array of (point_index, u, v) (bind_data.cpp).
std::vector<Keypoint> keypointsFrom(const py::handle& h);

/// A policy given as ObservationPolicy or as its name; ValueError otherwise (bind_observe.cpp).
ObservationPolicy policyFrom(const py::handle& h);

/// Detections from a list of Detection; ValueError naming `name` otherwise (bind_data.cpp).
std::vector<Detection> detectionList(const py::handle& h, const std::string& name);

}  // namespace ellreloc::python
