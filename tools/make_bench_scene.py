#!/usr/bin/env python3
"""Writes the benchmark scene scenes/bench/spheres_terrain.json and its mesh terrain.obj.

Deterministic (seeded, Python standard library only): running it again gives the same
bytes, so the committed output can be checked with `git diff --exit-code` after a run.

The scene: a displaced terrain (OBJ with vertex normals, quad faces) under a seeded field
of small spheres, a large mirror sphere, a large glass sphere and a mirror quad behind
them; about 113k triangles in all, most of them from the spheres, which the JSON
describes in a few bytes each (a sphere with s segments has 2 s (s/2 - 1) triangles).

Usage: tools/make_bench_scene.py [--out DIR] [--seed N]
"""
import argparse
import json
import math
import os
import random

GRID = 64             # terrain cells per side: 2 * 64 * 64 = 8192 triangles
TERRAIN_SIZE = 16.0   # metres per side, centred on the origin
SPHERE_ROWS = 6       # 6 x 8 small spheres
SPHERE_COLS = 8
SMALL_SEGMENTS = 40   # 2 * 40 * 19 = 1520 triangles each
BIG_SEGMENTS = 128    # 2 * 128 * 63 = 16128 triangles each


def height(x, z):
    """Smooth rolling hills, low enough that the spheres stand above them."""
    return 0.25 * math.sin(0.7 * x) * math.cos(0.5 * z) + 0.1 * math.sin(1.9 * x + 0.6 * z)


def height_normal(x, z, h=1e-3):
    """Unit normal of the height field y = height(x, z) by central differences."""
    dx = (height(x + h, z) - height(x - h, z)) / (2 * h)
    dz = (height(x, z + h) - height(x, z - h)) / (2 * h)
    n = (-dx, 1.0, -dz)
    length = math.sqrt(sum(c * c for c in n))
    return tuple(c / length for c in n)


def terrain_obj():
    """OBJ text of the terrain: (GRID+1)^2 vertices with normals, GRID^2 quads facing up."""
    lines = ["# Benchmark terrain written by tools/make_bench_scene.py; do not edit.",
             "o terrain"]
    coords = []
    for j in range(GRID + 1):
        for i in range(GRID + 1):
            x = -TERRAIN_SIZE / 2 + TERRAIN_SIZE * i / GRID
            z = -TERRAIN_SIZE / 2 + TERRAIN_SIZE * j / GRID
            coords.append((x, z))
    for x, z in coords:
        lines.append("v %.5f %.5f %.5f" % (x, height(x, z), z))
    for x, z in coords:
        lines.append("vn %.5f %.5f %.5f" % height_normal(x, z))
    for j in range(GRID):
        for i in range(GRID):
            a = j * (GRID + 1) + i + 1  # OBJ indices start at 1
            b, c, d = a + GRID + 1, a + GRID + 2, a + 1
            # a -> b -> c -> d runs counter-clockwise seen from above (+z then +x).
            lines.append("f %d//%d %d//%d %d//%d %d//%d" % (a, a, b, b, c, c, d, d))
    return "\n".join(lines) + "\n"


def small_spheres(rng):
    """A jittered grid of small diffuse spheres resting on the terrain."""
    spheres = []
    for r in range(SPHERE_ROWS):
        for c in range(SPHERE_COLS):
            x = -5.6 + 1.6 * c + rng.uniform(-0.3, 0.3)
            z = -4.0 + 1.6 * r + rng.uniform(-0.3, 0.3)
            radius = round(rng.uniform(0.25, 0.5), 3)
            spheres.append({
                "type": "sphere",
                "center": [round(x, 3), round(height(x, z) + radius, 3), round(z, 3)],
                "radius": radius,
                "segments": SMALL_SEGMENTS,
                "material": "diffuse%d" % ((r * SPHERE_COLS + c) % 4),
            })
    return spheres


def scene(rng):
    materials = {
        "ground": {"color": [0.55, 0.6, 0.45]},
        "mirror": {"color": [0.05, 0.05, 0.05], "specular": 0.5, "shininess": 96, "reflect": 0.9},
        "glass": {"color": [1, 1, 1], "diffuse": 0.0, "specular": 0.6, "shininess": 128,
                  "transmit": 0.9, "ior": 1.5},
    }
    palette = [[0.8, 0.2, 0.15], [0.2, 0.5, 0.8], [0.85, 0.75, 0.2], [0.3, 0.7, 0.35]]
    for k, color in enumerate(palette):
        materials["diffuse%d" % k] = {"color": color, "specular": 0.25, "shininess": 32}
    objects = [{"type": "mesh", "file": "terrain.obj", "material": "ground"}]
    objects += small_spheres(rng)
    objects += [
        {"type": "sphere", "center": [-1.6, 1.6, 1.2], "radius": 1.2,
         "segments": BIG_SEGMENTS, "material": "mirror"},
        {"type": "sphere", "center": [1.6, 1.4, 2.0], "radius": 1.0,
         "segments": BIG_SEGMENTS, "material": "glass"},
        {"type": "quad", "vertices": [[-6, 0, -6.5], [6, 0, -6.5], [6, 4, -6.5], [-6, 4, -6.5]],
         "material": "mirror"},
    ]
    return {
        "version": 1,
        "camera": {"position": [0, 3.2, 9], "look_at": [0, 0.8, 0], "up": [0, 1, 0],
                   "fov_y": 50, "width": 640, "height": 480},
        "background": [0.35, 0.5, 0.75],
        "ambient": [0.12, 0.12, 0.12],
        "lights": [
            {"type": "point", "position": [-5, 9, 6], "color": [0.9, 0.85, 0.8], "cast_shadows": True},
            {"type": "point", "position": [6, 6, -2], "color": [0.3, 0.35, 0.45], "cast_shadows": True},
        ],
        "materials": materials,
        "objects": objects,
        "render": {"method": "abuffer", "cube_resolution": 512, "max_depth": 3},
    }


def dump_scene(s):
    """JSON with one light, material or object per line: readable and diff-friendly."""
    def compact(v):
        return json.dumps(v, separators=(", ", ": "))
    out = ["{"]
    for k, (key, value) in enumerate(s.items()):
        comma = "," if k + 1 < len(s) else ""
        if isinstance(value, list) and value and isinstance(value[0], dict):
            out.append('  "%s": [' % key)
            out += ["    " + compact(v) + ("," if i + 1 < len(value) else "") for i, v in enumerate(value)]
            out.append("  ]" + comma)
        elif key == "materials":
            out.append('  "%s": {' % key)
            names = list(value)
            out += ['    "%s": %s%s' % (n, compact(value[n]), "," if i + 1 < len(names) else "")
                    for i, n in enumerate(names)]
            out.append("  }" + comma)
        else:
            out.append('  "%s": %s%s' % (key, compact(value), comma))
    out.append("}")
    return "\n".join(out) + "\n"


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=os.path.join(here, "..", "scenes", "bench"))
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    rng = random.Random(args.seed)
    os.makedirs(args.out, exist_ok=True)
    with open(os.path.join(args.out, "terrain.obj"), "w", newline="\n") as f:
        f.write(terrain_obj())
    with open(os.path.join(args.out, "spheres_terrain.json"), "w", newline="\n") as f:
        f.write(dump_scene(scene(rng)))


if __name__ == "__main__":
    main()
