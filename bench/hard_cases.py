#!/usr/bin/python3
"""Hard cases: every method on a few hundred generated scenes, against the exact tracer.

    /usr/bin/python3 bench/hard_cases.py [--abcube build/abcube] [--seed 1000]
        [--count-per-template 40] [--templates a,b,...] [--methods abuffer,zbuffer,envmap,gpu]
        [--threads 2] [--out bench/results] [--work DIR] [--keep]

Generates the scenes with tools/hard_scenes.py (template T, scenes T_SEED_K for
K = 0 .. count-1, i.e. random.Random(SEED + K)), renders them all in one `abcube batch`
(raytrace as the reference and every CPU method; gpu in a second batch with --gl egl,
skipped when `abcube info` finds no working EGL path), and reads each method's PSNR
against raytrace (as `abcube compare` prints it) and, where the stats JSON has it, the
share of search rays answered from the side structure: sum of
stats.searches.{reflection,refraction_exit,shadow}.side_hits over the sum of their rays
("n/a" when no stats carry side_hits).

Writes OUT/hard_cases.csv (one row per scene and method) and OUT/hard_cases.md (per
template and method: median and worst PSNR, the worst scene, the side share), and prints
the machine load before and after. tests/hard/floors.txt takes its floors from the worst
column. Exit status 1 if any render failed (the table still gets written).
"""
import argparse
import csv
import datetime
import json
import math
import os
import platform
import re
import shutil
import statistics
import subprocess
import sys
import tempfile

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(REPO, "tools"))
import hard_scenes  # noqa: E402  (the generator: same templates, same seeds)
sys.path.insert(0, os.path.join(REPO, "bench"))
from common import psnr  # noqa: E402

SEARCH_KINDS = ("reflection", "refraction_exit", "shadow")


def load_average():
    try:
        with open("/proc/loadavg") as f:
            return " ".join(f.read().split()[:3])
    except OSError:
        return "n/a"


def gl_works(abcube):
    """True when `abcube info` reports a working EGL path (the gpu method needs one)."""
    try:
        out = subprocess.run([abcube, "info"], capture_output=True, text=True, timeout=60).stdout
    except (OSError, subprocess.TimeoutExpired):
        return False
    return re.search(r"^\s*egl-(device \d+|surfaceless)\s+yes", out, re.M) is not None


def psnr_of(abcube, a, b, module):
    """PSNR dB of image a against b: through the Python module when built, else the CLI."""
    if module is not None:
        return float(module.compare(module.read_image(a), module.read_image(b))["psnr_db"])
    return psnr(abcube, a, b)


def side_counts(stats_path):
    """(side_hits, rays) summed over the search kinds, or None when no kind reports side_hits."""
    try:
        with open(stats_path) as f:
            searches = json.load(f).get("searches", {})
    except (OSError, ValueError):
        return None
    hits = rays = 0
    seen = False
    for kind in SEARCH_KINDS:
        s = searches.get(kind, {})
        if "side_hits" in s:
            seen = True
            hits += s["side_hits"]
            rays += s.get("rays", 0)
    return (hits, rays) if seen else None


def fmt_db(x):
    return "inf" if math.isinf(x) else "%.1f" % x


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--abcube", default=os.path.join(REPO, "build", "abcube"))
    ap.add_argument("--seed", type=int, default=1000)
    ap.add_argument("--count-per-template", type=int, default=40)
    ap.add_argument("--templates", default=",".join(hard_scenes.TEMPLATES))
    ap.add_argument("--methods", default="abuffer,zbuffer,envmap,gpu")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--size", default="64x48",
                    help="image WxH of the generated scenes (default 64x48, the test suite's); another "
                         "size writes hard_cases_WxH.{md,csv}")
    ap.add_argument("--out", default=os.path.join(REPO, "bench", "results"))
    ap.add_argument("--work", help="scene and image folder (default: a temporary one)")
    ap.add_argument("--keep", action="store_true", help="keep the work folder")
    args = ap.parse_args()

    load_before = load_average()
    print("load average before: %s (%d cores)" % (load_before, os.cpu_count() or 0), flush=True)
    templates = args.templates.split(",")
    methods = [m for m in args.methods.split(",") if m]
    if "gpu" in methods and not gl_works(args.abcube):
        print("no working EGL path: gpu skipped", flush=True)
        methods.remove("gpu")
    work = args.work or tempfile.mkdtemp(prefix="abcube_hard_bench.")
    os.makedirs(work, exist_ok=True)
    try:
        module = None
        try:
            sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(args.abcube)), "python"))
            import abcube as module  # noqa: F811
        except ImportError:
            pass

        # the scenes, and one batch of jobs per GL need
        scenes = []   # (template, stem)
        for t in templates:
            gen = [sys.executable, os.path.join(REPO, "tools", "hard_scenes.py"), "--seed", str(args.seed),
                   "--count", str(args.count_per_template), "--templates", t, "--size", args.size, "--out", work]
            subprocess.run(gen, check=True, stdout=subprocess.DEVNULL)
            scenes += [(t, "%s_%d_%d" % (t, args.seed, k)) for k in range(args.count_per_template)]
        cpu_jobs, gpu_jobs = [], []
        for _, stem in scenes:
            for m in ["raytrace"] + methods:
                job = {"scene": stem + ".json", "out": "%s.%s.exr" % (stem, m), "method": m,
                       "stats": "%s.%s.stats.json" % (stem, m)}
                (gpu_jobs if m == "gpu" else cpu_jobs).append(json.dumps(job))
        failed = False
        for name, jobs, gl in (("cpu", cpu_jobs, "auto"), ("gpu", gpu_jobs, "egl")):
            if not jobs:
                continue
            path = os.path.join(work, "jobs_%s.jsonl" % name)
            with open(path, "w") as f:
                f.write("\n".join(jobs) + "\n")
            print("rendering %d jobs (%s) ..." % (len(jobs), name), flush=True)
            r = subprocess.run([args.abcube, "batch", path, "--threads", str(args.threads), "--gl", gl],
                               capture_output=True, text=True)
            sys.stderr.write(r.stderr[-4000:])
            failed |= r.returncode != 0

        # per scene and method: PSNR against raytrace, side share
        rows = []
        for t, stem in scenes:
            ref = os.path.join(work, stem + ".raytrace.exr")
            for m in methods:
                img = os.path.join(work, "%s.%s.exr" % (stem, m))
                row = {"template": t, "scene": stem, "method": m, "psnr_db": "", "side_hits": "",
                       "search_rays": "", "error": ""}
                if not (os.path.exists(img) and os.path.exists(ref)):
                    row["error"] = "render failed"
                else:
                    row["psnr_db"] = psnr_of(args.abcube, img, ref, module)
                    side = side_counts(os.path.join(work, "%s.%s.stats.json" % (stem, m)))
                    if side:
                        row["side_hits"], row["search_rays"] = side
                rows.append(row)

        os.makedirs(args.out, exist_ok=True)
        base = "hard_cases" if args.size == "64x48" else "hard_cases_" + args.size
        with open(os.path.join(args.out, base + ".csv"), "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
            w.writeheader()
            for row in rows:
                out = dict(row)
                if isinstance(out["psnr_db"], float):
                    out["psnr_db"] = fmt_db(out["psnr_db"]) if math.isinf(out["psnr_db"]) else "%.2f" % out["psnr_db"]
                w.writerow(out)

        load_after = load_average()
        cmd = "/usr/bin/python3 bench/hard_cases.py --seed %d --count-per-template %d --threads %d --size %s" % (
            args.seed, args.count_per_template, args.threads, args.size)
        width, height = (int(v) for v in args.size.split("x"))
        lines = [
            "# Hard cases against the exact tracer",
            "",
            "`%s` (%s, %d scenes, %s; %dx%d px, N = 128, max_depth 3 unless the template "
            "raises it; PSNR of each method against `--method raytrace`, on sRGB values "
            "clamped to [0, 1]). Load average before / after: %s / %s on %d cores. Scenes: "
            "`tools/hard_scenes.py --seed %d --count %d --templates T` (TEMPLATE_SEED_K, "
            "random.Random(SEED + K)). Side share: search rays answered from the side "
            "structure (stats side_hits / rays), n/a where the stats carry no side_hits."
            % (cmd, datetime.date.today().isoformat(), len(scenes), platform.node() or "this machine",
               width, height, load_before, load_after, os.cpu_count() or 0, args.seed, args.count_per_template),
            "",
            "| template | method | median PSNR dB | worst PSNR dB | worst scene | failed | side share |",
            "|---|---|---|---|---|---|---|",
        ]
        for t in templates:
            for m in methods:
                sel = [r for r in rows if r["template"] == t and r["method"] == m]
                ok = [r for r in sel if r["psnr_db"] != ""]
                fails = len(sel) - len(ok)
                if not ok:
                    lines.append("| %s | %s | | | | %d | n/a |" % (t, m, fails))
                    continue
                vals = [r["psnr_db"] for r in ok]
                worst = min(ok, key=lambda r: r["psnr_db"])
                side = [r for r in ok if r["side_hits"] != ""]
                rays = sum(r["search_rays"] for r in side)
                share = ("%.2f%%" % (100.0 * sum(r["side_hits"] for r in side) / rays)) if rays else "n/a"
                lines.append("| %s | %s | %s | %s | %s | %d | %s |" % (
                    t if m == methods[0] else "", m, fmt_db(statistics.median(vals)),
                    fmt_db(worst["psnr_db"]), worst["scene"], fails, share))
        with open(os.path.join(args.out, base + ".md"), "w") as f:
            f.write("\n".join(lines) + "\n")
        print("\n".join(lines))
        print("load average after: %s" % load_after)
        return 1 if failed else 0
    finally:
        if not args.keep and not args.work:
            shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
