"""Where the thesis bound 1/(2N^2) breaks: a geometric model of the thesis mode's ideal candidate.

abcube's --stats give no per-hit geometry, so this re-traces the scene (pure Python; scenes made
of triangles, quads, boxes and untransformed spheres, spheres analytic; no meshes). For every
GEOMETRY_STEP-th pixel centre along x and y whose camera ray meets a reflecting surface at W
with reflected direction R and exact reflected point S (thesis 9.3.4, search.hpp MODE thesis):
the cube texel holding S - C at resolution N, its centre direction V, the point P where C + a V
meets S's plane (the Z-buffer's alpha), theta_c = angle(V, S - C) <= atan(sqrt(2)/N) and
theta_0 = angle(R, P - W). The thesis takes theta_0 as theta_c; the ideal candidate's
Error_Parallax is (1 - cos theta_0)/2, and it is rejected when theta_0 > theta_max. The
search may find a better texel than this one, so the model predicts aggregate shares, not
single hits. Used by sweep.py; standalone: python3 bench/bound_geometry.py SCENE.json N...
"""
import json
import math
import statistics

THETA_MAX_DEG = 2.0  # abcube's default --theta-max

GEOMETRY_STEP = 2


def _v_sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _v_add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def _v_mul(a, s):
    return (a[0] * s, a[1] * s, a[2] * s)


def _v_dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _v_cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _v_len(a):
    return math.sqrt(_v_dot(a, a))


def _v_norm(a):
    return _v_mul(a, 1.0 / _v_len(a))


def _v_angle(a, b):
    return math.atan2(_v_len(_v_cross(a, b)), _v_dot(a, b))


def _affine(t):
    """scale, then rotate_deg x, y, z (right-handed), then translate (tessellate.cpp make_affine_map)."""
    sc = t.get("scale", 1)
    sc = tuple(sc) if isinstance(sc, list) else (sc, sc, sc)
    rx, ry, rz = [math.radians(v) for v in t.get("rotate_deg", [0, 0, 0])]
    tr = tuple(t.get("translate", [0, 0, 0]))

    def apply(p):
        x, y, z = p[0] * sc[0], p[1] * sc[1], p[2] * sc[2]
        c, s = math.cos(rx), math.sin(rx)
        y, z = c * y - s * z, s * y + c * z
        c, s = math.cos(ry), math.sin(ry)
        x, z = c * x + s * z, -s * x + c * z
        c, s = math.cos(rz), math.sin(rz)
        x, y = c * x - s * y, s * x + c * y
        return (x + tr[0], y + tr[1], z + tr[2])
    return apply


def _primitives(scene):
    """(kind, geometry, reflects) of every object, or None if the scene holds one we do not model."""
    materials = scene.get("materials", {})
    prims = []
    for o in scene.get("objects", []):
        reflects = materials.get(o.get("material"), {}).get("reflect", 0.0) > 0
        f = _affine(o.get("transform", {}))
        kind = o.get("type")
        if kind == "triangle":
            prims.append(("tri", [f(tuple(p)) for p in o["vertices"]], reflects))
        elif kind == "quad":
            v = [f(tuple(p)) for p in o["vertices"]]
            prims += [("tri", [v[0], v[1], v[2]], reflects), ("tri", [v[0], v[2], v[3]], reflects)]
        elif kind == "box":
            a, b = o["min"], o["max"]
            c = [f((b[0] if i & 1 else a[0], b[1] if i & 2 else a[1], b[2] if i & 4 else a[2])) for i in range(8)]
            for q in ((0, 1, 3, 2), (4, 5, 7, 6), (0, 1, 5, 4), (2, 3, 7, 6), (0, 2, 6, 4), (1, 3, 7, 5)):
                prims += [("tri", [c[q[0]], c[q[1]], c[q[2]]], reflects), ("tri", [c[q[0]], c[q[2]], c[q[3]]], reflects)]
        elif kind == "sphere" and "transform" not in o:
            prims.append(("sphere", (tuple(o["center"]), float(o["radius"])), reflects))
        else:
            return None
    return prims


def _nearest(prims, o, d, tmin):
    """(t, unit normal, reflects) of the nearest hit beyond tmin, or None (Moller-Trumbore; analytic sphere)."""
    best = None
    for kind, g, reflects in prims:
        if kind == "tri":
            a, b, c = g
            e1, e2 = _v_sub(b, a), _v_sub(c, a)
            p = _v_cross(d, e2)
            det = _v_dot(e1, p)
            if abs(det) < 1e-14:
                continue
            s = _v_sub(o, a)
            u = _v_dot(s, p) / det
            if u < 0 or u > 1:
                continue
            q = _v_cross(s, e1)
            v = _v_dot(d, q) / det
            if v < 0 or u + v > 1:
                continue
            t = _v_dot(e2, q) / det
            if t > tmin and (best is None or t < best[0]):
                best = (t, _v_norm(_v_cross(e1, e2)), reflects)
        else:
            centre, r = g
            oc = _v_sub(o, centre)
            b = _v_dot(oc, d)
            disc = b * b - (_v_dot(oc, oc) - r * r)
            if disc < 0:
                continue
            for t in (-b - math.sqrt(disc), -b + math.sqrt(disc)):
                if t > tmin:
                    if best is None or t < best[0]:
                        best = (t, _v_norm(_v_sub(_v_add(o, _v_mul(d, t)), centre)), reflects)
                    break
    return best


def _texel_centre(d, n):
    """Direction of the centre of the cube texel holding direction d (any face orientation: the
    texel centres are the same grid whatever the (s, t) signs)."""
    k = max(range(3), key=lambda i: abs(d[i]))
    out = [0.0, 0.0, 0.0]
    out[k] = math.copysign(1.0, d[k])
    for axis in range(3):
        if axis != k:
            i = min(n - 1, max(0, int(math.floor((d[axis] / abs(d[k]) + 1) / 2 * n))))
            out[axis] = (i + 0.5) * 2 / n - 1
    return tuple(out)


def bound_geometry(scene_path, sizes, theta_max=math.radians(THETA_MAX_DEG)):
    """Per N: the model's shares (see above), or None if the scene holds meshes."""
    with open(scene_path) as f:
        scene = json.load(f)
    prims = _primitives(scene)
    if prims is None:
        return None
    cam = scene["camera"]
    c = tuple(cam["position"])
    w, h = cam.get("width", 512), cam.get("height", 512)
    fwd = _v_norm(_v_sub(tuple(cam["look_at"]), c))
    right = _v_norm(_v_cross(fwd, tuple(cam.get("up", [0, 1, 0]))))
    up = _v_cross(right, fwd)
    tan_half = math.tan(math.radians(cam.get("fov_y", 60)) / 2)
    rays = []  # (W, R, S, plane normal at S)
    for y in range(GEOMETRY_STEP // 2, h, GEOMETRY_STEP):
        for x in range(GEOMETRY_STEP // 2, w, GEOMETRY_STEP):
            sx, sy = (2 * (x + 0.5) / w - 1) * tan_half * w / h, (1 - 2 * (y + 0.5) / h) * tan_half
            d = _v_norm(_v_add(fwd, _v_add(_v_mul(right, sx), _v_mul(up, sy))))
            first = _nearest(prims, c, d, 1e-7)
            if not first or not first[2]:
                continue
            wpt, n = _v_add(c, _v_mul(d, first[0])), first[1]
            r = _v_sub(d, _v_mul(n, 2 * _v_dot(d, n)))
            second = _nearest(prims, wpt, r, 1e-9)
            if second:
                rays.append((wpt, r, _v_add(wpt, _v_mul(r, second[0])), second[1]))
    out = {}
    for n in sizes:
        bound = 1.0 / (2.0 * n * n)
        within, broken, rejected = [], [], 0
        for wpt, r, s, ns in rays:
            sc = _v_sub(s, c)
            v = _v_norm(_texel_centre(sc, n))
            theta_c = _v_angle(v, sc)
            p = _v_add(c, _v_mul(v, _v_dot(ns, sc) / _v_dot(ns, v)))
            theta_0 = _v_angle(r, _v_sub(p, wpt))
            if theta_0 > theta_max:
                rejected += 1
                continue
            distance_ratio = _v_len(sc) / _v_len(_v_sub(s, wpt))
            item = (distance_ratio, theta_0 / theta_c if theta_c > 0 else 1.0)
            if (1 - math.cos(theta_0)) / 2 > bound:
                broken.append(item)
            else:
                within.append(item)
        med = lambda xs: statistics.median(xs) if xs else None
        share = lambda xs, pred: sum(1 for x in xs if pred(x)) / len(xs) if xs else None
        accepted = len(within) + len(broken)
        out[n] = {"rays": len(rays), "rejected": rejected / len(rays) if rays else None,
                  "within": len(within) / accepted if accepted else None,
                  "ratio_broken": med([x[0] for x in broken]), "ratio_within": med([x[0] for x in within]),
                  "ratio_gt1_broken": share(broken, lambda x: x[0] > 1),
                  "ratio_gt1_within": share(within, lambda x: x[0] > 1),
                  "amp_broken": med([x[1] for x in broken]), "amp_within": med([x[1] for x in within]),
                  "amp_le1_broken": share(broken, lambda x: x[1] <= 1)}
    return out


if __name__ == "__main__":
    import sys
    result = bound_geometry(sys.argv[1], [int(n) for n in sys.argv[2:]] or [100, 200, 300])
    for n, v in (result or {}).items():
        print(n, " ".join("%s=%s" % (k, "-" if x is None else "%.4g" % x) for k, x in v.items()))
    if result is None:
        print("not modelled: the scene holds a mesh or a transformed sphere")
