#pragma once
/// \file convert.hpp
/// numpy <-> Eigen and mask conversions for the bindings. Every conversion names the argument
/// it failed on and says what it expected and what it got, as a ValueError: pybind11's own
/// Eigen caster would only say "incompatible function arguments".

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <Eigen/Core>
#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "ellreloc/core/rle.hpp"

namespace ellreloc::python {

namespace py = pybind11;

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

[[noreturn]] inline void badArgument(const std::string& name, const std::string& what) {
  throw py::value_error(name + ": " + what);
}

/// "a float64 array of shape (3, 2)" or "a str": what a user passed, for error messages.
inline std::string describe(const py::handle& h) {
  if (py::isinstance<py::array>(h)) {
    const auto a = py::reinterpret_borrow<py::array>(h);
    std::string shape = "(";
    for (py::ssize_t i = 0; i < a.ndim(); ++i) shape += (i ? ", " : "") + std::to_string(a.shape(i));
    if (a.ndim() == 1) shape += ",";
    return "a " + std::string(py::str(a.dtype())) + " array of shape " + shape + ")";
  }
  return "a " + std::string(py::str(h.get_type().attr("__name__")));
}

inline std::string shapeText(std::initializer_list<int> dims) {
  std::string s = "(";
  int i = 0;
  for (int d : dims) s += (i++ ? ", " : "") + (d < 0 ? std::string("N") : std::to_string(d));
  return s + (dims.size() == 1 ? ",)" : ")");
}

/// A path given as str or os.PathLike.
inline std::string pathFrom(const py::handle& h) {
  if (!py::isinstance<py::str>(h) && !py::hasattr(h, "__fspath__"))
    badArgument("path", "expected a str or os.PathLike, got " + describe(h));
  return py::str(py::module_::import("os").attr("fspath")(h));
}

/// The argument as a C-contiguous float64 array; converted only when it is not one already.
inline DoubleArray doubles(const py::handle& h, const std::string& name) {
  if (h.is_none()) badArgument(name, "expected numbers, got None");
  if (py::isinstance<py::str>(h) || py::isinstance<py::bytes>(h))
    badArgument(name, "expected numbers, got " + describe(h));
  if (py::isinstance<py::array>(h)) {
    const char kind = py::reinterpret_borrow<py::array>(h).dtype().kind();
    if (kind != 'f' && kind != 'i' && kind != 'u') badArgument(name, "expected numbers, got " + describe(h));
  }
  DoubleArray a = DoubleArray::ensure(h);
  if (!a) {
    PyErr_Clear();
    badArgument(name, "expected numbers, got " + describe(h));
  }
  return a;
}

inline void requireFinite(const double* data, py::ssize_t n, const std::string& name) {
  for (py::ssize_t i = 0; i < n; ++i)
    if (!std::isfinite(data[i])) badArgument(name, "contains a value that is not finite");
}

/// A fixed-size vector from any array-like of shape (N,); finite values only.
template <int N>
Eigen::Matrix<double, N, 1> vector(const py::handle& h, const std::string& name) {
  const DoubleArray a = doubles(h, name);
  if (a.ndim() != 1 || a.shape(0) != N) badArgument(name, "expected shape " + shapeText({N}) + ", got " + describe(a));
  requireFinite(a.data(), N, name);
  return Eigen::Map<const Eigen::Matrix<double, N, 1>>(a.data());
}

/// A fixed-size matrix from any array-like of shape (R, C); finite values only.
template <int R, int C>
Eigen::Matrix<double, R, C> matrix(const py::handle& h, const std::string& name) {
  const DoubleArray a = doubles(h, name);
  if (a.ndim() != 2 || a.shape(0) != R || a.shape(1) != C)
    badArgument(name, "expected shape " + shapeText({R, C}) + ", got " + describe(a));
  requireFinite(a.data(), R * C, name);
  return Eigen::Map<const Eigen::Matrix<double, R, C, Eigen::RowMajor>>(a.data());
}

/// Rows of an (n, N) array-like as vectors; an empty list or array gives none.
template <int N>
std::vector<Eigen::Matrix<double, N, 1>> rows(const py::handle& h, const std::string& name) {
  const DoubleArray a = doubles(h, name);
  if (a.size() == 0) return {};
  if (a.ndim() != 2 || a.shape(1) != N)
    badArgument(name, "expected shape " + shapeText({-1, N}) + ", got " + describe(a));
  requireFinite(a.data(), a.size(), name);
  std::vector<Eigen::Matrix<double, N, 1>> out(static_cast<size_t>(a.shape(0)));
  for (size_t i = 0; i < out.size(); ++i) out[i] = Eigen::Map<const Eigen::Matrix<double, N, 1>>(a.data() + i * N);
  return out;
}

/// A new numpy array with the matrix's values (row-major, as numpy users expect).
template <typename Derived>
py::array_t<double> toArray(const Eigen::MatrixBase<Derived>& m) {
  using RowMajor = Eigen::Matrix<double, Derived::RowsAtCompileTime, Derived::ColsAtCompileTime,
                                 Derived::ColsAtCompileTime == 1 ? Eigen::ColMajor : Eigen::RowMajor>;
  const RowMajor copy = m;
  if (Derived::ColsAtCompileTime == 1) return py::array_t<double>({copy.rows()}, copy.data());
  return py::array_t<double>({copy.rows(), copy.cols()}, copy.data());
}

/// Points as an (n, N) array.
template <int N>
py::array_t<double> rowsToArray(const std::vector<Eigen::Matrix<double, N, 1>>& points) {
  py::array_t<double> out({static_cast<py::ssize_t>(points.size()), static_cast<py::ssize_t>(N)});
  auto w = out.mutable_unchecked<2>();
  for (size_t i = 0; i < points.size(); ++i)
    for (int k = 0; k < N; ++k) w(static_cast<py::ssize_t>(i), k) = points[i](k);
  return out;
}

/// Hands a vector's buffer to numpy without copying it: the array owns the vector.
template <typename T>
py::array_t<T> adoptVector(std::vector<T>&& values, std::vector<py::ssize_t> shape) {
  auto* owned = new std::vector<T>(std::move(values));
  py::capsule free_when_done(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<T>(std::move(shape), owned->data(), free_when_done);
}

/// COCO run lengths of a 2-D bool or uint8 numpy mask (non-zero = object), read in place
/// through its strides: no copy, whatever its memory order.
inline RleMask maskFromArray(const py::handle& h, const std::string& name) {
  if (!py::isinstance<py::array>(h)) badArgument(name, "expected a 2-D bool or uint8 numpy array, got " + describe(h));
  const auto a = py::reinterpret_borrow<py::array>(h);
  const py::dtype dt = a.dtype();
  if (!((dt.kind() == 'b' || dt.kind() == 'u') && dt.itemsize() == 1) || a.ndim() != 2)
    badArgument(name, "expected a 2-D bool or uint8 numpy array, got " + describe(h));
  if (a.shape(0) <= 0 || a.shape(1) <= 0) badArgument(name, "the mask is empty (" + describe(h) + ")");
  const auto* base = static_cast<const char*>(a.data());
  const py::ssize_t sy = a.strides(0), sx = a.strides(1);
  return encodeRuns(static_cast<int>(a.shape(0)), static_cast<int>(a.shape(1)),
                    [&](int x, int y) { return base[y * sy + x * sx] != 0; });
}

}  // namespace ellreloc::python
