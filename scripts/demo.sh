#!/usr/bin/env bash
# Installs missing dependencies, builds, and runs the main example.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh
"${ELLRELOC_BUILD_DIR:-build}/examples/minimal/ellreloc_minimal" "$@"
