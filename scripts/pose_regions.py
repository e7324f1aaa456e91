#!/usr/bin/env python3
"""The "pose regions" table of docs/benchmarks.md: relocalization when the host knows roughly
where the camera is, as a SLAM system does a moment after it lost tracking (`ellreloc relocalize
--near`, PoseRegion). Each query frame's region is centred on where the camera truly was a
little earlier: on fr2_desk the previous keyframe's motion-capture pose (0.09 m and 3 degrees
away, median), on the fr3/long_office splits the motion-capture pose one second before the frame
(0.26 m and 11 degrees away, median; at most 0.41 m and 31 degrees in the first half).

  fr2_desk keyframes   the real GOReloc map
  fr3 60/40, 50/50     boxes maps of the first 60 / 50% of the fr3 first half, every 5th frame of
                       the rest queried (views the map's frames barely had)
  fr3 even/odd         a boxes map of the even frames, every 5th odd frame queried
  fr3 last 60%         a boxes map of the last 60%, every 5th frame of the first 40% queried (its
                       map holds little of what those frames see)

Rows: no region, then regions of 0.5 m and 45 degrees and of 1 m at any angle; ours by default,
with the acceptance test's evidence bar lowered to 1.5 (`--min-evidence 1.5`), and reporting
every pose (`--accept-all`), each with its wrong poses (off by 30 cm or 30 deg or more), and the
median time per frame (one thread, by default).

A second table counts the poses reported for frames that hold no evidence of the map: fr2_desk's
keyframes with every box moved to a random place (null_frames.py's "boxes moved", three seeds),
each searched within 0.5 m and 45 degrees of the previous keyframe's true pose as above, at each
evidence bar: a region rules out most of the poses such boxes would otherwise fit, so a lower bar
keeps them as rare.

Usage: scripts/pose_regions.py [BUILD_DIR] [DATA_DIR]   (prints two Markdown tables)
"""
import bisect
import json
import os
import re
import tempfile

from null_frames import moved_boxes  # noqa: E402
from real_data import box_map, data, fr3, run  # noqa: E402  (same arguments as real_data.py)

REGIONS = [("none", None), ("0.5 m, 45 deg", ("0.5", "45")), ("1 m, any angle", ("1", "180"))]
EVIDENCE = ["2.3", "1.5", "1.0"]  # the acceptance test's bar: the default, and lower ones


def read_tum(path):
    """(timestamp, the rest of the line) of a TUM trajectory, by time."""
    rows = []
    for line in open(path):
        if line.strip() and not line.startswith("#"):
            stamp, rest = line.split(None, 1)
            rows.append((float(stamp), rest.strip()))
    return sorted(rows)


def frame_stamp(frame):
    return os.path.splitext(os.path.basename(frame["file_name"]))[0]


def near_file(frames, groundtruth, lag_s, path, stamps=None):
    """The region's pose of each frame, stamped with the frame's time (or `stamps`): the true
    pose `lag_s` seconds before it, or (lag_s None) the previous frame's true pose."""
    truth = read_tum(groundtruth)
    times = [t for t, _ in truth]
    nearest = lambda t: truth[min(range(len(times)), key=lambda i: abs(times[i] - t))][1]
    stamps = stamps or [frame_stamp(f) for f in frames]
    lines = []
    for k, f in enumerate(frames):
        t = float(frame_stamp(f))
        if lag_s is None:
            if k == 0:
                continue  # no earlier keyframe: searched everywhere
            lines.append("%s %s" % (stamps[k], nearest(float(frame_stamp(frames[k - 1])))))
        else:
            i = min(bisect.bisect_left(times, t - lag_s), len(times) - 1)
            lines.append("%s %s" % (stamps[k], truth[i][1]))
    open(path, "w").write("\n".join(lines) + "\n")


def valid_and_time(camera, map_path, detections, groundtruth, work, extra):
    printed = run("relocalize", "--camera", camera, "--map", map_path, "--detections", detections, "--threads", "1",
                  "--out", os.path.join(work, "poses.txt"), "--reference", groundtruth, *extra)
    diagnoses = printed.split("against", 1)[1].split(":", 1)[1]
    counts = dict((k.strip(), int(v)) for k, v in re.findall(r"([a-z ]+) (\d+)", diagnoses))
    frames = sum(v for k, v in counts.items() if k != "no reference pose")
    wrong = counts.get("search failure", 0) + counts.get("scoring failure", 0)
    ms = float(re.search(r"median ([0-9.]+) ms per frame", printed).group(1))
    return "%.1f%% (%d wrong)" % (100.0 * counts.get("valid", 0) / frames, wrong), ms


def null_frames(work):
    """Poses reported for fr2_desk's keyframes with their boxes moved, without and with a region."""
    fr2 = os.path.join(data, "tum_fr2_desk")
    frames = json.load(open(os.path.join(fr2, "keyframes.detections.json")))
    camera = os.path.join(fr2, "camera.yaml")
    counts = {}
    for seed in (1, 2, 3):
        moved = moved_boxes(frames, 640, 480, seed)
        moved_path, near = os.path.join(work, "moved.json"), os.path.join(work, "moved_near.txt")
        json.dump(moved, open(moved_path, "w"))
        # Each moved frame gets its keyframe's region, under the moved frame's own name.
        near_file(frames, os.path.join(fr2, "keyframes.groundtruth.txt"), None, near, [frame_stamp(m) for m in moved])
        for label, extra in (("none", []), ("0.5 m, 45 deg", ["--near", near, "--near-radius", "0.5",
                                                              "--near-angle", "45"])):
            for bar in EVIDENCE:
                printed = run("relocalize", "--camera", camera, "--map", os.path.join(fr2, "map.json"),
                              "--detections", moved_path, "--out", os.path.join(work, "poses.txt"), "--min-evidence",
                              bar, *extra)
                reported = int(re.search(r": (\d+) of (\d+) frames relocalized", printed).group(1))
                counts[(label, bar)] = counts.get((label, bar), 0) + reported
    print()
    print("| frames of moved boxes (fr2_desk, 3 x %d) | region | %s |" %
          (len(frames), " | ".join("reported at --min-evidence " + b for b in EVIDENCE)))
    print("|---|---|%s" % ("---|" * len(EVIDENCE)))
    for label in ("none", "0.5 m, 45 deg"):
        print("| boxes moved | %s | %s |" % (label, " | ".join(
            "%d (%.2f%%)" % (counts[(label, b)], 100.0 * counts[(label, b)] / (3 * len(frames))) for b in EVIDENCE)))


def main():
    sets = []
    with tempfile.TemporaryDirectory() as work:
        fr2 = os.path.join(data, "tum_fr2_desk")
        sets.append(("fr2_desk keyframes", "the previous keyframe's", os.path.join(fr2, "camera.yaml"),
                     os.path.join(fr2, "map.json"), os.path.join(fr2, "keyframes.detections.json"),
                     os.path.join(fr2, "keyframes.groundtruth.txt"), None))
        camera, groundtruth = os.path.join(fr3, "camera.yaml"), os.path.join(fr3, "groundtruth.txt")
        frames = json.load(open(os.path.join(fr3, "detections.json")))
        n = len(frames)
        for name, mapping, query in (("fr3 60/40", frames[:int(0.6 * n)], frames[int(0.6 * n)::5]),
                                     ("fr3 50/50", frames[:int(0.5 * n)], frames[int(0.5 * n)::5]),
                                     ("fr3 even/odd", frames[0::2], frames[1::10]),
                                     ("fr3 last 60%", frames[int(0.4 * n):], frames[:int(0.4 * n):5])):
            tag = name.replace(" ", "_").replace("/", "_")
            map_path, query_path, what = box_map(camera, groundtruth, mapping, query, work, tag)
            sets.append((name + " (" + what + ")", "1 s before", camera, map_path, query_path, groundtruth, 1.0))

        print("| data | region's pose: the true pose | region | ours | ours, --min-evidence 1.5 | ours, every pose "
              "| median time |")
        print("|---|---|---|---|---|---|---|")
        for name, centre, camera, map_path, detections, groundtruth, lag in sets:
            near = os.path.join(work, "near.txt")
            near_file(json.load(open(detections)), groundtruth, lag, near)
            for label, bounds in REGIONS:
                extra = [] if bounds is None else ["--near", near, "--near-radius", bounds[0], "--near-angle",
                                                   bounds[1]]
                default, ms = valid_and_time(camera, map_path, detections, groundtruth, work, extra)
                lower, _ = valid_and_time(camera, map_path, detections, groundtruth, work,
                                          extra + ["--min-evidence", "1.5"])
                every, _ = valid_and_time(camera, map_path, detections, groundtruth, work, extra + ["--accept-all"])
                print("| %s | %s | %s | %s | %s | %s | %.1f ms |" % (name, centre, label, default, lower, every, ms))
        null_frames(work)


if __name__ == "__main__":
    main()
