#!/usr/bin/env python3
"""Relocalization along a track, from Python, on TUM fr2/desk: each keyframe relocalized with
the help of the keyframes before it, their poses from an odometry (here the ground truth seen
from a frame of its own, as a host's odometry would give it after losing the map; and the same
in units of 0.37 m, as a monocular odometry, whose scale the track estimates):

    python3 track.py [DATA_DIR] [frames in the track]

DATA_DIR holds camera.yaml, map.json, keyframes.detections.json and keyframes.groundtruth.txt
(default: the shared tum_fr2_desk folder beside the project). Prints the Table-I rows of the
keyframes alone and along the tracks, and the wrong poses each reported.
"""

import pathlib
import sys

import numpy as np

import ellreloc

here = pathlib.Path(__file__).resolve().parent
data = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else here.parents[2] / "shared" / "data" / "tum_fr2_desk"
length = int(sys.argv[2]) if len(sys.argv) > 2 else 5

camera = ellreloc.read_camera(data / "camera.yaml")
frames = ellreloc.read_detections(data / "keyframes.detections.json")
truth = ellreloc.read_trajectory(data / "keyframes.groundtruth.txt")
relocalizer = ellreloc.ObjectRelocalizer(ellreloc.read_map(data / "map.json"), camera)

# The odometry's own frame: any rigid motion away from the map's (only relative poses count).
odometry_to_map = ellreloc.Pose(np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]), [2.0, -1.0, 0.5])

track = ellreloc.TrackRelocalizer(relocalizer, max_frames=length)
monocular = ellreloc.TrackRelocalizer(relocalizer, max_frames=length, metric_odometry=False)
unit = 0.37  # metres per unit of the monocular odometry
rows = {"alone": [], "along the track": [], "along the track of a monocular odometry": []}
wrong = {name: 0 for name in rows}
truth_by_time = ellreloc.time_index(truth)
for frame in frames:
    k = truth_by_time.nearest(frame.timestamp)
    if k is None:  # no odometry pose: the track starts again
        track.reset()
        monocular.reset()
        continue
    odometry = truth[k].pose * odometry_to_map  # the frame's pose in the odometry
    along = track.add(frame, odometry)
    along_monocular = monocular.add(frame, ellreloc.Pose(odometry.R_cw, odometry.t_cw / unit))
    for name, result in (("alone", relocalizer.relocalize(frame)), ("along the track", along.result),
                         ("along the track of a monocular odometry", along_monocular.result)):
        error = ellreloc.pose_error(result.pose, truth[k].pose) if result.success else None
        rows[name].append(error)
        wrong[name] += error is not None and not error.valid
for name, errors in rows.items():
    s = ellreloc.summarize(errors)
    print(f"{name}: {s.frames} frames, {s.valid_percent:.1f}% valid, median {s.median_position_cm:.1f} cm, "
          f"{s.median_rotation_deg:.2f} deg, {wrong[name]} wrong pose{'' if wrong[name] == 1 else 's'} reported")
