#!/usr/bin/python3
"""--target-db on generated scenes: does the chosen plan reach the target, and what does it
cost against the plan at the scene's own N and against the exact tracer?

Usage: bench/target_db.py [--abcube build/abcube] [--seed 1] [--target 40] [--threads 2]
                          [--hard 22] [--flat 10] [--race 4] [--size 320x240] [--cube-res 512]
                          [--out DIR] [--report bench/results/target_db]

Scenes, all drawn from --seed (nobody picks them by hand):
  hard   tools/hard_scenes.py, --hard scenes cycling its eleven templates;
  flat   tools/flat_mirror_scenes.py, --flat scenes cycling its templates;
  race   bench/race_scenes.py's room and outdoor templates, --race scenes (seeds seed..).
The hard and flat scenes are written at --size with N = --cube-res, the race scenes at
their own sizes with N = 512: the scene's own N is what a user wrote in the file.

Per scene, one whole process each (wall clock, /usr/bin/time):
  raytrace   `abcube render --method raytrace` to EXR (the reference);
  own        `abcube render` (abuffer at the scene's N);
  target     `abcube render --target-db T`.
PSNR of each abuffer image against the reference by `abcube compare` (sRGB). The stats of
the target run give the N and shading plan chosen and the predicted PSNR. The plan: `one`
shading point a fragment, or the `quarters` with the edges refined at the samples
(`+ shadow`: --shadow-edges samples, `+ secondary`: --secondary-edges samples).
Writes REPORT.md and REPORT.csv.
"""
import argparse
import csv
import json
import os
import statistics
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import race  # noqa: E402  (timed)
from common import psnr  # noqa: E402
import race_scenes  # noqa: E402


def generate(args, out):
    """The scene files, generated into out."""
    scenes = race_scenes.generated_sample(out, args.seed, args.hard, args.flat, args.size, args.cube_res)
    for k in range(args.race):
        template = ("room", "outdoor")[k % 2]
        scenes.append(race_scenes.write(os.path.join(out, "race"), template, args.seed + k // 2))
    return scenes


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--abcube", default=os.path.join(ROOT, "build", "abcube"))
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--target", type=float, default=40.0)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--hard", type=int, default=22)
    ap.add_argument("--flat", type=int, default=10)
    ap.add_argument("--race", type=int, default=4)
    ap.add_argument("--size", default="320x240")
    ap.add_argument("--cube-res", type=int, default=512)
    ap.add_argument("--out", default=os.path.join(os.environ.get("TMPDIR", "/tmp"), "abcube-target-db"))
    ap.add_argument("--report", default=None, help="write REPORT.md and REPORT.csv")
    args = ap.parse_args(argv)
    abcube = os.path.abspath(args.abcube)
    os.makedirs(args.out, exist_ok=True)
    rows = []
    for path in generate(args, args.out):
        name = os.path.splitext(os.path.basename(path))[0]
        d = os.path.join(args.out, "runs", name)
        os.makedirs(d, exist_ok=True)
        ref = os.path.join(d, "ref.exr")
        common = [abcube, "render", path, "--threads", str(args.threads)]
        t_ray, _ = race.timed(common + ["-o", ref, "--method", "raytrace"])
        own = os.path.join(d, "own.exr")
        t_own, _ = race.timed(common + ["-o", own, "--method", "abuffer"])
        target = os.path.join(d, "target.exr")
        stats_path = os.path.join(d, "target.json")
        t_target, _ = race.timed(common + ["-o", target, "--method", "abuffer", "--target-db", str(args.target),
                                           "--stats", stats_path])
        with open(stats_path) as f:
            st = json.load(f)
        t = st.get("target_db", {})
        with open(path) as f:
            own_n = json.load(f).get("render", {}).get("cube_resolution", 512)
        row = {
            "scene": name,
            "triangles": st["counts"]["triangles"],
            "own_n": own_n,
            "own_db": psnr(abcube, own, ref),
            "chosen_n": t.get("cube_resolution", "-"),
            "points": race.plan_words(t),
            "predicted_db_low": t.get("predicted_psnr_db_low"),
            "target_db": psnr(abcube, target, ref),
            "pilots": len(t.get("pilots", [])),
            "pilot_ms": st["timings_ms"].get("target_pilots", 0.0),
            "raytrace_s": t_ray,
            "own_s": t_own,
            "target_s": t_target,
        }
        row["reached"] = row["target_db"] >= args.target
        print("%-32s own N %4s %6.2f dB %6.2f s | target N %4s %-22s %6.2f dB (low %s) %6.2f s | raytrace %6.2f s" % (
            name, own_n, row["own_db"], t_own, row["chosen_n"], row["points"], row["target_db"],
            "-" if row["predicted_db_low"] is None else "%.2f" % row["predicted_db_low"], t_target, t_ray),
            flush=True)
        rows.append(row)
    reached = sum(r["reached"] for r in rows)
    vs_own = [r["target_s"] / r["own_s"] for r in rows]
    vs_ray = [r["target_s"] / r["raytrace_s"] for r in rows]
    own_vs_ray = [r["own_s"] / r["raytrace_s"] for r in rows]
    worst = max(rows, key=lambda r: r["target_s"] / r["raytrace_s"])
    summary = [
        "scenes: %d (seed %d), target %.1f dB" % (len(rows), args.seed, args.target),
        "reached: %d of %d (%.0f%%)" % (reached, len(rows), 100.0 * reached / len(rows)),
        "target / own N time: median %.2f, min %.2f, max %.2f" % (
            statistics.median(vs_own), min(vs_own), max(vs_own)),
        "target / raytrace time: median %.2f, worst %.2f (%s)" % (
            statistics.median(vs_ray), max(vs_ray), worst["scene"]),
        "own N / raytrace time: median %.2f" % statistics.median(own_vs_ray),
        "own N reaching the target: %d of %d" % (sum(r["own_db"] >= args.target for r in rows), len(rows)),
    ]
    print("\n".join(summary))
    if args.report:
        fields = list(rows[0].keys())
        with open(args.report + ".csv", "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=fields)
            w.writeheader()
            w.writerows(rows)
        with open(args.report + ".md", "w") as f:
            f.write("# --target-db %.0f on generated scenes\n\n" % args.target)
            f.write("`bench/target_db.py --seed %d --target %g --hard %d --flat %d --race %d --size %s "
                    "--cube-res %d --threads %d`, one whole process per cell, 2-core machine, llvmpipe.\n\n" % (
                        args.seed, args.target, args.hard, args.flat, args.race, args.size, args.cube_res,
                        args.threads))
            f.write("\n".join("- " + s for s in summary) + "\n\n")
            f.write("| scene | triangles | own N | own dB | own s | chosen N | plan | predicted low | "
                    "target dB | target s | raytrace s |\n|" + "---|" * 11 + "\n")
            for r in rows:
                f.write("| %s | %d | %s | %.2f | %.2f | %s | %s | %s | %.2f | %.2f | %.2f |\n" % (
                    r["scene"], r["triangles"], r["own_n"], r["own_db"], r["own_s"], r["chosen_n"], r["points"],
                    "-" if r["predicted_db_low"] is None else "%.2f" % r["predicted_db_low"], r["target_db"],
                    r["target_s"], r["raytrace_s"]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
