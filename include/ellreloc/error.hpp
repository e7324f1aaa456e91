#pragma once
/// \file error.hpp
/// The library's exception type: invalid user input at the file / command-line boundary. Its
/// message is one line naming the file and the field or line at fault. FileError, a kind of
/// Error, is the file system's part: a file that cannot be opened, read, written or moved into
/// place (the Python bindings raise OSError for it, ValueError for any other Error).

#include <stdexcept>
#include <string>

namespace ellreloc {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

class FileError : public Error {
 public:
  explicit FileError(const std::string& message) : Error(message) {}
};

}  // namespace ellreloc
