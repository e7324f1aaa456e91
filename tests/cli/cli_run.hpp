#pragma once
// Running the `ellreloc` command from tests: exit code, stdout and stderr of one call.

#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "fixtures/temp_dir.hpp"

namespace ellreloc::test::cli {

namespace fs = std::filesystem;

struct CliRun {
  int code = -1;
  std::string out, err;
};

inline CliRun run(const std::string& args, const ellreloc::test::TempDir& dir) {
  const std::string out = dir.path("stdout.txt"), err = dir.path("stderr.txt");
  const std::string cmd = std::string(ELLRELOC_CLI) + " " + args + " >" + out + " 2>" + err;
  const int status = std::system(cmd.c_str());
  CliRun r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream o(out), e(err);
  std::stringstream so, se;
  so << o.rdbuf();
  se << e.rdbuf();
  r.out = so.str();
  r.err = se.str();
  return r;
}

inline int lines(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }

inline std::string data(const std::string& name) { return std::string(ELLRELOC_TEST_DATA_DIR) + "/" + name; }

inline void writeFile(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

inline std::string readFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace ellreloc::test::cli
