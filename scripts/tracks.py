#!/usr/bin/env python3
"""The "over a track" tables of docs/benchmarks.md: relocalization when the host follows the
camera with its own odometry since it lost the map (`ellreloc relocalize --track`,
TrackRelocalizer): each query frame is relocalized with the help of the frames before it.

  fr2_desk keyframes   the real GOReloc map; the track is the keyframes before (3 or 5)
  fr3 60/40, 50/50,    boxes maps of the first 60 / 50 / 70% of the fr3 first half, every 5th
  70/30                frame of the rest queried; the track is the query frames before (10 or 20:
                       1.7 or 3.3 s)
  fr3 even/odd         a boxes map of the even frames, every 10th odd frame queried (1.7 / 3.3 s)

The odometry is the motion-capture trajectory, exact or drifting as a visual odometry does: each
step's translation scaled by 1 + s and turned by b degrees per metre travelled about one fixed
axis (s = 2%, b = 1; and s = 5%, b = 3), accumulated along the whole sequence. A monocular
odometry has a unit of its own: the same trajectories in units of 0.37 m, with the scale left to
the track (`--track-scale-unknown`), and once read as if metric. Rows: each frame
alone, then along the track; ours by default and reporting every pose (`--accept-all`), each
with its wrong poses (off by 30 cm or 30 deg or more), and the median time per frame (one
thread, the frame's own search included).

A second table counts the poses reported for frames that hold no evidence of the map: the
fr2_desk keyframes and the fr3 60/40 query frames with every box moved to a random place
(null_frames.py's "boxes moved", three seeds), along their true odometry.

Usage: scripts/tracks.py [BUILD_DIR] [DATA_DIR]   (prints two Markdown tables)
"""
import bisect
import json
import math
import os
import re
import tempfile

from fr3_splits import splits  # noqa: E402
from null_frames import image_size, moved_boxes  # noqa: E402
from pose_regions import valid_and_time  # noqa: E402
from real_data import box_map, data, fr3, run  # noqa: E402  (same arguments as real_data.py)

DRIFTS = [("exact", 0.0, 0.0), ("drift 2%, 1 deg/m", 0.02, 1.0), ("drift 5%, 3 deg/m", 0.05, 3.0)]
MONOCULAR_UNIT = 0.37  # metres per unit of the monocular odometry
AXIS = (1 / math.sqrt(14), 2 / math.sqrt(14), 3 / math.sqrt(14))  # the fixed axis of the rotation drift


def qmul(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz)


def qconj(q):
    return (-q[0], -q[1], -q[2], q[3])


def rotate(q, v):
    x, y, z, _ = qmul(qmul(q, (v[0], v[1], v[2], 0.0)), qconj(q))
    return (x, y, z)


def read_tum(path):
    """[(stamp text, position, quaternion xyzw)] of a TUM trajectory (camera->world), by time."""
    rows = []
    for line in open(path):
        p = line.split()
        if len(p) == 8 and not line.startswith("#"):
            rows.append((p[0], tuple(map(float, p[1:4])), tuple(map(float, p[4:8]))))
    return sorted(rows, key=lambda r: float(r[0]))


def drifting(truth, scale, deg_per_m):
    """The trajectory as an odometry with that drift sees it (camera->world in its own frame)."""
    out = [truth[0]]
    for (_, p0, q0), (stamp, p1, q1) in zip(truth, truth[1:]):
        step_p = rotate(qconj(q0), tuple(b - a for a, b in zip(p0, p1)))  # the motion in the camera's frame
        step_q = qmul(qconj(q0), q1)
        length = math.sqrt(sum(c * c for c in step_p))
        half = math.radians(deg_per_m * length) / 2
        turn = (AXIS[0] * math.sin(half), AXIS[1] * math.sin(half), AXIS[2] * math.sin(half), math.cos(half))
        _, po, qo = out[-1]
        moved = rotate(qo, tuple((1 + scale) * c for c in step_p))
        out.append((stamp, tuple(a + b for a, b in zip(po, moved)), qmul(qo, qmul(turn, step_q))))
    return out


def write_tum(rows, path):
    with open(path, "w") as f:
        for stamp, p, q in rows:
            f.write("%s %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n" % ((stamp,) + p + q))


def in_units(rows, unit):
    """The trajectory with its positions in units of `unit` metres."""
    return [(stamp, tuple(c / unit for c in p), q) for stamp, p, q in rows]


def rows_of(name, camera, map_path, detections, groundtruth, lengths, work):
    """The frames alone, then along tracks of each length on each odometry."""
    truth = read_tum(groundtruth)

    def row(track, odometry, extra):
        default, ms = valid_and_time(camera, map_path, detections, groundtruth, work, extra)
        every, _ = valid_and_time(camera, map_path, detections, groundtruth, work, extra + ["--accept-all"])
        print("| %s | %s | %s | %s | %s | %.1f ms |" % (name, track, odometry, default, every, ms), flush=True)

    row("alone", "", [])
    odometry = os.path.join(work, "odometry.txt")
    for label, scale, deg in DRIFTS:
        write_tum(drifting(truth, scale, deg), odometry)
        for n in lengths:
            row("%d frames" % n, label, ["--track", odometry, "--track-frames", str(n)])
    for label, scale, deg in DRIFTS[:2]:
        write_tum(in_units(drifting(truth, scale, deg), MONOCULAR_UNIT), odometry)
        for n in lengths:
            row("%d frames" % n, "monocular (%s), scale estimated" % label,
                ["--track", odometry, "--track-frames", str(n), "--track-scale-unknown"])
    write_tum(in_units(truth, MONOCULAR_UNIT), odometry)
    row("%d frames" % lengths[-1], "monocular (exact), read as metric",
        ["--track", odometry, "--track-frames", str(lengths[-1])])


def null_rows(name, camera, map_path, frames, groundtruth, n, work):
    """Poses reported for the frames with their boxes moved, along their true odometry."""
    truth = {float(s): (s, p, q) for s, p, q in read_tum(groundtruth)}
    stamps = sorted(truth)
    width, height = image_size(camera)
    moved, odometry = [], []
    for seed in (1, 2, 3):
        for original, f in zip(frames, moved_boxes(frames, width, height, seed)):
            t = float(os.path.splitext(os.path.basename(original["file_name"]))[0])
            i = bisect.bisect_left(stamps, t)
            nearest = min(stamps[max(0, i - 1):i + 1], key=lambda s: abs(s - t))
            if abs(nearest - t) > 0.02:
                continue
            moved.append(f)
            _, p, q = truth[nearest]
            odometry.append((os.path.splitext(os.path.basename(f["file_name"]))[0], p, q))
    detections, odometry_path = os.path.join(work, "null.json"), os.path.join(work, "null_odometry.txt")
    json.dump(moved, open(detections, "w"))
    write_tum(sorted(odometry, key=lambda r: float(r[0])), odometry_path)
    counts = []
    for extra in ([], ["--track", odometry_path, "--track-frames", str(n)]):
        printed = run("relocalize", "--camera", camera, "--map", map_path, "--detections", detections, "--threads", "1",
                      "--out", os.path.join(work, "null_poses.txt"), *extra)
        counts.append(int(re.search(r": (\d+) of (\d+) frames relocalized", printed).group(1)))
    print("| %s | %d frames | %d | %d (%.2f%%) | %d (%.2f%%) |" % (
        name, n, len(moved), counts[0], 100.0 * counts[0] / len(moved), counts[1], 100.0 * counts[1] / len(moved)))


def main():
    fr2 = os.path.join(data, "tum_fr2_desk")
    fr2_files = [os.path.join(fr2, n) for n in ("camera.yaml", "map.json", "keyframes.detections.json",
                                                 "keyframes.groundtruth.txt")]
    camera3, truth3 = os.path.join(fr3, "camera.yaml"), os.path.join(fr3, "groundtruth.txt")
    frames3 = json.load(open(os.path.join(fr3, "detections.json")))
    chosen = {name: (m, q) for name, m, q in splits(frames3)}
    chosen["even/odd"] = (frames3[0::2], frames3[1::10])
    with tempfile.TemporaryDirectory() as work:
        maps = {}
        for k, name in enumerate(("60/40", "50/50", "70/30", "even/odd")):
            maps[name] = box_map(camera3, truth3, chosen[name][0], chosen[name][1], work, "split%d" % k)
        print("| data | track | odometry | ours | ours, every pose | median time |")
        print("|---|---|---|---|---|---|")
        rows_of("fr2_desk keyframes", fr2_files[0], fr2_files[1], fr2_files[2], fr2_files[3], (3, 5), work)
        for name in ("60/40", "50/50", "70/30", "even/odd"):
            map_path, query_path, what = maps[name]
            rows_of("fr3 %s (%s)" % (name, what), camera3, map_path, query_path, truth3, (10, 20), work)
        print()
        print("| frames of moved boxes | track | frames | poses reported alone | along the track |")
        print("|---|---|---|---|---|")
        null_rows("fr2_desk keyframes", fr2_files[0], fr2_files[1], json.load(open(fr2_files[2])), fr2_files[3], 5,
                  work)
        null_rows("fr3 60/40 query frames", camera3, maps["60/40"][0], chosen["60/40"][1], truth3, 20, work)


if __name__ == "__main__":
    main()
