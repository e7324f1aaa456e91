#include <unistd.h>

#include <cstdio>
#include <string>

#include "commands.hpp"

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

}  // namespace ellreloc::cli
