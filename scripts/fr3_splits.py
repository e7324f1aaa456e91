#!/usr/bin/env python3
"""The "fr3 splits" table of docs/benchmarks.md: monocular maps (`ellreloc map --mode boxes`,
motion-capture poses) of six splits of the fr3/long_office first half, each relocalized on
frames it was not built from, ours and the OA-SLAM preset. One split's figures move by several
points when a fit changes which detections the tracker joins; the mean over six is what a
change to the mapper is judged on.

  even/odd    map the even frames, query every 5th odd frame
  thirds      map two frames in three, query every 5th of the others
  50/50, 60/40, 70/30
              map the first 50, 60 or 70% of the frames, query every 5th of the rest (the
              camera moves on to views the map saw little of)
  last 60%    map the last 60%, query every 5th frame of the first 40%

and five more, a second check that a change which moves the first six is not one split's
noise (their own mean): the first 40, 55, 65 and 80% (every 5th frame of the rest), and two
frames in three offset by one ("thirds+1": every 5th of the others).

Usage: scripts/fr3_splits.py [BUILD_DIR] [DATA_DIR]   (prints a Markdown table)
ELLRELOC_FR3=FOLDER splits another part of the sequence in the same layout (real_data.py).
"""
import json
import os
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from real_data import box_map, data, fr3, relocalize  # noqa: E402  (same arguments as real_data.py)


def splits(frames):
    n = len(frames)
    cut = {p: int(p / 100 * n) for p in (40, 50, 60, 70)}
    return [
        ("even/odd", frames[0::2], frames[1::10]),
        ("thirds", [f for i, f in enumerate(frames) if i % 3], frames[0::15]),
        ("50/50", frames[:cut[50]], frames[cut[50]::5]),
        ("60/40", frames[:cut[60]], frames[cut[60]::5]),
        ("70/30", frames[:cut[70]], frames[cut[70]::5]),
        ("last 60%", frames[cut[40]:], frames[:cut[40]:5]),
    ]


def other_splits(frames):
    n = len(frames)
    cut = {p: int(p / 100 * n) for p in (40, 55, 65, 80)}
    return [("%d/%d" % (p, 100 - p), frames[:cut[p]], frames[cut[p]::5]) for p in (40, 55, 65, 80)] + [
        ("thirds+1", [f for i, f in enumerate(frames) if (i + 1) % 3], frames[2::15])]


def table(name_of_mean, chosen, camera, groundtruth, work, first_key):
    """One row per split, then their mean."""
    totals = [0.0, 0.0, 0.0, 0.0]
    for k, (name, mapping, query) in enumerate(chosen):
        map_path, query_path, what = box_map(camera, groundtruth, mapping, query, work, str(first_key + k))
        valid = [float(relocalize(camera, map_path, query_path, groundtruth, method, work, extra)["valid"])
                 for method, extra in (("ours", ()), ("ours", ("--accept-all",)), ("oa-slam", ()))]
        quality = float(what.split("IoU ")[1])
        for i, v in enumerate([quality] + valid):
            totals[i] += v
        print("| %s | %d | %d | %s | %.1f%% | %.1f%% | %.1f%% |" % (name, len(mapping), len(query), what, *valid))
    print("| **%s** | | | held-out IoU %.2f | **%.1f%%** | **%.1f%%** | %.1f%% |" %
          ((name_of_mean,) + tuple(t / len(chosen) for t in totals)))


def main():
    camera, groundtruth = os.path.join(fr3, "camera.yaml"), os.path.join(fr3, "groundtruth.txt")
    frames = json.load(open(os.path.join(fr3, "detections.json")))
    print("| split | map frames | query frames | map | ours | ours, every pose | oa-slam preset |")
    print("|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as work:
        table("mean", splits(frames), camera, groundtruth, work, 0)
        table("mean of the five others", other_splits(frames), camera, groundtruth, work, 100)


if __name__ == "__main__":
    main()
