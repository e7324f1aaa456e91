#!/usr/bin/env bash
# Installs missing dependencies, builds, and runs `ellreloc demo`: simulate an office, map it,
# relocalize 100 query frames with our method and the OA-SLAM baseline, print the comparison.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh
"${ELLRELOC_BUILD_DIR:-build}/apps/ellreloc/ellreloc" demo "$@"
