#!/usr/bin/env python3
"""The "no pose from noise" table of docs/reliability.md: how often `ellreloc relocalize`
(ours, default acceptance test) reports a pose for frames that hold no evidence of the map they
are relocalized against.

  boxes moved   each box of a real frame moved to a uniformly random place in the image and given
                the size of a random box of the same sequence (categories and sizes real, no
                geometry); fixed seeds
  other scene   the frames of one data set against the map of another

"a pose found" counts the frames where the search found any pose (reported or withheld as
LowEvidence); "reported" those given a pose (Success). The maps are those of the real-data table
(scripts/real_data.py): the fr2_desk GOReloc map, the fr3 maps built by `ellreloc map --mode boxes`
from the even frames and from the first 60% of the fr3/long_office first half, office_s11's noisy
map. Each set of frames is relocalized with its own camera.

Usage: scripts/null_frames.py [BUILD_DIR] [DATA_DIR]   (prints a Markdown table)
"""
import json
import os
import random
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from real_data import box_map, data, fr3, run, table_splits  # noqa: E402  (same arguments as real_data.py)


def moved_boxes(frames, width, height, seed):
    """The frames with every box at a random place, with the size of a random box of the frames."""
    sizes = [(d["bbox"][2] - d["bbox"][0], d["bbox"][3] - d["bbox"][1]) for f in frames for d in f["detections"]]
    rng = random.Random(seed)
    out = []
    for i, f in enumerate(frames):
        # A name of its own (a numeric base name is the frame's timestamp): two draws of the
        # same frames can go in one file.
        moved = dict(f, file_name="moved/%d.png" % (seed * 100000 + i), detections=[])
        for d in f["detections"]:
            w, h = rng.choice(sizes)
            x, y = rng.uniform(0, max(0.0, width - w)), rng.uniform(0, max(0.0, height - h))
            moved["detections"].append(dict(d, bbox=[x, y, x + w, y + h]))
        out.append(moved)
    return out


def count_poses(camera, map_path, frames, work):
    """(frames, frames with a pose found, frames with a pose reported)."""
    detections, report = os.path.join(work, "null.detections.json"), os.path.join(work, "null.report.json")
    json.dump(frames, open(detections, "w"))
    run("relocalize", "--camera", camera, "--map", map_path, "--detections", detections, "--threads", "2", "--out",
        os.path.join(work, "null.poses.txt"), "--report", report)
    statuses = [f["status"] for f in json.load(open(report))]
    return len(statuses), sum(s in ("success", "low evidence") for s in statuses), statuses.count("success")


def image_size(camera):
    """Width and height of an ORB-SLAM YAML camera file."""
    size = {}
    for line in open(camera):
        key, _, value = line.partition(":")
        if key.strip() in ("Camera.width", "Camera.height"):
            size[key.strip()] = float(value)
    return size["Camera.width"], size["Camera.height"]


def null_sets(work):
    """The null sets as (label, camera, map path, frames), and the real query sets of the same maps
    as (label, camera, map path, frames, ground truth); the fr3 maps are built in `work`."""
    fr2 = os.path.join(data, "tum_fr2_desk")
    s11 = os.path.join(data, "independent_synth", "office_s11")
    fr2_cam, fr3_cam, s11_cam = (os.path.join(d, "camera.yaml") for d in (fr2, fr3, s11))
    fr2_frames = json.load(open(os.path.join(fr2, "keyframes.detections.json")))
    s11_frames = json.load(open(os.path.join(s11, "query.detections.json")))
    splits = table_splits(json.load(open(os.path.join(fr3, "detections.json"))))
    fr3_odd, fr3_rest = splits["fr3 even/odd"][1], splits["fr3 60/40"][1]
    maps = {"fr2": os.path.join(fr2, "map.json"), "s11": os.path.join(s11, "map_noisy.json")}
    for name, split in (("fr3_even", "fr3 even/odd"), ("fr3_60", "fr3 60/40")):
        maps[name] = box_map(fr3_cam, os.path.join(fr3, "groundtruth.txt"), *splits[split], work, name)[0]

    def moved(frames, camera, seed):
        return moved_boxes(frames, *image_size(camera), seed)

    null = [
        ("fr2_desk keyframes, boxes moved (two draws), vs the fr2 map", fr2_cam, maps["fr2"],
         moved(fr2_frames, fr2_cam, 1) + moved(fr2_frames, fr2_cam, 2)),
        ("fr3 odd frames, boxes moved, vs its even-frame map", fr3_cam, maps["fr3_even"], moved(fr3_odd, fr3_cam, 3)),
        ("fr3 60/40 query frames, boxes moved, vs its 60% map", fr3_cam, maps["fr3_60"], moved(fr3_rest, fr3_cam, 4)),
        ("office_s11 frames, boxes moved, vs the office_s11 map", s11_cam, maps["s11"], moved(s11_frames, s11_cam, 5)),
        ("fr3 odd frames vs the fr2 map", fr3_cam, maps["fr2"], fr3_odd),
        ("fr2 keyframes vs the fr3 even-frame map", fr2_cam, maps["fr3_even"], fr2_frames),
        ("fr2 keyframes vs the fr3 60% map", fr2_cam, maps["fr3_60"], fr2_frames),
        ("fr2 keyframes vs the office_s11 map", fr2_cam, maps["s11"], fr2_frames),
        ("office_s11 frames vs the fr2 map", s11_cam, maps["fr2"], s11_frames),
        ("office_s11 frames vs the fr3 60% map", s11_cam, maps["fr3_60"], s11_frames),
    ]
    real = [
        ("fr2_desk keyframes", fr2_cam, maps["fr2"], fr2_frames, os.path.join(fr2, "keyframes.groundtruth.txt")),
        ("fr3 odd frames (even-frame map)", fr3_cam, maps["fr3_even"], fr3_odd, os.path.join(fr3, "groundtruth.txt")),
        ("fr3 60/40", fr3_cam, maps["fr3_60"], fr3_rest, os.path.join(fr3, "groundtruth.txt")),
        ("office_s11 (noisy map)", s11_cam, maps["s11"], s11_frames, os.path.join(s11, "query.groundtruth.txt")),
    ]
    return null, real


def main():
    with tempfile.TemporaryDirectory() as work:
        print("| null frames (each against the map named) | frames | a pose found | reported |")
        print("| --- | --- | --- | --- |")
        total = [0, 0, 0]
        for label, camera, map_path, frames in null_sets(work)[0]:
            counts = count_poses(camera, map_path, frames, work)
            total = [t + c for t, c in zip(total, counts)]
            print("| %s | %d | %d | %d |" % (label, *counts))
        n, found, reported = total
        print("| **all** | **{:,}** | **{:,} ({:.0f}%)** | **{} ({:.1f}%)** |".format(n, found, 100.0 * found / n, reported,
                                                                                100.0 * reported / n))


if __name__ == "__main__":
    main()
