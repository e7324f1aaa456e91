#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "ellreloc/error.hpp"
#include "ellreloc/io/files.hpp"

namespace ellreloc::io {

size_t maxInputBytes() {
  if (const char* v = std::getenv("ELLRELOC_MAX_INPUT_BYTES")) {
    char* end = nullptr;
    const unsigned long long n = std::strtoull(v, &end, 10);
    if (end != v && *end == '\0' && n > 0) return static_cast<size_t>(n);
  }
  return size_t{1} << 30;
}

std::string readTextFile(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) throw FileError(path + ": cannot open: " + std::strerror(errno));
  if (S_ISDIR(st.st_mode)) throw FileError(path + ": is a directory, expected a file");
  if (!S_ISREG(st.st_mode)) throw FileError(path + ": is not a regular file (a device, FIFO or socket)");
  if (static_cast<unsigned long long>(st.st_size) > maxInputBytes())
    throw FileError(path + ": is " + std::to_string(st.st_size) + " bytes, above the input limit of " +
                std::to_string(maxInputBytes()) + " (ELLRELOC_MAX_INPUT_BYTES)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw FileError(path + ": cannot open for reading");
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw FileError(path + ": read error");
  return ss.str();
}

void writeFileAtomically(const std::string& given, const std::string& content) {
  // A symlink is followed (its target is replaced, the link kept); anything but a regular file
  // (a device, a FIFO, a directory) is refused rather than replaced by one.
  std::string path = given;
  struct stat st {};
  if (::lstat(given.c_str(), &st) == 0 && S_ISLNK(st.st_mode)) {
    std::error_code ec;
    const std::filesystem::path target = std::filesystem::weakly_canonical(given, ec);
    if (ec) throw FileError(given + ": cannot resolve the symbolic link: " + ec.message());
    path = target.string();
  }
  if (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode))
    throw FileError(given + ": exists and is not a regular file (a directory, device or FIFO); refusing to replace it");
  const std::string tmp = path + ".tmp" + std::to_string(::getpid());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw FileError(given + ": cannot open for writing: " + std::strerror(errno));
    out << content;
    out.flush();
    if (!out) {
      out.close();
      std::remove(tmp.c_str());
      throw FileError(path + ": write failed");
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    std::remove(tmp.c_str());
    throw FileError(path + ": cannot move the written file into place: " + reason);
  }
}

}  // namespace ellreloc::io
