"""Shared fixtures: the real data beside the project and the ellreloc command line."""

import os
import pathlib
import shutil

import pytest

import ellreloc

HERE = pathlib.Path(__file__).resolve().parent
DATA = pathlib.Path(os.environ.get("ELLRELOC_DATA_DIR", HERE.parents[2] / "shared" / "data"))


@pytest.fixture(scope="session")
def data_dir():
    if not (DATA / "tum_fr2_desk" / "map.json").exists():
        pytest.skip(f"the shared data is not at {DATA} (set ELLRELOC_DATA_DIR)")
    return DATA


@pytest.fixture(scope="session")
def fr2(data_dir):
    """camera, map and keyframe detections of TUM fr2/desk."""
    d = data_dir / "tum_fr2_desk"
    return (ellreloc.read_camera(d / "camera.yaml"), ellreloc.read_map(d / "map.json"),
            ellreloc.read_detections(d / "keyframes.detections.json"))


@pytest.fixture(scope="session")
def cli():
    path = os.environ.get("ELLRELOC_CLI") or shutil.which("ellreloc")
    if not path or not os.path.exists(path):
        pytest.skip("the ellreloc command line is not built (ELLRELOC_CLI)")
    return path


@pytest.fixture(scope="session")
def office():
    """A simulated office: scene, camera, true map."""
    scene = ellreloc.sim.make_scene("office", 3)
    camera = ellreloc.Intrinsics(525.0, 525.0, 319.5, 239.5, 640, 480)
    return scene, camera, scene.ground_truth_map()
