#pragma once
/// \file map.hpp
/// Object maps: the JSON map of docs/formats.md (objects as centre/axes/rotation or as a dual
/// quadric) and OA-SLAM's text maps (`track_id category_id` + 16 column-major Q* entries).

#include <string>
#include <vector>

#include "ellreloc/core/object_map.hpp"

namespace ellreloc::io {

/// Reads a map file: JSON when the first non-blank character is '{' or '[', otherwise OA-SLAM's text
/// format. Rotations within 1e-3 of orthonormal (rounded files) are projected onto the nearest
/// rotation. Throws ellreloc::Error naming the file and the field or line on malformed input.
/// A well-formed object that cannot be used (mapObjectProblem: a zero, negative, non-finite,
/// sub-millimetre or > 10 m semi-axis, in metres by the map's `unit_metres` when the JSON gives
/// one, else 1; a singular dual quadric) is left out of the map, with
/// one line per object in `warnings` ("FILE: object ID left out: WHY"); a map left without
/// any object is an Error.
ObjectMap readMap(const std::string& path, std::vector<std::string>* warnings = nullptr);

/// Parses map JSON text; `source` names it in error and warning messages.
ObjectMap parseMapJson(const std::string& text, const std::string& source,
                       std::vector<std::string>* warnings = nullptr);

/// Parses OA-SLAM's text map; `source` names it in error and warning messages.
ObjectMap parseOaSlamMap(const std::string& text, const std::string& source,
                         std::vector<std::string>* warnings = nullptr);

/// Writes the JSON map (centre/axes/rotation form), atomically; `unit_metres` only when it is
/// not 1.
void writeMap(const std::string& path, const ObjectMap& map);

}  // namespace ellreloc::io
