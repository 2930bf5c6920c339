#!/usr/bin/python3
"""Whole renders before and after the hierarchical searches (issue 14 part 1).

For each scene and cube resolution N, renders `--method abuffer` with two abcube programs
(BEFORE: a build without the hierarchical skip; AFTER: this one), interleaved, `--repeat`
times each, and records per program the render ms (stats timings total less write, median
of the runs), shade_and_resolve ms, texels and pyramid nodes visited per search ray by kind,
peak RSS and the PSNR against the exact tracer's image (`--method raytrace`, rendered once
per scene by AFTER). The two programs' images must be identical (`abcube compare --exact`):
the hierarchy changes no answer. Then, when --bench-search is given, runs bench_search
(reflection and shadow rays, one thread, hierarchy off and on) on the same scenes and sizes.
Writes a markdown report (tables, commands, machine, load) to --out.

Usage: hier_search.py --before OLD/abcube --after build/abcube [--bench-search build/bench/bench_search]
                      [--scenes A.json,B.json@320x320] [--race room,outdoor] [--race-seed 1]
                      [--sizes 128,256,512,1024,2048] [--repeat 3]
                      [--threads 2] [--rays 3000] [--runs 5] [--out bench/results/hier_search.md]
                      [--lock /tmp/abcube.build.lock]
A scene written SCENE@WxH is rendered at that size (a copy of its JSON with the camera's
width and height changed, written next to the run's other files: scenes without mesh files).
--race adds bench/race_scenes.py's seeded scenes (room: the 320x320 room of chrome and glass
spheres at max_depth 4 of issue 14; outdoor: terrain under a sky).
Python 3 standard library only.
"""
import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time

KINDS = (("reflection", "refl"), ("refraction_exit", "refr"), ("shadow", "shadow"))


LOCK = []  # ["flock", FILE] with --lock: each program run holds the machine's lock


def run(cmd, check=True):
    cmd = LOCK + cmd
    start = time.monotonic()
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    ms = (time.monotonic() - start) * 1e3
    if check and p.returncode != 0:
        sys.exit("failed (%d): %s\n%s" % (p.returncode, " ".join(cmd), p.stderr.strip()[-2000:]))
    return p, ms


def scene_file(spec, work):
    """SCENE or SCENE@WxH -> (path to render, label)."""
    if "@" not in spec:
        return spec, os.path.basename(spec)
    path, size = spec.split("@")
    w, h = (int(v) for v in size.split("x"))
    with open(path) as f:
        scene = json.load(f)
    scene["camera"]["width"], scene["camera"]["height"] = w, h
    out = os.path.join(work, "%s_%dx%d.json" % (os.path.splitext(os.path.basename(path))[0], w, h))
    with open(out, "w") as f:
        json.dump(scene, f)
    return out, "%s %dx%d" % (os.path.basename(path), w, h)


def render(abcube, scene, n, ref, out, stats, threads):
    run([abcube, "render", scene, "-o", out, "--method", "abuffer", "--cube-res", str(n), "--threads", str(threads),
         "--gl", "none", "--reference-image", ref, "--stats", stats])
    with open(stats) as f:
        s = json.load(f)
    t = s["timings_ms"]
    row = {"ms": t["total"] - t.get("write", 0.0), "shade_ms": t.get("shade_and_resolve"),
           "psnr": s.get("reference", {}).get("image_error", {}).get("psnr_db"),
           "rss_mib": s.get("memory", {}).get("peak_rss_bytes", 0) / 2**20}
    for kind, short in KINDS:
        k = s.get("searches", {}).get(kind, {})
        row[short + "_rays"] = k.get("rays", 0)
        row[short + "_visits"] = k.get("texels_mean", 0.0) + k.get("nodes_mean", 0.0)
        row[short + "_nodes"] = k.get("nodes_mean", 0.0)
    return row


def median_row(rows):
    out = dict(rows[0])
    for key in ("ms", "shade_ms"):
        out[key] = statistics.median(r[key] for r in rows)
        out[key + "_min"] = min(r[key] for r in rows)
        out[key + "_max"] = max(r[key] for r in rows)
    return out


def fmt_psnr(v):
    return "-" if v is None else ("inf" if v == "inf" or v == float("inf") else "%.2f" % float(v))


def search_summary(bench_output):
    """bench_search's rows -> a markdown table: per scene, N and kind, visits, fragments and
    ns per ray with the hierarchy off and on."""
    rows = {}
    for line in bench_output.splitlines():
        f = line.split()
        if len(f) < 20 or line.startswith("#") or f[0] == "scene":
            continue
        scene, n, kind, hier = f[0], int(f[1]), f[3], f[4]
        rows.setdefault((scene, n, kind), {})[hier] = {"visits": float(f[11]), "frags": float(f[13]),
                                                       "ns": float(f[15]), "ns_min": float(f[16])}
    out = ["| scene | N | kind | visits/ray off | on | x | fragments tested/ray (both) | ns/ray off [min] | "
           "on [min] | x |", "|---|---|---|---|---|---|---|---|---|---|"]
    for (scene, n, kind), r in rows.items():
        if "off" not in r or "on" not in r:
            continue
        a, b = r["off"], r["on"]
        out.append("| %s | %d | %s | %.1f | %.1f | %.1f | %.1f | %.0f [%.0f] | %.0f [%.0f] | %.2f |" % (
            os.path.basename(scene), n, kind, a["visits"], b["visits"], a["visits"] / b["visits"], b["frags"],
            a["ns"], a["ns_min"], b["ns"], b["ns_min"], a["ns"] / b["ns"]))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--before", required=True, help="abcube without the hierarchical skip")
    ap.add_argument("--after", required=True, help="abcube with it")
    ap.add_argument("--bench-search", default="", help="bench_search of AFTER (optional)")
    ap.add_argument("--scenes", default="scenes/bench/spheres_terrain.json,scenes/cornell.json@320x320,"
                    "scenes/default.json")
    ap.add_argument("--race", default="room,outdoor",
                    help="also bench/race_scenes.py's templates (seeded; empty: none)")
    ap.add_argument("--race-seed", type=int, default=1)
    ap.add_argument("--sizes", default="128,256,512,1024,2048")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--rays", type=int, default=3000, help="bench_search rays per scene and kind")
    ap.add_argument("--runs", type=int, default=5, help="bench_search timed runs per row")
    ap.add_argument("--out", default="bench/results/hier_search.md")
    ap.add_argument("--lock", default="", help="run every program under flock LOCK (a machine shared by builds)")
    a = ap.parse_args()
    if a.lock:
        LOCK[:] = ["flock", a.lock]
    sizes = [int(v) for v in a.sizes.split(",")]
    work = tempfile.mkdtemp(prefix="hier_search.")
    load_start = os.getloadavg()
    lines = ["# Hierarchical searches (issue 14 part 1): before and after", "",
             "Command: `%s`" % " ".join([os.path.basename(sys.argv[0])] + sys.argv[1:]), "",
             "Machine: %s, %d cores (shared with other work: timings are noisy), %s; load average at start %.2f"
             % (platform.node(), os.cpu_count(), platform.platform(), load_start[0]), ""]
    tables = []
    specs = [s for s in a.scenes.split(",") if s]
    if a.race:
        p, _ = run([sys.executable, os.path.join(os.path.dirname(os.path.abspath(__file__)), "race_scenes.py"),
                    "--out", work, "--seed", str(a.race_seed), "--templates", a.race])
        specs += p.stdout.split()
    for spec in specs:
        scene, label = scene_file(spec, work)
        ref = os.path.join(work, "ref.exr")
        run([a.after, "render", scene, "-o", ref, "--method", "raytrace", "--threads", str(a.threads), "--gl", "none"])
        table = ["### %s" % label, "",
                 "| N | render ms before | after | x | shade_and_resolve ms before | after | shadow visits/ray before "
                 "| after (nodes) | reflection visits/ray before | after (nodes) | refraction visits/ray before "
                 "| after (nodes) | PSNR dB before | after | images | peak RSS MiB before | after |",
                 "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for n in sizes:
            runs = {"before": [], "after": []}
            for rep in range(a.repeat):
                for which in ("before", "after"):
                    prog = a.before if which == "before" else a.after
                    out = os.path.join(work, "%s_%d.exr" % (which, rep))
                    runs[which].append(render(prog, scene, n, ref, out, os.path.join(work, "s.json"), a.threads))
            same = all(run([a.after, "compare", os.path.join(work, "before_%d.exr" % r),
                            os.path.join(work, "after_%d.exr" % r), "--exact"], check=False)[0].returncode == 0
                       for r in range(a.repeat))
            b, f = median_row(runs["before"]), median_row(runs["after"])
            cells = [str(n), "%.0f [%.0f, %.0f]" % (b["ms"], b["ms_min"], b["ms_max"]),
                     "%.0f [%.0f, %.0f]" % (f["ms"], f["ms_min"], f["ms_max"]), "%.2f" % (b["ms"] / f["ms"]),
                     "%.0f" % b["shade_ms"], "%.0f" % f["shade_ms"]]
            for short in ("shadow", "refl", "refr"):
                if b[short + "_rays"] == 0:
                    cells += ["-", "-"]
                else:
                    cells += ["%.1f" % b[short + "_visits"], "%.1f (%.1f)" % (f[short + "_visits"], f[short + "_nodes"])]
            cells += [fmt_psnr(b["psnr"]), fmt_psnr(f["psnr"]), "identical" if same else "DIFFER",
                      "%.0f" % b["rss_mib"], "%.0f" % f["rss_mib"]]
            table.append("| " + " | ".join(cells) + " |")
            print(table[-1], flush=True)
        tables += table + [""]
    lines += ["## Whole renders (`abcube render --method abuffer --gl none --threads %d`)" % a.threads, "",
              "Render ms = stats timings total less write: median of %d runs [min, max], before and after "
              "interleaved. Visits = texels the walk stepped on + pyramid nodes it stepped over, per search ray "
              "(stats texels_mean + nodes_mean). PSNR against the exact tracer's image of the same scene; "
              "images: `abcube compare --exact` of every pair of runs." % a.repeat, ""] + tables
    if a.bench_search:
        outs = []
        for spec in specs:  # one scene a run: the lock is held a few minutes at most
            p, _ = run([a.bench_search, scene_file(spec, work)[0], "--sizes", a.sizes, "--modes", "crossing",
                        "--rays", str(a.rays), "--runs", str(a.runs)])
            outs.append(p.stdout.rstrip() if not outs else p.stdout.rstrip().split("\n", 2)[2])
            print(outs[-1], flush=True)
        out = "\n".join(outs).replace(work + "/", "")  # the resized copies by their names
        lines += ["## Search rays alone (`bench_search`, one thread, hierarchy off = the plain walk)", "",
                  "Median of %d runs over the same %d rays per scene and kind; x = off / on." % (a.runs, a.rays), ""]
        lines += search_summary(out) + ["", "bench_search's output:", "", "```", out, "```", ""]
    lines += ["Load average at end: %.2f" % os.getloadavg()[0], ""]
    with open(a.out, "w") as f:
        f.write("\n".join(lines))
    print("wrote", a.out)


if __name__ == "__main__":
    main()
