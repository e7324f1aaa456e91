#pragma once
// Location of ../shared/data, set by CMake (ELLRELOC_DATA_DIR).

#include <string>

namespace ellreloc::test {

inline std::string dataPath(const std::string& relative) { return std::string(ELLRELOC_TEST_DATA_DIR) + "/" + relative; }

}  // namespace ellreloc::test
