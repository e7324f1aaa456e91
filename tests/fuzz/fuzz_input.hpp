#pragma once
// Helpers shared by the libFuzzer targets: read numbers from the fuzzer's bytes, and write
// them to a file for the readers that take paths.

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>

/// A broken promise of the library: print which, then abort so that libFuzzer keeps the input.
#define FUZZ_CHECK(condition)                                                            \
  do {                                                                                   \
    if (!(condition)) {                                                                  \
      std::fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #condition); \
      std::abort();                                                                      \
    }                                                                                    \
  } while (false)

namespace ellreloc::fuzz {

/// Consumes the fuzzer's bytes as doubles, floats or small integers (zeros when exhausted).
class Input {
 public:
  Input(const uint8_t* data, size_t size) : data_(data), size_(size) {}
  double real() {  // any bit pattern: NaN, inf, denormals, huge values
    double v = 0.0;
    take(&v, sizeof v);
    return v;
  }
  double scaled(double lo, double hi) {  // a finite value in [lo, hi]
    uint32_t u = 0;
    take(&u, sizeof u);
    return lo + (hi - lo) * (u / 4294967295.0);
  }
  int small(int n) {
    uint8_t b = 0;
    take(&b, 1);
    return n > 0 ? b % n : 0;
  }
  bool empty() const { return pos_ >= size_; }

 private:
  void take(void* out, size_t n) {
    const size_t k = pos_ < size_ ? std::min(n, size_ - pos_) : 0;
    std::memcpy(out, data_ + pos_, k);
    pos_ += k;
  }
  const uint8_t* data_;
  size_t size_;
  size_t pos_ = 0;
};

/// A per-process scratch file holding the bytes, with the given extension.
inline std::string writeScratch(const uint8_t* data, size_t size, const std::string& extension) {
  const std::string path = "/tmp/ellreloc-fuzz-" + std::to_string(getpid()) + extension;
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(data), static_cast<long>(size));
  return path;
}

}  // namespace ellreloc::fuzz
