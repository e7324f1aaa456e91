#!/usr/bin/env python3
"""The "margin" table of docs/reliability.md: what asking for a margin over the best rival pose
(`ellreloc relocalize --min-margin M`, acceptance.min_margin) does to the poses reported for the
null frames of scripts/null_frames.py and for the real query frames of the same maps.

Each set is relocalized once with the default acceptance test and `--report`; a pose passes a
margin M when it was reported and its `margin` (null: no rival) is at least M, which is what
`--min-margin M` reports (the margin is checked after the evidence, on the same search). The real
sets are diagnosed against their ground truth (`--reference`): valid poses (< 30 cm, < 30 deg)
and wrong ones.

The second table is for a host that checks poses with its own points: every pose reported
(`--accept-all`), how many frames have a valid pose, how many have a valid pose or a valid rival
(the report's `rival`, the best refined pose 30 cm or 30 deg away), which such a host would try
next, and how many have a valid pose or a valid one among all the other answers found (the
report's `alternatives`, which it would try in turn).

Usage: scripts/acceptance_margin.py [BUILD_DIR] [DATA_DIR]   (prints a Markdown table)
"""
import json
import os
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from null_frames import null_sets  # noqa: E402
from real_data import run  # noqa: E402  (same arguments as real_data.py)

MARGINS = (0.0, 0.1, 0.2, 0.3, 0.5)


def report(camera, map_path, frames, work, extra):
    """The --report entries of `ellreloc relocalize` on `frames` with `extra` options."""
    detections, path = os.path.join(work, "margin.detections.json"), os.path.join(work, "margin.report.json")
    json.dump(frames, open(detections, "w"))
    run("relocalize", "--camera", camera, "--map", map_path, "--detections", detections, "--threads", "2", "--out",
        os.path.join(work, "margin.poses.txt"), "--report", path, *extra)
    return json.load(open(path))


def reported(camera, map_path, frames, work, groundtruth=None):
    """(frame count, [(margin, valid)] of the reported poses); valid is None without ground truth."""
    poses = []
    for f in report(camera, map_path, frames, work, ["--reference", groundtruth] if groundtruth else []):
        if f["status"] != "success":
            continue
        margin = float("inf") if f["margin"] is None else f["margin"]
        valid = f.get("reference", {}).get("diagnosis") == "valid" if groundtruth else None
        poses.append((margin, valid))
    return len(frames), poses


def main():
    with tempfile.TemporaryDirectory() as work:
        null, real = null_sets(work)
        null_frames, null_poses = 0, []
        for _, camera, map_path, frames in null:
            n, poses = reported(camera, map_path, frames, work)
            null_frames += n
            null_poses += poses
        real_runs = [(label, reported(camera, map_path, frames, work, truth)) for label, camera, map_path, frames, truth
                     in real]
        print("| min margin | null frames reported (of %s) | %s | all real frames: valid / wrong |" %
              ("{:,}".format(null_frames), " | ".join("%s (%d): valid / wrong" % (label, n)
                                                      for label, (n, _) in real_runs)))
        print("|---" * (3 + len(real_runs)) + "|")
        for m in MARGINS:
            passed = sum(1 for margin, _ in null_poses if margin >= m)
            cells, total_valid, total_wrong = [], 0, 0
            for _, (n, poses) in real_runs:
                valid = sum(1 for margin, ok in poses if margin >= m and ok)
                wrong = sum(1 for margin, ok in poses if margin >= m and not ok)
                total_valid, total_wrong = total_valid + valid, total_wrong + wrong
                cells.append("%d / %d" % (valid, wrong))
            print("| %s | %d (%.2f%%) | %s | %d / %d |" % ("%.1f%s" % (m, " (default)" if m == 0 else ""), passed,
                                                           100.0 * passed / null_frames, " | ".join(cells),
                                                           total_valid, total_wrong))
        print()
        print("| real set, every pose reported | frames | pose valid | pose or rival valid "
              "| pose or an alternative valid |")
        print("|---|---|---|---|---|")
        for label, camera, map_path, frames, truth in real:
            entries = report(camera, map_path, frames, work, ["--reference", truth, "--accept-all"])
            checks = [f.get("reference", {}) for f in entries]
            valid = sum(1 for c in checks if c.get("diagnosis") == "valid")
            either = sum(1 for c in checks if c.get("diagnosis") == "valid" or c.get("rival_valid"))
            any_ = sum(1 for c in checks if c.get("diagnosis") == "valid" or c.get("valid_alternative") is not None)
            print("| %s | %d | %s | %s | %s |" % (label, len(frames), *("%d (%.1f%%)" % (k, 100.0 * k / len(frames))
                                                                       for k in (valid, either, any_))))


if __name__ == "__main__":
    main()
