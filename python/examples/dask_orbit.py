#!/usr/bin/env python3
"""Render an orbit of camera views across Dask worker processes, through the abcube module.

A recipe for batches too big for one process: a Dask distributed LocalCluster (Debian 12:
python3-distributed) of worker processes, each with its own abcube Renderer, renders
chunks of views; the images are byte for byte those of the same views rendered in one
process. Run it (from the repository, after the build):

    PYTHONPATH=build/python /usr/bin/python3 python/examples/dask_orbit.py scenes/default.json \\
        --views 64 --size 128 96 --cube-res 128 --workers 2 --out orbit/

It prints the time of the batch in the cluster and in this process, checks that the images
are equal, and with --out writes orbit/view_000.exr ... (float EXR, linear).

On machines that may die mid-batch (preemptible, spot), write files from the workers
instead (files_in_cluster, render_views_to_files): each file lands whole or not at all, a
task run again skips what exists, and the temporaries a killed worker left are removed.

How it works, and what to copy:
  - Scenes do not travel between processes: send the scene's path (or its dict); each
    worker process loads it once and keeps it (load), so the per-scene data the first
    render builds (mesh neighbours, lens fits, BVH) serves every later task.
  - Each worker thread keeps its own Renderer (renderer_for). The map methods (abuffer,
    zbuffer, envmap) and raytrace need no GL: gl="none". A GL method ("gpu") needs its
    Renderer used on the thread that opened it: hence one Renderer per thread.
  - threads_per_worker=1 and Renderer(threads=1): one render thread per worker process,
    as many workers as cores; the process-level split costs no synchronisation.
  - Workers are new processes (spawn): they get this process's environment, so PYTHONPATH
    must name the folder of the abcube module (render_in_cluster adds it).
"""
import argparse
import importlib
import json
import math
import os
import pathlib
import sys
import threading
import time

import numpy as np

import abcube

GL_FREE_METHODS = ("abuffer", "zbuffer", "envmap", "raytrace")


def orbit_cameras(count, center, radius, height, width, image_height, fov_y=None):
    """`count` camera overrides evenly spaced on a circle of `radius` around `center`, at
    `height` above it, each looking at `center`, with the image size given."""
    cameras = []
    for k in range(count):
        angle = 2 * math.pi * k / count
        camera = {
            "position": [center[0] + radius * math.sin(angle), center[1] + height,
                         center[2] + radius * math.cos(angle)],
            "look_at": list(center),
            "width": width,
            "height": image_height,
        }
        if fov_y is not None:
            camera["fov_y"] = fov_y
        cameras.append(camera)
    return cameras


# Per-process caches: a worker loads each scene once (its per-scene data, built by the
# first render, is then reused by every later task) and keeps one Renderer per thread.
_SCENES = {}
_RENDERERS = {}


def load(scene_source):
    """A scene from a path or a dict (what travels to the workers), loaded once per process."""
    key = json.dumps(scene_source, sort_keys=True) if isinstance(scene_source, dict) \
        else str(scene_source)
    if key not in _SCENES:
        _SCENES[key] = abcube.scene_from_dict(scene_source) if isinstance(scene_source, dict) \
            else abcube.load_scene(str(scene_source))
    return _SCENES[key]


def renderer_for(method, threads):
    """This thread's Renderer (a Renderer that opened GL stays on its thread)."""
    gl = "none" if method in GL_FREE_METHODS else "auto"
    key = (threading.get_ident(), gl, threads)
    if key not in _RENDERERS:
        _RENDERERS[key] = abcube.Renderer(gl=gl, threads=threads)
    return _RENDERERS[key]


def render_views(scene_source, cameras, method="abuffer", cube_res=None, max_depth=None,
                 threads=1):
    """Renders `cameras` (a list of camera overrides) of one scene; the unit of work of a
    Dask task. Returns a list of float32 H x W x 3 arrays."""
    scene = load(scene_source)
    renderer = renderer_for(method, threads)
    return [renderer.render(scene, method=method, cube_res=cube_res, max_depth=max_depth,
                            camera=camera) for camera in cameras]


def render_views_to_files(scene_source, jobs, method="abuffer", cube_res=None, max_depth=None,
                          threads=1):
    """Renders each (camera, out) of `jobs` into its file, the unit of work of a Dask task a
    preemptible worker may not finish. A file that exists is whole (abcube.write_image
    writes a temporary and renames it into place), so it is skipped: a task run again redoes
    only what is missing. First the temporaries that killed workers of this host left in the
    output folders are removed (abcube.remove_stale_temporaries). Returns [(out, "rendered"
    or "skipped")]."""
    for folder in sorted({os.path.dirname(out) or "." for _, out in jobs}):
        abcube.remove_stale_temporaries(folder)
    done = []
    for camera, out in jobs:
        if os.path.exists(out):
            done.append((out, "skipped"))
            continue
        scene = load(scene_source)
        image = renderer_for(method, threads).render(scene, method=method, cube_res=cube_res,
                                                     max_depth=max_depth, camera=camera)
        abcube.write_image(out, image)
        done.append((out, "rendered"))
    return done


def worker_version():
    """Run on every worker before the clock starts: abcube imports there, and its version."""
    return abcube.__version__


def chunks(items, size):
    return [items[k:k + size] for k in range(0, len(items), size)]


def worker_environment():
    """PYTHONPATH for spawned workers: the abcube module's folder and this file's."""
    folders = [os.path.dirname(abcube.__file__), os.path.dirname(os.path.abspath(__file__))]
    old = os.environ.get("PYTHONPATH", "")
    folders += [p for p in old.split(os.pathsep) if p and p not in folders]
    return os.pathsep.join(folders)


def render_in_cluster(scene_source, cameras, method="abuffer", cube_res=None, max_depth=None,
                      n_workers=2, chunk=8):
    """The views rendered by a LocalCluster of `n_workers` processes, `chunk` views per
    task, in the order of `cameras`. Returns (images, seconds of the batch without the
    cluster's start-up, seconds of the start-up)."""
    from dask.distributed import Client, LocalCluster

    os.environ["PYTHONPATH"] = worker_environment()
    # Tasks name the function by module (dask_orbit.render_views), so that the workers
    # import this file as a module and its per-process caches live across tasks; run as a
    # script, this file is __main__, whose functions would travel by value instead.
    task = importlib.import_module("dask_orbit").render_views if __name__ == "__main__" \
        else render_views
    started = time.perf_counter()
    with LocalCluster(n_workers=n_workers, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        # Every worker imports abcube once before the clock starts.
        versions = client.run(worker_version)
        if set(versions.values()) != {abcube.__version__}:
            raise RuntimeError(f"the workers import another abcube: {versions}")
        startup = time.perf_counter() - started
        begin = time.perf_counter()
        futures = [client.submit(task, scene_source, part, method, cube_res, max_depth,
                                 1, pure=False)
                   for part in chunks(cameras, chunk)]
        images = [image for part in client.gather(futures) for image in part]
        batch = time.perf_counter() - begin
    return images, batch, startup


def task_retries(client, futures):
    """How many times a worker died while running each future's task (the scheduler's count),
    for the futures whose task ran more than once."""
    keys = [f.key for f in futures]

    def count(dask_scheduler, keys=keys):
        return {k: dask_scheduler.tasks[k].suspicious for k in keys if k in dask_scheduler.tasks}

    counts = client.run_on_scheduler(count)
    return {f.key: counts[f.key] for f in futures if counts.get(f.key)}


def files_in_cluster(scene_source, cameras, out_dir, method="abuffer", cube_res=None,
                     max_depth=None, n_workers=2, chunk=4, after_first=None):
    """Writes out_dir/view_NNN.exr for each camera from a LocalCluster of `n_workers` worker
    processes, `chunk` views per task. A worker that dies (killed, preempted) loses nothing:
    the scheduler runs its task again on another, which skips the files already whole.
    `after_first` (optional) is called with (client, cluster) once the first task is done
    (the kill test uses it). Returns (the views rendered, the views of tasks run again)."""
    from dask.distributed import Client, LocalCluster, as_completed

    os.environ["PYTHONPATH"] = worker_environment()
    task = importlib.import_module("dask_orbit").render_views_to_files if __name__ == "__main__" \
        else render_views_to_files
    out_dir = pathlib.Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    jobs = [(camera, str(out_dir / f"view_{k:03d}.exr")) for k, camera in enumerate(cameras)]
    with LocalCluster(n_workers=n_workers, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        parts = chunks(jobs, chunk)
        futures = [client.submit(task, scene_source, part, method, cube_res, max_depth, 1,
                                 pure=False) for part in parts]
        views = {f.key: [out for _, out in part] for f, part in zip(futures, parts)}
        results = []
        for k, done in enumerate(as_completed(futures)):
            results += done.result()
            if k == 0 and after_first:
                after_first(client, cluster)
        retried = sorted(out for key in task_retries(client, futures) for out in views[key])
    return [out for out, what in results if what == "rendered"], retried


def render_in_process(scene_source, cameras, method="abuffer", cube_res=None, max_depth=None,
                      threads=0):
    """The same views in this process, one Renderer (threads=0: every core)."""
    begin = time.perf_counter()
    images = render_views(scene_source, cameras, method, cube_res, max_depth, threads)
    return images, time.perf_counter() - begin


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scene", help="scene JSON file")
    parser.add_argument("--views", type=int, default=64)
    parser.add_argument("--size", type=int, nargs=2, default=[128, 96], metavar=("W", "H"))
    parser.add_argument("--method", default="abuffer")
    parser.add_argument("--cube-res", type=int, default=None)
    parser.add_argument("--max-depth", type=int, default=None)
    parser.add_argument("--radius", type=float, default=6.0)
    parser.add_argument("--height", type=float, default=2.0)
    parser.add_argument("--center", type=float, nargs=3, default=[0, 0.8, 0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--chunk", type=int, default=8, help="views per Dask task")
    parser.add_argument("--out", help="folder for view_NNN.exr")
    args = parser.parse_args(argv)

    cameras = orbit_cameras(args.views, args.center, args.radius, args.height, *args.size)
    scene_path = str(pathlib.Path(args.scene).resolve())
    options = dict(method=args.method, cube_res=args.cube_res, max_depth=args.max_depth)
    in_cluster, batch, startup = render_in_cluster(scene_path, cameras, n_workers=args.workers,
                                                   chunk=args.chunk, **options)
    in_process, alone = render_in_process(scene_path, cameras, **options)
    equal = all(a.tobytes() == b.tobytes() for a, b in zip(in_cluster, in_process))
    print(f"{args.views} views {args.size[0]}x{args.size[1]} {args.method}: "
          f"cluster of {args.workers} workers {batch:.2f} s (+ {startup:.2f} s start-up), "
          f"one process {alone:.2f} s; images equal byte for byte: {equal}")
    if args.out:
        out = pathlib.Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        for k, image in enumerate(in_cluster):
            abcube.write_image(str(out / f"view_{k:03d}.exr"), image)
    return 0 if equal and len(in_cluster) == len(in_process) == args.views else 1


if __name__ == "__main__":
    sys.exit(main())
