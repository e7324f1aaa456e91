#!/usr/bin/env bash
# Runs each libFuzzer target (ASan + UBSan, any report aborts) for SECONDS (default 30) from the
# seed corpus in tests/fuzz/corpus, as many targets at once as there are cores. The targets come
# from the sanitizer build of scripts/sanitize.sh asan (configured here if missing, built or
# brought up to date). The corpus grown during the run stays in build-asan/corpus/; crashing
# inputs go to build-asan/artifacts/.
#   scripts/fuzz.sh [SECONDS]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-30}"
dir=build-asan
targets=(fuzz_rle fuzz_json fuzz_text_files fuzz_geometry fuzz_relocalizer fuzz_image fuzz_mapper)
[ -f "$dir/build.ninja" ] || scripts/sanitize.sh configure-asan
cmake --build "$dir" -j "$(nproc)" --target "${targets[@]}"  # nothing to do when they are up to date
mkdir -p "$dir/artifacts"

# One target for SECONDS; prints one line (or the failure and the log's last lines) at once, so
# that targets run side by side do not interleave their output.
fuzz_one() {
  local target="$1" log="$dir/$1.log" runs
  mkdir -p "$dir/corpus/$target"
  if "$dir/tests/fuzz/$target" "$dir/corpus/$target" "tests/fuzz/corpus/$target" \
      -max_total_time="$seconds" -timeout=20 -rss_limit_mb=2048 -print_final_stats=1 \
      -artifact_prefix="$dir/artifacts/$target-" >"$log" 2>&1; then
    runs=$(grep -o 'stat::number_of_executed_units: [0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
    echo "fuzz: $target ok, $runs executions in ${seconds} s"
  else
    printf '%s\n%s\n' "fuzz: $target FAILED (input in $dir/artifacts/); last lines of $log:" "$(tail -n 30 "$log")" >&2
    return 1
  fi
}

# As many targets at once as there are cores (each fuzzer runs on one).
status=0
running=()
for target in "${targets[@]}"; do
  fuzz_one "$target" &
  running+=($!)
  if [ "${#running[@]}" -ge "$(nproc)" ]; then
    wait "${running[0]}" || status=1
    running=("${running[@]:1}")
  fi
done
for pid in "${running[@]}"; do wait "$pid" || status=1; done
exit $status
