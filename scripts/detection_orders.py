#!/usr/bin/env python3
"""The "detection order" table of docs/benchmarks.md: how much a data set's valid share moves
when only the order of each frame's detections changes.

Ties among near-equal hypotheses are settled by the order of the observations; fr2_desk's YOLO
boxes all have score 1.0, so its ties are many. The relocalizer works on the observations in a
canonical order (docs/pose.md), so no row should move: this checks it, and measures the band of
a search whose result depends on the order. Each set is relocalized with its frames' detections
in the given order (order 0) and in N - 1 seeded shuffles, ours by default, ours reporting every
pose (`--accept-all`) and the OA-SLAM preset.

  fr2_desk keyframes   the real GOReloc map
  fr3 even/odd         map (`ellreloc map --mode boxes`) from the even frames of the fr3/long_office
                       first half, every 5th odd frame queried (as scripts/fr3_splits.py)
  office_s11           the independent renderer's noisy map

Usage: scripts/detection_orders.py [BUILD_DIR] [DATA_DIR] [N]   (prints a Markdown table; N = 8)
"""
import json
import os
import random
import sys
import tempfile

from fr3_splits import splits  # noqa: E402
from real_data import box_map, data, fr3, relocalize  # noqa: E402  (same arguments as real_data.py)

orders = int(sys.argv[3]) if len(sys.argv) > 3 else 8
if orders < 1:
    sys.exit("%s: the number of orders must be at least 1" % sys.argv[0])


def shuffled(path, seed, work):
    """The detections file with each frame's detections in a seeded random order (0: as given)."""
    if seed == 0:
        return path
    frames = json.load(open(path))
    rng = random.Random(seed)
    for frame in frames:
        rng.shuffle(frame["detections"])
    out = os.path.join(work, "order%d.json" % seed)
    json.dump(frames, open(out, "w"))
    return out


def main():
    fr2 = os.path.join(data, "tum_fr2_desk")
    s11 = os.path.join(data, "independent_synth", "office_s11")
    methods = (("ours", "ours", ()), ("ours, every pose", "ours", ("--accept-all",)), ("oa-slam preset", "oa-slam", ()))
    print("| data | method | valid, given order | mean over %d orders | lowest - highest |" % orders)
    print("|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as work:
        _, mapping, query = splits(json.load(open(os.path.join(fr3, "detections.json"))))[0]  # even/odd
        fr3_map, fr3_query, _ = box_map(os.path.join(fr3, "camera.yaml"), os.path.join(fr3, "groundtruth.txt"),
                                        mapping, query, work, "evenodd")
        sets = [("fr2_desk keyframes", os.path.join(fr2, "camera.yaml"), os.path.join(fr2, "map.json"),
                 os.path.join(fr2, "keyframes.detections.json"), os.path.join(fr2, "keyframes.groundtruth.txt")),
                ("fr3 even/odd", os.path.join(fr3, "camera.yaml"), fr3_map, fr3_query,
                 os.path.join(fr3, "groundtruth.txt")),
                ("office_s11", os.path.join(s11, "camera.yaml"), os.path.join(s11, "map_noisy.json"),
                 os.path.join(s11, "query.detections.json"), os.path.join(s11, "query.groundtruth.txt"))]
        for name, camera, map_path, detections, groundtruth in sets:
            paths = [shuffled(detections, seed, work) for seed in range(orders)]
            for label, method, extra in methods:
                valid = [float(relocalize(camera, map_path, p, groundtruth, method, work, extra)["valid"]) for p in paths]
                print("| %s | %s | %.1f%% | %.1f%% | %.1f - %.1f%% |" %
                      (name, label, valid[0], sum(valid) / len(valid), min(valid), max(valid)))


if __name__ == "__main__":
    main()
