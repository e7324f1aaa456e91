/// \file bind_observe.cpp
/// Detections -> observation ellipses: the policies, the regular-mask test and mask fitting.

#include <pybind11/stl.h>

#include "bindings.hpp"
#include "convert.hpp"
#include "ellreloc/core/camera.hpp"
#include "ellreloc/core/mask.hpp"
#include "ellreloc/observe/observe.hpp"

namespace ellreloc::python {

ObservationPolicy policyFrom(const py::handle& h) {
  if (py::isinstance<ObservationPolicy>(h)) return h.cast<ObservationPolicy>();
  ObservationPolicy p;
  if (py::isinstance<py::str>(h) && parseObservationPolicy(h.cast<std::string>(), &p)) return p;
  badArgument("policy", "expected 'solid', 'paper', 'bbox', 'mask' or 'given', got " + std::string(py::repr(h)));
}

namespace {

ObserveOptions optionsFrom(const std::optional<ObserveOptions>& options, const py::handle& policy) {
  ObserveOptions o = options.value_or(ObserveOptions{});
  if (!policy.is_none()) o.policy = policyFrom(policy);
  if (const std::string why = o.validate(); !why.empty()) badArgument("options", why);
  return o;
}

void bindObserveOptions(py::module_& m) {
  py::enum_<ObservationPolicy>(m, "ObservationPolicy", "Which ellipse a detection gives.")
      .value("solid", ObservationPolicy::Solid,
             "regular mask -> mask fit, a solid one (options.solid_min_solidity) -> hull fit, otherwise the box")
      .value("paper", ObservationPolicy::Paper, "regular mask -> mask fit, otherwise the box-inscribed ellipse")
      .value("bbox", ObservationPolicy::Bbox, "always the box-inscribed ellipse (OA-SLAM)")
      .value("mask", ObservationPolicy::Mask, "fit the mask whenever there is one")
      .value("given", ObservationPolicy::Given, "the detection's own ellipse");
  py::enum_<MaskFitMethod>(m, "MaskFitMethod", "How an ellipse is fitted to a mask.")
      .value("moments", MaskFitMethod::Moments, "same second moments as the mask")
      .value("direct", MaskFitMethod::Direct, "direct least squares on the outline")
      .value("quadrilateral", MaskFitMethod::Quadrilateral,
             "regular masks: the projectively inscribed ellipse of the quadrilateral")
      .value("hull", MaskFitMethod::Hull, "the image of the cuboid's inscribed ellipsoid, from the mask's convex hull");
  py::class_<RegularMaskOptions>(m, "RegularMaskOptions", "Thresholds of the regular-mask test (regular_mask.hpp).")
      .def(py::init<>())
      .def_readwrite("min_solidity", &RegularMaskOptions::min_solidity)
      .def_readwrite("min_fill", &RegularMaskOptions::min_fill)
      .def_readwrite("max_fill", &RegularMaskOptions::max_fill)
      .def_readwrite("noise_band_px", &RegularMaskOptions::noise_band_px)
      .def_readwrite("min_core_fill", &RegularMaskOptions::min_core_fill)
      .def_readwrite("max_corner_angle_deg", &RegularMaskOptions::max_corner_angle_deg)
      .def_readwrite("min_corner_angle_deg", &RegularMaskOptions::min_corner_angle_deg)
      .def_readwrite("min_pixels", &RegularMaskOptions::min_pixels)
      .def_readwrite("outline_tolerance", &RegularMaskOptions::outline_tolerance);
  py::class_<ObserveOptions>(m, "ObserveOptions")
      .def(py::init<>())
      .def_readwrite("policy", &ObserveOptions::policy)
      .def_readwrite("regular_fit", &ObserveOptions::regular_fit)
      .def_readwrite("irregular_fit", &ObserveOptions::irregular_fit)
      .def_readwrite("regular", &ObserveOptions::regular)
      .def_readwrite("border_px", &ObserveOptions::border_px)
      .def_readwrite(
          "solid_min_solidity", &ObserveOptions::solid_min_solidity,
          "policy 'solid': a mask the quadrilateral test turns down gets the hull fit when it covers at least "
          "this share of its convex hull")
      .def_readwrite("lens", &ObserveOptions::lens,
                     "the Lens of the raw images the detections were made on: each observation is moved to the "
                     "pinhole image; None: the detections are taken as pinhole")
      .def("validate", &ObserveOptions::validate, "'' when every threshold is in range, else the first that is not.");
}

void bindResults(py::module_& m) {
  py::enum_<ObserveStatus>(m, "ObserveStatus")
      .value("ok", ObserveStatus::Ok)
      .value("invalid_box", ObserveStatus::InvalidBox, "NaN, empty, or wholly outside the image")
      .value("no_ellipse", ObserveStatus::NoEllipse, "policy given without a valid ellipse")
      .value("invalid_options", ObserveStatus::InvalidOptions);
  py::class_<ObserveResult>(m, "ObserveResult")
      .def_readonly("status", &ObserveResult::status)
      .def_readonly("observation", &ObserveResult::observation, "None when there is none.")
      .def_readonly("note", &ObserveResult::note, "Why the mask was not used when the policy wanted it.");
  py::class_<RegularVerdict>(m, "RegularVerdict", "The regular-mask test's verdict and its diagnostics.")
      .def_readonly("regular", &RegularVerdict::regular, "both tests pass: the paper's regular object")
      .def_readonly("quadrilateral", &RegularVerdict::quadrilateral,
                    "the quadrilateral test passes: the four-corner quadrilateral describes the mask")
      .def_readonly("outline_vertices", &RegularVerdict::outline_vertices,
                    "vertices of the outline reduced by Douglas-Peucker (0 when the quadrilateral test failed)")
      .def_readonly("hull_vertices", &RegularVerdict::hull_vertices)
      .def_readonly("quad_vertices", &RegularVerdict::quad_vertices)
      .def_readonly("solidity", &RegularVerdict::solidity)
      .def_readonly("fill", &RegularVerdict::fill)
      .def_readonly("core_fill", &RegularVerdict::core_fill)
      .def_readonly("triangle_fill", &RegularVerdict::triangle_fill)
      .def_readonly("max_corner_angle_deg", &RegularVerdict::max_corner_angle_deg)
      .def_readonly("min_corner_angle_deg", &RegularVerdict::min_corner_angle_deg)
      .def_readonly("touches_border", &RegularVerdict::touches_border)
      .def_property_readonly("corners",
                             [](const RegularVerdict& v) {
                               return rowsToArray<2>(std::vector<Eigen::Vector2d>(v.corners.begin(), v.corners.end()));
                             })
      .def_property_readonly(
          "hull", [](const RegularVerdict& v) { return rowsToArray<2>(v.hull); },
          "the convex hull of the mask's pixel squares, an (n, 2) array clockwise on screen")
      .def("__bool__", [](const RegularVerdict& v) { return v.regular; });
}

void bindFunctions(py::module_& m) {
  m.def(
      "observe",
      [](const Detection& d, int width, int height, const py::handle& policy,
         const std::optional<ObserveOptions>& options) {
        if (width <= 0 || height <= 0) badArgument("width, height", "must be positive");
        return observeDetection(d, width, height, optionsFrom(options, policy));
      },
      py::arg("detection"), py::arg("width"), py::arg("height"), py::arg("policy") = py::none(),
      py::arg("options") = py::none(),
      "Observes one detection of a width x height image; `policy` (a name or ObservationPolicy) overrides "
      "options.policy (default 'solid').");
  m.def(
      "observe_frame",
      [](const py::handle& frame, const Intrinsics& K, const py::handle& policy,
         const std::optional<ObserveOptions>& options) {
        const std::vector<Detection> detections = py::isinstance<DetectionFrame>(frame)
                                                      ? frame.cast<const DetectionFrame&>().detections
                                                      : detectionList(frame, "frame");
        return observeDetections(detections, K.width, K.height, optionsFrom(options, policy));
      },
      py::arg("frame"), py::arg("camera"), py::arg("policy") = py::none(), py::arg("options") = py::none(),
      "The observations of a DetectionFrame (or a list of Detection), as `ellreloc relocalize` makes them: "
      "detections without one are left out.");
  m.def(
      "observation_from_box",
      [](int category, const Box& box, int width, int height, double score, double border_px) {
        return observationFromBox(category, score, box, width, height, border_px);
      },
      py::arg("category"), py::arg("box"), py::arg("width"), py::arg("height"), py::arg("score") = 1.0,
      py::arg("border_px") = 2.0, "The box-inscribed ellipse as an observation; None for an invalid or empty box.");
  m.def(
      "observation_from_mask",
      [](const py::handle& mask, int category, double score, const std::optional<Box>& box, const py::handle& policy,
         const std::optional<ObserveOptions>& options) {
        Detection d;
        d.mask = maskFromObject(mask, "mask");
        if (!d.mask->isConsistent()) badArgument("mask", "its runs do not add up to height x width");
        d.category_id = category;
        d.score = score;
        d.bbox = box ? *box : maskBox(*d.mask).value_or(Box());
        ObserveOptions o = optionsFrom(options, policy.is_none() ? py::str("mask") : policy);
        return observeDetection(d, d.mask->width, d.mask->height, o);
      },
      py::arg("mask"), py::arg("category") = 0, py::arg("score") = 1.0, py::arg("box") = py::none(),
      py::arg("policy") = py::none(), py::arg("options") = py::none(),
      "Observes an instance mask (numpy bool/uint8 array, COCO RLE dict or RleMask) whose size is the image's; "
      "the box defaults to the mask's. Policy 'mask' by default; 'paper' fits regular masks only.");
  m.def(
      "test_regular_mask",
      [](const py::handle& mask, const std::optional<RegularMaskOptions>& options) {
        const RleMask rle = maskFromObject(mask, "mask");
        py::gil_scoped_release release;
        return testRegularMask(rle, options.value_or(RegularMaskOptions{}));
      },
      py::arg("mask"), py::arg("options") = py::none(),
      "Is the mask roughly a convex quadrilateral (a 'regular' object of the paper)?");
  m.def(
      "fit_mask_ellipse",
      [](const py::handle& mask, MaskFitMethod method) {
        const RleMask rle = maskFromObject(mask, "mask");
        if (!rle.isConsistent()) badArgument("mask", "its runs do not add up to height x width");
        std::optional<RegularVerdict> verdict;
        if (method == MaskFitMethod::Quadrilateral) verdict = testRegularMask(rle);
        return fitMaskEllipse(rle, method, verdict ? &*verdict : nullptr);
      },
      py::arg("mask"), py::arg("method") = MaskFitMethod::Moments,
      "An ellipse fitted to a mask; None when the fit fails (an empty mask). quadrilateral uses the mask's "
      "four-corner reduction, which describes regular masks only (test_regular_mask).");
}

}  // namespace

void bindObserve(py::module_& m) {
  bindObserveOptions(m);
  bindResults(m);
  bindFunctions(m);
}

}  // namespace ellreloc::python
