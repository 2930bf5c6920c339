#!/usr/bin/python3
"""The race: abcube's `abuffer` against its exact tracer (`raytrace`, Embree-backed) and
POV-Ray 3.7, whole processes, interleaved, each image's PSNR against the exact reference,
peak memory per triangle beside the time (issue 14 parts 3 and 4).

Usage: bench/race.py [--abcube build/abcube] [--runs 3] [--threads 2] [--out DIR]
                     [--seed 1] [--no-generated] [--report bench/results/race] [SCENE ...]

Scenes: the repository's bench scenes (scenes/bench/spheres_terrain.json, scenes/cornell.json,
scenes/default.json) and three generated ones that resemble what users render
(bench/race_scenes.py: a closed room, an open outdoor scene, a 1M-triangle mesh), unless
scenes are given.

Per scene:
  REFERENCE  `abcube render --method raytrace` to EXR, once (kept in DIR/NAME/ref.exr).
  N          the scene's own cube resolution, and the smallest N of 32, 48, 64, 96, 128, 192,
             256, 384, 512, 768, 1024 at which `abuffer` reaches 40 dB (untimed PSNR runs;
             "-" when none does).
  TIMED      per run, interleaved (so a drift in machine load hits every renderer alike):
             abuffer at the own N, abuffer at the 40 dB N, raytrace, POV-Ray
             (`povray +W8W +H4H -A` on `abcube export-pov`, whose pixel centres are our 32
             samples per pixel; box-filtered to our size untimed). Wall clock of the whole
             process under /usr/bin/time -v, which also gives the peak RSS.
  MEMORY     bytes per triangle = (peak RSS - peak RSS of `abcube --version`) / triangles.
  GOAL       abuffer at the own N: >= 40 dB, <= 0.5 x raytrace's time, <= 0.25 x POV-Ray's.

PSNR is sRGB, `abcube compare` against the reference (the reference's own PSNR is infinite).
POV-Ray's PSNR includes the model differences listed in cpu_core/scene/pov_export.hpp.
Writes REPORT.md and REPORT.csv.
"""
import argparse
import csv
import datetime
import os
import re
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import race_scenes  # noqa: E402
from memory import peak_rss_kib  # noqa: E402

N_LADDER = [32, 48, 64, 96, 128, 192, 256, 384, 512, 768, 1024]
DEFAULT_SCENES = ["scenes/bench/spheres_terrain.json", "scenes/cornell.json", "scenes/default.json"]


def run(cmd, **kw):
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kw)
    if p.returncode != 0:
        sys.exit("race.py: failed (%d): %s\n%s" % (p.returncode, " ".join(cmd), p.stderr[-2000:]))
    return p.stdout


def psnr(abcube, image, ref):
    # compare's exit status says pass/fail at its --fail threshold; only the figure is used
    out = subprocess.run([abcube, "compare", image, ref], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         text=True).stdout
    m = re.search(r"^PSNR\s+(\S+)", out, re.M)
    if not m:
        sys.exit("race.py: no PSNR from abcube compare %s %s" % (image, ref))
    return float(m.group(1))


def stats_of(path):
    import json
    with open(path) as f:
        return json.load(f)


class Scene:
    def __init__(self, path, out):
        self.path = os.path.abspath(path)
        self.name = os.path.splitext(os.path.basename(path))[0]
        self.dir = os.path.join(out, self.name)
        os.makedirs(self.dir, exist_ok=True)


def timed(cmd):
    """(wall s, peak RSS KiB) of one whole process."""
    rc, kib, seconds = peak_rss_kib(cmd)
    if rc != 0:
        sys.exit("race.py: failed: " + " ".join(cmd))
    return seconds, kib


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--abcube", default=os.path.join(ROOT, "build", "abcube"))
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--out", default=os.path.join(os.environ.get("TMPDIR", "/tmp"), "abcube-race"))
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--no-generated", action="store_true")
    ap.add_argument("--no-pov", action="store_true", help="leave POV-Ray out")
    ap.add_argument("--report", default=None, help="write REPORT.md and REPORT.csv")
    ap.add_argument("scenes", nargs="*")
    args = ap.parse_args(argv)
    ab = os.path.abspath(args.abcube)
    os.makedirs(args.out, exist_ok=True)
    paths = [os.path.join(ROOT, s) if not os.path.isabs(s) else s for s in (args.scenes or DEFAULT_SCENES)]
    if not args.scenes and not args.no_generated:
        gen = os.path.join(args.out, "generated")
        paths += [race_scenes.write(gen, t, args.seed) for t in ("room", "outdoor", "mesh1m")]
    scenes = [Scene(p, args.out) for p in paths]
    thr = ["--threads", str(args.threads)]

    _, base_kib, _ = peak_rss_kib([ab, "--version"])
    rows = []
    for sc in scenes:
        d = sc.dir
        ref = os.path.join(d, "ref.exr")
        print("[%s] reference" % sc.name, file=sys.stderr)
        run([ab, "render", sc.path, "-o", ref, "--method", "raytrace", "--stats", os.path.join(d, "ref.json")] + thr)
        st = stats_of(os.path.join(d, "ref.json"))
        tris = st["counts"]["triangles"]
        own_n = st["size"]["cube_resolution"]
        size = (st["size"]["width"], st["size"]["height"])

        def abuffer_cmd(n, out):
            return [ab, "render", sc.path, "-o", out, "--method", "abuffer", "--cube-res", str(n),
                    "--stats", out + ".json"] + thr

        psnr_at = {}

        def psnr_n(n):
            if n not in psnr_at:
                out = os.path.join(d, "abuffer_%d.png" % n)
                run(abuffer_cmd(n, out))
                psnr_at[n] = psnr(ab, out, ref)
            return psnr_at[n]

        print("[%s] PSNR at N = %d, then the smallest N at 40 dB" % (sc.name, own_n), file=sys.stderr)
        psnr_n(own_n)
        n40 = None
        for n in N_LADDER:   # PSNR is not monotone in N in every scene: take the first that holds
            if psnr_n(n) >= 40.0:
                n40 = n
                break
        pov_psnr = None
        if not args.no_pov:
            run([ab, "export-pov", sc.path, "-o", os.path.join(d, "scene.pov")])
        times = {"ab_own": [], "ab_40": [], "rt": [], "pov": []}
        rss = {k: [] for k in times}
        for k in range(args.runs):
            print("[%s] run %d/%d" % (sc.name, k + 1, args.runs), file=sys.stderr)
            jobs = [("ab_own", abuffer_cmd(own_n, os.path.join(d, "t_own.png")))]
            if n40 is not None:
                jobs.append(("ab_40", abuffer_cmd(n40, os.path.join(d, "t_40.png"))))
            jobs.append(("rt", [ab, "render", sc.path, "-o", os.path.join(d, "t_rt.png"),
                                "--method", "raytrace"] + thr))
            if not args.no_pov:
                jobs.append(("pov", ["povray", "+I" + os.path.join(d, "scene.pov"), "+O" + os.path.join(d, "pov.ppm"),
                                     "+FP16", "File_Gamma=1.0",
                                     "+W%d" % (8 * size[0]), "+H%d" % (4 * size[1]), "-A", "-D", "-P",
                                     "+WT%d" % args.threads]))
            for key, cmd in jobs:
                s, kib = timed(cmd)
                times[key].append(s)
                rss[key].append(kib)
        if not args.no_pov:
            run(["oiiotool", os.path.join(d, "pov.ppm"), "--resize:filter=box", "%dx%d" % size, "-d", "float",
                 "-o", os.path.join(d, "pov.exr")])
            pov_psnr = psnr(ab, os.path.join(d, "pov.exr"), ref)
        shade = stats_of(os.path.join(d, "t_own.png.json"))["timings_ms"]

        def med(key):
            return statistics.median(times[key]) * 1000 if times[key] else None

        def bpt(key):
            return (max(rss[key]) - base_kib) * 1024.0 / tris if rss[key] else None

        def mb(key):
            return (max(rss[key]) - base_kib) / 1024.0 if rss[key] else None

        def spread(key):
            v = times[key]
            return "%.0f [%.0f, %.0f]" % (med(key), min(v) * 1000, max(v) * 1000) if v else "-"

        row = {
            "scene": sc.name, "size": "%dx%d" % size, "triangles": tris, "own_N": own_n,
            "abuffer_ms": med("ab_own"), "abuffer_ms_range": spread("ab_own"), "abuffer_psnr": psnr_at[own_n],
            "abuffer_MB": mb("ab_own"), "abuffer_Btri": bpt("ab_own"),
            "N40": n40 or "", "abuffer40_ms": med("ab_40"), "abuffer40_psnr": psnr_at.get(n40) if n40 else None,
            "raytrace_ms": med("rt"), "raytrace_ms_range": spread("rt"), "raytrace_MB": mb("rt"), "raytrace_Btri": bpt("rt"),
            "pov_ms": med("pov"), "pov_ms_range": spread("pov"), "pov_psnr": pov_psnr,
            "shade_ms": shade.get("shade_and_resolve"), "cube_ms": shade.get("cube_abuffer"),
            "camera_ms": shade.get("camera_abuffer"), "load_ms": shade.get("load"),
        }
        row["ab_over_rt"] = row["abuffer_ms"] / row["raytrace_ms"]
        row["ab_over_pov"] = row["abuffer_ms"] / row["pov_ms"] if row["pov_ms"] else None
        row["goal"] = ("yes" if row["abuffer_psnr"] >= 40 and row["ab_over_rt"] <= 0.5
                       and (row["ab_over_pov"] is None or row["ab_over_pov"] <= 0.25) else "no")
        rows.append(row)
        print(row, file=sys.stderr)

    def f(v, fmt):
        return "-" if v is None or v == "" else fmt % v

    def mem(r, m):
        return "%.0f (%.0f)" % (r[m + "_MB"], r[m + "_Btri"])

    lines = [
        "# The race (bench/race.py)",
        "",
        "Command: `bench/race.py %s`  " % " ".join(argv if argv is not None else sys.argv[1:]),
        "Date: %s, %d cores, %d threads, median [min, max] of %d interleaved runs, whole processes.  " % (
            datetime.datetime.utcnow().strftime("%Y-%m-%d %H:%M UTC"), os.cpu_count(), args.threads, args.runs),
        "PSNR: sRGB dB against `raytrace` (the exact reference). MB (B/tri): peak RSS above `abcube --version` "
        "(%.1f MB), and that per triangle (on small scenes the cube map and image dominate it). Goal: abuffer at the own N >= 40 dB, <= 0.5x raytrace, <= 0.25x POV-Ray." % (
            base_kib / 1024.0),
        "",
        "| scene | size | triangles | N | abuffer ms | dB | MB (B/tri) | N @40 dB | abuffer ms @N40 | dB | raytrace ms | "
        "MB (B/tri) | POV-Ray ms | dB | abuffer/raytrace | abuffer/POV | goal |",
        "|---|---|---:|---:|---|---:|---:|---:|---:|---:|---|---:|---|---:|---:|---:|---|",
    ]
    for r in rows:
        lines.append("| %s | %s | %d | %d | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
            r["scene"], r["size"], r["triangles"], r["own_N"], r["abuffer_ms_range"], f(r["abuffer_psnr"], "%.1f"),
            mem(r, "abuffer"), r["N40"] or "-", f(r["abuffer40_ms"], "%.0f"),
            f(r["abuffer40_psnr"], "%.1f"), r["raytrace_ms_range"], mem(r, "raytrace"),
            r["pov_ms_range"], f(r["pov_psnr"], "%.1f"), f(r["ab_over_rt"], "%.2f"), f(r["ab_over_pov"], "%.2f"),
            r["goal"]))
    lines += ["", "abuffer per-pass ms at the own N (last timed run): load / cube A-buffer / camera A-buffer / "
              "shade and resolve", ""]
    for r in rows:
        lines.append("- %s: %s / %s / %s / %s" % (r["scene"], f(r["load_ms"], "%.0f"), f(r["cube_ms"], "%.0f"),
                                                  f(r["camera_ms"], "%.0f"), f(r["shade_ms"], "%.0f")))
    text = "\n".join(lines) + "\n"
    print(text)
    if args.report:
        os.makedirs(os.path.dirname(args.report) or ".", exist_ok=True)
        with open(args.report + ".md", "w") as fh:
            fh.write(text)
        with open(args.report + ".csv", "w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=list(rows[0].keys()))
            w.writeheader()
            w.writerows(rows)
    return 0


if __name__ == "__main__":
    sys.exit(main())
