#!/usr/bin/env python3
"""What Python costs on top of the C++ library: relocalizing every fr2_desk keyframe with a
Python loop (one relocalize() call per frame: argument conversion, observation, GIL release)
against the same loop in C++ (relocalize_frames, one thread), alternated in one run.

    PYTHONPATH=build/python python3 benchmarks/python_overhead.py [DATA_DIR] [repetitions]
"""

import pathlib
import statistics
import sys
import time

import ellreloc

data = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else \
    pathlib.Path(__file__).resolve().parents[2] / "shared" / "data" / "tum_fr2_desk"
repetitions = int(sys.argv[2]) if len(sys.argv) > 2 else 7

camera = ellreloc.read_camera(data / "camera.yaml")
frames = ellreloc.read_detections(data / "keyframes.detections.json")
relocalizer = ellreloc.ObjectRelocalizer(ellreloc.read_map(data / "map.json"), camera)

python_s, cpp_s = [], []
for _ in range(repetitions):
    start = time.perf_counter()
    by_python = [relocalizer.relocalize(f) for f in frames]
    python_s.append(time.perf_counter() - start)
    start = time.perf_counter()
    by_cpp = relocalizer.relocalize_frames(frames, threads=1)
    cpp_s.append(time.perf_counter() - start)
    assert all(a.status == b.status for a, b in zip(by_python, by_cpp))

py, cpp = statistics.median(python_s), statistics.median(cpp_s)
print(f"| fr2_desk keyframes ({len(frames)}), one thread | median of {repetitions} passes (ms) | per frame (ms) |")
print("| --- | --- | --- |")
print(f"| Python loop: `relocalize(frame)` per frame | {1000 * py:.1f} | {1000 * py / len(frames):.2f} |")
print(f"| C++ loop: `relocalize_frames(frames)` | {1000 * cpp:.1f} | {1000 * cpp / len(frames):.2f} |")
print(f"| Python's overhead | {100 * (py / cpp - 1):+.1f}% | |")
