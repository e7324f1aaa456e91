/// \file bind_core.cpp
/// Geometry and the plain data types: Box, Ellipse, Ellipsoid, Intrinsics, Pose, projection,
/// the ellipse distances, P3P and the evaluation metrics.

#include <pybind11/stl.h>

#include <array>
#include <cstdio>

#include "bindings.hpp"
#include "convert.hpp"
#include "ellreloc/core/box.hpp"
#include "ellreloc/core/camera.hpp"
#include "ellreloc/core/distances.hpp"
#include "ellreloc/core/distortion.hpp"
#include "ellreloc/core/ellipse.hpp"
#include "ellreloc/core/ellipsoid.hpp"
#include "ellreloc/core/evaluation.hpp"
#include "ellreloc/core/p3p.hpp"
#include "ellreloc/core/pose.hpp"
#include "ellreloc/core/projection.hpp"

namespace ellreloc::python {
namespace {

std::string format(const char* fmt, double a, double b = 0, double c = 0, double d = 0, double e = 0, double f = 0) {
  char text[256];
  std::snprintf(text, sizeof text, fmt, a, b, c, d, e, f);
  return text;
}

Ellipse makeEllipse(const py::handle& center, const py::handle& axes, double angle) {
  const Eigen::Vector2d c = vector<2>(center, "center"), a = vector<2>(axes, "axes");
  if (!(a.minCoeff() > 0)) badArgument("axes", "semi-axes must be positive");
  if (!std::isfinite(angle)) badArgument("angle", "must be finite");
  return Ellipse(c, a, angle);
}

Ellipsoid makeEllipsoid(const py::handle& center, const py::handle& axes, const py::handle& rotation) {
  const Eigen::Vector3d c = vector<3>(center, "center"), a = vector<3>(axes, "axes");
  if (!(a.minCoeff() > 0)) badArgument("axes", "semi-axes must be positive");
  const Eigen::Matrix3d R = rotation.is_none() ? Eigen::Matrix3d::Identity() : matrix<3, 3>(rotation, "rotation");
  if (!isRotation(R)) badArgument("rotation", "is not a rotation matrix (orthonormal, determinant +1)");
  return Ellipsoid(c, a, R);
}

/// A rigid transform from a 4x4 matrix: last row (0, 0, 0, 1), a rotation block.
std::pair<Eigen::Matrix3d, Eigen::Vector3d> rigid(const py::handle& h, const std::string& name) {
  const Eigen::Matrix4d T = matrix<4, 4>(h, name);
  if ((T.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 1e-9)
    badArgument(name, "the last row must be (0, 0, 0, 1)");
  if (!isRotation(T.topLeftCorner<3, 3>()))
    badArgument(name, "the top-left 3x3 block is not a rotation matrix (orthonormal, determinant +1)");
  return {T.topLeftCorner<3, 3>(), T.topRightCorner<3, 1>()};
}

Eigen::Matrix4d homogeneous(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() = R;
  T.topRightCorner<3, 1>() = t;
  return T;
}

void bindBoxAndEllipse(py::module_& m) {
  py::class_<Box>(m, "Box", "An axis-aligned box in pixels: corners (x1, y1) and (x2, y2), x2 > x1, y2 > y1.")
      .def(py::init<>())
      .def(py::init<double, double, double, double>(), py::arg("x1"), py::arg("y1"), py::arg("x2"), py::arg("y2"))
      .def_readwrite("x1", &Box::x1)
      .def_readwrite("y1", &Box::y1)
      .def_readwrite("x2", &Box::x2)
      .def_readwrite("y2", &Box::y2)
      .def_property_readonly("width", &Box::width)
      .def_property_readonly("height", &Box::height)
      .def_property_readonly("area", &Box::area)
      .def_property_readonly("center", [](const Box& b) { return toArray(b.center()); })
      .def("is_valid", &Box::isValid, "Finite corners with x2 >= x1 and y2 >= y1.")
      .def("intersection", &Box::intersection, py::arg("other"))
      .def(
          "to_array", [](const Box& b) { return toArray(Eigen::Vector4d(b.x1, b.y1, b.x2, b.y2)); },
          "(x1, y1, x2, y2) as a numpy array.")
      .def("__repr__", [](const Box& b) { return format("Box(%g, %g, %g, %g)", b.x1, b.y1, b.x2, b.y2); })
      .def(py::pickle([](const Box& b) { return py::make_tuple(b.x1, b.y1, b.x2, b.y2); },
                      [](const py::tuple& t) {
                        return Box(t[0].cast<double>(), t[1].cast<double>(), t[2].cast<double>(), t[3].cast<double>());
                      }));
  m.def("box_iou", &boxIoU, py::arg("a"), py::arg("b"), "Intersection over union of two boxes (0 for invalid ones).");

  py::class_<Ellipse>(m, "Ellipse",
                      "An image ellipse: centre (px), semi-axes (px, major first) and the angle (rad) of the "
                      "first axis from the image x axis. Its Gaussian covariance is R diag(a^2, b^2) R^T.")
      .def(py::init(&makeEllipse), py::arg("center"), py::arg("axes"), py::arg("angle") = 0.0)
      .def_property_readonly("center", [](const Ellipse& e) { return toArray(e.center()); })
      .def_property_readonly("axes", [](const Ellipse& e) { return toArray(e.axes()); })
      .def_property_readonly("angle", &Ellipse::angle)
      .def_static(
          "from_dual_conic", [](const py::handle& C) { return Ellipse::fromDualConic(matrix<3, 3>(C, "C")); },
          py::arg("C"), "The ellipse of a 3x3 dual conic (any scale and sign); None when it is not one.")
      .def_static(
          "from_gaussian",
          [](const py::handle& mean, const py::handle& cov) {
            return Ellipse::fromGaussian(vector<2>(mean, "mean"), matrix<2, 2>(cov, "cov"));
          },
          py::arg("mean"), py::arg("cov"),
          "The ellipse of a mean and a 2x2 covariance; None when not positive definite.")
      .def_static(
          "inscribed_in_box", [](const py::handle& box) { return Ellipse::inscribedInBox(boxFrom(box, "box")); },
          py::arg("box"), "The axis-aligned ellipse inscribed in a box (OA-SLAM's observation); None for an empty box.")
      .def("is_valid", &Ellipse::isValid)
      .def("covariance", [](const Ellipse& e) { return toArray(e.covariance()); })
      .def(
          "dual_conic", [](const Ellipse& e) { return toArray(e.dualConic()); },
          "The 3x3 dual conic, normalised to C[2, 2] = -1.")
      .def("conic", [](const Ellipse& e) { return toArray(e.conic()); })
      .def_property_readonly("area", &Ellipse::area)
      .def("bounding_box", &Ellipse::boundingBox)
      .def(
          "contains", [](const Ellipse& e, const py::handle& p) { return e.contains(vector<2>(p, "point")); },
          py::arg("point"))
      .def(
          "sample_boundary", [](const Ellipse& e, int n) { return rowsToArray<2>(e.sampleBoundary(n)); },
          py::arg("n") = 64, "n points on the outline, as an (n, 2) array.")
      .def("__repr__",
           [](const Ellipse& e) {
             return format("Ellipse(center=(%.6g, %.6g), axes=(%.6g, %.6g), angle=%.6g)", e.center()(0), e.center()(1),
                           e.axes()(0), e.axes()(1), e.angle());
           })
      .def(
          py::pickle([](const Ellipse& e) { return py::make_tuple(toArray(e.center()), toArray(e.axes()), e.angle()); },
                     [](const py::tuple& t) { return makeEllipse(t[0], t[1], t[2].cast<double>()); }));
}

void bindEllipsoidAndCamera(py::module_& m) {
  py::class_<Ellipsoid>(m, "Ellipsoid",
                        "A world ellipsoid: centre (m), semi-axes (m) and the rotation object->world whose "
                        "columns are the axes' directions.")
      .def(py::init(&makeEllipsoid), py::arg("center"), py::arg("axes"), py::arg("rotation") = py::none())
      .def_property_readonly("center", [](const Ellipsoid& e) { return toArray(e.center()); })
      .def_property_readonly("axes", [](const Ellipsoid& e) { return toArray(e.axes()); })
      .def_property_readonly("rotation", [](const Ellipsoid& e) { return toArray(e.rotation()); })
      .def_static(
          "from_dual_quadric", [](const py::handle& Q) { return Ellipsoid::fromDualQuadric(matrix<4, 4>(Q, "Q")); },
          py::arg("Q"), "The ellipsoid of a 4x4 dual quadric (any scale and sign); None when it is not one.")
      .def("is_valid", &Ellipsoid::isValid)
      .def(
          "dual_quadric", [](const Ellipsoid& e) { return toArray(e.dualQuadric()); },
          "The 4x4 dual quadric, normalised to Q[3, 3] = -1.")
      .def("shape_matrix", [](const Ellipsoid& e) { return toArray(e.shapeMatrix()); })
      .def_property_readonly("volume", &Ellipsoid::volume)
      .def(
          "contains", [](const Ellipsoid& e, const py::handle& x) { return e.contains(vector<3>(x, "point")); },
          py::arg("point"))
      .def(
          "sample_surface", [](const Ellipsoid& e, int n) { return rowsToArray<3>(e.sampleSurface(n)); },
          py::arg("n") = 256, "n points spread over the surface, as an (n, 3) array.")
      .def("__repr__",
           [](const Ellipsoid& e) {
             return format("Ellipsoid(center=(%.6g, %.6g, %.6g), axes=(%.6g, %.6g, %.6g))", e.center()(0),
                           e.center()(1), e.center()(2), e.axes()(0), e.axes()(1), e.axes()(2));
           })
      .def(py::pickle(
          [](const Ellipsoid& e) {
            return py::make_tuple(toArray(e.center()), toArray(e.axes()), toArray(e.rotation()));
          },
          [](const py::tuple& t) { return makeEllipsoid(t[0], t[1], t[2]); }));

  py::class_<Intrinsics>(m, "Intrinsics", "Pinhole intrinsics of an undistorted camera, in pixels.")
      .def(py::init([](double fx, double fy, double cx, double cy, int width, int height) {
             const Intrinsics K(fx, fy, cx, cy, width, height);
             if (!K.isValid())
               throw py::value_error("Intrinsics: fx, fy must be positive and finite, width and height positive");
             return K;
           }),
           py::arg("fx"), py::arg("fy"), py::arg("cx"), py::arg("cy"), py::arg("width"), py::arg("height"))
      .def_readonly("fx", &Intrinsics::fx)
      .def_readonly("fy", &Intrinsics::fy)
      .def_readonly("cx", &Intrinsics::cx)
      .def_readonly("cy", &Intrinsics::cy)
      .def_readonly("width", &Intrinsics::width)
      .def_readonly("height", &Intrinsics::height)
      .def_property_readonly(
          "K", [](const Intrinsics& K) { return toArray(K.K()); }, "The 3x3 calibration matrix.")
      .def(
          "project", [](const Intrinsics& K, const py::handle& x) { return toArray(K.project(vector<3>(x, "x_c"))); },
          py::arg("x_c"), "Pixel of a point in camera coordinates.")
      .def("__repr__",
           [](const Intrinsics& K) {
             return format("Intrinsics(fx=%g, fy=%g, cx=%g, cy=%g, width=%g, height=%g)", K.fx, K.fy, K.cx, K.cy,
                           K.width, K.height);
           })
      .def(py::pickle([](const Intrinsics& K) { return py::make_tuple(K.fx, K.fy, K.cx, K.cy, K.width, K.height); },
                      [](const py::tuple& t) {
                        return Intrinsics(t[0].cast<double>(), t[1].cast<double>(), t[2].cast<double>(),
                                          t[3].cast<double>(), t[4].cast<int>(), t[5].cast<int>());
                      }));
}

void bindLens(py::module_& m) {
  py::class_<Distortion>(m, "Distortion",
                         "Radial-tangential lens distortion (OpenCV's and ORB-SLAM's k1, k2, p1, p2, k3).")
      .def(py::init([](double k1, double k2, double p1, double p2, double k3) {
             return Distortion{k1, k2, p1, p2, k3};
           }),
           py::arg("k1") = 0.0, py::arg("k2") = 0.0, py::arg("p1") = 0.0, py::arg("p2") = 0.0, py::arg("k3") = 0.0)
      .def_readwrite("k1", &Distortion::k1)
      .def_readwrite("k2", &Distortion::k2)
      .def_readwrite("p1", &Distortion::p1)
      .def_readwrite("p2", &Distortion::p2)
      .def_readwrite("k3", &Distortion::k3)
      .def("is_zero", &Distortion::isZero)
      .def("__repr__", [](const Distortion& d) {
        return format("Distortion(k1=%g, k2=%g, p1=%g, p2=%g, k3=%g)", d.k1, d.k2, d.p1, d.p2, d.k3);
      });
  py::class_<Lens>(m, "Lens",
                   "A raw image's camera: pinhole intrinsics and the distortion of its lens. Detections made on "
                   "the raw image are moved to the pinhole image of the same intrinsics (ObserveOptions.lens).")
      .def(py::init([](const Intrinsics& K, const Distortion& d) {
             const Lens lens{K, d};
             if (const std::string why = lens.whyNotUsable(); !why.empty()) badArgument("distortion", why);
             return lens;
           }),
           py::arg("intrinsics"), py::arg("distortion"))
      .def_readonly("intrinsics", &Lens::intrinsics)
      .def_readonly("distortion", &Lens::distortion)
      .def(
          "undistort_pixel",
          [](const Lens& lens, const py::handle& uv) -> py::object {
            const std::optional<Eigen::Vector2d> p = lens.undistortPixel(vector<2>(uv, "uv"));
            return p ? py::object(toArray(*p)) : py::none();
          },
          py::arg("uv"), "The pinhole pixel of a raw pixel; None where the model cannot be undone.")
      .def(
          "distort_pixel",
          [](const Lens& lens, const py::handle& uv) {
            return toArray(lens.distortion.distortPixel(lens.intrinsics, vector<2>(uv, "uv")));
          },
          py::arg("uv"), "The raw pixel where the pinhole image's pixel was taken.")
      .def("undistort_box", &Lens::undistortBox, py::arg("box"),
           "The bounding box of the raw box's outline once undistorted; None where it cannot be.")
      .def("undistort_ellipse", &Lens::undistortEllipse, py::arg("ellipse"),
           "The ellipse of the raw ellipse's outline once undistorted; None where it cannot be.");
}

void bindPoseClass(py::module_& m) {
  py::class_<Pose>(m, "Pose",
                   "A camera pose, stored world->camera: x_c = R_cw x_w + t_cw. T_wc is the camera->world "
                   "4x4 matrix (what TUM files hold), T_cw its inverse.")
      .def(py::init<>())
      .def(py::init([](const py::handle& R, const py::handle& t) {
             const Eigen::Matrix3d R_cw = matrix<3, 3>(R, "R_cw");
             if (!isRotation(R_cw)) badArgument("R_cw", "is not a rotation matrix (orthonormal, determinant +1)");
             return Pose(R_cw, vector<3>(t, "t_cw"));
           }),
           py::arg("R_cw"), py::arg("t_cw"))
      .def_static(
          "from_T_wc",
          [](const py::handle& T) {
            const auto [R, t] = rigid(T, "T_wc");
            return Pose::fromCameraToWorld(R, t);
          },
          py::arg("T_wc"), "From a 4x4 camera->world matrix.")
      .def_static(
          "from_T_cw",
          [](const py::handle& T) {
            const auto [R, t] = rigid(T, "T_cw");
            return Pose(R, t);
          },
          py::arg("T_cw"), "From a 4x4 world->camera matrix.")
      .def_static(
          "look_at",
          [](const py::handle& eye, const py::handle& target, const py::handle& up) {
            const Eigen::Vector3d e = vector<3>(eye, "eye"), t = vector<3>(target, "target");
            if (!((t - e).norm() > 0)) badArgument("target", "equals eye");
            return Pose::lookAt(e, t, up.is_none() ? Eigen::Vector3d::UnitZ() : vector<3>(up, "up"));
          },
          py::arg("eye"), py::arg("target"), py::arg("up") = py::none(),
          "A camera at `eye` looking at `target`, image-up towards `up` (default +z).")
      .def_property_readonly("R_cw", [](const Pose& p) { return toArray(p.rotation()); })
      .def_property_readonly("t_cw", [](const Pose& p) { return toArray(p.translation()); })
      .def_property_readonly(
          "center", [](const Pose& p) { return toArray(p.center()); }, "The camera centre in the world.")
      .def_property_readonly("T_cw", [](const Pose& p) { return toArray(homogeneous(p.rotation(), p.translation())); })
      .def_property_readonly("T_wc",
                             [](const Pose& p) {
                               const Pose inv = p.inverse();
                               return toArray(homogeneous(inv.rotation(), inv.translation()));
                             })
      .def("inverse", &Pose::inverse)
      .def(
          "transform",
          [](const Pose& p, const py::handle& x) -> py::object {
            const DoubleArray a = doubles(x, "x_w");
            if (a.ndim() == 1) return toArray(p.transform(vector<3>(a, "x_w")));
            std::vector<Eigen::Vector3d> points = rows<3>(a, "x_w");
            for (Eigen::Vector3d& q : points) q = p.transform(q);
            return rowsToArray<3>(points);
          },
          py::arg("x_w"), "World points, (3,) or (n, 3), in camera coordinates.")
      .def("__mul__", &Pose::operator*)
      .def("is_valid", &Pose::isValid)
      .def("__repr__",
           [](const Pose& p) {
             const Eigen::Vector3d c = p.center();
             return format("Pose(center=(%.6g, %.6g, %.6g))", c(0), c(1), c(2));
           })
      .def(py::pickle([](const Pose& p) { return py::make_tuple(toArray(p.rotation()), toArray(p.translation())); },
                      [](const py::tuple& t) { return Pose(matrix<3, 3>(t[0], "R_cw"), vector<3>(t[1], "t_cw")); }));
}

void bindGeometryFunctions(py::module_& m) {
  m.def(
      "project",
      [](const Ellipsoid& e, const Intrinsics& K, const Pose& pose) -> std::optional<Ellipse> {
        const Projection p = project(e, K, pose);
        if (!p) return std::nullopt;
        return p.ellipse;
      },
      py::arg("ellipsoid"), py::arg("camera"), py::arg("pose"),
      "The image ellipse of an ellipsoid seen from a world->camera pose (P Q* P^T); None when the camera is "
      "inside it, it is behind the camera or it crosses the principal plane.");
  m.def("wasserstein", &wasserstein2, py::arg("a"), py::arg("b"),
        "2-Wasserstein distance (px) between the ellipses' Gaussians; inf for invalid ellipses.");
  m.def(
      "wasserstein_squared", [](const Ellipse& a, const Ellipse& b) { return wasserstein2Squared(a, b); }, py::arg("a"),
      py::arg("b"), "The squared 2-Wasserstein distance (px^2), what the refiner minimises.");
  m.def("bhattacharyya", &bhattacharyya, py::arg("a"), py::arg("b"),
        "Bhattacharyya distance between the ellipses' Gaussians.");
  m.def("iou", &ellipseIoU, py::arg("a"), py::arg("b"), py::arg("vertices") = 128,
        "Intersection over union of two ellipses (polygons of `vertices` vertices against an exact disc).");
  m.def(
      "level_set_distance", [](const Ellipse& a, const Ellipse& b, int n) { return levelSetDistance(a, b, n); },
      py::arg("a"), py::arg("b"), py::arg("samples_per_level") = 16,
      "Mean algebraic distance between the level sets of two ellipses (docs/distances.md).");
  m.def(
      "p3p",
      [](const py::handle& bearings, const py::handle& points) {
        const Eigen::Matrix3d B = matrix<3, 3>(bearings, "bearings"), X = matrix<3, 3>(points, "points");
        std::array<Eigen::Vector3d, 3> b, x;
        for (int i = 0; i < 3; ++i) {
          if (!(B.row(i).norm() > 0)) badArgument("bearings", "row " + std::to_string(i) + " is zero");
          b[i] = B.row(i).transpose().normalized();
          x[i] = X.row(i).transpose();
        }
        std::array<Pose, 4> poses;
        const int n = p3p(b, x, &poses);
        return std::vector<Pose>(poses.begin(), poses.begin() + n);
      },
      py::arg("bearings"), py::arg("points"),
      "World->camera poses (up to four) that see the world points (rows of a 3x3 array) along the bearings "
      "(rows; normalised here). Degenerate input gives fewer or none.");
}

void bindEvaluation(py::module_& m) {
  m.attr("VALID_POSITION_CM") = kValidPositionCm;
  m.attr("VALID_ROTATION_DEG") = kValidRotationDeg;
  py::class_<PoseError>(m, "PoseError", "Position (cm) and rotation (deg) error of an estimated pose.")
      .def(py::init<>())
      .def_readwrite("position_cm", &PoseError::position_cm)
      .def_readwrite("rotation_deg", &PoseError::rotation_deg)
      .def_property_readonly("valid", &PoseError::valid, "Within 30 cm and 30 degrees of the truth.")
      .def("__repr__", [](const PoseError& e) {
        return format("PoseError(position_cm=%.4g, rotation_deg=%.4g)", e.position_cm, e.rotation_deg);
      });
  m.def("pose_error", &poseError, py::arg("estimate"), py::arg("truth"), py::arg("unit_metres") = 1.0,
        "Distance between the camera centres (cm; unit_metres: metres per unit of the poses) and angle between the "
        "rotations (deg).");
  py::class_<RelocalizationSummary>(
      m, "Summary", "A row of the paper's Table I: every query frame counts, medians over valid frames.")
      .def_readonly("frames", &RelocalizationSummary::frames)
      .def_readonly("relocalized", &RelocalizationSummary::relocalized)
      .def_readonly("valid", &RelocalizationSummary::valid)
      .def_readonly("median_position_cm", &RelocalizationSummary::median_position_cm)
      .def_readonly("median_rotation_deg", &RelocalizationSummary::median_rotation_deg)
      .def_property_readonly("valid_percent", &RelocalizationSummary::validPercent)
      .def("__repr__", [](const RelocalizationSummary& s) {
        return format("Summary(frames=%g, valid=%.1f%%, median %.2f cm, %.2f deg)", s.frames, s.validPercent(),
                      s.median_position_cm, s.median_rotation_deg);
      });
  m.def("summarize", &summarize, py::arg("errors"),
        "Table-I row from one entry per query frame: its PoseError, or None when it got no pose.");
}

}  // namespace

Box boxFrom(const py::handle& h, const std::string& name) {
  if (py::isinstance<Box>(h)) return h.cast<Box>();
  const Eigen::Vector4d v = vector<4>(h, name + " (x1, y1, x2, y2)");
  return Box(v(0), v(1), v(2), v(3));
}

void bindCore(py::module_& m) {
  bindBoxAndEllipse(m);
  bindEllipsoidAndCamera(m);
  bindLens(m);
  bindPoseClass(m);
  bindGeometryFunctions(m);
  bindEvaluation(m);
}

}  // namespace ellreloc::python
