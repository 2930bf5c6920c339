#!/usr/bin/python3
"""How fast the program starts, and what it loads.

Usage: bench/start_time.py [--abcube build/abcube] [--runs 20] [--report bench/results/start]

  version   `abcube --version`, --runs whole processes after two to warm the file cache:
            the median and the range of their wall clocks (perf_counter around the process).
  render    a small render (cornell.json, 64x48, N = 64, abuffer, PNG), --runs processes:
            the wall clock, the render's own total from its stats (timings_ms.total: the
            passes) and the difference: what the process spends outside the render (start,
            scene load, image write, exit).
  libraries the shared objects the dynamic loader opens (LD_DEBUG=files), for --version,
            the PNG render, a TIFF render (the image module) and a gpu render (GL).
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def wall(cmd):
    t0 = time.perf_counter()
    subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
    return 1000.0 * (time.perf_counter() - t0)


def libraries(cmd):
    env = dict(os.environ, LD_DEBUG="files")
    p = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=env)
    return len({w.split("=", 1)[1] for line in p.stderr.splitlines() for w in line.split() if w.startswith("file=")})


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--abcube", default=os.path.join(ROOT, "build", "abcube"))
    ap.add_argument("--runs", type=int, default=20)
    ap.add_argument("--report", default=None, help="write REPORT.md")
    args = ap.parse_args(argv)
    abcube = os.path.abspath(args.abcube)
    scene = os.path.join(ROOT, "scenes", "cornell.json")
    tmp = tempfile.mkdtemp(prefix="abcube-start.")
    small = [abcube, "render", scene, "--width", "64", "--height", "48", "--cube-res", "64", "--threads", "2"]
    for _ in range(2):
        wall([abcube, "--version"])
    version = [wall([abcube, "--version"]) for _ in range(args.runs)]
    renders, totals = [], []
    for k in range(args.runs):
        stats = os.path.join(tmp, "s.json")
        renders.append(wall(small + ["-o", os.path.join(tmp, "r.png"), "--stats", stats]))
        with open(stats) as f:
            totals.append(json.load(f)["timings_ms"]["total"])
    outside = [r - t for r, t in zip(renders, totals)]
    libs = {
        "--version": libraries([abcube, "--version"]),
        "render to PNG (abuffer)": libraries(small + ["-o", os.path.join(tmp, "l.png")]),
        "render to TIFF (the image module)": libraries(small + ["-o", os.path.join(tmp, "l.tif")]),
        "render --method gpu (GL)": libraries(small + ["-o", os.path.join(tmp, "g.png"), "--method", "gpu"]),
    }
    med = statistics.median
    lines = [
        "`abcube --version`: median %.1f ms [%.1f, %.1f] over %d starts" % (
            med(version), min(version), max(version), args.runs),
        "small render (cornell 64x48, N = 64, PNG): median %.1f ms whole process, %.1f ms in the render's passes, "
        "%.1f ms outside them (start, load, write, exit)" % (med(renders), med(totals), med(outside)),
    ] + ["shared objects opened, %s: %d" % (k, v) for k, v in libs.items()]
    print("\n".join(lines))
    if args.report:
        with open(args.report + ".md", "w") as f:
            f.write("# Start time and libraries loaded\n\n`bench/start_time.py --runs %d`, 2-core machine.\n\n" % args.runs)
            f.write("\n".join("- " + s for s in lines) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
