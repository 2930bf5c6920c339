#!/usr/bin/python3
"""gpu_abuffer with its searches on the GPU against the same method with them on the CPU.

    /usr/bin/python3 bench/gpu_searches.py [--abcube build/abcube] [--gl egl] [--runs 3]
        [--size 120x90] [--cube-res 96] [--seed 5000] [--count 4]
        [--out bench/results/gpu_searches_llvmpipe]

The scenes: the repository's (scenes/*.json) and `--count` generated hard scenes
(tools/hard_scenes.py, the templates cycled), all at --size and --cube-res. Each is rendered
by `gpu_abuffer --search-on cpu` and `--search-on gpu`, interleaved, --runs times. The table
gives the median wall time of the whole process [min, max], the median scan time of the
GPU, the passes, the rays scanned, the texels their scans walked a ray, the share of scans a
STOP HINT ended and the rays scanned again whole, the answers the last pass used, and whether
the two images are the same bytes (they must be). Writes OUT.md.
"""
import argparse
import filecmp
import glob
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def render(args, scene, on, out_dir, k):
    image = os.path.join(out_dir, f"{os.path.basename(scene)}_{on}_{k}.exr")
    stats = image + ".json"
    w, h = args.size.split("x")
    t0 = time.monotonic()
    subprocess.run([args.abcube, "render", scene, "--method", "gpu_abuffer", "--search-on", on, "--gl", args.gl,
                    "--width", w, "--height", h, "--cube-res", str(args.cube_res), "-o", image, "--stats", stats],
                   check=True, stdout=subprocess.DEVNULL)
    seconds = time.monotonic() - t0
    return seconds, json.load(open(stats)), image


def spread(values):
    return f"{statistics.median(values):.2f} [{min(values):.2f}, {max(values):.2f}]"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--abcube", default=os.path.join(ROOT, "build", "abcube"))
    ap.add_argument("--gl", default="egl")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--size", default="120x90")
    ap.add_argument("--cube-res", type=int, default=96)
    ap.add_argument("--seed", type=int, default=5000)
    ap.add_argument("--count", type=int, default=4)
    ap.add_argument("--out", default=os.path.join(ROOT, "bench", "results", "gpu_searches_llvmpipe"))
    args = ap.parse_args()
    work = tempfile.mkdtemp(prefix="abcube_gpu_searches.")
    subprocess.run([sys.executable, os.path.join(ROOT, "tools", "hard_scenes.py"), "--seed", str(args.seed), "--count",
                    str(args.count), "--out", os.path.join(work, "gen")], check=True, stdout=subprocess.DEVNULL)
    scenes = sorted(glob.glob(os.path.join(ROOT, "scenes", "*.json"))) + sorted(glob.glob(os.path.join(work, "gen",
                                                                                                    "*.json")))
    rows = []
    for scene in scenes:
        times = {"cpu": [], "gpu": []}
        scan, last = [], {}
        for k in range(args.runs):
            for on in ("cpu", "gpu"):
                seconds, stats, image = render(args, scene, on, work, k)
                times[on].append(seconds)
                last[on] = image
                if on == "gpu":
                    scan.append(stats["timings_ms"].get("gpu_search_scan", 0.0) / 1000.0)
                    deferred = stats["searches"]["deferred"]
        same = filecmp.cmp(last["cpu"], last["gpu"], shallow=False)
        rays = max(deferred["rays"], 1)
        rows.append((os.path.basename(scene), spread(times["cpu"]), spread(times["gpu"]),
                     f"{statistics.median(scan):.2f}", deferred["passes"], deferred["rays"],
                     f"{deferred['texels'] / rays:.0f}", f"{100.0 * deferred['stopped'] / rays:.0f}%",
                     deferred["rescanned"], deferred["answers_used"], "yes" if same else "NO",
                     statistics.median(times["gpu"]) / statistics.median(times["cpu"])))
        print(rows[-1], flush=True)
    renderer = stats["gl"]["renderer"]
    with open(args.out + ".md", "w") as f:
        f.write("# gpu_abuffer: the searches on the GPU against the CPU\n\n")
        f.write(f"GL: {renderer}. {os.cpu_count()} cores. `/usr/bin/python3 bench/gpu_searches.py --gl {args.gl} "
                f"--runs {args.runs} --size {args.size} --cube-res {args.cube_res} --seed {args.seed} "
                f"--count {args.count}`. Wall seconds of the whole process, median [min, max] of {args.runs} "
                "interleaved runs; the GPU's scan time is the median of `timings_ms.gpu_search_scan`.\n\n")
        f.write("| scene | --search-on cpu s | --search-on gpu s | GPU scan s | passes | rays scanned | texels a ray "
                "| ended by a stop hint | scanned again | answers used | same bytes | gpu / cpu |\n"
                "|---|---|---|---|---|---|---|---|---|---|---|---|\n")
        for r in rows:
            f.write("| " + " | ".join(str(x) for x in r[:-1]) + f" | {r[-1]:.1f} |\n")
    print("wrote", args.out + ".md")


if __name__ == "__main__":
    main()
