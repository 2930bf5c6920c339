#!/usr/bin/python3
"""A V-view orbit of one scene rendered two ways in one run: one `abcube batch` process,
and V separate `abcube render` processes (each view's camera baked into its own scene
file). Prints the wall time of each way, per view, and checks that the two ways wrote the
same bytes for every view (batch and render are the same library call).

  /usr/bin/python3 bench/orbit_batch.py [--views 200] [--size 128] [--method abuffer]
      [--cube-res 128] [--scene scenes/cornell.json] [--abcube build/abcube] [--out DIR]
"""
import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)


def orbit_cameras(scene, views):
    """Positions on a circle around the scene camera's look_at, at the camera's height."""
    cam = scene["camera"]
    look = cam.get("look_at", [0, 0.5, 0])
    pos = cam.get("position", [0, 1, -4])
    radius = max(math.hypot(pos[0] - look[0], pos[2] - look[2]), 1e-3)
    start = math.atan2(pos[2] - look[2], pos[0] - look[0])
    for k in range(views):
        # A quarter-turn arc each side of the scene's own view (closed rooms stay inside).
        a = start + (k / max(views - 1, 1) - 0.5) * math.pi / 2
        yield [look[0] + radius * math.cos(a), pos[1], look[2] + radius * math.sin(a)]


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--views", type=int, default=200)
    p.add_argument("--size", type=int, default=128, help="image width and height, pixels")
    p.add_argument("--method", default="abuffer")
    p.add_argument("--cube-res", type=int, default=128)
    p.add_argument("--scene", default=os.path.join(REPO, "scenes", "cornell.json"))
    p.add_argument("--abcube", default=os.path.join(REPO, "build", "abcube"))
    p.add_argument("--out", default=None, help="keep the images here (default: a temporary folder)")
    a = p.parse_args()
    if a.views < 1 or a.size < 1 or a.cube_res < 1:
        sys.exit("orbit_batch.py: --views, --size and --cube-res must be >= 1")

    work = a.out or tempfile.mkdtemp(prefix="abcube_orbit_")
    os.makedirs(os.path.join(work, "batch"), exist_ok=True)
    os.makedirs(os.path.join(work, "render"), exist_ok=True)
    scene = json.load(open(a.scene))
    scene_dir = os.path.dirname(os.path.abspath(a.scene))
    jobs = []
    scene_files = []
    for k, position in enumerate(orbit_cameras(scene, a.views)):
        camera = {"position": position, "width": a.size, "height": a.size}
        jobs.append({"scene": os.path.abspath(a.scene), "out": "batch/%04d.png" % k, "method": a.method,
                     "cube_res": a.cube_res, "camera": camera})
        # The same view as its own scene file, beside the original (relative mesh paths hold).
        s = json.loads(json.dumps(scene))
        s["camera"].update(camera)
        path = os.path.join(scene_dir, ".orbit_%d_%04d.json" % (os.getpid(), k))
        json.dump(s, open(path, "w"))
        scene_files.append(path)
    jobs_path = os.path.join(work, "jobs.jsonl")
    with open(jobs_path, "w") as f:
        f.write("\n".join(json.dumps(j) for j in jobs) + "\n")

    try:
        t0 = time.perf_counter()
        subprocess.run([a.abcube, "batch", jobs_path], check=True, stdout=subprocess.DEVNULL)
        batch_s = time.perf_counter() - t0
        t0 = time.perf_counter()
        for k, path in enumerate(scene_files):
            subprocess.run([a.abcube, "render", path, "-o", os.path.join(work, "render", "%04d.png" % k),
                            "--method", a.method, "--cube-res", str(a.cube_res)], check=True)
        render_s = time.perf_counter() - t0
    finally:
        for path in scene_files:
            os.remove(path)

    same = sum(open(os.path.join(work, "batch", "%04d.png" % k), "rb").read() ==
               open(os.path.join(work, "render", "%04d.png" % k), "rb").read() for k in range(a.views))
    load = os.getloadavg()[0]
    print("orbit of %s: %d views, %dx%d, method %s, cube %d" % (os.path.basename(a.scene), a.views, a.size, a.size,
                                                                 a.method, a.cube_res))
    print("  abcube batch (one process):   %7.2f s, %7.1f ms per view" % (batch_s, 1000 * batch_s / a.views))
    print("  abcube render (a process each): %7.2f s, %7.1f ms per view" % (render_s, 1000 * render_s / a.views))
    print("  speed-up %.2fx; identical images: %d of %d; load average at the end %.2f"
          % (render_s / batch_s, same, a.views, load))
    if not a.out:
        shutil.rmtree(work)
    return 0 if same == a.views else 1


if __name__ == "__main__":
    sys.exit(main())
