#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include "commands.hpp"
#include "ellreloc/error.hpp"
#include "ellreloc/io/camera.hpp"

namespace ellreloc::cli {

void Console::progress(const char* what, size_t done, size_t total) const {
  if (quiet || !isatty(STDERR_FILENO) || total == 0) return;
  const int width = 30, filled = static_cast<int>(width * done / total);
  std::fprintf(stderr, "\r%-12s [%s%s] %zu/%zu", what, std::string(static_cast<size_t>(filled), '=').c_str(),
               std::string(static_cast<size_t>(width - filled), ' ').c_str(), done, total);
}

void Console::endProgress() const {
  if (!quiet && isatty(STDERR_FILENO)) std::fprintf(stderr, "\r%60s\r", "");
}

namespace {

/// What identifies a path's file: device and inode when it exists, else its resolved path.
std::string fileIdentity(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0) return "inode " + std::to_string(st.st_dev) + ":" + std::to_string(st.st_ino);
  std::error_code ec;
  const std::filesystem::path resolved = std::filesystem::weakly_canonical(path, ec);
  return "path " + (ec ? path : resolved.string());
}

}  // namespace

void mentionTheLens(const std::string& camera) {
  try {
    if (io::readDistortion(camera).isZero()) return;
  } catch (const Error&) {
    return;
  }
  std::printf(
      "%s gives a lens distortion (Camera.k1 ...): if the detections were made on its raw images, --undistort moves "
      "them to the pinhole image the map is projected into\n",
      camera.c_str());
}

void checkPaths(const std::vector<NamedPath>& outputs, const std::vector<NamedPath>& inputs) {
  std::vector<std::pair<std::string, const NamedPath*>> seen;
  for (const NamedPath& in : inputs)
    if (!in.path.empty()) seen.emplace_back(fileIdentity(in.path), &in);
  for (const NamedPath& out : outputs) {
    if (out.path.empty()) continue;
    struct stat st {};
    if (::stat(out.path.c_str(), &st) == 0 && !S_ISREG(st.st_mode))
      throw Error(out.option + ": '" + out.path + "' exists and is not a regular file (a directory, device or FIFO)");
    // The folder must exist and take files now: a long run should not end in an error it could
    // have given before its work.
    const std::filesystem::path parent = std::filesystem::path(out.path).parent_path();
    const std::string folder = parent.empty() ? "." : parent.string();
    if (::stat(folder.c_str(), &st) != 0)
      throw Error(out.option + ": '" + out.path + "': the folder '" + folder + "' does not exist");
    if (!S_ISDIR(st.st_mode)) throw Error(out.option + ": '" + out.path + "': '" + folder + "' is not a folder");
    if (::access(folder.c_str(), W_OK | X_OK) != 0)
      throw Error(out.option + ": '" + out.path + "': cannot write into the folder '" + folder + "'");
    const std::string id = fileIdentity(out.path);
    for (const auto& [other_id, other] : seen)
      if (other_id == id)
        throw Error(out.option + ": '" + out.path + "' is the same file as " + other->option +
                    "; refusing to overwrite it");
    seen.emplace_back(id, &out);
  }
}

}  // namespace ellreloc::cli
