"""Shared fixtures of the Python module's tests (docs/python.md).

ctest runs them with PYTHONPATH=build/python, ABCUBE_SOURCE_DIR (the repository) and
ABCUBE_BIN (the abcube program); by hand:

    PYTHONPATH=build/python ABCUBE_BIN=build/abcube /usr/bin/python3 -m pytest -q tests/python
"""
import copy
import json
import os
import pathlib

import numpy as np
import pytest

import abcube

SOURCE_DIR = pathlib.Path(os.environ.get("ABCUBE_SOURCE_DIR",
                                         pathlib.Path(__file__).resolve().parents[2]))
SCENES = SOURCE_DIR / "scenes"
# Where a failing image test leaves its actual images for a person to look at.
TEST_OUT = pathlib.Path(os.environ.get("ABCUBE_TEST_OUT", "/tmp/abcube_python_test_out"))

# Small images and maps so that the whole suite runs in well under a minute on 2 cores.
WIDTH, HEIGHT, CUBE_RES = 32, 24, 32


def small_scene_dict(width=WIDTH, height=HEIGHT, cube_res=CUBE_RES, method="abuffer",
                     max_depth=2):
    """scenes/default.json (mirror, glass sphere, boxes, an OBJ mesh) made small, its mesh
    path absolute so that the dict loads from any folder."""
    scene = json.loads((SCENES / "default.json").read_text())
    scene["camera"]["width"], scene["camera"]["height"] = width, height
    scene["render"] = {"method": method, "cube_resolution": cube_res, "max_depth": max_depth}
    for obj in scene["objects"]:
        if obj["type"] == "mesh":
            obj["file"] = str(SCENES / obj["file"])
        if obj["type"] == "sphere":
            obj["segments"] = 24
    return scene


def write_scene(path, scene):
    path.write_text(json.dumps(scene, indent=1))
    return path


def save_failure(name, **images):
    """Writes the images of a failed comparison into the build folder (style.md, Tests)."""
    TEST_OUT.mkdir(parents=True, exist_ok=True)
    for key, image in images.items():
        abcube.write_image(str(TEST_OUT / f"{name}_{key}.exr"), image)
    return TEST_OUT


def assert_same_image(actual, expected, name):
    """Byte-for-byte equality of two float32 images; on failure the images are saved and the
    error figures printed."""
    assert actual.dtype == np.float32 and expected.dtype == np.float32
    assert actual.shape == expected.shape, (actual.shape, expected.shape)
    if not np.array_equal(actual, expected) or actual.tobytes() != expected.tobytes():
        where = save_failure(name, actual=actual, expected=expected)
        pytest.fail(f"{name}: images differ: {abcube.compare(actual, expected)}; see {where}")


@pytest.fixture(scope="session")
def scene_dict():
    return small_scene_dict()


@pytest.fixture(scope="session")
def scene(scene_dict):
    return abcube.scene_from_dict(copy.deepcopy(scene_dict), name="small")


@pytest.fixture(scope="session")
def abcube_bin():
    path = os.environ.get("ABCUBE_BIN", str(SOURCE_DIR / "build" / "abcube"))
    if not os.access(path, os.X_OK):
        pytest.fail(f"ABCUBE_BIN={path}: the abcube program is not there")
    return path

