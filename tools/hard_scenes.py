#!/usr/bin/python3
"""Seeded generator of hard-case scenes (issue 12, part 5).

Each scene comes from one template: a function that draws its parameters from
random.Random(seed + k) and returns a scene dict in the format of
docs/scene-format.md (version 1): a floor, a light or two and a few objects with
plausible materials, arranged around one case the map searches find hard (a decal just
above a floor, z-fighting quads, a plane containing the camera, a camera inside a room,
shallow intersections, features thinner than a texel, grazing mirrors, nested glass, a
light on a surface, km-wide terrain with mm detail, objects across the cube map's seams).

Deterministic: the same arguments give the same bytes (standard library only).

Usage: hard_scenes.py --seed S --count N --out DIR [--templates a,b,...] [--size WxH]
                      [--cube-res N] [--max-depth D]
Scene k (0 <= k < N) uses template templates[k % len(templates)] and is written as
DIR/TEMPLATE_SEED_K.json (with DIR/TEMPLATE_SEED_K.obj where it needs a mesh).
"""
import argparse
import json
import math
import os
import random
import sys

# --- small vector helpers ---------------------------------------------------------------


def add(a, b):
    return [a[i] + b[i] for i in range(3)]


def sub(a, b):
    return [a[i] - b[i] for i in range(3)]


def mul(a, s):
    return [a[i] * s for i in range(3)]


def dot(a, b):
    return sum(a[i] * b[i] for i in range(3))


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def normalize(a):
    length = math.sqrt(dot(a, a))
    return [c / length for c in a]


def rot_x(v, deg):
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return [v[0], c * v[1] - s * v[2], s * v[1] + c * v[2]]


def rot_y(v, deg):
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return [c * v[0] + s * v[2], v[1], -s * v[0] + c * v[2]]


def rot_z(v, deg):
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return [c * v[0] - s * v[1], s * v[0] + c * v[1], v[2]]


def spherical(azimuth_deg, elevation_deg):
    """Unit direction: azimuth about +y from +z towards +x, elevation above the xz plane."""
    a, e = math.radians(azimuth_deg), math.radians(elevation_deg)
    return [math.cos(e) * math.sin(a), math.sin(e), math.cos(e) * math.cos(a)]


def r6(v):
    """Rounded for readable JSON (1e-9 keeps mm detail at km scale exact enough)."""
    if isinstance(v, list):
        return [r6(x) for x in v]
    return round(v, 9)


# --- scene building blocks --------------------------------------------------------------


def colour(rng, lo=0.15, hi=0.95):
    return [round(rng.uniform(lo, hi), 3) for _ in range(3)]


def diffuse(rng, lo=0.15, **extra):
    m = {"color": colour(rng, lo)}
    m.update(extra)
    return m


def mirror_material(rng):
    return {"color": [0.1, 0.1, 0.1], "ambient": 0.1, "diffuse": 0.1, "specular": 0.4,
            "shininess": 64, "reflect": round(rng.uniform(0.7, 0.95), 3)}


def glass_material(ior=1.5, tint=(1, 1, 1)):
    return {"color": list(tint), "ambient": 0.0, "diffuse": 0.0, "specular": 0.3,
            "shininess": 96, "transmit": 0.9, "ior": ior}


def quad(center, u, v, material):
    """Quad with corners center -/+ u -/+ v (u, v half-edges), normal u x v."""
    c = center
    return {"type": "quad", "material": material, "vertices": r6([
        sub(sub(c, u), v), sub(add(c, u), v), add(add(c, u), v), add(sub(c, u), v)])}


def floor(half, material, y=0.0):
    # u = +z, v = +x half-edges: u x v = +y, the floor faces up
    return quad([0, y, 0], [0, 0, half], [half, 0, 0], material)


def box(lo, hi, material, transform=None):
    obj = {"type": "box", "min": r6(lo), "max": r6(hi), "material": material}
    if transform:
        obj["transform"] = transform
    return obj


def sphere(center, radius, material, segments=32):
    return {"type": "sphere", "center": r6(center), "radius": r6(radius),
            "segments": segments, "material": material}


def point_light(position, intensity=1.0, shadows=True, tint=None):
    c = tint if tint else [intensity] * 3
    return {"type": "point", "position": r6(position), "color": r6(c), "cast_shadows": shadows}


def camera_looking(position, look_at, fov_y, up=(0, 1, 0)):
    d = normalize(sub(look_at, position))
    up = list(up)
    if abs(dot(d, up)) > 0.999:   # never parallel to the view direction
        up = [0, 0, 1]
    return {"position": r6(position), "look_at": r6(look_at), "up": up, "fov_y": round(fov_y, 3)}


def scene(rng, camera, lights, materials, objects, background=None):
    return {
        "version": 1,
        "camera": camera,
        "background": background if background else colour(rng, 0.0, 0.25),
        "ambient": [0.1, 0.1, 0.1],
        "lights": lights,
        "materials": materials,
        "objects": objects,
    }


def scatter_props(rng, materials, count, radius_lo, radius_hi, ring=(1.5, 3.5), y0=0.0):
    """A few boxes and spheres standing on the floor around the origin."""
    objects = []
    for i in range(count):
        name = "prop%d" % i
        materials[name] = diffuse(rng, specular=round(rng.uniform(0, 0.4), 3))
        a = rng.uniform(0, 360)
        d = rng.uniform(*ring)
        p = [d * math.sin(math.radians(a)), y0, d * math.cos(math.radians(a))]
        r = rng.uniform(radius_lo, radius_hi)
        if rng.random() < 0.5:
            objects.append(sphere([p[0], y0 + r, p[2]], r, name, 24))
        else:
            objects.append(box([p[0] - r, y0, p[2] - r], [p[0] + r, y0 + 2 * r, p[2] + r], name))
    return objects


# --- templates --------------------------------------------------------------------------


def t_decal(rng, ctx):
    """A thin quad 1e-2..1e-4 of the floor's size above the floor; moderate or grazing view."""
    size = rng.uniform(4, 20)
    height = size * 10 ** rng.uniform(-4, -2)
    mats = {"floor": diffuse(rng), "decal": diffuse(rng)}
    dh = size * rng.uniform(0.04, 0.12)
    centre = [rng.uniform(-0.05, 0.05) * size, height, rng.uniform(-0.05, 0.05) * size]
    u = rot_y([dh, 0, 0], rng.uniform(0, 90))
    v = normalize(cross([0, 1, 0], u))   # in the floor's plane, perpendicular to u
    v = mul(v, dh * rng.uniform(0.5, 1.0))
    objs = [floor(size / 2, "floor"), quad(centre, v, u, "decal")]
    objs += scatter_props(rng, mats, 2, 0.1 * dh, 0.3 * dh, ring=(1.5 * dh, 3 * dh))
    elevation = rng.choice([rng.uniform(25, 60), rng.uniform(2, 8)])
    dist = dh * rng.uniform(4, 8)
    eye = add(centre, mul(spherical(rng.uniform(0, 360), elevation), dist))
    lights = [point_light(add(centre, [rng.uniform(-1, 1) * dh, 3 * dh, rng.uniform(-1, 1) * dh]), 0.9)]
    return scene(rng, camera_looking(eye, centre, rng.uniform(35, 60)), lights, mats, objs)


def t_coplanar(rng, ctx):
    """Two overlapping coplanar quads of different colours (z-fighting), on a floor or a wall."""
    mats = {"floor": diffuse(rng), "a": diffuse(rng), "b": diffuse(rng)}
    s = rng.uniform(0.4, 1.0)
    vertical = rng.random() < 0.5
    if vertical:   # a wall panel facing +z at z = -1
        base, u, v = [0, 1.2, -1.0], [s, 0, 0], [0, s, 0]
        shift = [rng.uniform(0.2, 0.6) * s, rng.uniform(-0.4, 0.4) * s, 0]
    else:          # a mat lying 2 cm above the floor
        base, u, v = [0, 0.02, 0], [0, 0, s], [s, 0, 0]
        shift = [rng.uniform(0.2, 0.6) * s, 0, rng.uniform(-0.4, 0.4) * s]
    objs = [floor(6, "floor"), quad(base, u, v, "a"), quad(add(base, shift), u, v, "b")]
    objs += scatter_props(rng, mats, 2, 0.15, 0.35, ring=(1.8, 3.0))
    look = add(base, mul(shift, 0.5))
    eye = add(look, mul(spherical(rng.uniform(-40, 40), rng.uniform(15, 60)), rng.uniform(2.5, 4)))
    lights = [point_light([rng.uniform(-2, 2), 4, rng.uniform(1, 3)], 0.9)]
    return scene(rng, camera_looking(eye, look, rng.uniform(40, 60)), lights, mats, objs)


def t_plane_through_camera(rng, ctx):
    """A wide plane at exactly the camera's height (its plane contains the camera), seen in
    a tilted mirror in front of the camera. The height is a multiple of 1/64, exact in float
    and double alike: the camera lies on the plane exactly, not a rounding away from it."""
    h = round(rng.uniform(0.8, 1.6) * 64) / 64
    mats = {"floor": diffuse(rng), "shelf": diffuse(rng, specular=0.2), "mirror": mirror_material(rng)}
    side = rng.choice([-1, 1])
    # the shelf: y = h exactly, beside the camera (x from 0.6 to 4.6 on one side), long in z
    x0, x1 = 0.6, rng.uniform(3, 5)
    shelf_c = [side * (x0 + x1) / 2, h, rng.uniform(-1, 1)]
    shelf = quad(shelf_c, [0, 0, rng.uniform(3, 6)], [(x1 - x0) / 2, 0, 0], "shelf")   # faces up
    eye = [0, h, 4.0]
    # a mirror 3-4 m ahead, turned towards the shelf and tilted about x
    mc = [side * 0.3, h + rng.uniform(-0.3, 0.3), rng.uniform(0.0, 1.0)]
    tilt, turn = rng.uniform(8, 30) * rng.choice([-1, 1]), -side * rng.uniform(10, 30)
    mu = rot_y(rot_x([1.2, 0, 0], tilt), turn)
    mv = rot_y(rot_x([0, 0.9, 0], tilt), turn)
    objs = [floor(10, "floor"), shelf, quad(mc, mu, mv, "mirror")]
    objs += scatter_props(rng, mats, 3, 0.15, 0.35, ring=(1.5, 3.5))
    lights = [point_light([rng.uniform(-2, 2), h + rng.uniform(1.5, 3), rng.uniform(2, 5)], 0.9)]
    return scene(rng, camera_looking(eye, mc, rng.uniform(45, 65)), lights, mats, objs)


def t_camera_inside(rng, ctx):
    """The camera inside a closed box or sphere (a room), objects inside, light inside."""
    mats = {"room": diffuse(rng), "mirror": mirror_material(rng)}
    half = [rng.uniform(2, 4), rng.uniform(1.2, 2), rng.uniform(2, 4)]
    if rng.random() < 0.5:
        room = box([-half[0], 0, -half[2]], [half[0], 2 * half[1], half[2]], "room")
    else:
        r = min(half)
        room = sphere([0, r * 0.6, 0], r * 1.2, "room", rng.choice([24, 32, 48]))
    objs = [room]
    objs += scatter_props(rng, mats, 3, 0.15, 0.4, ring=(0.6, 1.4), y0=0.0 if room["type"] == "box" else 0.2)
    if rng.random() < 0.6:   # a mirror ball in the room
        objs.append(sphere([rng.uniform(-0.5, 0.5), 0.8, rng.uniform(-1.2, -0.6)], 0.3, "mirror", 32))
    eye = [rng.uniform(-0.5, 0.5), rng.uniform(0.9, 1.4), rng.uniform(1.0, 1.6)]
    look = [rng.uniform(-0.5, 0.5), 0.6, -1.0]
    lights = [point_light([rng.uniform(-0.8, 0.8), 1.8, rng.uniform(-0.5, 0.5)], 0.8)]
    return scene(rng, camera_looking(eye, look, rng.uniform(50, 75)), lights, mats, objs)


def box_obj(lo, hi, deg_z, deg_y, pivot):
    """OBJ text of a box rotated about z then y around pivot (outward quads)."""
    corners = [[lo[0] if i & 1 == 0 else hi[0], lo[1] if i & 2 == 0 else hi[1],
                lo[2] if i & 4 == 0 else hi[2]] for i in range(8)]
    lines = ["# box rotated %.4f deg about z, %.4f deg about y (tools/hard_scenes.py)" % (deg_z, deg_y)]
    for c in corners:
        p = add(rot_y(rot_z(sub(c, pivot), deg_z), deg_y), pivot)
        lines.append("v %.9f %.9f %.9f" % tuple(p))
    # faces by corner index (1-based), counter-clockwise seen from outside
    for f in [(1, 3, 4, 2), (5, 6, 8, 7), (1, 2, 6, 5), (3, 7, 8, 4), (1, 5, 7, 3), (2, 4, 8, 6)]:
        lines.append("f %d %d %d %d" % f)
    return "\n".join(lines) + "\n"


def t_shallow_boxes(rng, ctx):
    """Two boxes intersecting at a shallow angle (1..5 degrees)."""
    mats = {"floor": diffuse(rng), "a": diffuse(rng, specular=0.2), "b": diffuse(rng, specular=0.2)}
    angle = rng.uniform(1, 5) * rng.choice([-1, 1])
    turn = rng.uniform(-30, 30)
    lo, hi = [-0.8, 0, -0.5], [0.8, 0.6, 0.5]
    objs = [floor(6, "floor"), box(lo, hi, "a")]
    lo2, hi2 = [-0.7, 0.3, -0.45], [0.9, 0.9, 0.55]
    if rng.random() < 0.5:
        pivot = [0, 0.6, 0]
        ctx["obj"] = box_obj(lo2, hi2, angle, turn, pivot)
        objs.append({"type": "mesh", "file": ctx["obj_name"], "material": "b"})
    else:
        centre = mul(add(lo2, hi2), 0.5)
        half = mul(sub(hi2, lo2), 0.5)
        objs.append(box(mul(half, -1), half, "b",
                        {"translate": r6(centre), "rotate_deg": r6([0, turn, angle])}))
    objs += scatter_props(rng, mats, 2, 0.15, 0.3, ring=(2.0, 3.0))
    look = [0, 0.55, 0]
    eye = add(look, mul(spherical(rng.uniform(-60, 60), rng.uniform(5, 40)), rng.uniform(2.5, 3.5)))
    lights = [point_light([rng.uniform(-2, 2), 3.5, rng.uniform(1, 3)], 0.9)]
    return scene(rng, camera_looking(eye, look, rng.uniform(40, 55)), lights, mats, objs)


def t_thin_features(rng, ctx):
    """Poles and wires 1 mm thick at a few metres (thinner than a cube texel), lit, seen
    directly and in a mirror."""
    mats = {"floor": diffuse(rng), "pole": diffuse(rng, lo=0.6), "wire": diffuse(rng, lo=0.6),
            "mirror": mirror_material(rng)}
    t = 0.0005 * rng.uniform(1, 2)   # half thickness: 1..2 mm poles
    objs = [floor(8, "floor")]
    for i in range(rng.randint(2, 4)):
        x, z = rng.uniform(-2, 2), rng.uniform(-2.5, 0.5)
        objs.append(box([x - t, 0, z - t], [x + t, rng.uniform(1.5, 2.5), z + t], "pole"))
    y = rng.uniform(1.0, 1.6)
    objs.append(box([-3, y - t, -1 - t], [3, y + t, -1 + t], "wire"))   # a wire along x
    # a mirror behind the poles, facing the camera, slightly turned
    turn = rng.uniform(-25, 25)
    objs.append(quad([0, 1.2, -3.5], rot_y([2.0, 0, 0], turn), [0, 1.1, 0], "mirror"))
    eye = [rng.uniform(-1, 1), rng.uniform(1.0, 1.8), rng.uniform(2.5, 4.5)]
    lights = [point_light([rng.uniform(-2, 2), 3.5, rng.uniform(0, 3)], 0.9)]
    return scene(rng, camera_looking(eye, [0, 1.0, -1.5], rng.uniform(45, 60)), lights, mats, objs)


def t_grazing_mirror(rng, ctx):
    """A mirror seen 80..89 degrees from its normal, reflecting coloured objects."""
    mats = {"floor": diffuse(rng), "mirror": mirror_material(rng)}
    objs = [floor(8, "floor")]
    # a mirror wall in the plane x = 0, facing +x, 6 m long
    objs.append(quad([0, 1.0, 0], [0, 0, -3.0], [0, 1.0, 0], "mirror"))
    graze = rng.uniform(80, 89)                 # angle between the view and the normal
    d = rng.uniform(2.5, 4.5)
    target = [0, rng.uniform(0.6, 1.4), rng.uniform(-1, 1)]
    # view direction from the eye to the target makes `graze` with the normal (+x)
    direction = [-math.cos(math.radians(graze)), 0, -math.sin(math.radians(graze))]
    direction = normalize(rot_z(direction, rng.uniform(-5, 5)))
    eye = sub(target, mul(direction, d))
    for i in range(rng.randint(3, 5)):
        name = "obj%d" % i
        mats[name] = diffuse(rng, specular=0.3)
        p = [rng.uniform(0.4, 2.0), 0, rng.uniform(-3.5, 1.5)]
        r = rng.uniform(0.15, 0.4)
        if rng.random() < 0.5:
            objs.append(sphere([p[0], r, p[2]], r, name, 24))
        else:
            objs.append(box([p[0] - r, 0, p[2] - r], [p[0] + r, 2 * r, p[2] + r], name))
    lights = [point_light([2.5, 3.5, rng.uniform(-1, 2)], 0.9)]
    return scene(rng, camera_looking(eye, target, rng.uniform(40, 55)), lights, mats, objs)


def t_nested_glass(rng, ctx):
    """A water sphere (ior 1.33) inside a glass sphere (ior 1.5), touching glass boxes
    sharing a face, over a striped floor."""
    ctx["min_depth"] = 6   # in glass, in water, out of water, out of glass, and a reflection
    mats = {"stripe_a": diffuse(rng), "stripe_b": diffuse(rng),
            "glass": glass_material(1.5), "water": glass_material(1.33, (0.8, 0.9, 1.0))}
    objs = []
    width = 0.5
    for i in range(-6, 6):   # stripes along z, each a quad
        x = (i + 0.5) * width
        objs.append(quad([x, 0, 0], [0, 0, 4], [width / 2, 0, 0], "stripe_a" if i % 2 else "stripe_b"))
    r = rng.uniform(0.5, 0.8)
    c = [rng.uniform(-1.2, -0.4), r + 0.05, rng.uniform(-0.5, 0.5)]
    objs.append(sphere(c, r, "glass", 48))
    objs.append(sphere(add(c, [rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1), 0]), r * rng.uniform(0.4, 0.7), "water", 40))
    s = rng.uniform(0.25, 0.4)
    bx = rng.uniform(0.4, 0.9)
    objs.append(box([bx, 0, -s], [bx + 2 * s, 2 * s, s], "glass"))
    objs.append(box([bx + 2 * s, 0, -s], [bx + 4 * s, 2 * s * rng.uniform(0.7, 1.3), s], "glass"))
    eye = add([0, 0.5, 0], mul(spherical(rng.uniform(-30, 30), rng.uniform(15, 40)), rng.uniform(3.5, 4.5)))
    lights = [point_light([rng.uniform(-2, 2), 4, rng.uniform(1, 3)], 0.9),
              point_light([rng.uniform(-3, 3), 3, -3], 0.3, shadows=False)]
    return scene(rng, camera_looking(eye, [0, 0.5, 0], rng.uniform(45, 60)), lights, mats, objs)


def t_light_on_surface(rng, ctx):
    """A point light lying on (or 1e-6 above) a surface: the floor or a box's top."""
    mats = {"floor": diffuse(rng), "table": diffuse(rng)}
    objs = [floor(6, "floor")]
    top = rng.uniform(0.5, 0.9)
    objs.append(box([-0.6, 0, -0.4], [0.6, top, 0.4], "table"))
    objs += scatter_props(rng, mats, 3, 0.1, 0.3, ring=(1.2, 2.5))
    lift = rng.choice([0.0, 1e-6])
    if rng.random() < 0.5:
        on = [rng.uniform(-0.4, 0.4), top + lift, rng.uniform(-0.3, 0.3)]
    else:
        on = [rng.uniform(-1.5, 1.5), lift, rng.uniform(0.6, 1.5)]
    lights = [point_light(on, rng.uniform(0.6, 1.0)),
              point_light([rng.uniform(-2, 2), 3.0, 2.5], 0.4)]
    eye = add([0, 0.4, 0], mul(spherical(rng.uniform(-40, 40), rng.uniform(20, 45)), rng.uniform(3, 4)))
    return scene(rng, camera_looking(eye, [0, 0.4, 0], rng.uniform(45, 60)), lights, mats, objs)


def t_km_scale(rng, ctx):
    """A km-wide terrain quad with mm-scale detail near the camera."""
    mats = {"terrain": diffuse(rng), "pebble": diffuse(rng), "mirror": mirror_material(rng)}
    half = rng.uniform(500, 2000)
    objs = [floor(half, "terrain")]
    eye_h = rng.uniform(0.02, 0.1)
    eye = [0, eye_h, 0]
    # pebbles 1..5 mm ahead of the camera, within a few cm to a metre
    for i in range(rng.randint(4, 8)):
        s = rng.uniform(0.0005, 0.0025)
        d = rng.uniform(0.03, 0.6)
        a = rng.uniform(-25, 25)
        p = [d * math.sin(math.radians(a)), 0, -d * math.cos(math.radians(a))]
        if i % 2:
            objs.append(sphere([p[0], s, p[2]], s, "pebble", 16))
        else:
            objs.append(box([p[0] - s, 0, p[2] - s], [p[0] + s, 2 * s, p[2] + s], "pebble"))
    # a far hill and a mirror ball a few hundred metres out
    objs.append(sphere([rng.uniform(-200, 200), 0, -rng.uniform(300, 900)], rng.uniform(40, 120), "pebble", 32))
    objs.append(sphere([rng.uniform(-0.05, 0.05), 0.01, -rng.uniform(0.15, 0.3)], 0.01, "mirror", 32))
    look = [0, 0, -rng.uniform(0.2, 1.0)]
    lights = [point_light([rng.uniform(-300, 300), 800, rng.uniform(-300, 300)], 1.0)]
    return scene(rng, camera_looking(eye, look, rng.uniform(40, 60)), lights, mats, objs)


SEAM_DIRECTIONS = [
    [1, 1, 1], [-1, 1, 1], [1, -1, -1], [-1, 1, -1],   # cube corners
    [1, 0, 1], [-1, 0, 1], [1, 0, -1], [0, 1, 1],      # face edges
    [1, 1, 0], [-1, -1, 0], [0, -1, 1], [-1, 0, -1],
]


def t_seams(rng, ctx):
    """Objects across the cube map's face seams and corners around the camera (directions
    near (1,1,1)/sqrt(3), (1,0,1)/sqrt(2), ...), mirrors and glass among them."""
    eye = [0, 1.5, 0]
    mats = {"floor": diffuse(rng), "mirror": mirror_material(rng), "glass": glass_material(1.5)}
    objs = [floor(10, "floor", y=-0.5)]
    dirs = rng.sample(SEAM_DIRECTIONS, 6)
    view = None
    for i, d in enumerate(dirs):
        d = normalize([c + rng.uniform(-0.01, 0.01) for c in d])
        if d[1] < -0.3:   # below the camera: keep it above the floor
            d = normalize([d[0], -0.3, d[2]])
        dist = rng.uniform(1.5, 3.0)
        p = add(eye, mul(d, dist))
        kind = ["mirror", "glass", None][i % 3]
        name = kind if kind else "seam%d" % i
        if not kind:
            mats[name] = diffuse(rng, specular=0.3)
        r = rng.uniform(0.25, 0.5)
        if kind == "mirror" and rng.random() < 0.5:   # a mirror panel facing the camera
            n = mul(d, -1)
            u = normalize(cross(n, [0, 1, 0] if abs(n[1]) < 0.9 else [1, 0, 0]))
            v = cross(u, n)
            objs.append(quad(p, mul(u, r * 1.5), mul(v, r * 1.5), name))
        elif i % 2:
            objs.append(box(sub(p, [r, r, r]), add(p, [r, r, r]), name))
        else:
            objs.append(sphere(p, r, name, 32))
        if view is None and kind == "mirror":
            view = p
    lights = [point_light([rng.uniform(-2, 2), 4, rng.uniform(-2, 2)], 0.9),
              point_light([rng.uniform(-3, 3), 2.5, rng.uniform(-3, 3)], 0.3, shadows=False)]
    return scene(rng, camera_looking(eye, view, rng.uniform(60, 90)), lights, mats, objs)


# --- third-party models ---------------------------------------------------------------
#
# The models_in_rooms template places files of Debian's assimp-testmodels (installed by
# `tools/setup.sh --test`): textured glTF (as .gltf and as .glb) and OBJ (one with an MTL
# and a JPEG texture, one without). Their bounds are read from the files themselves.
MODEL_CORPUS = "/usr/share/assimp/models"
MAX_GL_TEXTURE_SIZES = 4   # host/gl/gl_passes.hpp MAX_TEXTURE_ARRAYS
MODELS = (
    "glTF2/BoxTextured-glTF/BoxTextured.gltf",
    "glTF2/BoxTextured-glTF-Binary/BoxTextured.glb",
    "OBJ/WusonOBJ.obj",
    "OBJ/spider.obj",
)


def mat4_mul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(4)) for j in range(4)] for i in range(4)]


def node_matrix(node):
    """A glTF node's local matrix (its `matrix`, column-major, or T * R * S)."""
    if "matrix" in node:
        m = node["matrix"]
        return [[m[c * 4 + r] for c in range(4)] for r in range(4)]
    tx, ty, tz = node.get("translation", [0, 0, 0])
    qx, qy, qz, qw = node.get("rotation", [0, 0, 0, 1])
    sx, sy, sz = node.get("scale", [1, 1, 1])
    rot = [[1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)],
           [2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)],
           [2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)]]
    scale = (sx, sy, sz)
    out = [[rot[r][c] * scale[c] for c in range(3)] + [(tx, ty, tz)[r]] for r in range(3)]
    return out + [[0, 0, 0, 1]]


def model_bounds(path):
    """The axis-aligned bounds [lo, hi] of a model file's points: an OBJ's `v` lines, or a
    glTF's POSITION accessors' min and max through its scene's node matrices."""
    lo, hi = [math.inf] * 3, [-math.inf] * 3

    def grow(p):
        for i in range(3):
            lo[i], hi[i] = min(lo[i], p[i]), max(hi[i], p[i])

    if path.endswith(".obj"):
        with open(path, errors="replace") as f:
            for line in f:
                if line.startswith("v "):
                    grow([float(x) for x in line.split()[1:4]])
        return lo, hi
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] == b"glTF":   # the JSON chunk of a .glb
        length = int.from_bytes(data[12:16], "little")
        data = data[20:20 + length]
    doc = json.loads(data)
    identity = [[float(r == c) for c in range(4)] for r in range(4)]

    def visit(index, parent):
        node = doc["nodes"][index]
        world = mat4_mul(parent, node_matrix(node))
        if "mesh" in node:
            for prim in doc["meshes"][node["mesh"]]["primitives"]:
                acc = doc["accessors"][prim["attributes"]["POSITION"]]
                a, b = acc["min"], acc["max"]
                for corner in ([x, y, z] for x in (a[0], b[0]) for y in (a[1], b[1]) for z in (a[2], b[2])):
                    grow([sum(world[r][c] * corner[c] for c in range(3)) + world[r][3] for r in range(3)])
        for child in node.get("children", []):
            visit(child, world)

    for root in doc["scenes"][doc.get("scene", 0)]["nodes"]:
        visit(root, identity)
    return lo, hi


def image_size(data):
    """(width, height) of a PNG or JPEG image's bytes, from its header (IHDR; a JPEG's SOF
    marker)."""
    if data[:8] == b"\x89PNG\r\n\x1a\n":
        return int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big")
    at = 2
    while at + 9 < len(data):
        marker, length = data[at + 1], int.from_bytes(data[at + 2:at + 4], "big")
        if 0xC0 <= marker <= 0xCF and marker not in (0xC4, 0xC8, 0xCC):   # a start of frame
            return int.from_bytes(data[at + 7:at + 9], "big"), int.from_bytes(data[at + 5:at + 7], "big")
        at += 2 + length
    raise ValueError("no PNG or JPEG size found")


def model_texture_sizes(path):
    """The sizes of the base-colour images a model file names: an OBJ's MTL map_Kd lines, a
    glTF's images (files, or a .glb's buffer views)."""
    folder = os.path.dirname(path)

    def file_size(name):
        with open(os.path.join(folder, name.replace("\\", "/").lstrip("./")), "rb") as f:
            return image_size(f.read())

    if path.endswith(".obj"):
        names = []
        with open(path, errors="replace") as f:
            libs = [line.split(None, 1)[1].strip() for line in f if line.startswith("mtllib ")]
        for lib in libs:
            with open(os.path.join(folder, lib), errors="replace") as f:
                names += [line.split(None, 1)[1].strip() for line in f if line.strip().startswith("map_Kd ")]
        return {file_size(n) for n in names}
    with open(path, "rb") as f:
        data = f.read()
    binary = b""
    if data[:4] == b"glTF":   # the JSON chunk, then the BIN chunk
        length = int.from_bytes(data[12:16], "little")
        binary = data[20 + length + 8:]
        data = data[20:20 + length]
    doc = json.loads(data)
    sizes = set()
    for image in doc.get("images", []):
        if "uri" in image:
            sizes.add(file_size(image["uri"]))
        elif "bufferView" in image:
            view = doc["bufferViews"][image["bufferView"]]
            start = view.get("byteOffset", 0)
            sizes.add(image_size(binary[start:start + view["byteLength"]]))
    return sizes


def t_models_in_rooms(rng, ctx):
    """One or two third-party models (MODELS), each scaled to 0.5..1.3 m and standing on the
    floor of a room (floor, back and side walls) beside boxes, spheres, a chrome sphere and a
    glass one, under two shadow-casting lights: the models' edges, thin parts and textures,
    directly, in the chrome and through the glass."""
    mats = {"floor": diffuse(rng), "wall": diffuse(rng), "chrome": mirror_material(rng),
            "glass": glass_material()}
    objs = [floor(8, "floor"),
            quad([0, 2.0, -4.0], [4.0, 0, 0], [0, 2.0, 0], "wall"),
            quad([-4.0, 2.0, 0], [0, 0, -4.0], [0, 2.0, 0], "wall")]
    # Two models where their textures come in at most MAX_GL_TEXTURE_SIZES sizes (the GL
    # passes' limit, docs/models-and-textures.md), else one: every method renders the scene.
    chosen = rng.sample(MODELS, rng.randint(1, 2))
    if len(chosen) == 2:
        sizes = set()
        for name in chosen:
            sizes |= model_texture_sizes(os.path.join(MODEL_CORPUS, name))
        if len(sizes) > MAX_GL_TEXTURE_SIZES:
            chosen = chosen[:1]
    for i, name in enumerate(chosen):
        path = os.path.join(MODEL_CORPUS, name)
        if not os.path.exists(path):
            raise SystemExit("hard_scenes.py: models_in_rooms needs %s: install assimp-testmodels "
                             "(bash tools/setup.sh --test) or leave the template out (--templates)" % path)
        lo, hi = model_bounds(path)
        size = max(hi[i2] - lo[i2] for i2 in range(3))
        s = rng.uniform(0.5, 1.3) / size
        centre = [(lo[0] + hi[0]) / 2, lo[1], (lo[2] + hi[2]) / 2]   # the base's middle
        x = -0.7 + 1.4 * i + rng.uniform(-0.3, 0.3)
        z = rng.uniform(-1.2, 0.2)
        kind = "gltf" if name.endswith((".gltf", ".glb")) else "mesh"
        objs.append({"type": kind, "file": path,
                     "transform": {"scale": round(s, 9), "translate": r6([x - s * centre[0], -s * centre[1],
                                                                         z - s * centre[2]])}})
        if kind == "mesh" and name.endswith("WusonOBJ.obj"):
            mats["wuson"] = diffuse(rng, lo=0.4, specular=0.3)
            objs[-1]["material"] = "wuson"
    objs += scatter_props(rng, mats, rng.randint(1, 3), 0.12, 0.3, ring=(1.6, 3.0))
    r = rng.uniform(0.25, 0.4)
    objs.append(sphere([rng.uniform(1.2, 2.0), r, rng.uniform(-2.0, -0.5)], r, "chrome", 32))
    r = rng.uniform(0.2, 0.35)
    objs.append(sphere([rng.uniform(-1.6, -0.8), r, rng.uniform(0.6, 1.4)], r, "glass", 32))
    lights = [point_light([rng.uniform(-2, 2), rng.uniform(3, 4), rng.uniform(0, 2.5)], 0.8),
              point_light([rng.uniform(-3, 3), rng.uniform(2, 3), rng.uniform(1, 3)], 0.4)]
    eye = [rng.uniform(-1.5, 1.5), rng.uniform(1.0, 2.2), rng.uniform(2.8, 4.2)]
    ctx["min_depth"] = 2
    return scene(rng, camera_looking(eye, [0, 0.5, -0.6], rng.uniform(45, 60)), lights, mats, objs)


TEMPLATES = {
    "decal": t_decal,
    "coplanar": t_coplanar,
    "plane_through_camera": t_plane_through_camera,
    "camera_inside": t_camera_inside,
    "shallow_boxes": t_shallow_boxes,
    "thin_features": t_thin_features,
    "grazing_mirror": t_grazing_mirror,
    "nested_glass": t_nested_glass,
    "light_on_surface": t_light_on_surface,
    "km_scale": t_km_scale,
    "seams": t_seams,
    "models_in_rooms": t_models_in_rooms,
}


def make_scene(template, seed, k, width, height, cube_res, max_depth):
    """Scene k of this seed from one template; returns (scene dict, OBJ text or None)."""
    rng = random.Random(seed + k)
    stem = "%s_%d_%d" % (template, seed, k)
    ctx = {"obj_name": stem + ".obj", "obj": None}
    s = TEMPLATES[template](rng, ctx)
    s["camera"]["width"], s["camera"]["height"] = width, height
    depth = max(max_depth, ctx.get("min_depth", 0))   # a template may need more bounces
    s["render"] = {"method": "abuffer", "cube_resolution": cube_res, "max_depth": depth}
    return stem, s, ctx["obj"]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seed", type=int, required=True)
    ap.add_argument("--count", type=int, required=True, help="scenes to write")
    ap.add_argument("--out", required=True, help="output folder (created)")
    ap.add_argument("--templates", default=",".join(TEMPLATES),
                    help="comma-separated templates, cycled (default: all: %(default)s)")
    ap.add_argument("--size", default="64x48", help="image WxH (default %(default)s)")
    ap.add_argument("--cube-res", type=int, default=128, help="cube map N (default %(default)s)")
    ap.add_argument("--max-depth", type=int, default=3, help="bounces (default %(default)s)")
    args = ap.parse_args(argv)
    templates = [t for t in args.templates.split(",") if t]
    unknown = [t for t in templates if t not in TEMPLATES]
    if unknown or not templates:
        ap.error("unknown template(s) %s; known: %s" % (",".join(unknown), ",".join(TEMPLATES)))
    try:
        width, height = (int(x) for x in args.size.lower().split("x"))
    except ValueError:
        ap.error("--size must be WxH, got %r" % args.size)
    os.makedirs(args.out, exist_ok=True)
    for k in range(args.count):
        template = templates[k % len(templates)]
        stem, s, obj = make_scene(template, args.seed, k, width, height, args.cube_res, args.max_depth)
        if obj is not None:
            with open(os.path.join(args.out, stem + ".obj"), "w") as f:
                f.write(obj)
        with open(os.path.join(args.out, stem + ".json"), "w") as f:
            json.dump(s, f, indent=1)
            f.write("\n")
        print(os.path.join(args.out, stem + ".json"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
