#!/usr/bin/python3
"""Seeded generator of scenes whose mirrors are all flat (issue 19): what the gpu method
renders exactly (planar mirrors by the stencil test, shadows by volumes) and the cube-map
methods approximate.

Six templates, after the cases where the old gpu method scored 12 to 30 dB against the
exact tracer: a mirror whose plane holds the camera, seen in a second mirror; a floor
mirror showing a quad that an occluder hides from the camera; thin boxes in front of
mirror boxes (mirrors facing mirrors: rays bounce to max_depth); a wide flat water surface
seen at a grazing angle; a point light lying on a mirror box; a point light on, or 1e-6
above or below, an open mirror quad (its shadow volume reaches infinity in nearly the
quad's plane, across every camera tile). No material refracts, no mirror
is curved, nothing is coverage-transparent (those keep the cube maps:
docs/design/gpu-exact-paths.md).

Deterministic: the same arguments give the same bytes (standard library only; the
helpers of tools/hard_scenes.py).

Usage: flat_mirror_scenes.py --seed S --count N --out DIR [--templates a,b,...]
                             [--size WxH] [--cube-res N] [--max-depth D]
Scene k uses template templates[k % len(templates)]: DIR/TEMPLATE_SEED_K.json.
"""
import argparse
import json
import math
import os
import random
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from hard_scenes import (add, box, camera_looking, diffuse, floor, mirror_material, mul, point_light, quad,  # noqa: E402
                         rot_x, rot_y, scatter_props, scene, spherical, sphere)


def t_mirror_through_camera(rng):
    """A mirror shelf at exactly the camera's height (its plane holds the eye: seen edge-on,
    it covers no sample directly), seen in a tilted mirror ahead."""
    h = rng.uniform(0.8, 1.6)
    mats = {"floor": diffuse(rng), "shelf": mirror_material(rng), "mirror": mirror_material(rng)}
    side = rng.choice([-1, 1])
    x0, x1 = 0.6, rng.uniform(3, 5)
    shelf = quad([side * (x0 + x1) / 2, h, rng.uniform(-1, 1)], [0, 0, rng.uniform(3, 6)], [(x1 - x0) / 2, 0, 0],
                 "shelf")
    eye = [0, h, 4.0]
    mc = [side * 0.3, h + rng.uniform(-0.3, 0.3), rng.uniform(0.0, 1.0)]
    tilt, turn = rng.uniform(8, 30) * rng.choice([-1, 1]), -side * rng.uniform(10, 30)
    mu = rot_y(rot_x([1.2, 0, 0], tilt), turn)
    mv = rot_y(rot_x([0, 0.9, 0], tilt), turn)
    objs = [floor(10, "floor"), shelf, quad(mc, mu, mv, "mirror")]
    objs += scatter_props(rng, mats, 4, 0.15, 0.35, ring=(1.5, 3.5))
    lights = [point_light([rng.uniform(-2, 2), h + rng.uniform(1.5, 3), rng.uniform(2, 5)], 0.9)]
    return scene(rng, camera_looking(eye, mc, rng.uniform(45, 65)), lights, mats, objs)


def t_floor_mirror_hidden(rng):
    """A mirror floor; a coloured quad standing behind a wall that hides it from the camera,
    whose underside and lower part the floor mirror shows."""
    mats = {"floor": mirror_material(rng), "wall": diffuse(rng), "quad": diffuse(rng, 0.4)}
    objs = [floor(8, "floor")]
    wall_h = rng.uniform(0.5, 0.9)
    objs.append(box([-1.5, 0, -0.1], [1.5, wall_h, 0.1], "wall"))
    # the quad behind the wall (z < 0), lifted off the floor so that its lower part shows below
    lift = rng.uniform(0.15, 0.4)
    objs.append(quad([rng.uniform(-0.5, 0.5), lift + 0.5, rng.uniform(-1.5, -0.6)], [0.6, 0, 0], [0, 0.5, 0.15],
                     "quad"))
    objs += scatter_props(rng, mats, 3, 0.15, 0.3, ring=(1.6, 3.0))
    eye = [rng.uniform(-1, 1), rng.uniform(0.9, 1.4), rng.uniform(3.0, 4.5)]
    lights = [point_light([rng.uniform(-2, 2), 3.5, rng.uniform(1, 3)], 0.9)]
    return scene(rng, camera_looking(eye, [0, 0.3, -0.5], rng.uniform(45, 60)), lights, mats, objs)


def t_box_mirrors(rng):
    """Mirror boxes facing each other (every face a planar mirror) with thin boxes in front:
    rays bounce between mirrors to max_depth."""
    mats = {"floor": diffuse(rng), "mirror": mirror_material(rng)}
    objs = [floor(8, "floor")]
    gap = rng.uniform(1.6, 2.4)
    for side in (-1, 1):
        x = side * gap / 2
        objs.append(box([x - 0.15 if side > 0 else x - 0.3, 0, -1.2], [x + 0.3 if side > 0 else x + 0.15, 1.6, 1.2],
                        "mirror", {"rotate_deg": [0, rng.uniform(-6, 6), 0]}))
    for i in range(rng.randint(3, 5)):
        name = "thin%d" % i
        mats[name] = diffuse(rng, 0.3, specular=0.3)
        t = rng.uniform(0.01, 0.05)   # thin: a few centimetres
        c = [rng.uniform(-0.5, 0.5), 0, rng.uniform(-0.8, 0.8)]
        h = rng.uniform(0.4, 1.2)
        objs.append(box([c[0] - t, 0, c[2] - 0.3], [c[0] + t, h, c[2] + 0.3], name,
                        {"rotate_deg": [0, rng.uniform(0, 180), 0]}))
    eye = add([0, 0.8, 0], mul(spherical(rng.uniform(-25, 25), rng.uniform(10, 30)), rng.uniform(3.0, 4.0)))
    lights = [point_light([rng.uniform(-1, 1), 3.5, rng.uniform(1, 2.5)], 0.9)]
    return scene(rng, camera_looking(eye, [0, 0.7, 0], rng.uniform(45, 60)), lights, mats, objs)


def t_grazing_water(rng):
    """A wide flat water surface (a weak mirror) seen 80..88 degrees from its normal, with
    objects on its banks."""
    water = {"color": [0.05, 0.12, 0.15], "ambient": 0.3, "diffuse": 0.4, "specular": 0.5, "shininess": 128,
             "reflect": round(rng.uniform(0.3, 0.6), 3)}
    mats = {"water": water, "bank": diffuse(rng)}
    objs = [quad([0, 0, 0], [0, 0, 20], [6, 0, 0], "water"),
            quad([-9, 0.02, 0], [0, 0, 20], [3, 0, 0], "bank"),
            quad([9, 0.02, 0], [0, 0, 20], [3, 0, 0], "bank")]
    for i in range(rng.randint(4, 7)):
        name = "obj%d" % i
        mats[name] = diffuse(rng, specular=0.3)
        side = rng.choice([-1, 1])
        p = [side * rng.uniform(6.5, 9), 0.02, rng.uniform(-15, 5)]
        r = rng.uniform(0.3, 1.0)
        if rng.random() < 0.5:
            objs.append(sphere([p[0], p[1] + r, p[2]], r, name, 24))
        else:
            objs.append(box([p[0] - r, p[1], p[2] - r], [p[0] + r, p[1] + 2 * r * rng.uniform(1, 3), p[2] + r], name))
    graze = rng.uniform(80, 88)
    eye = [rng.uniform(-1, 1), 0, 12.0]
    target = [0, 0, 12.0 - 10.0]
    eye[1] = 10.0 / math.tan(math.radians(graze))   # the view meets the water `graze` from its normal
    lights = [point_light([rng.uniform(-6, 6), 8, rng.uniform(-10, 0)], 0.9)]
    return scene(rng, camera_looking(eye, target, rng.uniform(40, 55)), lights, mats, objs)


def t_light_on_mirror(rng):
    """A point light lying on (or 1e-6 above) a mirror table top, objects around it."""
    mats = {"floor": diffuse(rng), "table": mirror_material(rng)}
    objs = [floor(6, "floor")]
    top = rng.uniform(0.5, 0.9)
    objs.append(box([-0.8, 0, -0.5], [0.8, top, 0.5], "table"))
    objs += scatter_props(rng, mats, 4, 0.1, 0.3, ring=(1.2, 2.5))
    lift = rng.choice([0.0, 1e-6])
    lights = [point_light([rng.uniform(-0.5, 0.5), top + lift, rng.uniform(-0.3, 0.3)], rng.uniform(0.6, 1.0)),
              point_light([rng.uniform(-2, 2), 3.0, 2.5], 0.4)]
    eye = add([0, 0.4, 0], mul(spherical(rng.uniform(-40, 40), rng.uniform(20, 45)), rng.uniform(3, 4)))
    return scene(rng, camera_looking(eye, [0, 0.4, 0], rng.uniform(45, 60)), lights, mats, objs)


def t_light_on_open_mirror(rng):
    """A point light on (or 1e-6 above or below) an open mirror quad: its shadow volume's
    sides lie nearly in the quad's plane and reach infinity across the whole view."""
    mats = {"floor": diffuse(rng), "table": mirror_material(rng)}
    objs = [floor(6, "floor")]
    top = rng.uniform(0.5, 0.9)
    w, d = rng.uniform(0.5, 1.0), rng.uniform(0.3, 0.7)
    objs.append(quad([0, top, 0], [0, 0, d], [w, 0, 0], "table"))  # u x v = +y: faces up
    objs += scatter_props(rng, mats, 4, 0.1, 0.3, ring=(1.2, 2.5))
    lift = rng.choice([0.0, 1e-6, -1e-6])
    lights = [point_light([rng.uniform(-0.4, 0.4) * w, top + lift, rng.uniform(-0.4, 0.4) * d], rng.uniform(0.6, 1.0)),
              point_light([rng.uniform(-2, 2), 3.0, 2.5], 0.4)]
    eye = add([0, 0.4, 0], mul(spherical(rng.uniform(-40, 40), rng.uniform(20, 45)), rng.uniform(3, 4)))
    return scene(rng, camera_looking(eye, [0, 0.4, 0], rng.uniform(45, 60)), lights, mats, objs)


TEMPLATES = {
    "mirror_through_camera": t_mirror_through_camera,
    "floor_mirror_hidden": t_floor_mirror_hidden,
    "box_mirrors": t_box_mirrors,
    "grazing_water": t_grazing_water,
    "light_on_mirror": t_light_on_mirror,
    "light_on_open_mirror": t_light_on_open_mirror,
}


def make_scene(template, seed, k, width, height, cube_res, max_depth):
    rng = random.Random(seed * 7919 + k)
    s = TEMPLATES[template](rng)
    s["camera"]["width"], s["camera"]["height"] = width, height
    s["render"] = {"method": "abuffer", "cube_resolution": cube_res, "max_depth": max_depth}
    return "%s_%d_%d" % (template, seed, k), s


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seed", type=int, required=True)
    ap.add_argument("--count", type=int, required=True, help="scenes to write")
    ap.add_argument("--out", required=True, help="output folder (created)")
    ap.add_argument("--templates", default=",".join(TEMPLATES), help="comma-separated, cycled (default: all)")
    ap.add_argument("--size", default="160x120", help="image WxH (default %(default)s)")
    ap.add_argument("--cube-res", type=int, default=256, help="cube map N (default %(default)s)")
    ap.add_argument("--max-depth", type=int, default=4, help="bounces (default %(default)s)")
    a = ap.parse_args(argv)
    templates = [t for t in a.templates.split(",") if t]
    unknown = [t for t in templates if t not in TEMPLATES]
    if unknown or not templates:
        ap.error("unknown template(s) %s; known: %s" % (",".join(unknown), ",".join(TEMPLATES)))
    try:
        width, height = (int(x) for x in a.size.lower().split("x"))
    except ValueError:
        ap.error("--size must be WxH, got %r" % a.size)
    os.makedirs(a.out, exist_ok=True)
    for k in range(a.count):
        stem, s = make_scene(templates[k % len(templates)], a.seed, k, width, height, a.cube_res, a.max_depth)
        path = os.path.join(a.out, stem + ".json")
        with open(path, "w") as f:
            json.dump(s, f, indent=1)
            f.write("\n")
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
