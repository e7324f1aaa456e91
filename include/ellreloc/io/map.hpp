#pragma once
/// \file map.hpp
/// Object maps: the JSON map of FORMATS.md (objects as centre/axes/rotation or as a dual
/// quadric) and OA-SLAM's text maps (`track_id category_id` + 16 column-major Q* entries).

#include "ellreloc/core/object_map.hpp"

#include <string>

namespace ellreloc::io {

/// Reads a map file: JSON when the first non-blank character is '{', otherwise OA-SLAM's text
/// format. Rotations within 1e-3 of orthonormal (rounded files) are projected onto the nearest
/// rotation. Throws ellreloc::Error naming the file and the field or line on malformed input.
ObjectMap readMap(const std::string& path);

/// Parses map JSON text; `source` names it in error messages.
ObjectMap parseMapJson(const std::string& text, const std::string& source);

/// Parses OA-SLAM's text map; `source` names it in error messages.
ObjectMap parseOaSlamMap(const std::string& text, const std::string& source);

/// Writes the JSON map (centre/axes/rotation form), atomically.
void writeMap(const std::string& path, const ObjectMap& map);

}  // namespace ellreloc::io
