#!/usr/bin/env python3
"""The unit a monocular map's objects tell (docs/mapping.md, "Poses of unknown scale"): the fr3
first half's boxes, with the motion-capture poses given in units of U metres (every translation
divided by U, as a monocular SLAM system's poses are in a unit of its own), mapped in boxes mode
taking a unit of 1 m, then mapped again with the unit the objects told (`Mapper.estimated_unit_metres`),
three passes in all. Prints a Markdown table: each pass's unit taken, objects and estimate.

Usage: PYTHONPATH=BUILD/python python3 scripts/unit_estimates.py [DATA_DIR]
"""
import os
import sys

import ellreloc

UNITS = (0.25, 1.0, 2.5, 4.0)  # metres per unit of the poses
PASSES = 3


def main():
    data = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "..", "shared", "data")
    folder = os.path.join(data, "tum_fr3_office_first_half")
    camera = ellreloc.read_camera(os.path.join(folder, "camera.yaml"))
    truth = ellreloc.read_trajectory(os.path.join(folder, "groundtruth.txt"))
    index = ellreloc.time_index(truth)
    keyframes = [(truth[k].pose, f.detections) for f in ellreloc.read_detections(os.path.join(folder, "detections.json"))
                 if (k := index.nearest(f.timestamp)) is not None]

    def mapped(frames, unit_metres):
        options = ellreloc.MapperOptions()
        options.unit_metres = unit_metres
        mapper = ellreloc.Mapper(camera, options, mode="boxes")
        for pose, detections in frames:
            mapper.add_keyframe(pose, detections)
        mapper.finish()
        return mapper

    header = ["poses' unit (m)"] + [f"pass {p + 1}: unit taken, objects, unit told" for p in range(PASSES)]
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    for unit in UNITS:
        in_unit = [(ellreloc.Pose(pose.R_cw, pose.t_cw / unit), detections) for pose, detections in keyframes]
        taken, cells = 1.0, []
        for _ in range(PASSES):
            mapper = mapped(in_unit, taken)
            told = mapper.estimated_unit_metres()
            cells.append(f"{taken:.3g}, {len(mapper.map().objects)}, {told:.3g}" if told else f"{taken:.3g}, -, -")
            if told is None:
                break
            taken = told
        print(f"| {unit:g} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
