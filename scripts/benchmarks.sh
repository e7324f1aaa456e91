#!/usr/bin/env bash
# Builds the benchmarks, runs them all, and rewrites the generated tables of docs/benchmarks.md
# and docs/reliability.md from this one run (each between <!-- bench:NAME --> and
# <!-- /bench:NAME -->, stamped with the date, the core count and the command). Raw outputs stay
# in $ELLRELOC_BUILD_DIR/bench-results.
#   scripts/benchmarks.sh           the full set (about 20 minutes on 2 cores)
#   scripts/benchmarks.sh --quick   fewer repetitions and seeds, no exhaustive baseline on the cluttered scene
set -euo pipefail
cd "$(dirname "$0")/.."
quick=0
[ "${1:-}" = "--quick" ] && quick=1
build="${ELLRELOC_BUILD_DIR:-build}"
scripts/build.sh >/dev/null
out="$build/bench-results"
rm -rf "$out" && mkdir -p "$out"
bin="$build/benchmarks"
reps=5 seeds=5
[ $quick = 1 ] && reps=3 seeds=2

gbench() {  # NAME BINARY [FILTER]: Google Benchmark, medians of $reps repetitions, as JSON
  local name=$1 binary=$2 filter=${3:-.}
  local cmd="$bin/$binary --benchmark_filter=$filter --benchmark_repetitions=$reps --benchmark_report_aggregates_only=true"
  echo "benchmarks: $name" >&2
  $cmd --benchmark_format=json >"$out/$name.json" 2>/dev/null
  echo "$cmd" >"$out/$name.command"
}
table() {  # NAME COMMAND...: an accuracy binary that prints a Markdown table
  local name=$1
  shift
  echo "benchmarks: $name" >&2
  "$@" >"$out/$name.txt"
  echo "$*" >"$out/$name.command"
}

gbench core bench_core
gbench p3p bench_p3p
gbench frame_poses bench_io
gbench refiner bench_pose 'Refine'
gbench relocalize_room bench_pose 'Relocalize47|WorstCase'
gbench huge_frames bench_pose 'HugeFrame'
gbench real_frames bench_real_frames
gbench observe bench_observe
gbench sim bench_sim
gbench mapping bench_mapping
if [ $quick = 1 ]; then
  table reloc_accuracy "$bin/reloc_accuracy" --ours-only
else
  table reloc_accuracy "$bin/reloc_accuracy"
fi
table real_data python3 scripts/real_data.py "$build"
table fr3_splits python3 scripts/fr3_splits.py "$build"
table keyframe_maps python3 scripts/keyframe_maps.py "$build"
table detection_orders python3 scripts/detection_orders.py "$build"
table null_frames python3 scripts/null_frames.py "$build"
table acceptance_margin python3 scripts/acceptance_margin.py "$build"
table pose_regions python3 scripts/pose_regions.py "$build"
table tracks python3 scripts/tracks.py "$build"
table observe_accuracy "$bin/observe_accuracy"
table mapping_accuracy "$bin/mapping_accuracy" --seeds "$seeds"
# Observations, voxel maps and relocalization on the independent renderer's scene and on two
# of the project's simulator with the same room preset, noise and mapping keyframe count.
data=$(sed -n 's/^ELLRELOC_DATA_DIR:[A-Z]*=//p' "$build/CMakeCache.txt")
data=$(realpath --relative-to=. "$data")
for seed in 1 2; do
  "$build/apps/ellreloc/ellreloc" --quiet simulate --preset office --seed $seed --noise realistic \
    --mapping-frames 40 --out "$out/scenes/sim_office_$seed"
done
table scene_accuracy "$bin/scene_accuracy" "$data/independent_synth/office_s11" "$out/scenes/sim_office_1" \
  "$out/scenes/sim_office_2"
python=$(sed -n 's/^Python3_EXECUTABLE:[A-Z]*=//p' "$build/CMakeCache.txt")
if [ -d "$build/python/ellreloc" ] && [ -n "$python" ]; then
  table python_overhead env PYTHONPATH="$build/python" "$python" benchmarks/python_overhead.py
  table regular_verdict env PYTHONPATH="$build/python" "$python" benchmarks/regular_verdict.py \
    "$data/independent_synth/office_s11" "$out/scenes/sim_office_1" "$out/scenes/sim_office_2"
  table split_map_limits env PYTHONPATH="$build/python" "$python" scripts/split_map_limits.py "$build" "$data"
  table unit_estimates env PYTHONPATH="$build/python" "$python" scripts/unit_estimates.py "$data"
  table associations env PYTHONPATH="$build/python" "$python" scripts/associations.py "$data" \
    "$out/scenes/sim_office_1" "$out/scenes/sim_office_2"
else
  echo "benchmarks: python_overhead, regular_verdict, split_map_limits, unit_estimates and associations skipped (no Python bindings in $build)" >&2
fi
table startup python3 benchmarks/startup.py "$build" "$data" "$python"

scripts/doc_images.sh "$build"

python3 scripts/benchmark_tables.py "$out" docs/benchmarks.md "$(nproc)"
python3 scripts/benchmark_tables.py "$out" docs/reliability.md "$(nproc)"
echo "benchmarks: docs/benchmarks.md and docs/reliability.md rewritten from $out" >&2
