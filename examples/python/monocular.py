#!/usr/bin/env python3
"""A monocular SLAM host, from Python, on TUM fr2/desk: its keyframe poses have no metric scale
(here the keyframes' poses in units of 2.5 m), and it maps the objects from their boxes alone.
The mapper reads the unit off the objects' sizes and maps again in it; each keyframe's report
names the object each box joined; the map records its unit, so that poses found against it, in
the host's own unit, are told in metres.

    python3 monocular.py [DATA_DIR]

DATA_DIR holds camera.yaml, keyframes.detections.json and keyframes.groundtruth.txt (default: the
shared tum_fr2_desk folder beside the project). Prints the unit of each mapping pass, the map, how
the boxes were associated, and the Table-I row of the keyframes relocalized against the map.
"""

import pathlib
import sys

import ellreloc

here = pathlib.Path(__file__).resolve().parent
data = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else here.parents[2] / "shared" / "data" / "tum_fr2_desk"

camera = ellreloc.read_camera(data / "camera.yaml")
frames = ellreloc.read_detections(data / "keyframes.detections.json")
truth = ellreloc.read_trajectory(data / "keyframes.groundtruth.txt")
truth_by_time = ellreloc.time_index(truth)
true_unit = 2.5  # metres per unit of the host's poses, which the host does not know
keyframes = [(ellreloc.Pose(truth[k].pose.R_cw, truth[k].pose.t_cw / true_unit), frame)
             for frame in frames if (k := truth_by_time.nearest(frame.timestamp)) is not None]


def mapped(unit_metres):
    """The keyframes mapped from their boxes in a unit of `unit_metres`; each box's object."""
    options = ellreloc.MapperOptions()
    options.unit_metres = unit_metres
    mapper = ellreloc.Mapper(camera, options, mode="boxes")
    joined = [mapper.add_keyframe(pose, frame.detections).object_ids for pose, frame in keyframes]
    mapper.finish()
    return mapper, joined


# Map taking 1 m, then again in the unit the objects tell, until it settles.
unit = 1.0
mapper, joined = mapped(unit)
for _ in range(3):
    told = mapper.estimated_unit_metres()  # None: too few objects triangulated to tell
    print(f"mapped in a unit of {unit:.3g} m: {len(mapper.map())} objects"
          + (f", whose sizes tell {told:.3g} m" if told else ""))
    if told is None or abs(told / unit - 1.0) <= 0.02:
        break
    unit = told
    mapper, joined = mapped(unit)
object_map = mapper.map()
print(f"the map records its unit: {object_map.unit_metres:.3g} m")

# Which object each box joined, followed through the joins of later keyframes.
in_map = {o.id for o in object_map.objects}
boxes = sum(len(ids) for ids in joined)
current = [mapper.current_object_id(i) for ids in joined for i in ids if i >= 0]
print(f"{sum(c in in_map for c in current)} of {boxes} boxes joined one of the map's objects")

# The keyframes relocalized against the map: poses in the host's unit, errors told in metres.
relocalizer = ellreloc.ObjectRelocalizer(object_map, camera)
errors = []
for pose, frame in keyframes:
    result = relocalizer.relocalize(frame)
    errors.append(ellreloc.pose_error(result.pose, pose, object_map.unit_metres) if result.success else None)
s = ellreloc.summarize(errors)
print(f"relocalized: {s.frames} keyframes, {s.valid_percent:.1f}% valid, median {s.median_position_cm:.1f} cm, "
      f"{s.median_rotation_deg:.2f} deg")
