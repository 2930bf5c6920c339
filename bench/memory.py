#!/usr/bin/python3
"""Peak resident memory per triangle of scene data, per method (issue 14 part 6).

Generates seeded terrain scenes (an OBJ height field with vertex normals, quad faces,
under a mirror sphere, a glass sphere and two shadow-casting lights) into a temporary
folder, renders each with every method at a small image and cube resolution, and reads
the peak RSS of each whole process from `/usr/bin/time -v` (maximum resident set size).
The baseline is `abcube --version`: bytes per triangle = (peak - baseline) / triangles.
A method's own baseline is the same render of a near-empty scene (the terrain of 1 cell:
2 triangles beside the spheres): what that method holds before any scene data (for gpu,
the GL driver, its compiled shaders and its render targets). Bytes per triangle above it
= (peak - its peak) / (triangles - its triangles).
The marginal figures are the slopes between consecutive scenes: what one more triangle
costs, free of every per-process constant (the GL driver, the cube map, the image).
`gpu:maps` is gpu with `--gpu-shadows maps` (cube shadow maps instead of volumes).

Nothing large is committed: the scenes live in a temporary folder (--keep DIR keeps them).

Usage: bench/memory.py [--abcube build/abcube] [--grids 469,707,1000,1414] [--size 64] [--cube-res 128]
                       [--methods raytrace,abuffer,zbuffer,envmap,gpu,gpu:maps] [--out bench/results/memory]
"""
import argparse
import datetime
import math
import os
import random
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import peak_rss_kib  # noqa: E402

METHODS = ["raytrace", "abuffer", "zbuffer", "envmap", "gpu", "gpu:maps"]
# A method name, or METHOD:SHADOWS for gpu with --gpu-shadows SHADOWS (volumes, its default, or maps).


def method_arguments(method):
    name, _, shadows = method.partition(":")
    return ["--method", name] + (["--gpu-shadows", shadows] if shadows else [])


def write_terrain_scene(folder, grid, seed, size, cube_res):
    """A (grid x grid)-cell terrain, 2 grid^2 triangles, plus two spheres of 2 * 48 * 23 each."""
    rng = random.Random(seed)
    waves = [(rng.uniform(0.2, 1.5), rng.uniform(0.2, 1.5), rng.uniform(0, 6.3), rng.uniform(0.05, 0.3))
             for _ in range(6)]
    extent = 40.0

    def height(x, z):
        return sum(a * math.sin(fx * x + ph) * math.cos(fz * z - ph) for fx, fz, ph, a in waves)

    def normal(x, z, h=1e-3):
        dx = (height(x + h, z) - height(x - h, z)) / (2 * h)
        dz = (height(x, z + h) - height(x, z - h)) / (2 * h)
        length = math.sqrt(dx * dx + 1 + dz * dz)
        return (-dx / length, 1 / length, -dz / length)

    obj = os.path.join(folder, "terrain_%d.obj" % grid)
    with open(obj, "w") as f:
        f.write("# bench/memory.py terrain, grid %d, seed %d\no terrain\n" % (grid, seed))
        coords = [(-extent / 2 + extent * i / grid, -extent / 2 + extent * j / grid)
                  for j in range(grid + 1) for i in range(grid + 1)]
        f.write("".join("v %.5f %.5f %.5f\n" % (x, height(x, z), z) for x, z in coords))
        f.write("".join("vn %.5f %.5f %.5f\n" % normal(x, z) for x, z in coords))
        rows = []
        for j in range(grid):
            for i in range(grid):
                a = j * (grid + 1) + i + 1
                b, c, d = a + grid + 1, a + grid + 2, a + 1
                rows.append("f %d//%d %d//%d %d//%d %d//%d\n" % (a, a, b, b, c, c, d, d))
        f.write("".join(rows))
    scene = os.path.join(folder, "terrain_%d.json" % grid)
    with open(scene, "w") as f:
        f.write("""{
  "version": 1,
  "camera": {"position": [0, 4, 12], "look_at": [0, 0.5, 0], "up": [0, 1, 0], "fov_y": 55, "width": %d, "height": %d},
  "background": [0.35, 0.5, 0.75],
  "lights": [
    {"type": "point", "position": [-8, 12, 6], "color": [0.9, 0.85, 0.8], "cast_shadows": true},
    {"type": "point", "position": [7, 6, -3], "color": [0.3, 0.35, 0.45], "cast_shadows": true}
  ],
  "materials": {
    "ground": {"color": [0.55, 0.6, 0.45]},
    "mirror": {"color": [0.05, 0.05, 0.05], "specular": 0.5, "shininess": 96, "reflect": 0.9},
    "glass": {"color": [1, 1, 1], "diffuse": 0.0, "specular": 0.6, "shininess": 128, "transmit": 0.9, "ior": 1.5}
  },
  "objects": [
    {"type": "mesh", "file": "%s", "material": "ground"},
    {"type": "sphere", "center": [-1.5, 2.2, 0], "radius": 1.2, "segments": 48, "material": "mirror"},
    {"type": "sphere", "center": [1.6, 2.0, 1.5], "radius": 1.0, "segments": 48, "material": "glass"}
  ],
  "render": {"cube_resolution": %d, "max_depth": 4}
}
""" % (size, size, os.path.basename(obj), cube_res))
    return scene, 2 * grid * grid + 2 * 2 * 48 * 23


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--abcube", default="build/abcube")
    ap.add_argument("--grids", default="469,707,1000,1414",
                    help="terrain cells per side (469: 440k, 707: 1M, 1000: 2M, 1414: 4M triangles)")
    ap.add_argument("--size", type=int, default=64, help="image width and height")
    ap.add_argument("--cube-res", type=int, default=128)
    ap.add_argument("--methods", default=",".join(METHODS))
    ap.add_argument("--seed", type=int, default=14)
    ap.add_argument("--out", default="bench/results/memory", help="writes OUT.md and OUT.txt")
    ap.add_argument("--keep", help="write the scenes into this folder and keep them")
    args = ap.parse_args()
    methods = args.methods.split(",")
    grids = [int(g) for g in args.grids.split(",")]
    folder = args.keep or tempfile.mkdtemp(prefix="abcube_memory_")
    os.makedirs(folder, exist_ok=True)
    start = datetime.datetime.now(datetime.timezone.utc)
    load_before = os.getloadavg()
    try:
        status, base_kib, _ = peak_rss_kib([args.abcube, "--version"])
        if status != 0:
            sys.exit("abcube --version failed")
        own_base = {}  # method -> (peak KiB, triangles) of the 1-cell terrain
        base_scene, base_triangles = write_terrain_scene(folder, 1, args.seed, args.size, args.cube_res)
        for method in methods:
            out = os.path.join(folder, "out_1_%s.png" % method.replace(":", "_"))
            status, kib, _ = peak_rss_kib([args.abcube, "render", base_scene, "-o", out] +
                                          method_arguments(method) + ["--threads", "2"])
            if status != 0:
                sys.exit("the near-empty scene failed under " + method)
            own_base[method] = (kib, base_triangles)
            print("%-18s %8d %-9s own baseline %8.1f MB" % ("terrain_1.json", base_triangles, method, kib / 1024), flush=True)
        rows = []  # (scene, triangles, method, status, peak KiB, seconds)
        scenes = []
        for grid in grids:
            scene, triangles = write_terrain_scene(folder, grid, args.seed, args.size, args.cube_res)
            scenes.append((scene, triangles))
            for method in methods:
                out = os.path.join(folder, "out_%d_%s.png" % (grid, method.replace(":", "_")))
                status, kib, seconds = peak_rss_kib([args.abcube, "render", scene, "-o", out] +
                                                    method_arguments(method) + ["--threads", "2"])
                rows.append((os.path.basename(scene), triangles, method, status, kib, seconds))
                print("%-18s %8d %-9s exit %d  peak %8.1f MB  %6.1f B/tri  %.1f s" % (
                    os.path.basename(scene), triangles, method, status, kib / 1024,
                    (kib - base_kib) * 1024 / triangles, seconds), flush=True)
    finally:
        if not args.keep:
            shutil.rmtree(folder, ignore_errors=True)
    load_after = os.getloadavg()
    command = " ".join(["bench/memory.py"] + sys.argv[1:])
    commit = subprocess.run(["git", "rev-parse", "--short=12", "HEAD"], stdout=subprocess.PIPE, text=True).stdout.strip()
    lines = ["# Peak resident memory per triangle (bench/memory.py)", "",
             "Command: `%s`  " % command,
             "Date: %s, commit %s, load average %.2f / %.2f / %.2f before, %.2f / %.2f / %.2f after (2 cores)  " % (
                 start.strftime("%Y-%m-%d %H:%M UTC"), commit, *load_before, *load_after),
             "Scenes: seeded terrain OBJ (vertex normals, quads) + mirror sphere + glass sphere, 2 shadow-casting lights; "
             "image %dx%d, cube N = %d, max_depth 4, 2 threads." % (args.size, args.size, args.cube_res),
             "Baseline `abcube --version`: %.1f MB peak RSS. B/tri = (peak - baseline) / triangles; marginal = slope "
             "between consecutive scenes (per-process constants removed); gpu:maps is gpu with --gpu-shadows maps." % (base_kib / 1024), "",
             "Own baseline: each method's peak on terrain_1.json (%d triangles): %s." % (
                 base_triangles, ", ".join("%s %.1f MB" % (m, own_base[m][0] / 1024) for m in methods)), "",
             "| scene | triangles | method | exit | peak RSS MB | B/tri above baseline | B/tri above own baseline | s |",
             "|---|---:|---|---:|---:|---:|---:|---:|"]
    for name, triangles, method, status, kib, seconds in rows:
        own_kib, own_triangles = own_base[method]
        lines.append("| %s | %d | %s | %d | %.1f | %.0f | %.0f | %.1f |" % (
            name, triangles, method, status, kib / 1024, (kib - base_kib) * 1024 / triangles,
            (kib - own_kib) * 1024 / (triangles - own_triangles), seconds))
    if len(scenes) >= 2:
        pairs = list(zip(scenes, scenes[1:]))
        lines += ["", "| method | " + " | ".join("marginal B/tri (%d -> %d triangles)" % (a[1], b[1]) for a, b in pairs)
                  + " |", "|---|" + "---:|" * len(pairs)]
        for method in methods:
            slopes = []
            for (_, t0), (_, t1) in pairs:
                k0 = [r[4] for r in rows if r[1] == t0 and r[2] == method][0]
                k1 = [r[4] for r in rows if r[1] == t1 and r[2] == method][0]
                slopes.append("%.0f" % ((k1 - k0) * 1024 / (t1 - t0)))
            lines.append("| %s | %s |" % (method, " | ".join(slopes)))
    text = "\n".join(lines) + "\n"
    os.makedirs(os.path.dirname(args.out) or ".", exist_ok=True)
    with open(args.out + ".txt", "w") as f:
        f.write(text)
    print(text)


if __name__ == "__main__":
    main()
