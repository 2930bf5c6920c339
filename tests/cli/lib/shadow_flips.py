"""Whether hybrid's excess error over abuffer is all shadow-boundary samples decided by the GPU.

    python3 shadow_flips.py REFERENCE.exr ABUFFER.exr HYBRID.exr REFERENCE.shadowed.exr

The GPU counts a shadow volume's faces against each sample's surface depth in float: where a
volume's side meets the surface within that rounding of a sample, the sample can fall on the
other side of the shadow's edge. Such a flip costs its pixel one sample's share (1/32) of the
difference between the lit and the shadowed colour, and happens only at a shadow's edge. So
each pixel where hybrid is further from the reference than abuffer, by more than one 8-bit
code, must have a shadow edge in its 3x3 neighbourhood of the reference (the `shadowed` AOV
not constant there), and be off by at most two samples' share of the colour range there. A
shadow lost over a region, or any other fault, breaks one of the two. Exits 0 when every such
pixel holds both, 1 otherwise, printing the pixels.
"""
import sys

import abcube
import numpy as np

SAMPLES = 32
FLIPS = 2  # samples a pixel that may fall on the other side of a shadow's edge


def main(reference, map_image, hybrid, shadowed):
    ref, ab, hy = (abcube.read_image(p)[..., :3] for p in (reference, map_image, hybrid))
    sh = abcube.read_image(shadowed)
    sh = sh if sh.ndim == 2 else sh[..., 0]
    h, w = sh.shape
    err_hy = np.abs(hy - ref).max(axis=2)
    err_ab = np.abs(ab - ref).max(axis=2)
    worse = np.argwhere(err_hy > err_ab + 1.0 / 255.0)
    bad = []
    for y, x in worse:
        y0, y1, x0, x1 = max(y - 1, 0), min(y + 2, h), max(x - 1, 0), min(x + 2, w)
        window = ref[y0:y1, x0:x1].reshape(-1, 3)
        spread = float((window.max(axis=0) - window.min(axis=0)).max())
        at_edge = float(np.ptp(sh[y0:y1, x0:x1])) > 0.0
        allowed = FLIPS / SAMPLES * spread + 1e-4
        if not at_edge or err_hy[y, x] > allowed:
            bad.append((int(y), int(x), round(float(err_hy[y, x]), 4), round(allowed, 4), at_edge))
    print("hybrid worse than abuffer at %d pixels, %d of them not a shadow-edge flip%s"
          % (len(worse), len(bad), (": " + str(bad[:10])) if bad else ""))
    return 1 if bad else 0


if __name__ == "__main__":
    if len(sys.argv) != 5:
        sys.exit(__doc__)
    sys.exit(main(*sys.argv[1:]))
