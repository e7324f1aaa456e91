#!/usr/bin/env bash
# The whole test suite under AddressSanitizer + UndefinedBehaviorSanitizer (errors abort), in
# build-asan/, then the concurrency tests under ThreadSanitizer, in build-tsan/.
#   scripts/sanitize.sh [asan|tsan|all]
set -euo pipefail
cd "$(dirname "$0")/.."
what="${1:-all}"
jobs="$(nproc)"
# -O1 without debug info: sanitizer builds compile several times slower than release ones.
common=(-G Ninja -DCMAKE_BUILD_TYPE= -DELLRELOC_BUILD_BENCHMARKS=OFF)

if [ "$what" = asan ] || [ "$what" = all ]; then
  cmake -S . -B build-asan "${common[@]}" \
    -DCMAKE_CXX_FLAGS="-O1 -fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer" \
    >/dev/null
  cmake --build build-asan -j "$jobs"
  # The packaging test installs and rebuilds the examples: nothing to sanitize there.
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
    ctest --test-dir build-asan --output-on-failure -j "$jobs" -E packaging.consumer
fi

if [ "$what" = tsan ] || [ "$what" = all ]; then
  cmake -S . -B build-tsan "${common[@]}" -DELLRELOC_BUILD_EXAMPLES=OFF \
    -DCMAKE_CXX_FLAGS="-O1 -fsanitize=thread" >/dev/null
  cmake --build build-tsan -j "$jobs" --target pose_tests mapping_tests
  # One relocalizer shared by 8 threads, and a mapper read while it maps: same answers as serial.
  TSAN_OPTIONS=halt_on_error=1 build-tsan/tests/pose_tests --gtest_filter='*ThreadSafe*'
  TSAN_OPTIONS=halt_on_error=1 build-tsan/tests/mapping_tests --gtest_filter='*ReadsWhileMapping*'
fi
