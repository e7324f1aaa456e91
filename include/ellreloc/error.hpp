#pragma once
/// \file error.hpp
/// The one exception type of the library: invalid user input at the file / command-line
/// boundary. Its message is one line naming the file and the field or line at fault.

#include <stdexcept>
#include <string>

namespace ellreloc {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace ellreloc
