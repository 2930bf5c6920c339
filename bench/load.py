#!/usr/bin/python3
"""How fast a large mesh loads, from OBJ and from glTF, and the peak memory of the load.

Usage: bench/load.py [--abcube build/abcube [--abcube OTHER ...]] [--grid 707] [--runs 5]
                     [--threads 0] [--report bench/results/load]

Writes bench/memory.py's seeded terrain (2 grid^2 triangles: 707 gives 1M) as an OBJ file
(text, quads, vertex normals) and as a binary glTF (.glb: float positions and normals,
32-bit triangle indices), and renders each with `--method raytrace` at 8x8 pixels: the
scene's load is nearly the whole process. Each binary given with --abcube runs each file
--runs times, interleaved with the others. Reported: the load from the render's stats
(timings_ms.load, which includes the triangles' soup, the closed-surface tests and the
MTL and texture reads) and the whole process's peak RSS (/usr/bin/time -v), medians
[min, max]. The scenes live in a temporary folder (--keep DIR keeps them).
"""
import argparse
import datetime
import json
import os
import re
import statistics
import struct
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import memory  # noqa: E402  (the terrain writer)


def obj_to_glb(obj, glb):
    """The OBJ's v, vn and f lines (v//vn corners, as memory.py writes them) as a .glb of one
    indexed primitive, quads split along the first corner's diagonal."""
    positions, normals, indices = [], [], []
    with open(obj) as f:
        for line in f:
            if line.startswith("v "):
                positions.extend(float(x) for x in line.split()[1:4])
            elif line.startswith("vn "):
                normals.extend(float(x) for x in line.split()[1:4])
            elif line.startswith("f "):
                c = [int(w.split("/")[0]) - 1 for w in line.split()[1:]]
                for k in range(1, len(c) - 1):
                    indices.extend((c[0], c[k], c[k + 1]))
    p = struct.pack("<%df" % len(positions), *positions)
    n = struct.pack("<%df" % len(normals), *normals)
    i = struct.pack("<%dI" % len(indices), *indices)
    count = len(positions) // 3
    lo = [min(positions[k::3]) for k in range(3)]
    hi = [max(positions[k::3]) for k in range(3)]
    doc = {
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2}]}],
        "buffers": [{"byteLength": len(p) + len(n) + len(i)}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(p)},
                        {"buffer": 0, "byteOffset": len(p), "byteLength": len(n)},
                        {"buffer": 0, "byteOffset": len(p) + len(n), "byteLength": len(i)}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": count, "type": "VEC3", "min": lo, "max": hi},
                      {"bufferView": 1, "componentType": 5126, "count": count, "type": "VEC3"},
                      {"bufferView": 2, "componentType": 5125, "count": len(indices), "type": "SCALAR"}],
    }
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    data = p + n + i
    with open(glb, "wb") as f:
        f.write(struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(text) + 8 + len(data)))
        f.write(struct.pack("<II", len(text), 0x4E4F534A) + text)
        f.write(struct.pack("<II", len(data), 0x004E4942) + data)


def run(abcube, scene, out, threads):
    """One render: (load ms from its stats, peak RSS MB)."""
    stats = out + ".json"
    cmd = ["/usr/bin/time", "-v", abcube, "render", scene, "-o", out + ".png", "--method", "raytrace",
           "--width", "8", "--height", "8", "--stats", stats]
    if threads:
        cmd += ["--threads", str(threads)]
    p = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if p.returncode != 0:
        sys.exit("FAILED (%d): %s\n%s" % (p.returncode, " ".join(cmd), p.stderr[-2000:]))
    rss = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", p.stderr).group(1))
    with open(stats) as f:
        return json.load(f)["timings_ms"]["load"], rss * 1024 / 1e6


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--abcube", action="append", help="a binary to time (repeatable); default build/abcube")
    ap.add_argument("--grid", type=int, default=707, help="terrain cells per side (707: 1M triangles)")
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--threads", type=int, default=0, help="--threads of the renders (0: not given)")
    ap.add_argument("--seed", type=int, default=14)
    ap.add_argument("--report", help="write REPORT.md")
    ap.add_argument("--keep", help="write the scenes into this folder and keep them")
    args = ap.parse_args(argv)
    binaries = [os.path.abspath(b) for b in (args.abcube or [os.path.join(os.path.dirname(HERE), "build", "abcube")])]
    folder = args.keep or tempfile.mkdtemp(prefix="abcube_load_")
    os.makedirs(folder, exist_ok=True)
    obj_scene, triangles = memory.write_terrain_scene(folder, args.grid, args.seed, 8, 64)
    obj = os.path.join(folder, "terrain_%d.obj" % args.grid)
    glb = os.path.join(folder, "terrain_%d.glb" % args.grid)
    obj_to_glb(obj, glb)
    glb_scene = os.path.join(folder, "terrain_%d_glb.json" % args.grid)
    with open(obj_scene) as f:
        text = f.read()
    with open(glb_scene, "w") as f:
        f.write(text.replace('"type": "mesh", "file": "%s"' % os.path.basename(obj),
                             '"type": "gltf", "file": "%s"' % os.path.basename(glb)))
    files = [("OBJ", obj_scene, obj), ("glTF (.glb)", glb_scene, glb)]
    results = {(b, name): ([], []) for b in binaries for name, _, _ in files}
    start = datetime.datetime.now(datetime.timezone.utc)
    for r in range(args.runs):
        for name, scene, _ in files:
            for k, b in enumerate(binaries):
                load, rss = run(b, scene, os.path.join(folder, "out%d" % k), args.threads)
                results[(b, name)][0].append(load)
                results[(b, name)][1].append(rss)

    def fmt(values, digits=0):
        return "%.*f [%.*f, %.*f]" % (digits, statistics.median(values), digits, min(values), digits, max(values))

    rows = ["| binary | file | bytes | load ms | peak RSS MB |", "|---|---|---:|---:|---:|"]
    for name, _, path in files:
        for b in binaries:
            loads, rss = results[(b, name)]
            rows.append("| %s | %s | %d | %s | %s |" % (b, name, os.path.getsize(path), fmt(loads), fmt(rss, 1)))
    table = "\n".join(rows)
    print(table)
    if args.report:
        commit = subprocess.run(["git", "-C", HERE, "rev-parse", "--short=12", "HEAD"], capture_output=True,
                                text=True).stdout.strip()
        with open(args.report + ".md", "w") as f:
            f.write("# Loading a large mesh (bench/load.py)\n\n")
            f.write("Command: `bench/load.py %s`  \n" % " ".join(argv if argv is not None else sys.argv[1:]))
            f.write("Date: %s, commit %s, load average %.2f (%d cores)  \n" % (
                start.strftime("%Y-%m-%d %H:%M UTC"), commit, os.getloadavg()[0], os.cpu_count()))
            f.write("Terrain of %d triangles (grid %d, seed %d), `--method raytrace` at 8x8; medians [min, max] "
                    "of %d interleaved runs.\n\n" % (triangles, args.grid, args.seed, args.runs))
            f.write(table + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
