#!/usr/bin/env python3
"""How the mapper associates detections with objects, against a reference association. Each box's
object is the one its keyframe's report named (`KeyframeReport.object_ids`), followed through
later joins (`Mapper.current_object_id`); boxes that joined none of the map's objects are left
out. The data sets:

- fr2_desk's keyframe boxes (../shared/data/tum_fr2_desk), boxes mode at the keyframes' poses.
  The reference is the association GOReloc's own mapping made (`object_id`, 1,185 of 1,200
  boxes): not a ground truth, since it gives a fifth of its boxes to an object of another
  category; a second row keeps the boxes of their reference object's category.
- office_s11's 40 mapping keyframes (independent renderer), voxel mode with their depth images
  and boxes mode, against the true object of each detection (mapping.ellipse_truth.json; false
  positives have none);
- the same for each further scene folder given, of either layout (benchmarks/scene_folder.hpp):
  `ellreloc simulate`'s scenes, whose truth names each detection's object by its box.

Prints a Markdown table: over the pairs of boxes that both associations hold in an object, the
share of the pairs ours puts in one object that the reference does too (precision) and the
reverse (recall); the reference objects split over two of ours, and our objects merging two of
the reference's (at least 3 boxes each).

Usage: PYTHONPATH=BUILD/python python3 scripts/associations.py [DATA_DIR [SCENE_DIR...]]
"""
import collections
import json
import os
import sys

import ellreloc

MIN_BOXES = 3  # boxes of one object in another that make a split or a merge


def agreement(pairs):
    """pairs: (reference id, our id) per box. Precision, recall, split, merged, reference objects, ours."""
    def together(key):
        groups = collections.Counter(key(p) for p in pairs)
        return sum(n * (n - 1) // 2 for n in groups.values())
    both, ours, reference = together(lambda p: p), together(lambda p: p[1]), together(lambda p: p[0])
    ours_of = collections.defaultdict(collections.Counter)
    reference_of = collections.defaultdict(collections.Counter)
    for r, o in pairs:
        ours_of[r][o] += 1
        reference_of[o][r] += 1
    split = sum(1 for c in ours_of.values() if sum(n >= MIN_BOXES for n in c.values()) >= 2)
    merged = sum(1 for c in reference_of.values() if sum(n >= MIN_BOXES for n in c.values()) >= 2)
    return both / ours, both / reference, split, merged, len(ours_of), len(reference_of)


def mapped(camera, mode, keyframes):
    """keyframes: (pose, detections, depth or None, references per detection). The mapper and,
    per box, (reference id or None, our object's id now or None)."""
    mapper = ellreloc.Mapper(camera, mode=mode)
    reported = []
    for pose, detections, depth, references in keyframes:
        report = mapper.add_keyframe(pose, detections, depth) if depth is not None else \
            mapper.add_keyframe(pose, detections)
        reported += list(zip(references, report.object_ids))
    mapper.finish()
    in_map = {o.id for o in mapper.map().objects}
    boxes = []
    for r, i in reported:
        now = mapper.current_object_id(i) if i >= 0 else None
        boxes.append((r, now if now in in_map else None))
    return mapper, boxes


def row(name, mapper, boxes):
    pairs = [(r, o) for r, o in boxes if r is not None and o is not None]
    precision, recall, split, merged, references, ours = agreement(pairs)
    return (f"| {name} | {len(boxes)} | {sum(r is not None for r, _ in boxes)} | {len(pairs)} (in {ours} of our "
            f"{len(mapper.map().objects)} objects) | {precision:.3f} / {recall:.3f} | {split} of {references} | "
            f"{merged} of {ours} |")


def fr2_rows(data):
    folder = os.path.join(data, "tum_fr2_desk")
    camera = ellreloc.read_camera(os.path.join(folder, "camera.yaml"))
    truth = ellreloc.read_trajectory(os.path.join(folder, "keyframes.groundtruth.txt"))
    index = ellreloc.time_index(truth)
    category = {o.id: o.category for o in ellreloc.read_map(os.path.join(folder, "map.json")).objects}
    keyframes, same_category = [], []
    for frame in ellreloc.read_detections(os.path.join(folder, "keyframes.detections.json")):
        k = index.nearest(frame.timestamp)
        if k is not None:
            keyframes.append((truth[k].pose, frame.detections, None, [d.object_id for d in frame.detections]))
            same_category += [category.get(d.object_id) == d.category_id for d in frame.detections]
    mapper, boxes = mapped(camera, "boxes", keyframes)
    kept = [b for b, same in zip(boxes, same_category) if same]
    return [row("fr2_desk keyframes, boxes mode (reference: GOReloc's association)", mapper, boxes),
            row("the same, the boxes of their reference object's category", mapper, kept)]


def scene_rows(folder):
    """A scene folder of either layout (benchmarks/scene_folder.hpp): its mapping keyframes, voxel
    and boxes mode, against the true object of each detection (false positives have none)."""
    independent = os.path.exists(os.path.join(folder, "mapping.detections.json"))
    base = folder if independent else os.path.join(folder, "mapping")
    prefix = "mapping." if independent else ""
    camera = ellreloc.read_camera(os.path.join(folder, "camera.yaml"))
    trajectory = ellreloc.read_trajectory(os.path.join(base, prefix + "trajectory.txt"))
    index = ellreloc.time_index(trajectory)
    associations = ellreloc.AssociationIndex(ellreloc.read_associations(os.path.join(base, "associations.txt")))
    with open(os.path.join(base, prefix + "ellipse_truth.json")) as f:
        truth = {t["file_name"]: t["detections"] for t in json.load(f)}
    keyframes = []
    for frame in ellreloc.read_detections(os.path.join(base, prefix + "detections.json")):
        a = associations.find(os.path.join(base, frame.file_name), frame.timestamp)
        pose = trajectory[index.nearest(a.rgb_time)].pose
        true_objects = truth.get(frame.file_name, [])
        if independent:  # the truth names each detection by its index
            by_index = {t["det_index"]: t["object_id"] for t in true_objects}
            references = [by_index.get(j) for j in range(len(frame.detections))]
        else:  # the truth repeats the box of each detection of a true object
            references = [next((t["object_id"] for t in true_objects
                                if max(abs(x - y) for x, y in zip(d.bbox.to_array(), t["bbox"])) < 1e-3), None)
                          for d in frame.detections]
        keyframes.append((pose, frame.detections, ellreloc.read_depth_png(a.depth_path), references))
    name = os.path.basename(os.path.normpath(folder))
    rows = []
    for mode in ("voxel", "boxes"):
        mapper, boxes = mapped(camera, mode, keyframes if mode == "voxel" else
                               [(p, d, None, r) for p, d, _, r in keyframes])
        rows.append(row(f"{name} mapping keyframes, {mode} mode (reference: the true objects)", mapper, boxes))
    return rows


def main():
    data = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "..", "shared", "data")
    scenes = [os.path.join(data, "independent_synth", "office_s11")] + sys.argv[2:]
    print("| data, mode (reference) | boxes | with a reference object | in one of our objects | pairs: precision / recall "
          "| reference objects split | our objects merging two |")
    print("|---|---|---|---|---|---|---|")
    rows = fr2_rows(data)
    for scene in scenes:
        rows += scene_rows(scene)
    for line in rows:
        print(line)


if __name__ == "__main__":
    main()
