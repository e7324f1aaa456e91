#pragma once
// Checked access to JSON fields: every failure names the file and the field path.

#include "ellreloc/error.hpp"

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <cmath>
#include <string>

namespace ellreloc::io::detail {

using nlohmann::json;

/// Parses text as JSON; a syntax error names the file and nlohmann's byte position.
inline json parseJson(const std::string& text, const std::string& file) {
  if (text.find_first_not_of(" \t\r\n") == std::string::npos) throw Error(file + ": empty file, expected JSON");
  try {
    return json::parse(text);
  } catch (const json::exception& e) {  // syntax errors, and numbers too large for a double
    throw Error(file + ": invalid JSON (" + std::string(e.what()) + ")");
  }
}

/// A context: the file and the path of the JSON value within it, e.g. objects[3].axes.
struct Where {
  const std::string& file;
  std::string path;

  Where operator[](const std::string& key) const { return {file, path.empty() ? key : path + "." + key}; }
  Where operator[](size_t i) const { return {file, path + "[" + std::to_string(i) + "]"}; }
  [[noreturn]] void fail(const std::string& what) const {
    throw Error(file + ": " + (path.empty() ? std::string("top level") : path) + ": " + what);
  }
};

inline const json& member(const json& obj, const char* key, const Where& where) {
  if (!obj.is_object()) where.fail("expected an object");
  const auto it = obj.find(key);
  if (it == obj.end()) where[key].fail("missing");
  return *it;
}

inline double finiteNumber(const json& v, const Where& where) {
  if (!v.is_number()) where.fail("expected a number, got " + std::string(v.type_name()));
  const double x = v.get<double>();
  if (!std::isfinite(x)) where.fail("not a finite number");
  return x;
}

inline int integer(const json& v, const Where& where) {
  if (!v.is_number_integer()) {
    // Accept 7.0 but not 7.5: some writers emit integers as floats.
    if (v.is_number_float() && std::isfinite(v.get<double>()) && v.get<double>() == std::floor(v.get<double>()) &&
        std::abs(v.get<double>()) < 2e9)
      return static_cast<int>(v.get<double>());
    where.fail("expected an integer, got " + std::string(v.dump()));
  }
  const auto x = v.get<long long>();
  if (x < -2147483647LL || x > 2147483647LL) where.fail("integer out of range");
  return static_cast<int>(x);
}

/// A JSON array of exactly n finite numbers.
template <int N>
Eigen::Matrix<double, N, 1> vector(const json& v, const Where& where) {
  if (!v.is_array() || v.size() != static_cast<size_t>(N))
    where.fail("expected an array of " + std::to_string(N) + " numbers");
  Eigen::Matrix<double, N, 1> out;
  for (int i = 0; i < N; ++i) out(i) = finiteNumber(v[static_cast<size_t>(i)], where[static_cast<size_t>(i)]);
  return out;
}

}  // namespace ellreloc::io::detail
