#pragma once
/// \file files.hpp
/// Whole-file reading and atomic writing, shared by every reader and writer.

#include <string>

namespace ellreloc::io {

/// The file's bytes. Throws ellreloc::Error("PATH: cannot open ...") when it cannot be read.
std::string readTextFile(const std::string& path);

/// Writes to a temporary file beside `path` and renames it into place, so a failure never
/// leaves a half-written file. Throws ellreloc::Error naming the path on failure.
void writeFileAtomically(const std::string& path, const std::string& content);

}  // namespace ellreloc::io
