#pragma once
/// \file files.hpp
/// Whole-file reading and atomic writing, shared by every reader and writer.

#include <cstddef>
#include <sstream>
#include <string>

namespace ellreloc::io {

/// Inputs larger than this are refused before reading: 1 GiB, or the environment variable
/// ELLRELOC_MAX_INPUT_BYTES.
size_t maxInputBytes();

/// The file's bytes. Throws ellreloc::Error("PATH: ...") when it cannot be read, is not a
/// regular file (a device such as /dev/zero, a FIFO: refused at once, never read) or is larger
/// than maxInputBytes().
std::string readTextFile(const std::string& path);

/// Writes to a temporary file beside `path` and renames it into place, so a failure never
/// leaves a half-written file. A symbolic link is followed; an existing path that is not a
/// regular file (a directory, device or FIFO) is refused. Throws ellreloc::Error naming the
/// path on failure.
void writeFileAtomically(const std::string& path, const std::string& content);

/// Calls f(line_number, line) for each line of a line-oriented text format (TUM trajectories,
/// association files, OA-SLAM maps) that is neither blank nor a `#` comment. Numbers are 1-based.
template <typename F>
void forEachDataLine(const std::string& text, F f) {
  std::istringstream in(text);
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    f(line_no, line);
  }
}

}  // namespace ellreloc::io
