"""python/examples/dask_orbit.py: a 64-view batch rendered by a Dask LocalCluster of worker
processes equals the same batch rendered in this process, byte for byte."""
import importlib
import json
import subprocess
import sys

import pytest

from conftest import SOURCE_DIR, small_scene_dict

EXAMPLES = SOURCE_DIR / "python" / "examples"


@pytest.fixture(scope="module")
def dask_orbit():
    sys.path.insert(0, str(EXAMPLES))
    try:
        yield importlib.import_module("dask_orbit")
    finally:
        sys.path.remove(str(EXAMPLES))


def test_cluster_equals_one_process(dask_orbit):
    scene = small_scene_dict(24, 24, 32)
    cameras = dask_orbit.orbit_cameras(64, [0, 0.8, 0], 6.0, 2.0, 24, 24)
    assert len({tuple(c["position"]) for c in cameras}) == 64

    in_cluster, batch, startup = dask_orbit.render_in_cluster(scene, cameras, method="abuffer",
                                                              n_workers=2, chunk=8)
    in_process, alone = dask_orbit.render_in_process(scene, cameras, method="abuffer")
    print(f"64 views 24x24: cluster {batch:.2f} s (+ {startup:.2f} s start-up), "
          f"one process {alone:.2f} s")
    assert len(in_cluster) == len(in_process) == 64
    for k, (a, b) in enumerate(zip(in_cluster, in_process)):
        assert a.dtype == b.dtype and a.shape == b.shape == (24, 24, 3)
        assert a.tobytes() == b.tobytes(), f"view {k} differs"
    # The views differ from each other (the orbit moves the camera).
    assert len({image.tobytes() for image in in_process}) == 64


def test_recipe_runs_as_a_script(tmp_path):
    # The documented command line, small: exit 0 means the images were equal.
    scene = tmp_path / "scene.json"
    scene.write_text(json.dumps(small_scene_dict(16, 16, 32)))
    done = subprocess.run([sys.executable, str(EXAMPLES / "dask_orbit.py"), str(scene),
                           "--views", "8", "--size", "16", "16", "--chunk", "2",
                           "--out", str(tmp_path / "orbit")],
                          capture_output=True, text=True, timeout=180)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "equal byte for byte: True" in done.stdout
    assert len(list((tmp_path / "orbit").glob("view_*.exr"))) == 8
