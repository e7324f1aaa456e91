#!/usr/bin/env python3
"""How the boxes mapper associates real detections, against a reference association: fr2_desk's
keyframe boxes (../shared/data/tum_fr2_desk), each of which GOReloc's own mapping associated with
one of its map objects (`object_id`; 1,185 of 1,200), mapped in boxes mode at the keyframes' poses.
Each box's object is the one its keyframe's report named (`KeyframeReport.object_ids`), followed
through later joins (`Mapper.current_object_id`). Prints a Markdown table:

- pairs: over the pairs of boxes that both associations hold in a map object, the share of the
  pairs ours puts in one object that the reference does too (precision) and the reverse (recall);
- split: reference objects with at least 3 boxes in each of two or more of our objects;
- merged: our objects with at least 3 boxes of each of two or more reference objects.

The reference is GOReloc's tracker, not a ground truth (it gives a fifth of its boxes to an object
of another category): read the figures as agreement.

Usage: PYTHONPATH=BUILD/python python3 scripts/associations.py [DATA_DIR]
"""
import collections
import itertools
import os
import sys

import ellreloc

MIN_BOXES = 3  # boxes of one object in another that make a split or a merge


def agreement(pairs):
    """pairs: (reference id, our id) per box; ids of boxes in no object left out."""
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


def main():
    data = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "..", "shared", "data")
    folder = os.path.join(data, "tum_fr2_desk")
    camera = ellreloc.read_camera(os.path.join(folder, "camera.yaml"))
    truth = ellreloc.read_trajectory(os.path.join(folder, "keyframes.groundtruth.txt"))
    index = ellreloc.time_index(truth)
    mapper = ellreloc.Mapper(camera, mode="boxes")
    reference_category = {o.id: o.category for o in ellreloc.read_map(os.path.join(folder, "map.json")).objects}
    boxes = []  # (reference id or None, our id as reported, the box's category is its reference object's)
    for frame in ellreloc.read_detections(os.path.join(folder, "keyframes.detections.json")):
        k = index.nearest(frame.timestamp)
        if k is None:
            continue
        report = mapper.add_keyframe(truth[k].pose, frame.detections)
        boxes += [(d.object_id, i, reference_category.get(d.object_id) == d.category_id)
                  for d, i in zip(frame.detections, report.object_ids)]
    mapper.finish()
    in_map = {o.id for o in mapper.map().objects}
    print("| boxes of fr2_desk's keyframes | boxes | with a reference object | in one of our objects "
          "| pairs: precision / recall | reference objects split | our objects merging two |")
    print("|---|---|---|---|---|---|---|")
    for name, keep in (("all", lambda same: True), ("of their reference object's category", lambda same: same)):
        kept = [(r, i) for r, i, same in boxes if keep(same)]
        pairs = []
        for r, i in kept:
            now = mapper.current_object_id(i) if i >= 0 else None
            if r is not None and now in in_map:
                pairs.append((r, now))
        precision, recall, split, merged, references, ours = agreement(pairs)
        print(f"| {name} | {len(kept)} | {sum(r is not None for r, _ in kept)} | {len(pairs)} (in {ours} of our "
              f"{len(in_map)} objects) | {precision:.3f} / {recall:.3f} | {split} of {references} | {merged} of {ours} |")


if __name__ == "__main__":
    main()
