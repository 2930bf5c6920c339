#!/usr/bin/python3
"""One abuffer option's two values side by side: error against the tracer, time, edges.

    /usr/bin/python3 bench/ab_option.py [--option shadow_edges] [--values points,samples]
        [--abcube build/abcube] [--baseline OTHER_ABCUBE] [--runs 3] [--seed 5000] [--count 12]
        [--templates a,b,...]
        [--size 160x120] [--cube-res 128] [--generated-only] [--threads 2]
        [--out bench/results/shadow_edges]

The scenes: the repository's (scenes/*.json at their own size), the race's seeded room and
outdoor scenes (bench/race_scenes.py, at their own size) and `--count` generated hard
scenes (tools/hard_scenes.py: the templates cycled, at --size and --cube-res); with
--generated-only, those alone. Each is traced once by raytrace,
the reference, and rendered by abuffer with the option's two values (the first the
baseline: --shadow-edges points and samples, or --texture-lookups points and samples), interleaved,
--runs times; the table gives the median wall time of the whole process, the median
shade-and-resolve time from the stats, the PSNR of each against the reference (sRGB, as
`abcube compare`), and what the edges cost: the share of multi-point fragments refined,
the sample searches, the pixels shaded again and the shadow rays beside the points'.

With --baseline, the first value is rendered by that program instead (two builds side by
side: --option none --values before,after --baseline old/abcube passes no option at all).

Writes OUT.md and OUT.csv, and prints the machine load before and after.
"""
import argparse
import csv
import glob
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(REPO, "tools"))
import hard_scenes  # noqa: E402  (the generator: same templates, same seeds)
sys.path.insert(0, os.path.join(REPO, "bench"))
from common import psnr, run  # noqa: E402


def scenes(work, args):
    found = []
    if not args.generated_only:
        found += [(os.path.basename(p)[:-5], p, []) for p in sorted(glob.glob(os.path.join(REPO, "scenes", "*.json")))]
        race_dir = os.path.join(work, "race")
        listing = subprocess.run([sys.executable, os.path.join(REPO, "bench", "race_scenes.py"), "--out", race_dir,
                                  "--seed", str(args.seed), "--templates", "room,outdoor"],
                                 check=True, capture_output=True, text=True).stdout.split()
        found += [(os.path.basename(p)[:-5], p, []) for p in listing if p.endswith(".json")]
    hard_dir = os.path.join(work, "hard")
    run([sys.executable, os.path.join(REPO, "tools", "hard_scenes.py"), "--seed", str(args.seed), "--count",
         str(args.count), "--out", hard_dir, "--size", args.size, "--cube-res", str(args.cube_res),
         "--templates", args.templates])
    found += [(os.path.basename(p)[:-5], p, []) for p in sorted(glob.glob(os.path.join(hard_dir, "*.json")))]
    return found


def load():
    with open("/proc/loadavg") as f:
        return f.read().split()[0]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--option", default="shadow_edges", help="the option, as its batch key")
    ap.add_argument("--values", default="points,samples", help="its two values: the baseline, then the other")
    ap.add_argument("--abcube", default=os.path.join(REPO, "build", "abcube"))
    ap.add_argument("--baseline", help="another abcube program for the first value")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--seed", type=int, default=5000)
    ap.add_argument("--count", type=int, default=len(hard_scenes.TEMPLATES))
    ap.add_argument("--templates", default=",".join(hard_scenes.TEMPLATES))
    ap.add_argument("--size", default="160x120")
    ap.add_argument("--cube-res", type=int, default=128)
    ap.add_argument("--generated-only", action="store_true")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--out", default=os.path.join(REPO, "bench", "results", "shadow_edges"))
    args = ap.parse_args()
    flag = "--" + args.option.replace("_", "-")
    modes = tuple(args.values.split(","))
    if len(modes) != 2:
        ap.error("--values takes two values, the baseline first")
    load_before = load()
    rows = []
    with tempfile.TemporaryDirectory() as work:
        for name, path, extra in scenes(work, args):
            base = [args.abcube, "render", path, "--gl", "none", "--threads", str(args.threads)] + extra
            reference = os.path.join(work, name + "_rt.exr")
            run(base + ["--method", "raytrace", "-o", reference])
            result = {"scene": name}
            walls = {mode: [] for mode in modes}
            shade = {mode: [] for mode in modes}
            for _ in range(args.runs):
                for mode in modes:
                    image = os.path.join(work, f"{name}_{mode}.exr")
                    stats_path = os.path.join(work, f"{name}_{mode}.json")
                    start = time.perf_counter()
                    program = base[:]
                    if args.baseline and mode == modes[0]:
                        program[0] = args.baseline
                    option = [] if args.option == "none" else [flag, mode]
                    run(program + ["--method", "abuffer"] + option + ["-o", image, "--stats", stats_path])
                    walls[mode].append(1000 * (time.perf_counter() - start))
                    with open(stats_path) as f:
                        stats = json.load(f)
                    shade[mode].append(stats["timings_ms"]["shade_and_resolve"])
                    result[f"{mode}_shadow_rays"] = stats["searches"]["shadow"]["rays"]
                    if mode == modes[1]:
                        result["edges"] = stats["searches"]["shadow_edges"]
                    result["size"] = f'{stats["size"]["width"]}x{stats["size"]["height"]}'
                    result["n"] = stats["size"]["cube_resolution"]
            for mode in modes:
                result[f"{mode}_db"] = psnr(args.abcube, os.path.join(work, f"{name}_{mode}.exr"), reference)
                result[f"{mode}_ms"] = statistics.median(walls[mode])
                result[f"{mode}_shade_ms"] = statistics.median(shade[mode])
            rows.append(result)
            e = result["edges"]
            a, b = modes
            print(f'{name}: {result[a + "_db"]:.2f} -> {result[b + "_db"]:.2f} dB, '
                  f'{result[a + "_ms"]:.0f} -> {result[b + "_ms"]:.0f} ms, refined {e["share"]:.4f}', flush=True)
    load_after = load()
    a, b = modes
    with open(args.out + ".csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["scene", "size", "n", a + "_db", b + "_db", a + "_ms", b + "_ms", a + "_shade_ms",
                    b + "_shade_ms", "refined_share", "sample_searches", "pixels_again", a + "_shadow_rays",
                    b + "_shadow_rays"])
        for r in rows:
            e = r["edges"]
            w.writerow([r["scene"], r["size"], r["n"], f'{r[a + "_db"]:.2f}', f'{r[b + "_db"]:.2f}',
                        f'{r[a + "_ms"]:.0f}', f'{r[b + "_ms"]:.0f}', f'{r[a + "_shade_ms"]:.0f}',
                        f'{r[b + "_shade_ms"]:.0f}', f'{e["share"]:.5f}', e["sample_searches"],
                        e["pixels_shaded_again"], r[a + "_shadow_rays"], r[b + "_shadow_rays"]])
    gains = [r[b + "_db"] - r[a + "_db"] for r in rows]
    costs = [r[b + "_ms"] / r[a + "_ms"] for r in rows]
    with open(args.out + ".md", "w") as f:
        f.write(f"# abuffer {flag} {a} against {b} (bench/ab_option.py)\n\n")
        templates = "" if args.templates == ",".join(hard_scenes.TEMPLATES) else f" --templates {args.templates}"
        only = " --generated-only" if args.generated_only else ""
        baseline = f" --baseline {args.baseline}" if args.baseline else ""
        f.write(f"Command: `bench/ab_option.py --option {args.option} --values {args.values}{baseline} --runs {args.runs} --seed {args.seed} --count {args.count}{templates} "
                f"--size {args.size} --cube-res {args.cube_res}{only} --threads {args.threads}`  \n")
        f.write(f"{os.cpu_count()} cores, {args.threads} threads, load {load_before} before, {load_after} after; "
                f"median of {args.runs} interleaved runs, whole processes.  \n")
        f.write("PSNR: sRGB dB against `raytrace`. ms: the whole process (shade and resolve in brackets). "
                "refined: the share of multi-point fragments whose shadow was searched per sample; "
                f"searches: those sample searches; again: pixels shaded a second time ({b}); rays: shadow rays, "
                f"{a} -> {b}.\n\n")
        f.write(f"| scene | size | N | {a} dB | {b} dB | gain dB | {a} ms | {b} ms | time x | refined | "
                "searches | again | shadow rays |\n|---|---|---:|---:|---:|---:|---|---|---:|---:|---:|---:|---|\n")
        for r, g, c in zip(rows, gains, costs):
            e = r["edges"]
            f.write(f'| {r["scene"]} | {r["size"]} | {r["n"]} | {r[a + "_db"]:.2f} | {r[b + "_db"]:.2f} | '
                    f'{g:+.2f} | {r[a + "_ms"]:.0f} ({r[a + "_shade_ms"]:.0f}) | '
                    f'{r[b + "_ms"]:.0f} ({r[b + "_shade_ms"]:.0f}) | {c:.2f} | {e["share"]:.4f} | '
                    f'{e["sample_searches"]} | {e["pixels_shaded_again"]} | '
                    f'{r[a + "_shadow_rays"]} -> {r[b + "_shadow_rays"]} |\n')
        for mode in modes:
            dbs = sorted(r[f"{mode}_db"] for r in rows)
            tenth = dbs[int(0.1 * (len(dbs) - 1))]   # the nearest rank at or below
            f.write(f"\n{mode}: median {statistics.median(dbs):.2f} dB, 10th percentile {tenth:.2f}, "
                    f"worst {dbs[0]:.2f}.")
        f.write("\n")
        f.write(f"\nOver {len(rows)} scenes: gain median {statistics.median(gains):+.2f} dB "
                f"(min {min(gains):+.2f}, max {max(gains):+.2f}); time ratio median {statistics.median(costs):.2f} "
                f"(min {min(costs):.2f}, max {max(costs):.2f}).\n")
    print(f"wrote {args.out}.md and {args.out}.csv")


if __name__ == "__main__":
    main()
