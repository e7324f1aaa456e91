#!/usr/bin/env python3
"""What limits the fr3 splits whose query frames see the room from where the map's frames
barely did (docs/benchmarks.md, "fr3: box maps over six splits"; the 50/50, 60/40, 70/30 and
last-60% splits and two of the five others): each split's box map against
the box map of the whole first half, which also saw the query frames (an upper bound).

For every query box: the whole-half map object of its category that explains it best, and
whether the split's map holds an object of that category within 30 cm of it ("mapped"). Then
the split's map with the objects that differ from their whole-half counterparts (nearest of the
category, 5 mm to 30 cm away) exchanged for them: its held-out IoU and its valid share, every
pose reported (`ellreloc relocalize --accept-all`).

Usage: PYTHONPATH=BUILD/python python3 scripts/split_map_limits.py [BUILD_DIR] [DATA_DIR]
(needs the Python bindings and numpy; prints a Markdown table)
"""
import copy
import json
import os
import sys
import tempfile
import warnings

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fr3_splits import other_splits, splits  # noqa: E402
from real_data import box_map, data, fr3, relocalize  # noqa: E402

import ellreloc  # noqa: E402

SAME, NEAR = 0.005, 0.3  # metres: an object unchanged, an object held by the split's map
# The splits whose query frames go on to (or come from) parts of the loop the map's frames saw little of.
LIMITED = ("50/50", "60/40", "70/30", "last 60%", "40/60", "55/45")


def posed(camera_frames, trajectory):
    """(pose, detections) of each frame with a ground-truth pose (ellreloc.find_nearest's 20 ms)."""
    nearest_pose = [ellreloc.find_nearest(trajectory, frame.timestamp) for frame in camera_frames]
    return [(trajectory[i].pose, frame.detections) for i, frame in zip(nearest_pose, camera_frames) if i is not None]


def nearest(obj, objects):
    """The object of obj's category in `objects` nearest to it, and the distance (inf: none)."""
    same = [o for o in objects if o["category"] == obj["category"]]
    if not same:
        return None, np.inf
    best = min(same, key=lambda o: np.linalg.norm(np.subtract(o["center"], obj["center"])))
    return best, float(np.linalg.norm(np.subtract(best["center"], obj["center"])))


def box_by_box(split_map, whole_map, camera, frames, whole_json, split_json):
    """Each query box's best IoU under the split's map, and whether its object is mapped."""
    singles = [ellreloc.ObjectMap([o]) for o in whole_map.objects]
    by_id = {o["id"]: o for o in whole_json["objects"]}
    ious, mapped = [], []
    for pose, detections in frames:
        for d in detections:
            one = [(pose, [d])]
            quality = ellreloc.map_quality(split_map, camera, one)
            if quality.boxes == 0:
                continue
            per_object = [ellreloc.map_quality(s, camera, one).median_best_iou
                          if s.objects[0].category == d.category_id else -1.0 for s in singles]
            explains = by_id[whole_map.objects[int(np.argmax(per_object))].id]
            ious.append(quality.median_best_iou)
            mapped.append(nearest(explains, split_json["objects"])[1] < NEAR)
    return np.array(ious), np.array(mapped)


def main():
    warnings.simplefilter("ignore", UserWarning)  # read_map names the objects it leaves out
    camera_path, groundtruth = os.path.join(fr3, "camera.yaml"), os.path.join(fr3, "groundtruth.txt")
    frames = json.load(open(os.path.join(fr3, "detections.json")))
    camera, trajectory = ellreloc.read_camera(camera_path), ellreloc.read_trajectory(groundtruth)
    print("| split | query boxes | boxes of unmapped objects | held-out IoU: split map (mapped objects' boxes) |"
          " whole-half map | objects exchanged | exchanged map | valid every pose: split map | exchanged map |"
          " whole-half map |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as work:
        chosen = [s for s in splits(frames) + other_splits(frames) if s[0] in LIMITED]
        whole_path = box_map(camera_path, groundtruth, frames, chosen[0][2], work, "whole")[0]
        whole_json, whole_map = json.load(open(whole_path)), ellreloc.read_map(whole_path)
        for k, (name, mapping, query) in enumerate(chosen):
            split_path, query_path, _ = box_map(camera_path, groundtruth, mapping, query, work, str(k))
            split_json = json.load(open(split_path))
            exchanged_json = copy.deepcopy(split_json)
            exchanged = 0
            for obj in exchanged_json["objects"]:
                twin, distance = nearest(obj, whole_json["objects"])
                if SAME < distance < NEAR:
                    obj.update({key: twin[key] for key in ("center", "axes", "rotation")})
                    exchanged += 1
            exchanged_path = os.path.join(work, "%d.exchanged.map.json" % k)
            json.dump(exchanged_json, open(exchanged_path, "w"))
            split_map = ellreloc.read_map(split_path)
            query_frames = posed(ellreloc.read_detections(query_path), trajectory)
            ious, mapped = box_by_box(split_map, whole_map, camera, query_frames, whole_json, split_json)
            quality = [ellreloc.map_quality(m, camera, query_frames).median_best_iou
                       for m in (split_map, whole_map, ellreloc.read_map(exchanged_path))]
            valid = [relocalize(camera_path, m, query_path, groundtruth, "ours", work, ("--accept-all",))["valid"]
                     for m in (split_path, exchanged_path, whole_path)]
            print("| %s | %d | %.0f%% | %.2f (%.2f) | %.2f | %d of %d | %.2f | %s%% | %s%% | %s%% |" %
                  (name, len(ious), 100 * (1 - mapped.mean()), quality[0], np.median(ious[mapped]), quality[1],
                   exchanged, len(split_json["objects"]), quality[2], *valid))


if __name__ == "__main__":
    main()
