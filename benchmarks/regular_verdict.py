#!/usr/bin/env python3
"""The regular-mask verdict against a scene's truth for several outline tolerances
(`RegularMaskOptions.outline_tolerance`, 2% by default: the paper's rule), on scene folders of
either layout (benchmarks/scene_folder.hpp): precision and recall of the flag over the query
detections of true objects, matched to their truth by box, as `scene_accuracy` does.

    PYTHONPATH=build/python python3 benchmarks/regular_verdict.py SCENE_DIR...
"""

import json
import pathlib
import sys

import ellreloc

TOLERANCES = (0.01, 0.015, 0.02, 0.025, 0.03)


def query_files(scene):
    if (scene / "query.detections.json").exists():  # the independent renderer's layout
        return scene / "query.detections.json", scene / "ellipse_truth.json"
    return scene / "query" / "detections.json", scene / "query" / "ellipse_truth.json"


def masks_with_truth(scene):
    """(mask, truly regular) for each query detection with a mask whose truth has a projected
    ellipse and a regular flag (the detections `scene_accuracy` scores)."""
    detections_path, truth_path = query_files(scene)
    frames = ellreloc.read_detections(detections_path)
    truth = json.load(open(truth_path))
    pairs = []
    for frame, truth_frame in zip(frames, truth):
        for t in truth_frame["detections"]:
            if t.get("regular") is None or t.get("ellipse") is None:
                continue
            same_box = [d for d in frame.detections
                        if max(abs(a - b) for a, b in zip(d.bbox.to_array(), t["bbox"])) < 1e-3]
            if same_box and same_box[0].mask is not None:
                pairs.append((same_box[0].mask, bool(t["regular"])))
    return pairs


def main():
    scenes = [pathlib.Path(p) for p in sys.argv[1:]]
    if not scenes:
        sys.exit("usage: regular_verdict.py SCENE_DIR...")
    print("| scene | masks | truly regular | " +
          " | ".join("%.1f%%: precision / recall" % (100 * t) for t in TOLERANCES) + " |")
    print("|---|---|---|" + "---|" * len(TOLERANCES))
    for scene in scenes:
        pairs = masks_with_truth(scene)
        truly = sum(regular for _, regular in pairs)
        cells = []
        for tolerance in TOLERANCES:
            options = ellreloc.RegularMaskOptions()
            options.outline_tolerance = tolerance
            flags = [ellreloc.test_regular_mask(mask, options).regular for mask, _ in pairs]
            flagged = sum(flags)
            right = sum(f and regular for f, (_, regular) in zip(flags, pairs))
            cells.append("%.2f / %.2f" % (right / max(flagged, 1), right / max(truly, 1)))
        print("| %s | %d | %d | %s |" % (scene.name, len(pairs), truly, " | ".join(cells)))


if __name__ == "__main__":
    main()
