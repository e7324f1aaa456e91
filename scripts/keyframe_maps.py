#!/usr/bin/env python3
"""The "box maps from keyframes" table of docs/benchmarks.md: `ellreloc map --mode boxes` fed
keyframes far apart, as a SLAM system's keyframes are, instead of every video frame, on real
boxes with their true poses; each map relocalizes frames it was not built from (ours by
default, ours every pose, the OA-SLAM preset).

  fr2 even/odd keyframes   map fr2_desk's even keyframes, query the odd ones; and the same with
                           the boxes undistorted (`--undistort` to map and to relocalize: they
                           were detected on the raw images of fr2's Kinect)
  fr3 every 10th frame     map every 10th frame of the fr3/long_office first half (3 a second),
                           query the frames halfway between them
  fr3 every 20th frame     the same, one frame in 20
  fr3 60/40, every 10th    map every 10th frame of the first 60%, query every 5th of the rest

Between keyframes far apart a small object's image moves further than its size, which is what
the mapper's 2D tracking has to follow there (docs/mapping.md).

Usage: scripts/keyframe_maps.py [BUILD_DIR] [DATA_DIR]   (prints a Markdown table)
"""
import json
import os
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from real_data import box_map, data, fr3, relocalize  # noqa: E402  (same arguments as real_data.py)


def keyframe_splits():
    """(name, camera, ground truth, mapping frames, query frames, options of map and relocalize)
    of each row."""
    fr2 = os.path.join(data, "tum_fr2_desk")
    keyframes = json.load(open(os.path.join(fr2, "keyframes.detections.json")))
    frames = json.load(open(os.path.join(fr3, "detections.json")))
    cut = int(0.6 * len(frames))
    fr2_files = (os.path.join(fr2, "camera.yaml"), os.path.join(fr2, "keyframes.groundtruth.txt"))
    fr3_files = (os.path.join(fr3, "camera.yaml"), os.path.join(fr3, "groundtruth.txt"))
    return [
        ("fr2 even/odd keyframes", *fr2_files, keyframes[0::2], keyframes[1::2], ()),
        ("fr2 even/odd keyframes, boxes undistorted", *fr2_files, keyframes[0::2], keyframes[1::2], ("--undistort",)),
        ("fr3 every 10th frame", *fr3_files, frames[0::10], frames[5::10], ()),
        ("fr3 every 20th frame", *fr3_files, frames[0::20], frames[10::20], ()),
        ("fr3 60/40, every 10th frame", *fr3_files, frames[:cut:10], frames[cut::5], ()),
    ]


def main():
    print("| data | map frames | query frames | map | ours | ours, every pose | oa-slam preset |")
    print("|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as work:
        for k, (name, camera, groundtruth, mapping, query, options) in enumerate(keyframe_splits()):
            map_path, query_path, what = box_map(camera, groundtruth, mapping, query, work, str(k), options)
            rows = [relocalize(camera, map_path, query_path, groundtruth, method, work, extra + options)
                    for method, extra in (("ours", ()), ("ours", ("--accept-all",)), ("oa-slam", ()))]
            cells = ["%s%% (%s cm)" % (r["valid"], r["pos"]) for r in rows]
            print("| %s | %d | %d | %s | %s |" % (name, len(mapping), len(query), what, " | ".join(cells)))


if __name__ == "__main__":
    main()
