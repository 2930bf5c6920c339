"""python/examples/dask_orbit.py: a 64-view batch rendered by a Dask LocalCluster of worker
processes equals the same batch rendered in this process, byte for byte; a worker killed
mid-run loses no view and leaves no partial file."""
import importlib
import json
import os
import subprocess
import sys

import pytest

import abcube

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


def test_a_killed_worker_loses_nothing(dask_orbit, tmp_path):
    # 48 views written by 2 worker processes; one worker SIGKILLed mid-run (after the first
    # task is done). Every view's file exists once, byte-equal to the same file written by
    # one process, no temporary file is left (a worker killed mid-write leaves one, which the
    # task run again removes), and the views of the task run again are reported.
    import signal

    scene = small_scene_dict(64, 48, 32)
    cameras = dask_orbit.orbit_cameras(48, [0, 0.8, 0], 6.0, 2.0, 64, 48)
    killed = {}

    def kill_one(client, cluster):
        pids = client.run(os.getpid)
        address, pid = sorted(pids.items())[0]
        os.kill(pid, signal.SIGKILL)
        killed[address] = pid

    out = tmp_path / "cluster"
    rendered, retried = dask_orbit.files_in_cluster(scene, cameras, out, method="abuffer", n_workers=2,
                                                    chunk=2, after_first=kill_one)
    assert killed, "no worker was killed"
    print(f"killed worker {killed}; {len(rendered)} views rendered, retried: {retried}")
    files = sorted(p.name for p in out.iterdir())
    assert files == [f"view_{k:03d}.exr" for k in range(48)], files  # each view once, nothing else
    assert retried, "the killed worker's task was not reported as run again"
    alone = tmp_path / "alone"
    alone.mkdir()
    for k, image in enumerate(dask_orbit.render_in_process(scene, cameras, method="abuffer")[0]):
        abcube.write_image(str(alone / f"view_{k:03d}.exr"), image)
    for k in range(48):
        name = f"view_{k:03d}.exr"
        assert (out / name).read_bytes() == (alone / name).read_bytes(), f"{name} differs"


def test_stale_temporaries_of_dead_processes_go(tmp_path):
    # A temporary named by a process of this host that is gone is removed; one of a live
    # process (this one), one of another host, and other files stay.
    import socket
    import subprocess as sp

    dead = sp.Popen(["true"])
    dead.wait()
    host = "".join(c for c in socket.gethostname() if c.isalnum() or c in "-_")[:32]
    names = {f".view_001.tmp{dead.pid}-{host}.exr": False,   # removed
             f".view_002.tmp{os.getpid()}-{host}.exr": True,  # this process: alive
             f".view_003.tmp{dead.pid}-otherhost.exr": True,  # another host's
             "view_004.exr": True}
    for name in names:
        (tmp_path / name).write_bytes(b"x")
    assert abcube.remove_stale_temporaries(str(tmp_path)) == 1
    for name, stays in names.items():
        assert (tmp_path / name).exists() == stays, name
