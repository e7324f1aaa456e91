#!/usr/bin/env bash
# Sanitizer runs (docs/reliability.md), with clang-14:
#   asan: the whole test suite under AddressSanitizer + UndefinedBehaviorSanitizer (any report
#         aborts), in build-asan/. The same build holds the libFuzzer targets (scripts/fuzz.sh
#         uses it), so one instrumented build serves both.
#   tsan: the concurrency tests under ThreadSanitizer, in build-tsan/.
#   configure-asan: only configures build-asan/ (scripts/fuzz.sh builds its fuzzers there).
#   scripts/sanitize.sh [asan|tsan|all|configure-asan]
set -euo pipefail
cd "$(dirname "$0")/.."
what="${1:-all}"
case "$what" in
  asan | tsan | all | configure-asan) ;;
  *) echo "sanitize: unknown stage '$what' (asan, tsan, all or configure-asan)" >&2; exit 2 ;;
esac
jobs="$(nproc)"
# -O1 without debug info: sanitizer builds compile several times slower than release ones.
# Unity builds (CMake merges each target's sources eight at a time): the Eigen templates every
# file instantiates are instantiated once per batch, which nearly halves the instrumented build
# (ASan: 451 s against 833 s on 2 cores). So two source files of one target must not define the
# same name at namespace scope, anonymous namespaces included; the release build batches the
# tests, the command and the Python extension too, but compiles the library file by file.
# No Python bindings: an instrumented extension needs the sanitizer runtime preloaded into python.
common=(-G Ninja -DCMAKE_BUILD_TYPE= -DCMAKE_UNITY_BUILD=ON -DELLRELOC_BUILD_BENCHMARKS=OFF -DELLRELOC_PYTHON=OFF)
export CC=clang-14 CXX=clang++-14
start=$SECONDS

if [ "$what" != tsan ]; then
  cmake -S . -B build-asan "${common[@]}" -DELLRELOC_BUILD_FUZZERS=ON \
    -DCMAKE_CXX_FLAGS="-O1 -gline-tables-only -fsanitize=address,undefined,fuzzer-no-link -fno-sanitize-recover=all -fno-omit-frame-pointer" \
    >/dev/null
fi
if [ "$what" = configure-asan ]; then exit 0; fi

if [ "$what" = asan ] || [ "$what" = all ]; then
  cmake --build build-asan -j "$jobs"
  echo "sanitize: asan build done after $((SECONDS - start)) s"
  # Left out: the packaging test (installs and rebuilds the examples: nothing to sanitize) and
  # the real-data regressions (fr2_desk: 198 relocalizations, 90 s under ASan; fr3: a 646-frame
  # box map; fr3_cabinet: 58 RGB-D frames, 31 s; the CLI paths they take are covered by the other
  # CLI tests).
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
    ctest --test-dir build-asan --output-on-failure -j "$jobs" \
    -E "packaging.consumer|Cli.Fr2Desk|Cli.Fr3Boxes|Cli.Fr3Cabinet|Acceptance.NoPose"
  echo "sanitize: asan tests done after $((SECONDS - start)) s"
fi

if [ "$what" = tsan ] || [ "$what" = all ]; then
  cmake -S . -B build-tsan "${common[@]}" -DELLRELOC_BUILD_EXAMPLES=OFF \
    -DCMAKE_CXX_FLAGS="-O1 -fsanitize=thread" >/dev/null
  cmake --build build-tsan -j "$jobs" --target concurrency_tests
  echo "sanitize: tsan build done after $((SECONDS - start)) s"
  # One relocalizer shared by 8 threads, one frame split over threads, and a mapper read while it
  # maps: the serial answers.
  TSAN_OPTIONS=halt_on_error=1 build-tsan/tests/concurrency_tests --gtest_filter='*ThreadSafe*:*ReadsWhileMapping*'
fi
