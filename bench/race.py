#!/usr/bin/python3
"""The race: abcube's `abuffer` against its exact tracer (`raytrace`, Embree-backed) and
POV-Ray 3.7, whole processes, interleaved, each image's PSNR against the exact reference,
peak memory per triangle beside the time.

Usage: bench/race.py [--abcube build/abcube] [--runs 3] [--threads 2] [--out DIR] [--target 40]
                     [--seed 1] [--hard 8] [--flat 4] [--sample-size 480x480] [--no-generated]
                     [--no-pov] [--report bench/results/race] [SCENE ...]

Scenes: the repository's bench scenes (scenes/bench/spheres_terrain.json, scenes/cornell.json,
scenes/default.json), three generated ones that resemble what users render
(bench/race_scenes.py: a closed room, an open outdoor scene, a 1M-triangle mesh), and a
sample of the generated templates drawn from --seed (--hard scenes cycling
tools/hard_scenes.py's templates, --flat cycling tools/flat_mirror_scenes.py's, at
--sample-size with N = 512), unless scenes are given. --no-generated keeps the repository's
three alone.

Per scene:
  REFERENCE  `abcube render --method raytrace` to EXR, once (kept in DIR/NAME/ref.exr).
  TIMED      per run, interleaved (so a drift in machine load hits every renderer alike):
             abuffer at the target (`--target-db T`: abcube picks N and the shading plan),
             abuffer at the scene's own N and plan, raytrace, the tracer's ladder (`--samples`
             1, 2, 4, 8, 16), POV-Ray (`povray +W8W +H4H -A` on `abcube export-pov`, whose
             pixel centres are our 32 samples per pixel; box-filtered to our size untimed).
             Wall clock of the whole process under /usr/bin/time -v, which also gives the
             peak RSS.
  MATCHED    each abuffer image's matched rung: the fastest rung of the ladder (1 to 32
             samples; 32 is raytrace, the reference, infinitely close) whose image is at
             least as close to the reference; the ratio of abuffer's time to that rung's is
             the speed at matched error (above 1: the tracer at fewer samples is faster).
  MEMORY     bytes per triangle = (peak RSS - peak RSS of `abcube --version`) / triangles.
  GOAL       abuffer at the target: >= T dB, <= 0.5 x raytrace's time, <= 0.25 x POV-Ray's.

PSNR is sRGB, `abcube compare` against the reference (the reference's own PSNR is infinite).
POV-Ray's PSNR includes the model differences listed in cpu_core/scene/pov_export.hpp.
The summary gives the median and the worst abuffer/matched rung, abuffer/raytrace and
abuffer/POV-Ray ratios at the target, for the race scenes and for the generated sample apart.
Writes REPORT.md and REPORT.csv.
"""
import argparse
import csv
import datetime
import os
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import race_scenes  # noqa: E402
from common import peak_rss_kib, psnr, run  # noqa: E402

DEFAULT_SCENES = ["scenes/bench/spheres_terrain.json", "scenes/cornell.json", "scenes/default.json"]


def plan_words(t):
    """The shading plan --target-db chose (its stats' target_db object), in a few words."""
    if not t.get("shading_points"):
        return "-"
    if t["shading_points"] != "quarters":
        return t["shading_points"]
    edges = [name for name in ("shadow", "secondary") if t.get(name + "_edges") == "samples"]
    return " + ".join(["quarters"] + edges)


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


RUNGS = (1, 2, 4, 8, 16)  # the tracer's ladder below the reference's 32 samples


def matched_rung(ladder, db):
    """(samples, ms) of the fastest rung of `ladder` [(samples, ms, psnr)] at least as close
    to the reference as `db`."""
    spp, ms, _ = min((r for r in ladder if r[2] >= db), key=lambda r: r[1])
    return spp, ms


def ratio_summary(rows, key):
    v = [r[key] for r in rows if r[key] is not None]
    if not v:
        return "-"
    worst = max((r for r in rows if r[key] is not None), key=lambda r: r[key])
    return "median %.2f, worst %.2f (%s)" % (statistics.median(v), worst[key], worst["scene"])


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--abcube", default=os.path.join(ROOT, "build", "abcube"))
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--out", default=os.path.join(os.environ.get("TMPDIR", "/tmp"), "abcube-race"))
    ap.add_argument("--target", type=float, default=40.0, help="--target-db of the timed abuffer column")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--hard", type=int, default=8, help="generated sample: hard-case scenes")
    ap.add_argument("--flat", type=int, default=4, help="generated sample: flat-mirror scenes")
    ap.add_argument("--sample-size", default="480x480")
    ap.add_argument("--no-generated", action="store_true")
    ap.add_argument("--no-pov", action="store_true", help="leave POV-Ray out")
    ap.add_argument("--report", default=None, help="write REPORT.md and REPORT.csv")
    ap.add_argument("scenes", nargs="*")
    args = ap.parse_args(argv)
    ab = os.path.abspath(args.abcube)
    os.makedirs(args.out, exist_ok=True)
    paths = [(os.path.join(ROOT, s) if not os.path.isabs(s) else s, "race") for s in (args.scenes or DEFAULT_SCENES)]
    if not args.scenes and not args.no_generated:
        gen = os.path.join(args.out, "generated")
        paths += [(race_scenes.write(gen, t, args.seed), "race") for t in ("room", "outdoor", "mesh1m")]
        paths += [(p, "sample") for p in race_scenes.generated_sample(
            os.path.join(args.out, "sample"), args.seed, args.hard, args.flat, args.sample_size, 512)]
    scenes = [(Scene(p, args.out), group) for p, group in paths]
    thr = ["--threads", str(args.threads)]

    _, base_kib, _ = peak_rss_kib([ab, "--version"])
    rows = []
    for sc, group in scenes:
        d = sc.dir
        ref = os.path.join(d, "ref.exr")
        print("[%s] reference" % sc.name, file=sys.stderr)
        run([ab, "render", sc.path, "-o", ref, "--method", "raytrace", "--stats", os.path.join(d, "ref.json")] + thr)
        st = stats_of(os.path.join(d, "ref.json"))
        tris = st["counts"]["triangles"]
        own_n = st["size"]["cube_resolution"]
        size = (st["size"]["width"], st["size"]["height"])
        pov = not args.no_pov and subprocess.run(
            [ab, "export-pov", sc.path, "-o", os.path.join(d, "scene.pov")], stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL).returncode == 0
        target_png = os.path.join(d, "t_target.png")
        own_png = os.path.join(d, "t_own.png")
        jobs = [("ab_target", [ab, "render", sc.path, "-o", target_png, "--method", "abuffer", "--target-db",
                               "%g" % args.target, "--stats", target_png + ".json"] + thr),
                ("ab_own", [ab, "render", sc.path, "-o", own_png, "--method", "abuffer", "--stats",
                            own_png + ".json"] + thr),
                ("rt", [ab, "render", sc.path, "-o", os.path.join(d, "t_rt.png"), "--method", "raytrace"] + thr)]
        for spp in RUNGS:
            jobs.append(("rt%d" % spp, [ab, "render", sc.path, "-o", os.path.join(d, "t_rt%d.png" % spp),
                                        "--method", "raytrace", "--samples", str(spp)] + thr))
        if pov:
            jobs.append(("pov", ["povray", "+I" + os.path.join(d, "scene.pov"), "+O" + os.path.join(d, "pov.ppm"),
                                 "+FP16", "File_Gamma=1.0",
                                 "+W%d" % (8 * size[0]), "+H%d" % (4 * size[1]), "-A", "-D", "-P",
                                 "+WT%d" % args.threads]))
        times = {k: [] for k in ["ab_target", "ab_own", "rt", "pov"] + ["rt%d" % spp for spp in RUNGS]}
        rss = {k: [] for k in times}
        for k in range(args.runs):
            print("[%s] run %d/%d" % (sc.name, k + 1, args.runs), file=sys.stderr)
            for key, cmd in jobs:
                s, kib = timed(cmd)
                times[key].append(s)
                rss[key].append(kib)
        pov_psnr = None
        if pov:
            run(["oiiotool", os.path.join(d, "pov.ppm"), "--resize:filter=box", "%dx%d" % size, "-d", "float",
                 "-o", os.path.join(d, "pov.exr")])
            pov_psnr = psnr(ab, os.path.join(d, "pov.exr"), ref)
        target_stats = stats_of(target_png + ".json")
        chosen = target_stats.get("target_db", {})
        shade = target_stats["timings_ms"]

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
            "scene": sc.name, "group": group, "size": "%dx%d" % size, "triangles": tris, "own_N": own_n,
            "target_N": chosen.get("cube_resolution", own_n), "target_plan": plan_words(chosen),
            "target_ms": med("ab_target"), "target_ms_range": spread("ab_target"),
            "target_psnr": psnr(ab, target_png, ref), "target_MB": mb("ab_target"), "target_Btri": bpt("ab_target"),
            "own_ms": med("ab_own"), "own_psnr": psnr(ab, own_png, ref), "own_MB": mb("ab_own"),
            "own_Btri": bpt("ab_own"),
            "raytrace_ms": med("rt"), "raytrace_ms_range": spread("rt"), "raytrace_MB": mb("rt"), "raytrace_Btri": bpt("rt"),
            "pov_ms": med("pov"), "pov_ms_range": spread("pov"), "pov_psnr": pov_psnr,
            "pilots_ms": shade.get("target_pilots"), "shade_ms": shade.get("shade_and_resolve"),
            "cube_ms": shade.get("cube_abuffer"), "camera_ms": shade.get("camera_abuffer"), "load_ms": shade.get("load"),
        }
        ladder = [(spp, med("rt%d" % spp), psnr(ab, os.path.join(d, "t_rt%d.png" % spp), ref)) for spp in RUNGS]
        ladder.append((32, row["raytrace_ms"], float("inf")))
        for spp, ms, db in ladder:
            row["rung%d_ms" % spp], row["rung%d_psnr" % spp] = ms, db
        for key in ("target", "own"):
            spp, ms = matched_rung(ladder, row[key + "_psnr"])
            row[key + "_rung"], row[key + "_rung_ms"] = spp, ms
            row[key + "_over_rung"] = row[key + "_ms"] / ms
        row["ab_over_rt"] = row["target_ms"] / row["raytrace_ms"]
        row["ab_over_pov"] = row["target_ms"] / row["pov_ms"] if row["pov_ms"] else None
        row["own_over_rt"] = row["own_ms"] / row["raytrace_ms"]
        row["goal"] = ("yes" if row["target_psnr"] >= args.target and row["ab_over_rt"] <= 0.5
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
        "(%.1f MB), and that per triangle (on small scenes the cube map and image dominate it). "
        "abuffer is timed at `--target-db %g` (abcube's own choice of N and plan) and at the scene's own N. "
        "Goal: at the target, >= %g dB, <= 0.5x raytrace, <= 0.25x POV-Ray." % (
            base_kib / 1024.0, args.target, args.target),
        "",
    ]
    for group, title in (("race", "Race scenes"), ("sample", "Generated sample (seed %d, %s)" % (
            args.seed, args.sample_size))):
        rs = [r for r in rows if r["group"] == group]
        if not rs:
            continue
        lines += [
            "## " + title, "",
            "- abuffer at the target / the tracer at its matched rung: %s" % ratio_summary(rs, "target_over_rung"),
            "- abuffer at the own N / the tracer at its matched rung: %s" % ratio_summary(rs, "own_over_rung"),
            "- abuffer at the target / raytrace at 32 samples: %s" % ratio_summary(rs, "ab_over_rt"),
            "- abuffer at the target / POV-Ray: %s" % ratio_summary(rs, "ab_over_pov"),
            "- abuffer at the own N / raytrace: %s" % ratio_summary(rs, "own_over_rt"),
            "- at the target: %d of %d reach %g dB; goal met on %d" % (
                sum(r["target_psnr"] >= args.target for r in rs), len(rs), args.target,
                sum(r["goal"] == "yes" for r in rs)),
            "",
            "| scene | size | triangles | target N, plan | target ms | dB | MB (B/tri) | own N | own ms | dB | "
            "MB (B/tri) | raytrace ms | MB (B/tri) | POV-Ray ms | dB | target/raytrace | target/POV | goal |",
            "|---|---|---:|---|---|---:|---:|---:|---:|---:|---:|---|---:|---|---:|---:|---:|---|",
        ]
        for r in rs:
            lines.append("| %s | %s | %d | %s, %s | %s | %s | %s | %d | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |"
                         % (r["scene"], r["size"], r["triangles"], r["target_N"], r["target_plan"],
                            r["target_ms_range"], f(r["target_psnr"], "%.1f"), mem(r, "target"), r["own_N"],
                            f(r["own_ms"], "%.0f"), f(r["own_psnr"], "%.1f"), mem(r, "own"),
                            r["raytrace_ms_range"], mem(r, "raytrace"), r["pov_ms_range"], f(r["pov_psnr"], "%.1f"),
                            f(r["ab_over_rt"], "%.2f"), f(r["ab_over_pov"], "%.2f"), r["goal"]))
        lines += ["", "At matched error: the tracer's ladder (ms, dB) and each abuffer image's matched rung.", "",
                  "| scene | " + " | ".join("%d spp" % spp for spp in RUNGS) + " | target dB: rung, ms, ratio | "
                  "own dB: rung, ms, ratio |", "|---|" + "---|" * len(RUNGS) + "---|---|"]
        for r in rs:
            lines.append("| %s | %s | %.1f: %d, %.0f, **%.2f** | %.1f: %d, %.0f, %.2f |" % (
                r["scene"], " | ".join("%.0f, %.1f" % (r["rung%d_ms" % spp], r["rung%d_psnr" % spp]) for spp in RUNGS),
                r["target_psnr"], r["target_rung"], r["target_rung_ms"], r["target_over_rung"],
                r["own_psnr"], r["own_rung"], r["own_rung_ms"], r["own_over_rung"]))
        lines += ["", "abuffer at the target, ms of the last timed run: load / pilots / cube A-buffer / "
                  "camera A-buffer / shade and resolve", ""]
        for r in rs:
            lines.append("- %s: %s / %s / %s / %s / %s" % (
                r["scene"], f(r["load_ms"], "%.0f"), f(r["pilots_ms"], "%.0f"), f(r["cube_ms"], "%.0f"),
                f(r["camera_ms"], "%.0f"), f(r["shade_ms"], "%.0f")))
        lines.append("")
    text = "\n".join(lines)
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
