#!/usr/bin/env bash
# Regenerates the pictures of docs/cli.md from the demo scene: one relocalization overlay
# (docs/images/overlay.png) and the comparison figure of ours and OA-SLAM
# (docs/images/comparison.png). Run by scripts/benchmarks.sh; needs a built `ellreloc`.
#   scripts/doc_images.sh [build dir]
set -euo pipefail
cd "$(dirname "$0")/.."
cli="${1:-build}/apps/ellreloc/ellreloc"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$cli" -q demo --out "$work/demo" >/dev/null
d="$work/demo"
"$cli" -q relocalize --camera "$d/camera.yaml" --map "$d/map_voxel.json" --detections "$d/query/detections.json" \
  --out "$work/ours.txt" --reference "$d/query/groundtruth.txt" --overlays "$work/overlays" >/dev/null
mkdir -p docs/images
cp "$work/overlays/2001.000000.png" docs/images/overlay.png
"$cli" evaluate --groundtruth "$d/query/groundtruth.txt" --detections "$d/query/detections.json" \
  --estimate "$d/poses_ours_map_voxel.txt:ours" --estimate "$d/poses_oa-slam_map_voxel.txt:OA-SLAM" \
  --map "$d/map_voxel.json" --plot docs/images/comparison.png >/dev/null
echo "doc_images: docs/images/overlay.png, docs/images/comparison.png" >&2
