#!/usr/bin/env bash
# Runs each libFuzzer target (ASan + UBSan, any report aborts) for SECONDS (default 30) from the
# seed corpus in tests/fuzz/corpus. The targets come from the sanitizer build of
# scripts/sanitize.sh asan (configured here if missing, built or brought up to date). The
# corpus grown during the run stays in build-asan/corpus/; crashing inputs go to
# build-asan/artifacts/.
#   scripts/fuzz.sh [SECONDS]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-30}"
dir=build-asan
targets=(fuzz_rle fuzz_json fuzz_text_files fuzz_geometry fuzz_relocalizer fuzz_image fuzz_mapper)
[ -f "$dir/build.ninja" ] || scripts/sanitize.sh configure-asan
cmake --build "$dir" -j "$(nproc)" --target "${targets[@]}"  # nothing to do when they are up to date
mkdir -p "$dir/artifacts"
status=0
for target in "${targets[@]}"; do
  mkdir -p "$dir/corpus/$target"
  log="$dir/$target.log"
  if "$dir/tests/fuzz/$target" "$dir/corpus/$target" "tests/fuzz/corpus/$target" \
      -max_total_time="$seconds" -timeout=20 -rss_limit_mb=2048 -print_final_stats=1 \
      -artifact_prefix="$dir/artifacts/$target-" >"$log" 2>&1; then
    runs=$(grep -o 'stat::number_of_executed_units: [0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
    echo "fuzz: $target ok, $runs executions in ${seconds} s"
  else
    echo "fuzz: $target FAILED (input in $dir/artifacts/); last lines of $log:" >&2
    tail -n 30 "$log" >&2
    status=1
  fi
done
exit $status
