#!/usr/bin/env python3
"""What a process pays before its first frame, and a whole relocalization command: wall times of
`ellreloc --help`, of importing the Python bindings, and of `ellreloc relocalize` on the fr2_desk
keyframes (ours and the OA-SLAM preset, one thread), medians of repeated runs. Prints a Markdown
table (docs/benchmarks.md, "Start-up").

Usage: benchmarks/startup.py BUILD_DIR DATA_DIR [PYTHON]   (PYTHON: the interpreter of the bindings)
"""
import os
import statistics
import subprocess
import sys
import tempfile
import time


def median_seconds(command, runs, env=None):
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        subprocess.run(command, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    build, data = sys.argv[1], sys.argv[2]
    python = sys.argv[3] if len(sys.argv) > 3 else ""
    cli = os.path.join(build, "apps", "ellreloc", "ellreloc")
    rows = [("`ellreloc --help` (start, parse, exit)", 1000 * median_seconds([cli, "--help"], 20), "ms", 20)]
    bindings = os.path.join(build, "python")
    if python and os.path.isdir(os.path.join(bindings, "ellreloc")):
        env = dict(os.environ, PYTHONPATH=bindings)
        rows.append(("`python3 -c 'import ellreloc'`",
                     1000 * median_seconds([python, "-c", "import ellreloc"], 10, env), "ms", 10))
        rows.append(("`python3 -c 'import numpy'` (which the bindings import)",
                     1000 * median_seconds([python, "-c", "import numpy"], 10, env), "ms", 10))
    fr2 = os.path.join(data, "tum_fr2_desk")
    whole = {}
    with tempfile.TemporaryDirectory() as work:
        for method in ("ours", "oa-slam"):
            command = [cli, "relocalize", "--camera", os.path.join(fr2, "camera.yaml"), "--map",
                       os.path.join(fr2, "map.json"), "--detections", os.path.join(fr2, "keyframes.detections.json"),
                       "--method", method, "--threads", "1", "--out", os.path.join(work, method + ".txt")]
            whole[method] = median_seconds(command, 5)
            rows.append(("`ellreloc relocalize --method %s`, fr2_desk's 198 keyframes, one thread" % method,
                         whole[method], "s", 5))
    print("| command | median wall time | unit | runs |")
    print("| --- | --- | --- | --- |")
    for what, value, unit, runs in rows:
        print("| %s | %.3g | %s | %d |" % (what, value, unit, runs))
    print("| the whole fr2 command: the preset's time over ours | %.2fx | | |" % (whole["oa-slam"] / whole["ours"]))


if __name__ == "__main__":
    main()
