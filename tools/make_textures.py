#!/usr/bin/env python3
"""Writes the repository's test texture scenes/textures/checker.png and the textured mesh
scenes/meshes/tile.obj with its MTL file tile.mtl (map_Kd ../textures/checker.png).

Deterministic (seeded, Python standard library only: zlib for the PNG): running it again
gives the same bytes, so the committed files can be checked with `git diff --exit-code`.

checker.png: 32 x 32 8-bit sRGB, a 4 x 4 checker of seeded colours whose cells blend into
each other smoothly (cosine weights between cell centres, periodic, so the image tiles
without a seam). Smooth on purpose: the GPU and the CPU paths filter differently (GL
mipmaps at 32 samples a pixel, OpenImageIO point samples), and `abcube crosscheck` and
the method-agreement tests compare them per pixel; a hard edge would measure the filters,
not the texture lookup.

Usage: tools/make_textures.py [--out DIR] [--seed N]
"""
import argparse
import math
import os
import random
import struct
import zlib

SIZE = 32   # texels per side
CELLS = 4   # checker cells per side


def png_bytes(width, height, rows):
    """An 8-bit RGB PNG (no ancillary chunks: no time stamp)."""
    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)
    raw = b"".join(b"\x00" + bytes(row) for row in rows)
    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw, 9)) +
            chunk(b"IEND", b""))


def checker(seed):
    rng = random.Random(seed)
    light = [(rng.uniform(0.75, 1.0), rng.uniform(0.6, 0.95), rng.uniform(0.3, 0.7)) for _ in range(CELLS * CELLS)]
    dark = [(rng.uniform(0.05, 0.25), rng.uniform(0.1, 0.35), rng.uniform(0.3, 0.6)) for _ in range(CELLS * CELLS)]
    colour = [light[i] if (i % CELLS + i // CELLS) % 2 == 0 else dark[i] for i in range(CELLS * CELLS)]
    cell = SIZE / CELLS
    rows = []
    for y in range(SIZE):
        row = []
        for x in range(SIZE):
            # Position in cell units, relative to cell centres; cosine blend of the 4 nearest.
            fx, fy = (x + 0.5) / cell - 0.5, (y + 0.5) / cell - 0.5
            x0, y0 = math.floor(fx), math.floor(fy)
            wx = 0.5 - 0.5 * math.cos(math.pi * (fx - x0))
            wy = 0.5 - 0.5 * math.cos(math.pi * (fy - y0))
            rgb = [0.0, 0.0, 0.0]
            for dy, ky in ((0, 1 - wy), (1, wy)):
                for dx, kx in ((0, 1 - wx), (1, wx)):
                    c = colour[((y0 + dy) % CELLS) * CELLS + (x0 + dx) % CELLS]
                    for k in range(3):
                        rgb[k] += kx * ky * c[k]
            row.extend(int(round(255 * v)) for v in rgb)
        rows.append(row)
    return png_bytes(SIZE, SIZE, rows)


TILE_OBJ = """# A textured tile: two quads with vt (v up), material from tile.mtl (map_Kd).
# Written by tools/make_textures.py.
mtllib tile.mtl
v -1 0 -1
v 1 0 -1
v 1 0 1
v -1 0 1
v 1 1 -1
v 1 1 1
vt 0 0
vt 2 0
vt 2 2
vt 0 2
vt 2 1
vt 0 1
vn 0 1 0
usemtl tiled
f 4/1/1 3/2/1 2/3/1 1/4/1
f 3/1 6/6 5/5 2/2
"""

TILE_MTL = """# Written by tools/make_textures.py. map_Kd is relative to this file.
newmtl tiled
Kd 1 1 1
Ks 0.1 0.1 0.1
Ns 20
map_Kd ../textures/checker.png
"""


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scenes"))
    ap.add_argument("--seed", type=int, default=15)
    args = ap.parse_args()
    os.makedirs(os.path.join(args.out, "textures"), exist_ok=True)
    os.makedirs(os.path.join(args.out, "meshes"), exist_ok=True)
    with open(os.path.join(args.out, "textures", "checker.png"), "wb") as f:
        f.write(checker(args.seed))
    with open(os.path.join(args.out, "meshes", "tile.obj"), "w") as f:
        f.write(TILE_OBJ)
    with open(os.path.join(args.out, "meshes", "tile.mtl"), "w") as f:
        f.write(TILE_MTL)


if __name__ == "__main__":
    main()
