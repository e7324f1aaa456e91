#!/usr/bin/env bash
# Compiles every public header on its own (-fsyntax-only, -Wall -Wextra): a header that needs
# another include before it, or warns, fails a host that includes it first. About 3 CPU-minutes,
# so it is a check to run after changing includes, not part of CI.
#   scripts/check_headers.sh
set -euo pipefail
cd "$(dirname "$0")/.."
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
check() {  # HEADER: prints the header and the compiler's first lines when it fails or warns
  local tu="$work/$(echo "$1" | tr '/.' '__').cpp"
  echo "#include \"$1\"" >"$tu"
  if ! ${CXX:-g++} -std=c++17 -Iinclude -isystem /usr/include/eigen3 -isystem /usr/include/opencv4 -fsyntax-only \
      -Wall -Wextra "$tu" >"$tu.log" 2>&1 || [ -s "$tu.log" ]; then
    echo "check_headers: $1 does not compile cleanly on its own:"
    head -n 5 "$tu.log"
    return 1
  fi
}
export -f check
export work
(cd include && ls ellreloc/*.hpp ellreloc/*/*.hpp) | xargs -P "$(nproc)" -I{} bash -c 'check {}'
echo "check_headers: every public header compiles on its own"
