#!/usr/bin/env python3
"""The calls behind `ellreloc relocalize`, from Python, on TUM fr2/desk:

    python3 relocalize.py [DATA_DIR] [frame index]

DATA_DIR holds camera.yaml, map.json, keyframes.detections.json and keyframes.groundtruth.txt
(default: the shared tum_fr2_desk folder beside the project). Relocalizes one frame and prints
its pose and matches, then every frame and the Table-I row against the ground truth.
"""

import pathlib
import sys

import ellreloc

here = pathlib.Path(__file__).resolve().parent
data = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else here.parents[2] / "shared" / "data" / "tum_fr2_desk"
index = int(sys.argv[2]) if len(sys.argv) > 2 else 0

camera = ellreloc.read_camera(data / "camera.yaml")
world = ellreloc.read_map(data / "map.json")
frames = ellreloc.read_detections(data / "keyframes.detections.json")

# One relocalizer per map: it observes each frame's detections (the 'solid' policy: masks
# fitted where their shape allows, other detections as box-inscribed ellipses; fr2's keyframes
# have boxes only) and searches, scores and refines.
relocalizer = ellreloc.ObjectRelocalizer(world, camera)
frame = frames[index]
result = relocalizer.relocalize(frame)
if result.status != ellreloc.RelocalizationStatus.success:
    print(f"{frame.file_name}: not relocalized: {result.status.name} ({result.reason})")
else:
    x, y, z = result.T_wc[:3, 3]  # camera -> world: the camera centre is its translation
    print(f"{frame.file_name}: camera centre {x:.3f} {y:.3f} {z:.3f}, {len(result.matches)} of "
          f"{len(frame.detections)} detections matched, {result.time_ms:.2f} ms")
    for m in result.matches:
        print(f"  observation {m.observation} -> object {world.objects[m.object].id} (overlap {m.overlap:.2f})")

# Every frame against the ground truth: the paper's Table I row (30 cm / 30 degree rule).
truth = ellreloc.read_trajectory(data / "keyframes.groundtruth.txt")
truth_by_time = ellreloc.time_index(truth)  # each frame's true pose: the nearest in time, within 20 ms
errors = []
for frame, r in zip(frames, relocalizer.relocalize_frames(frames)):
    k = truth_by_time.nearest(frame.timestamp)
    errors.append(ellreloc.pose_error(r.pose, truth[k].pose) if r.success and k is not None else None)
s = ellreloc.summarize(errors)
print(f"{s.frames} frames: {s.valid_percent:.1f}% valid, median {s.median_position_cm:.1f} cm, "
      f"{s.median_rotation_deg:.2f} deg")
