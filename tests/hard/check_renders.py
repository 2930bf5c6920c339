#!/usr/bin/python3
"""Checks the renders of tests/hard/hard_cases.sh; exit 1 when any check fails.

    check_renders.py ABCUBE FLOORS.txt MANIFEST.tsv [METHOD]

MANIFEST.tsv, one render a line, tab-separated:
    template  scene.json  method  image.exr  exit_status  log  reproduce-command
Per render: exit status 0 and every float of the image finite (read through the
`abcube` Python module when it is on PYTHONPATH; said so when it is not). Per scene with
both a METHOD (default abuffer) and a raytrace image: PSNR of METHOD against raytrace (as `abcube compare`
prints it) at or above the template's floor in FLOORS.txt. Every failure prints the scene,
the template and the commands that reproduce it.
"""
import math
import re
import subprocess
import sys


def read_floors(path):
    """template -> (floor dB, reason) from lines 'template floor_db reason...'."""
    floors = {}
    with open(path) as f:
        for n, line in enumerate(f, 1):
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            parts = line.split(None, 2)
            if len(parts) < 3:
                sys.exit("%s:%d: want 'template floor_db reason', got %r" % (path, n, line))
            floors[parts[0]] = (float(parts[1]), parts[2])
    return floors


def main():
    abcube_bin, floors_path, manifest = sys.argv[1:4]
    tested = sys.argv[4] if len(sys.argv) > 4 else "abuffer"
    floors = read_floors(floors_path)
    try:
        import abcube
    except ImportError:
        abcube = None
        print("note: no abcube Python module on PYTHONPATH: the NaN/Inf check is skipped")

    def psnr(a, b):
        if abcube is not None:
            return float(abcube.compare(abcube.read_image(a), abcube.read_image(b))["psnr_db"])
        out = subprocess.run([abcube_bin, "compare", a, b], capture_output=True, text=True).stdout
        m = re.search(r"^PSNR\s+(\S+)", out, re.M)
        return math.inf if m and m.group(1).startswith("inf") else float(m.group(1)) if m else -math.inf

    scenes = {}   # scene -> {"template", "method" -> (image, reproduce)}
    failures = []
    for line in open(manifest):
        template, scene, method, image, status, log, reproduce = line.rstrip("\n").split("\t")
        entry = scenes.setdefault(scene, {"template": template, "images": {}})
        if status != "0":
            with open(log) as f:
                reason = f.read().strip().splitlines()[-1:] or ["(no output)"]
            failures.append("FAIL %s [%s] %s: exit status %s: %s\n  reproduce: %s"
                            % (scene, template, method, status, reason[0], reproduce))
            continue
        if abcube is not None:
            import numpy
            pixels = abcube.read_image(image)
            bad = int(numpy.count_nonzero(~numpy.isfinite(pixels)))
            if bad:
                failures.append("FAIL %s [%s] %s: %d NaN or Inf floats\n  reproduce: %s"
                                % (scene, template, method, bad, reproduce))
                continue
        entry["images"][method] = (image, reproduce)

    for scene, entry in sorted(scenes.items()):
        template, images = entry["template"], entry["images"]
        if tested not in images or "raytrace" not in images:
            continue
        if template not in floors:
            failures.append("FAIL %s: template %s has no floor in %s" % (scene, template, floors_path))
            continue
        floor, reason = floors[template]
        value = psnr(images[tested][0], images["raytrace"][0])
        verdict = "ok  " if value >= floor else "FAIL"
        line = "%s %-30s %s vs raytrace %6.2f dB (floor %.1f)" % (verdict, scene, tested, value, floor)
        print(line)
        if value < floor:
            failures.append("%s\n  floor's reason: %s\n  reproduce: %s\n             %s\n             %s compare %s.%s.exr %s.raytrace.exr"
                            % (line, reason, images[tested][1], images["raytrace"][1], abcube_bin, scene, tested, scene))
    for other in sorted(set(m for e in scenes.values() for m in e["images"]) - {tested, "raytrace"}):
        n = sum(1 for e in scenes.values() if other in e["images"])
        print("ok   %d %s renders: exit 0, finite" % (n, other))
    if failures:
        print("\n%d failure(s):" % len(failures))
        print("\n".join(failures))
        return 1
    print("all %d scenes passed" % len(scenes))
    return 0


if __name__ == "__main__":
    sys.exit(main())
