#!/usr/bin/env bash
# Installs the Debian 12 packages ellreloc needs, only those that are missing.
set -euo pipefail

packages=(
  cmake ninja-build g++ pkg-config
  libeigen3-dev libceres-dev libopencv-dev libpng-dev libjpeg-dev nlohmann-json3-dev libcli11-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libopengv-dev  # benchmarks only: P3P comparison with OpenGV's Kneip solver
  clang-14 libclang-rt-14-dev  # reliability only: sanitizer builds and libFuzzer (scripts/sanitize.sh, fuzz.sh)
  pybind11-dev python3-dev python3-numpy python3-pytest  # the Python bindings (python/) and their tests
  linux-perf  # profiling only: `perf record` (docs/benchmarks.md, "Start-up": the profiles' commands)
  chromium  # tests only: renders `ellreloc report` pages headless (skipped without it)
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
[ ${#missing[@]} -eq 0 ] && exit 0

echo "install-deps: installing ${missing[*]}" >&2
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install-deps: need root or sudo to install ${missing[*]}" >&2; exit 1; }
  SUDO=sudo
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
