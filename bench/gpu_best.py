#!/usr/bin/python3
"""The gpu method at its best, and hybrid (issue 19): speed against error beside abuffer
and raytrace, on generated scenes and the repository's.

    /usr/bin/python3 bench/gpu_best.py [--abcube build/abcube] [--seeds 2,3,4] [--size 640x480]
                                       [--cube-res 512] [--runs 3] [--out bench/results]

Scenes: tools/flat_mirror_scenes.py (every template for each seed: mirrors all flat), one
scene of each tools/hard_scenes.py template (first seed), the repository's scenes/*.json,
scenes/models/engine_room.json. Methods: raytrace (the reference), abuffer at the scene's
N, gpu (exact camera pass: stencil mirrors, shadow volumes), gpu_maps (the old techniques:
--gpu-mirrors envmap --gpu-shadows maps), hybrid (its camera pass shaded once a pixel and
surface), hybrid_samples (--gpu-shading samples: once a sample). Each render is a whole `abcube render`
process, the methods interleaved, `--runs` times; the time is the program's own total
(stats timings_ms.total: load, GL start, passes; not the process start), median [min,
max]; the error is PSNR against raytrace on displayed values. Writes NAME.csv and NAME.md
(NAME = gpu_best) in --out. Python 3 standard library only.
"""
import argparse
import csv
import json
import os
import statistics
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import psnr, run  # noqa: E402

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
METHODS = [("abuffer", ["--method", "abuffer"]), ("gpu", ["--method", "gpu"]),
           ("gpu_maps", ["--method", "gpu", "--gpu-mirrors", "envmap", "--gpu-shadows", "maps"]),
           ("hybrid", ["--method", "hybrid"]), ("hybrid_samples", ["--method", "hybrid", "--gpu-shading", "samples"])]


def render(abcube, scene, out, args, stats):
    run([abcube, "render", scene, "-o", out, "--stats", stats] + args)
    with open(stats) as f:
        s = json.load(f)
    return s["timings_ms"]["total"], s


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--abcube", default=os.path.join(REPO, "build", "abcube"))
    ap.add_argument("--seeds", default="2,3,4")
    ap.add_argument("--size", default="640x480")
    ap.add_argument("--cube-res", type=int, default=512)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--out", default=os.path.join(REPO, "bench", "results"))
    ap.add_argument("--name", default="gpu_best")
    ap.add_argument("--no-repo", action="store_true", help="generated scenes only")
    a = ap.parse_args(argv)
    work = tempfile.mkdtemp(prefix="abcube_gpu_best.")
    py = "/usr/bin/python3"
    scenes = []  # (set, path)
    seeds = [int(s) for s in a.seeds.split(",") if s]
    sys.path.insert(0, os.path.join(REPO, "tools"))
    import flat_mirror_scenes  # noqa: E402 (every template once a seed)
    for seed in seeds:
        out = run([py, os.path.join(REPO, "tools", "flat_mirror_scenes.py"), "--seed", str(seed), "--count",
                   str(len(flat_mirror_scenes.TEMPLATES)),
                   "--out", os.path.join(work, "flat"), "--size", a.size, "--cube-res", str(a.cube_res)])
        scenes += [("flat mirrors", p) for p in out.split()]
    if not a.no_repo:
        out = run([py, os.path.join(REPO, "tools", "hard_scenes.py"), "--seed", str(seeds[0]), "--count", "11",
                   "--out", os.path.join(work, "hard"), "--size", a.size, "--cube-res", str(a.cube_res)])
        scenes += [("hard templates", p) for p in out.split()]
        scenes += [("repository", os.path.join(REPO, "scenes", n)) for n in
                   ("cornell.json", "default.json", "hidden_point.json", "shadows.json", "textured.json")]
        scenes += [("repository", os.path.join(REPO, "scenes", "models", "engine_room.json"))]
    rows = []
    load = os.getloadavg()[0]
    t_start = time.time()
    for set_name, scene in scenes:
        stem = os.path.splitext(os.path.basename(scene))[0]
        ref = os.path.join(work, stem + ".raytrace.exr")
        rt_ms, _ = render(a.abcube, scene, ref, ["--method", "raytrace"], os.path.join(work, "s.json"))
        times = {m: [] for m, _ in METHODS}
        stats = {}
        for r in range(a.runs):
            for m, args in METHODS:
                ms, s = render(a.abcube, scene, os.path.join(work, "%s.%s.exr" % (stem, m)), args,
                               os.path.join(work, "s.json"))
                times[m].append(ms)
                stats[m] = s
        row = {"set": set_name, "scene": stem, "raytrace_ms": round(rt_ms)}
        for m, _ in METHODS:
            v = sorted(times[m])
            row[m + "_ms"] = round(statistics.median(v))
            row[m + "_ms_min"], row[m + "_ms_max"] = round(v[0]), round(v[-1])
            row[m + "_db"] = round(psnr(a.abcube, os.path.join(work, "%s.%s.exr" % (stem, m)), ref), 2)
        h = stats["hybrid"].get("hybrid", {})
        row["hybrid_cpu_share"] = round(h.get("pixels_cpu", 0) / max(h.get("pixels", 1), 1), 3)
        g = stats["gpu"].get("gpu_paths", {})
        row["gpu_mirrors"] = g.get("planar_mirrors", {}).get("technique", "")
        row["gpu_shadows"] = g.get("shadows", {}).get("technique", "")
        rows.append(row)
        print("%-16s %-30s rt %6d  ab %6.2f dB %5d ms  gpu %6.2f dB %5d ms  old %6.2f dB  hybrid %6.2f dB %5d ms (cpu %3.0f%%)"
              % (set_name, stem, rt_ms, row["abuffer_db"], row["abuffer_ms"], row["gpu_db"], row["gpu_ms"],
                 row["gpu_maps_db"], row["hybrid_db"], row["hybrid_ms"], 100 * row["hybrid_cpu_share"]),
              file=sys.stderr, flush=True)
    os.makedirs(a.out, exist_ok=True)
    with open(os.path.join(a.out, a.name + ".csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    L = ["# The gpu method at its best, and hybrid", "",
         "Written by `bench/gpu_best.py` %s UTC; %s; %s, cube N = %d, `--runs %d`, 2 threads (the default)."
         % (time.strftime("%Y-%m-%d %H:%M", time.gmtime()), run([a.abcube, "--version"]).strip(), a.size, a.cube_res,
            a.runs),
         "Load average (1 min) %.2f at start, %.2f at end; %.0f s in all." % (load, os.getloadavg()[0], time.time() - t_start),
         "", "Times: the program's own total (load, GL start, passes, not the process start), median of the runs "
         "[min, max], ms. Errors: PSNR against raytrace (displayed values), dB. `gpu_maps`: the old techniques "
         "(`--gpu-mirrors envmap --gpu-shadows maps`). `hybrid_samples`: hybrid with `--gpu-shading samples` "
         "(the GPU's colour shaded once a sample, as before per-pixel shading). `cpu`: the share of pixels hybrid "
         "sent to the CPU.", ""]
    flat = [r for r in rows if r["set"] == "flat mirrors"]
    if flat:
        faster = sum(r["hybrid_ms"] < r["abuffer_ms"] for r in flat)
        apart = sum(r["hybrid_ms_max"] < r["abuffer_ms_min"] for r in flat)
        slower_apart = sum(r["hybrid_ms_min"] > r["abuffer_ms_max"] for r in flat)
        worse = sum(r["hybrid_db"] < r["abuffer_db"] for r in rows)
        ratios = sorted(r["hybrid_ms"] / r["abuffer_ms"] for r in flat)
        L += ["Flat mirrors, hybrid against abuffer: median faster on %d of %d scenes (every run faster on %d, every "
              "run slower on %d); hybrid's time over abuffer's %.2f-%.2f (median %.2f). hybrid less accurate than "
              "abuffer on %d of %d scenes in all." % (faster, len(flat), apart, slower_apart, ratios[0], ratios[-1],
                                                     statistics.median(ratios), worse, len(rows)), ""]
    L += ["| set | scene | raytrace ms | abuffer dB | ms | gpu dB | ms | gpu_maps dB | ms | hybrid dB | ms | cpu "
          "| hybrid_samples dB | ms |",
          "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        L.append("| %s | %s | %d | %.2f | %d [%d, %d] | %.2f | %d [%d, %d] | %.2f | %d | %.2f | %d [%d, %d] | %.0f%% "
                 "| %.2f | %d [%d, %d] |" % (
            r["set"], r["scene"], r["raytrace_ms"], r["abuffer_db"], r["abuffer_ms"], r["abuffer_ms_min"],
            r["abuffer_ms_max"], r["gpu_db"], r["gpu_ms"], r["gpu_ms_min"], r["gpu_ms_max"], r["gpu_maps_db"],
            r["gpu_maps_ms"], r["hybrid_db"], r["hybrid_ms"], r["hybrid_ms_min"], r["hybrid_ms_max"],
            100 * r["hybrid_cpu_share"], r["hybrid_samples_db"], r["hybrid_samples_ms"], r["hybrid_samples_ms_min"],
            r["hybrid_samples_ms_max"]))
    with open(os.path.join(a.out, a.name + ".md"), "w") as f:
        f.write("\n".join(L) + "\n")
    print("wrote %s.{csv,md}" % os.path.join(a.out, a.name), file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
