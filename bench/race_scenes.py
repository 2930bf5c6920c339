#!/usr/bin/python3
"""Seeded scenes that resemble what users render, for the race (bench/race.py).

Three templates, each drawn from a seed (same seed, same bytes):

  room     a closed room of six walls (camera inside), chrome and glass spheres across the
           cube map's seams and corners around the camera, boxes, two ceiling lights;
           about 13k triangles; 320x320, N = 512, max_depth 4.
  outdoor  an open scene: a rolling terrain mesh (about 30k triangles) under a sky colour,
           scattered boxes and spheres, a chrome sphere and a glass sphere, a far sun and a
           fill light; rays escape to the background; 320x240, N = 512, max_depth 4.
  mesh1m   a 1M-triangle terrain mesh (bench/memory.py's, 707 x 707 cells, vertex normals)
           with a chrome and a glass sphere and two shadow-casting lights; 256x256, N = 512.

Usage: race_scenes.py --out DIR [--seed S] [--templates room,outdoor,mesh1m]
Prints the scene files written, one per line.
"""
import argparse
import math
import os
import random
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "tools"))
sys.path.insert(0, HERE)
import hard_scenes as hs  # noqa: E402  (helpers: quad, sphere, box, materials, camera)
import memory  # noqa: E402  (the seeded terrain writer)


def t_room(rng, folder, stem):
    half = [rng.uniform(3.0, 4.5), 1.5, rng.uniform(3.0, 4.5)]   # x, y (height 3 m), z
    eye = [rng.uniform(-0.5, 0.5), 1.5, rng.uniform(-0.5, 0.5)]
    mats = {"mirror": hs.mirror_material(rng), "glass": hs.glass_material(1.5)}
    objs = []
    # Six walls, each facing into the room (normal u x v points inward).
    walls = [
        ([0, 0, 0], [0, 0, half[2]], [half[0], 0, 0]),                # floor, +y
        ([0, 2 * half[1], 0], [half[0], 0, 0], [0, 0, half[2]]),     # ceiling, -y
        ([-half[0], half[1], 0], [0, half[1], 0], [0, 0, half[2]]),  # +x
        ([half[0], half[1], 0], [0, 0, half[2]], [0, half[1], 0]),   # -x
        ([0, half[1], -half[2]], [half[0], 0, 0], [0, half[1], 0]),  # +z
        ([0, half[1], half[2]], [0, half[1], 0], [half[0], 0, 0]),   # -z
    ]
    for i, (c, u, v) in enumerate(walls):
        name = "wall%d" % i
        mats[name] = hs.diffuse(rng, 0.3, specular=round(rng.uniform(0, 0.2), 3))
        objs.append(hs.quad(c, u, v, name))
    view = None
    for i, d in enumerate(rng.sample(hs.SEAM_DIRECTIONS, 7)):
        d = hs.normalize([c + rng.uniform(-0.01, 0.01) for c in d])
        dist = rng.uniform(1.6, 2.8)
        p = hs.add(eye, hs.mul(d, dist))
        r = rng.uniform(0.3, 0.55)
        p[1] = min(max(p[1], r + 0.05), 2 * half[1] - r - 0.05)   # inside floor and ceiling
        kind = ["mirror", "glass", None][i % 3]
        name = kind or "ball%d" % i
        if not kind:
            mats[name] = hs.diffuse(rng, specular=0.3, shininess=48)
        if kind is None and rng.random() < 0.5:
            objs.append(hs.box(hs.sub(p, [r, r, r]), hs.add(p, [r, r, r]), name))
        else:
            objs.append(hs.sphere(p, r, name, 48))
        if view is None and kind == "mirror":
            view = p
    lights = [hs.point_light([rng.uniform(-1, 1) * half[0] * 0.6, 2 * half[1] - 0.3,
                              rng.uniform(-1, 1) * half[2] * 0.6], 1.0),
              hs.point_light([rng.uniform(-1, 1) * half[0] * 0.6, 2 * half[1] - 0.3,
                              rng.uniform(-1, 1) * half[2] * 0.6], 0.5)]
    s = hs.scene(rng, hs.camera_looking(eye, view, rng.uniform(70, 85)), lights, mats, objs)
    s["camera"].update(width=320, height=320)
    s["render"] = {"method": "abuffer", "cube_resolution": 512, "max_depth": 4}
    return s


def t_outdoor(rng, folder, stem):
    grid = 120
    waves = [(rng.uniform(0.05, 0.3), rng.uniform(0.05, 0.3), rng.uniform(0, 6.3), rng.uniform(0.1, 0.6))
             for _ in range(5)]
    extent = 80.0

    def height(x, z):
        return sum(a * math.sin(fx * x + ph) * math.cos(fz * z - ph) for fx, fz, ph, a in waves)

    obj = stem + ".obj"
    with open(os.path.join(folder, obj), "w") as f:
        f.write("# bench/race_scenes.py outdoor terrain\no ground\n")
        f.write("".join("v %.5f %.5f %.5f\n" % (x, height(x, z), z)
                        for z in (-extent / 2 + extent * j / grid for j in range(grid + 1))
                        for x in (-extent / 2 + extent * i / grid for i in range(grid + 1))))
        for j in range(grid):
            for i in range(grid):
                a = j * (grid + 1) + i + 1
                f.write("f %d %d %d %d\n" % (a, a + grid + 1, a + grid + 2, a + 1))
    mats = {"ground": hs.diffuse(rng, 0.3), "mirror": hs.mirror_material(rng), "glass": hs.glass_material(1.5)}
    objs = [{"type": "mesh", "file": obj, "material": "ground"}]
    props = hs.scatter_props(rng, mats, 14, 0.4, 1.2, ring=(3.0, 14.0))
    for p in props:   # stand each prop on the terrain
        if p["type"] == "sphere":
            p["center"][1] = round(height(p["center"][0], p["center"][2]) + p["radius"], 6)
        else:
            y = height((p["min"][0] + p["max"][0]) / 2, (p["min"][2] + p["max"][2]) / 2) - 0.1
            size = p["max"][1] - p["min"][1]
            p["min"][1], p["max"][1] = round(y, 6), round(y + size, 6)
    objs += props
    focus = [rng.uniform(-2, 2), 0, rng.uniform(-9, -6)]
    for kind, dx in (("mirror", -1.6), ("glass", 1.6)):
        r = rng.uniform(0.9, 1.4)
        c = [focus[0] + dx, 0, focus[2] + rng.uniform(-1, 1)]
        c[1] = height(c[0], c[2]) + r
        objs.append(hs.sphere(c, r, kind, 48))
    eye = [0, height(0, 0) + rng.uniform(1.6, 3.0), 0]
    focus[1] = height(focus[0], focus[2]) + 1.0
    sun = hs.spherical(rng.uniform(0, 360), rng.uniform(25, 60))
    lights = [hs.point_light(hs.mul(sun, 200.0), 1.0), hs.point_light([eye[0] + 3, eye[1] + 4, eye[2] + 2], 0.25)]
    s = hs.scene(rng, hs.camera_looking(eye, focus, rng.uniform(50, 70)), lights, mats, objs,
                 background=[0.45, 0.62, 0.85])
    s["camera"].update(width=320, height=240)
    s["render"] = {"method": "abuffer", "cube_resolution": 512, "max_depth": 4}
    return s


TEMPLATES = {"room": t_room, "outdoor": t_outdoor}


def write(folder, template, seed):
    """Writes one scene (and its OBJ) into folder; returns the scene path."""
    import json
    os.makedirs(folder, exist_ok=True)
    if template == "mesh1m":
        path, _ = memory.write_terrain_scene(folder, 707, seed, 256, 512)
        return path
    stem = "%s_%d" % (template, seed)
    s = TEMPLATES[template](random.Random(seed), folder, stem)
    path = os.path.join(folder, stem + ".json")
    with open(path, "w") as f:
        json.dump(s, f, indent=1)
        f.write("\n")
    return path


def generated_sample(folder, seed, hard, flat, size, cube_res):
    """The hard-case and flat-mirror templates' scenes drawn from seed: `hard` scenes cycling
    tools/hard_scenes.py's templates and `flat` cycling tools/flat_mirror_scenes.py's, at
    `size` ("WxH") with N = cube_res, written into folder/hard_SEED and folder/flat_SEED (a
    folder per seed: another seed's scenes left in the same --out are not swept in). Returns
    their paths, sorted within each generator."""
    import subprocess
    tools = os.path.join(HERE, "..", "tools")
    paths = []
    for tool, count, sub in (("hard_scenes.py", hard, "hard"), ("flat_mirror_scenes.py", flat, "flat")):
        if count <= 0:
            continue
        d = os.path.join(folder, "%s_%d" % (sub, seed))
        subprocess.run(["/usr/bin/python3", os.path.join(tools, tool), "--seed", str(seed), "--count", str(count),
                        "--out", d, "--size", size, "--cube-res", str(cube_res)], check=True,
                       stdout=subprocess.DEVNULL)
        paths += sorted(os.path.join(d, f) for f in os.listdir(d) if f.endswith(".json"))
    return paths


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", required=True)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--templates", default="room,outdoor,mesh1m")
    args = ap.parse_args(argv)
    for t in args.templates.split(","):
        if t not in TEMPLATES and t != "mesh1m":
            ap.error("unknown template %r (room, outdoor, mesh1m)" % t)
        print(write(args.out, t, args.seed))
    return 0


if __name__ == "__main__":
    sys.exit(main())
