#!/usr/bin/env python3
"""The "real data" table of docs/benchmarks.md: ours against the OA-SLAM preset, in one run,
on every real data set (and the independent renderer's scene), through the `ellreloc` command.

  fr2_desk keyframes   the real GOReloc map, each keyframe relocalized from its YOLO boxes
  fr3 60/40            map (`ellreloc map --mode boxes`, motion-capture poses) from the first
                       60% of the fr3/long_office first half; every 5th frame of the rest queried
  fr3 even/odd         map from the even frames, every odd frame queried
  office_s11           the independent renderer's noisy map and its 100 query frames

"ours" withholds poses its matches support too weakly (the acceptance test); "ours, every
pose" reports them (`--accept-all`), as the OA-SLAM preset does. "wrong poses" are reported
poses off by more than 30 cm or 30 deg.
Maps built by `ellreloc map` (the fr3 rows) record where their keyframes were taken, and "ours"
keeps the camera within those heights and tilts (the map's camera envelope); "ours without the
map's envelope" (`--no-map-envelope`) does not. The GOReloc map of fr2_desk and office_s11's
map have none: "ours" keeps the camera upright (image-up within 90 degrees of up, at any height)
about the up their objects tell (estimateMapUp), which "ours, anywhere" (`--no-map-envelope`)
does not. "ours + envelope" gives fr2 one from the keyframes' own poses (`--envelope`; they are
the map's keyframes and the queries, so read that row as an upper bound), up from their
image-up. fr2's boxes were detected on its raw Kinect images, which its lens distorts by up to
15 pixels near the border: "boxes undistorted" moves them to the pinhole image first (`--undistort`,
with the lens of its camera.yaml). "upright camera" gives the map's up direction instead (`--map-up`; the GOReloc map's
frame is its first keyframe's camera, so about -y; office_s11's world is z-up) with
`--max-tilt 90`.

Usage: scripts/real_data.py [BUILD_DIR] [DATA_DIR]   (prints a Markdown table)
The fr3 rows split ELLRELOC_FR3 when it names a folder of the first half's layout (e.g. the
second half of the sequence), else DATA_DIR/tum_fr3_office_first_half; the scripts that import
this one do the same.
"""
import json
import os
import re
import subprocess
import sys
import tempfile

build = sys.argv[1] if len(sys.argv) > 1 else "build"
data = sys.argv[2] if len(sys.argv) > 2 else "../shared/data"
cli = os.path.join(build, "apps", "ellreloc", "ellreloc")
if not os.access(cli, os.X_OK):
    sys.exit("%s: no ellreloc command at %s (build first: scripts/build.sh)" % (sys.argv[0], cli))
if not os.path.isdir(os.path.join(data, "tum_fr2_desk")):
    sys.exit("%s: %s is not the shared data folder (no tum_fr2_desk in it)" % (sys.argv[0], data))
# The fr3/long_office sequence the fr3 rows split: the shipped first half, or another part of
# the sequence in the same layout (camera.yaml, groundtruth.txt, detections.json), e.g. its
# second half, given by ELLRELOC_FR3.
fr3 = os.environ.get("ELLRELOC_FR3") or os.path.join(data, "tum_fr3_office_first_half")
for name in ("camera.yaml", "groundtruth.txt", "detections.json"):
    if not os.path.isfile(os.path.join(fr3, name)):
        sys.exit("%s: the fr3 folder %s has no %s (ELLRELOC_FR3 names another folder of the first half's layout)" %
                 (sys.argv[0], fr3, name))


def run(*args):
    done = subprocess.run([cli, *args], capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit("%s %s failed: %s" % (cli, args[0], done.stderr.strip()))
    return done.stdout


def relocalize(camera, map_path, detections, groundtruth, method, work, extra=()):
    out = os.path.join(work, "poses.txt")
    printed = run("relocalize", "--camera", camera, "--map", map_path, "--detections", detections, "--method", method,
                  "--threads", "2", "--out", out, "--reference", groundtruth, *extra)
    ms = float(re.search(r"median ([0-9.]+) ms per frame", printed).group(1))
    diagnosis = dict((k.strip(), int(v)) for v, k in
                     [(m.group(2), m.group(1)) for m in re.finditer(r"([a-z ]+) (\d+)", printed.split(":", 1)[1])])
    row = run("evaluate", "--groundtruth", groundtruth, "--estimate", out, "--detections", detections)
    pos, rot, valid, posed = [c.strip() for c in row.strip().splitlines()[-1].strip("|").split("|")][:4]
    posed, frames = [int(x) for x in posed.split("/")]
    wrong = posed - round(float(valid) * frames / 100.0)
    return {"valid": valid, "pos": pos, "rot": rot, "ms": ms, "diagnosis": diagnosis, "wrong": wrong}


def box_map(camera, trajectory, mapping, query, work, name, extra=()):
    """`ellreloc map --mode boxes` (with `extra` options) on the frames `mapping`, its quality
    measured on the frames `query`: (map path, query detections path, "N objects, held-out IoU Q")."""
    mapping_path, query_path, path = (os.path.join(work, name + s) for s in (".map_frames.json", ".q.json", ".map.json"))
    json.dump(mapping, open(mapping_path, "w"))
    json.dump(query, open(query_path, "w"))
    printed = run("map", "--camera", camera, "--trajectory", trajectory, "--detections", mapping_path, "--mode",
                  "boxes", "--out", path, "--holdout", query_path, *extra)
    objects = int(re.search(r": (\d+) objects", printed).group(1))
    quality = float(re.search(r"IoU ([0-9.]+)", printed).group(1))
    return path, query_path, "%d objects, held-out IoU %.2f" % (objects, quality)


def table_splits(frames):
    """The fr3 splits of this table: name -> (mapping frames, query frames)."""
    cut = int(0.6 * len(frames))
    return {"fr3 60/40": (frames[:cut], frames[cut::5]), "fr3 even/odd": (frames[0::2], frames[1::2])}


def main():
    rows = []
    with tempfile.TemporaryDirectory() as work:
        fr2 = os.path.join(data, "tum_fr2_desk")
        rows.append(("fr2_desk keyframes", "GOReloc map, 47 objects", os.path.join(fr2, "camera.yaml"),
                     os.path.join(fr2, "map.json"), os.path.join(fr2, "keyframes.detections.json"),
                     os.path.join(fr2, "keyframes.groundtruth.txt"),
                     [("ours, anywhere (--no-map-envelope)", ["--no-map-envelope"]),
                      ("ours, anywhere, every pose", ["--no-map-envelope", "--accept-all"]),
                      ("ours + envelope", ["--envelope", os.path.join(fr2, "keyframes.groundtruth.txt")]),
                      ("ours, upright camera (--map-up 0,-1,0 --max-tilt 90)",
                       ["--map-up", "0,-1,0", "--max-tilt", "90"]),
                      ("ours, upright camera, every pose",
                       ["--map-up", "0,-1,0", "--max-tilt", "90", "--accept-all"]),
                      # Its raw Kinect images are not undistorted: the boxes are where the lens put them.
                      ("ours, boxes undistorted (--undistort)", ["--undistort"]),
                      ("ours, boxes undistorted, every pose", ["--undistort", "--accept-all"]),
                      ("oa-slam preset, boxes undistorted", ["--undistort"], "oa-slam")]))
        camera, groundtruth = os.path.join(fr3, "camera.yaml"), os.path.join(fr3, "groundtruth.txt")
        frames = json.load(open(os.path.join(fr3, "detections.json")))
        for name, (mapping, query) in table_splits(frames).items():
            tag = name.replace(" ", "_").replace("/", "_")
            map_path, query_path, what = box_map(camera, groundtruth, mapping, query, work, tag)
            rows.append((name, "boxes map: " + what, camera, map_path, query_path, groundtruth,
                         [("ours without the map's envelope", ["--no-map-envelope"])]))
        s11 = os.path.join(data, "independent_synth", "office_s11")
        rows.append(("office_s11 (independent renderer)", "its noisy map", os.path.join(s11, "camera.yaml"),
                     os.path.join(s11, "map_noisy.json"), os.path.join(s11, "query.detections.json"),
                     os.path.join(s11, "query.groundtruth.txt"),
                     [("ours, anywhere (--no-map-envelope)", ["--no-map-envelope"]),
                      ("ours, upright camera (--map-up 0,0,1 --max-tilt 90)",
                       ["--map-up", "0,0,1", "--max-tilt", "90"])]))

        print("| data | map | method | valid | wrong poses | median pos | median rot | median time | lost frames: "
              "no pose / search / scoring failure |")
        print("|---|---|---|---|---|---|---|---|---|")
        for name, what, camera, map_path, detections, groundtruth, variants in rows:
            runs = [("ours", "ours", ())] + [(v[2] if len(v) > 2 else "ours", v[0], v[1]) for v in variants] + \
                   [("ours", "ours, every pose (--accept-all)", ("--accept-all",)), ("oa-slam", "oa-slam preset", ())]
            for method, label, extra in runs:
                r = relocalize(camera, map_path, detections, groundtruth, method, work, extra)
                d = r["diagnosis"]
                lost = "%d / %d / %d" % (d.get("no pose", 0), d.get("search failure", 0), d.get("scoring failure", 0))
                print("| %s | %s | %s | %s%% | %d | %s cm | %s deg | %.1f ms | %s |" %
                      (name, what, label, r["valid"], r["wrong"], r["pos"], r["rot"], r["ms"], lost))


if __name__ == "__main__":
    main()
