#!/usr/bin/env python3
"""Speed against error: every method of abcube over cube resolutions N and scenes.

    python3 bench/sweep.py [--abcube build/abcube] [--scenes a.json,b.json] [--sizes 64,128,...]
                           [--methods gpu,envmap_R,...] [--out bench/results] [--threads 2] [--quick]

Per scene: the exact reference (`render --method raytrace`, its time is the raytrace row),
POV-Ray on the exported scene, then every N-dependent method at every N, each one
`abcube render --threads T --cube-res N --reference-image REF.exr --stats S.json`. Then the
thesis figures (abuffer_thesis at N = 100, 200, 300, thesis 9.3.4) and what the plan's
skips save (abuffer_crossing at the scene's own N, --plan everything against --plan
needed, median of 3), and bound_geometry.py's model of where 1/(2N^2) breaks. Outputs in
--out, named NAME.* (NAME = sweep, or sweep_quick with --quick): NAME.csv (one row per run),
NAME.md (tables), NAME.error_vs_time.svg, NAME.parallax_vs_N.svg, NAME.bound_geometry.csv,
NAME.stats.jsonl (every run's --stats as written). bench/README.md explains the columns. Python 3 standard library only. A failed run is recorded with its
error and the sweep goes on; the exit status is 1 if any run failed.
"""
import argparse
import csv
import glob
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
import time

from bound_geometry import GEOMETRY_STEP, THETA_MAX_DEG, bound_geometry

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# Method variants: the abcube arguments of each (N-dependent); raytrace and povray are special.
MAP_METHODS = {
    "gpu": ["--method", "gpu"],
    "envmap_R": ["--method", "envmap", "--envmap-lookup", "R"],
    "envmap_bisector": ["--method", "envmap", "--envmap-lookup", "bisector"],
    "zbuffer": ["--method", "zbuffer"],
    "abuffer_thesis": ["--method", "abuffer", "--search", "thesis"],
    "abuffer_crossing": ["--method", "abuffer", "--search", "crossing"],
    "abuffer_plane": ["--method", "abuffer", "--search", "crossing", "--refine", "plane"],
    "thick_lens": ["--method", "abuffer", "--refraction", "thick_lens"],
    "thin_lens": ["--method", "abuffer", "--refraction", "thin_lens"],
}
# The exact tracer's ladder below its 32 samples a pixel (N-independent): each map method's
# row is held to the fastest rung at least as close to the reference, its matched rung.
LADDER = {"raytrace_%dspp" % s: ["--method", "raytrace", "--samples", str(s)] for s in (1, 2, 4, 8, 16)}
ALL_METHODS = list(MAP_METHODS) + ["raytrace", "povray"] + list(LADDER)
LENS_METHODS = ("thick_lens", "thin_lens")
DEFAULT_SIZES = [64, 128, 256, 512, 1024, 2048]
QUICK_SIZES = [64, 128, 256]
QUICK_SCENES = ["scenes/hidden_point.json", "scenes/cornell.json"]
# A real model in a room with a mirror and glass (issue 15 part 6; its model comes with
# assimp-testmodels, installed by tools/setup.sh).
MODEL_SCENES = ["scenes/models/engine_room.json"]
THESIS_SIZES = [100, 200, 300]
THESIS_FIGURES = {100: 5e-5, 200: 1.25e-5, 300: 5.5e-6}  # thesis 9.3.4, as printed
THESIS_SCENES = ("hidden_point", "cornell")
SKIP_REPEATS = 3
# POV-Ray: 4x4 supersamples in every pixel (threshold 0, no jitter), sRGB 8-bit PNG.
POVRAY_AA = ["+A0.0", "+AM1", "+R4", "-J"]

SEARCH_KINDS = (("refl", "reflection"), ("refr", "refraction_exit"), ("shad", "shadow"))
SEARCH_FIELDS = ("rays", "texels_mean", "texels_max", "fragments_tested", "hits", "misses", "threshold_rejections")
PASS_ORDER = ["load", "gl_init", "upload", "shadow_maps", "environment_map", "camera_raster", "readback",
              "cube_abuffer", "map_setup", "camera_abuffer", "shade_and_resolve", "bvh_build", "trace",
              "pov_export", "pov_parse", "pov_trace", "write", "total"]
HEAD_COLUMNS = ["set", "scene", "method", "N", "plan", "rep", "status", "error", "wall_ms", "render_ms", "repeats",
                "render_ms_min", "render_ms_max"]
TAIL_COLUMNS = (["cube_fragments", "cube_bytes", "camera_fragments"]
                + ["%s_%s" % (k, f) for k, _ in SEARCH_KINDS for f in SEARCH_FIELDS]
                + ["lens_transfers", "lens_fallbacks", "envmap_lookups", "peak_rss_mib",
                   "rmse", "psnr_db", "max_abs", "share_over_2_255",
                   "cp_mean", "cp_p99", "cp_max", "cp_misses",
                   "par_count", "par_mean", "par_p99", "par_max", "par_misses", "par_miss_share",
                   "false_hits", "wrong_object", "bound", "within_bound",
                   "skipped_steps", "gl_renderer", "note"])


def log(msg):
    print(msg, file=sys.stderr, flush=True)


def scene_name(path):
    base = os.path.splitext(os.path.basename(path))[0]
    return ("bench/" + base) if os.path.basename(os.path.dirname(os.path.abspath(path))) == "bench" else base


def last_line(text):
    lines = [l.strip() for l in (text or "").splitlines() if l.strip()]
    return lines[-1] if lines else ""


def run_timed(cmd, timeout, cwd=None):
    """Runs cmd; returns (returncode or None on timeout, wall ms, stdout, stderr)."""
    t0 = time.perf_counter()
    try:
        p = subprocess.run(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=timeout)
        return p.returncode, (time.perf_counter() - t0) * 1e3, p.stdout, p.stderr
    except subprocess.TimeoutExpired:
        return None, (time.perf_counter() - t0) * 1e3, "", "timeout after %g s" % timeout
    except OSError as e:
        return -1, (time.perf_counter() - t0) * 1e3, "", str(e)


def num(v):
    """A JSON number, or None ("inf" strings become inf)."""
    if v is None:
        return None
    if isinstance(v, str):
        return math.inf if v == "inf" else None
    return float(v)


def row_from_stats(row, stats):
    """Flattens one abcube --stats into the CSV row (see bench/README.md, Columns)."""
    timings = dict(stats.get("timings_ms", {}))
    for key in ("raytrace", "reference"):  # the tracer's own passes (nested)
        timings.update(stats.get(key, {}).get("timings_ms", {}) if isinstance(stats.get(key), dict) else {})
    for k, v in timings.items():
        row["ms_" + k] = v
    if "total" in timings:
        row["render_ms"] = timings["total"] - timings.get("write", 0.0)
    cube, cam = stats.get("cube_abuffer", {}), stats.get("abuffer", {})
    row["cube_fragments"] = cube.get("fragments")
    row["cube_bytes"] = cube.get("bytes_total")
    row["camera_fragments"] = cam.get("fragments")
    searches = stats.get("searches", {})
    for short, kind in SEARCH_KINDS:
        for f in SEARCH_FIELDS:
            row["%s_%s" % (short, f)] = searches.get(kind, {}).get(f)
    for f in ("lens_transfers", "lens_fallbacks", "envmap_lookups"):
        row[f] = searches.get(f)
    rss = stats.get("memory", {}).get("peak_rss_bytes")
    row["peak_rss_mib"] = rss / 2**20 if rss is not None else None
    ref = stats.get("reference", {})
    ie = ref.get("image_error", {})
    if ie:
        row["rmse"] = ie.get("rmse")
        row["psnr_db"] = num(ie.get("psnr_db"))
        row["max_abs"] = ie.get("max_abs")
        row["share_over_2_255"] = ie.get("share_over_2_255")
    re_ = ref.get("ray_error")
    if isinstance(re_, dict):
        cp, par = re_.get("error_cp", {}), re_.get("error_parallax", {})
        row.update(cp_mean=cp.get("mean"), cp_p99=cp.get("p99"), cp_max=cp.get("max"), cp_misses=cp.get("misses"),
                   par_count=par.get("count"), par_mean=par.get("mean"), par_p99=par.get("p99"),
                   par_max=par.get("max"), par_misses=par.get("misses"), par_miss_share=par.get("miss_share"),
                   false_hits=re_.get("false_hits"), wrong_object=re_.get("wrong_object"),
                   bound=re_.get("bound_1_over_2n2"), within_bound=re_.get("error_parallax_within_bound"))
    skipped = stats.get("plan", {}).get("skipped", [])
    row["skipped_steps"] = "; ".join(s.get("pass", "") for s in skipped if isinstance(s, dict))
    row["gl_renderer"] = stats.get("gl", {}).get("renderer")


class Sweep:
    def __init__(self, args):
        self.a = args
        self.rows = []
        self.failures = 0
        self.stats_log = open(os.path.join(args.out, args.name + ".stats.jsonl"), "w")
        self.geometry = {}  # scene name -> bound_geometry()
        self.count = 0

    def record(self, row, stats=None):
        self.rows.append(row)
        if stats is not None:
            self.stats_log.write(json.dumps({"scene": row["scene"], "method": row["method"], "N": row["N"],
                                             "set": row["set"], "plan": row["plan"], "rep": row["rep"],
                                             "stats": stats}) + "\n")
            self.stats_log.flush()
        if row["status"] == "failed":
            self.failures += 1
        self.count += 1
        what = "%s %s N=%s%s" % (row["scene"], row["method"], row["N"] or "-",
                                 (" plan=%s" % row["plan"]) if row["plan"] else "")
        if row["status"] == "ok":
            psnr = row.get("psnr_db")
            log("[%3d] %-48s %9.0f ms  PSNR %s" % (self.count, what, row["wall_ms"] or 0,
                                                     "-" if psnr is None else "%.2f dB" % psnr))
        else:
            log("[%3d] %-48s %s: %s" % (self.count, what, row["status"].upper(), row.get("error") or row.get("note")))

    def new_row(self, set_, scene, method, n, plan="", rep=""):
        return {"set": set_, "scene": scene_name(scene), "method": method, "N": n, "plan": plan, "rep": rep,
                "status": "ok", "error": "", "note": ""}

    def render(self, set_, scene, method, n, ref, work, extra=(), plan="", rep="", repeat=1):
        """abcube render of a map method, `repeat` times; records the run of median render ms."""
        runs = []
        for k in range(repeat):
            row = self.new_row(set_, scene, method, n, plan, rep)
            tag = "%s_%s_%s_%s%s" % (method, n, plan or "default", rep or 0, k)
            out_png, out_stats = os.path.join(work, tag + ".png"), os.path.join(work, tag + ".json")
            size = [] if method in LADDER else ["--cube-res", str(n)]
            cmd = ([self.a.abcube, "render", scene, "-o", out_png, "--threads", str(self.a.threads)] + size +
                   ["--reference-image", ref, "--stats", out_stats] + (LADDER.get(method) or MAP_METHODS[method]) +
                   list(extra))
            rc, ms, _, err = run_timed(cmd, self.a.timeout)
            row["wall_ms"] = ms
            stats = None
            if rc != 0:
                row["status"], row["error"] = "failed", "exit %s: %s" % (rc, last_line(err))
            else:
                try:
                    with open(out_stats) as f:
                        stats = json.load(f)
                    row_from_stats(row, stats)
                except (OSError, ValueError) as e:
                    row["status"], row["error"] = "failed", "stats unreadable: %s" % e
            for path in (out_png, out_stats):
                if os.path.exists(path) and not self.a.keep:
                    os.remove(path)
            runs.append((row, stats))
            if row["status"] != "ok":
                break  # a failure is not retried
        ok = sorted([r for r in runs if r[0]["status"] == "ok"], key=lambda r: r[0].get("render_ms") or 0)
        row, stats = ok[len(ok) // 2] if ok and len(ok) == len(runs) else runs[-1]
        if len(runs) > 1 and row["status"] == "ok":
            row["repeats"] = len(runs)
            row["render_ms_min"] = ok[0][0].get("render_ms")
            row["render_ms_max"] = ok[-1][0].get("render_ms")
        self.record(row, stats)
        return row, stats

    def reference(self, scene, work):
        """The exact image of the scene, rendered --repeat times (its time is the raytrace row, the
        run of median render ms); returns (path, stats) or (None, None)."""
        ref, out_stats = os.path.join(work, "ref.exr"), os.path.join(work, "ref.json")
        cmd = [self.a.abcube, "render", scene, "-o", ref, "--method", "raytrace", "--threads", str(self.a.threads),
               "--stats", out_stats]
        runs = []
        for _ in range(self.a.repeat):
            row = self.new_row("sweep", scene, "raytrace", "")
            rc, ms, _, err = run_timed(cmd, self.a.timeout)
            row["wall_ms"] = ms
            try:
                if rc != 0:
                    raise RuntimeError("exit %s: %s" % (rc, last_line(err)))
                with open(out_stats) as f:
                    stats = json.load(f)
            except (OSError, ValueError, RuntimeError) as e:
                row["status"], row["error"] = "failed", str(e)
                self.record(row)
                return None, None
            row_from_stats(row, stats)
            runs.append((row, stats))
        runs.sort(key=lambda r: r[0].get("render_ms") or 0)
        row, stats = runs[len(runs) // 2]
        if len(runs) > 1:
            row.update(repeats=len(runs), render_ms_min=runs[0][0].get("render_ms"),
                       render_ms_max=runs[-1][0].get("render_ms"))
        row.update(rmse=0.0, psnr_db=math.inf, max_abs=0.0, share_over_2_255=0.0,
                   note="the reference itself (4x8 samples per pixel); N-independent")
        self.record(row, stats)
        return ref, stats

    def povray(self, scene, ref, ref_stats, work):
        row = self.new_row("sweep", scene, "povray", "")
        povray = shutil.which("povray")
        if not povray:
            row["status"], row["note"] = "skipped", "povray not on PATH"
            self.record(row)
            return
        size = ref_stats.get("size", {})
        w, h = size.get("width"), size.get("height")
        pov, png, logf = (os.path.join(work, "scene.pov"), os.path.join(work, "pov.png"), os.path.join(work, "pov.log"))
        rc, ms_export, _, err = run_timed([self.a.abcube, "export-pov", scene, "-o", pov], self.a.timeout)
        if rc != 0:
            row["status"], row["error"] = "failed", "export-pov exit %s: %s" % (rc, last_line(err))
            self.record(row)
            return
        cmd = [povray, "+I" + os.path.basename(pov), "+O" + os.path.basename(png), "+FN8", "File_Gamma=sRGB",
               "+W%d" % w, "+H%d" % h, "-D", "-P", "+WT%d" % self.a.threads] + POVRAY_AA
        rc, ms, out, err = run_timed(cmd, self.a.timeout, cwd=work)
        with open(logf, "w") as f:
            f.write(out + err)
        row["wall_ms"] = ms_export + ms
        row["render_ms"] = ms
        row["ms_pov_export"] = ms_export
        for key, label in (("ms_pov_parse", "Parse Time"), ("ms_pov_trace", "Trace Time")):
            m = re.search(label + r":.*\(([\d.]+) seconds\)", out + err)
            if m:
                row[key] = float(m.group(1)) * 1e3
        row["note"] = "%dx%d, %s, %d threads, File_Gamma=sRGB; model differences: pov_export.hpp" % (
            w, h, " ".join(POVRAY_AA), self.a.threads)
        if rc != 0 or not os.path.exists(png):
            row["status"], row["error"] = "failed", "povray exit %s: %s" % (rc, last_line(err))
            self.record(row)
            return
        rc, _, out, err = run_timed([self.a.abcube, "compare", png, ref], self.a.timeout)
        if rc not in (0, 1):  # 1 = over compare's default tolerance, still a measurement
            row["status"], row["error"] = "failed", "compare exit %s: %s" % (rc, last_line(err))
        else:
            for key, label in (("rmse", "RMSE"), ("psnr_db", "PSNR"), ("max_abs", "max abs"),
                               ("share_over_2_255", "over 2/255")):
                m = re.search(r"^%s\s+([-\d.e+inf]+)" % re.escape(label), out, re.M)
                if m:
                    row[key] = float(m.group(1))
            if row.get("share_over_2_255") is not None:
                row["share_over_2_255"] /= 100.0  # compare prints percent
        self.record(row)

    def scene(self, scene):
        """Every run of one scene, in a temporary work folder (kept with --keep)."""
        work = tempfile.mkdtemp(prefix="sweep_%s_" % scene_name(scene).replace("/", "_"), dir=self.a.work)
        log("== %s (work %s)" % (scene_name(scene), work))
        try:
            self.scene_runs(scene, work)
        except Exception as e:  # a bug or surprise in one scene must not lose the others' results
            row = self.new_row("sweep", scene, "(sweep.py)", "")
            row["status"], row["error"] = "failed", "%s: %s" % (type(e).__name__, e)
            self.record(row)
        finally:
            if not self.a.keep:
                shutil.rmtree(work, ignore_errors=True)

    def scene_runs(self, scene, work):
        name = scene_name(scene)
        ref, ref_stats = self.reference(scene, work)
        if ref is None:
            for m in self.a.methods:
                if m == "raytrace":
                    continue
                row = self.new_row("sweep", scene, m, "")
                row["status"], row["error"] = "failed", "no reference image (the raytrace run failed)"
                self.record(row)
            return
        if "povray" in self.a.methods:
            self.povray(scene, ref, ref_stats, work)
        if "raytrace" in self.a.methods:  # the rival at matched error: the tracer at fewer samples
            for m in LADDER:
                self.render("sweep", scene, m, "", ref, work, repeat=self.a.repeat)
        no_transmit = None  # learnt from the plan of a map method at this scene
        for n in self.a.sizes:
            for m in self.a.methods:
                if m not in MAP_METHODS:
                    continue
                if m in LENS_METHODS and no_transmit:
                    row = self.new_row("sweep", scene, m, n)
                    row["status"] = "skipped"
                    row["note"] = "no material transmits: the lens modes are abuffer_crossing's image"
                    self.record(row)
                    continue
                row, stats = self.render("sweep", scene, m, n, ref, work, repeat=self.a.repeat)
                if stats and m != "gpu" and "plan" in stats:
                    no_transmit = any(s.get("pass") == "refraction_searches" for s in stats["plan"].get("skipped", []))
        thesis_sizes = []
        if name in THESIS_SCENES and not self.a.no_thesis and "abuffer_thesis" in self.a.methods:
            thesis_sizes = THESIS_SIZES
            for n in thesis_sizes:
                self.render("thesis", scene, "abuffer_thesis", n, ref, work)
        if "abuffer_thesis" in self.a.methods:
            t0 = time.perf_counter()
            try:
                self.geometry[name] = bound_geometry(scene, sorted(set(thesis_sizes) | set(self.a.sizes)))
                log("      %s: bound geometry model in %.1f s" % (name, time.perf_counter() - t0))
            except (OSError, ValueError, KeyError, ZeroDivisionError) as e:
                self.geometry[name] = "failed: %s" % e
                log("      %s: bound geometry model failed: %s" % (name, e))
        if not self.a.no_skips and "abuffer_crossing" in self.a.methods:
            n = (ref_stats.get("size") or {}).get("cube_resolution", 512)
            for rep in range(1, SKIP_REPEATS + 1):
                for plan in ("needed", "everything"):  # interleaved, so drift hits both alike
                    self.render("skips", scene, "abuffer_crossing", n, ref, work, ["--plan", plan], plan, rep)



# ---------------------------------------------------------------------------------------------
# Outputs


def fmt(v, kind="g"):
    if v is None or v == "":
        return ""
    if isinstance(v, str):
        return v
    if isinstance(v, float) and math.isinf(v):
        return "inf"
    if kind == "ms":
        return "%.0f" % v if v >= 100 else "%.1f" % v
    if kind == "db":
        return "%.2f" % v
    if kind == "pct":
        return "%.1f%%" % (100 * v)
    if kind == "int":
        return "%d" % v
    if kind == "mib":
        return "%.0f" % v
    if kind == "e":
        return "%.2e" % v
    if kind == "f1":
        return "%.1f" % v
    if kind == "f2":
        return "%.2f" % v
    return "%g" % v


def ep(row, key, kind="e"):
    """An Error_Parallax figure, blank when the method found no point at all (nothing to measure)."""
    if row.get("par_count"):
        return fmt(row.get(key), kind)
    if row.get("par_count") == 0:
        return "no hit" if row.get("par_misses") else "no ray"
    return ""


def write_csv(path, rows):
    ms_keys = sorted({k for r in rows for k in r if k.startswith("ms_")},
                     key=lambda k: (PASS_ORDER.index(k[3:]) if k[3:] in PASS_ORDER else len(PASS_ORDER), k))
    columns = HEAD_COLUMNS + ms_keys + TAIL_COLUMNS
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(columns)
        for r in rows:
            w.writerow(["inf" if isinstance(r.get(c), float) and math.isinf(r[c]) else
                        ("%.6g" % r[c] if isinstance(r.get(c), float) else r.get(c, "")) for c in columns])


def write_geometry_csv(path, geometry):
    keys = ["rays", "rejected", "within", "ratio_broken", "ratio_within", "ratio_gt1_broken", "ratio_gt1_within",
            "amp_broken", "amp_within", "amp_le1_broken"]
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["scene", "N"] + keys)
        for scene, g in geometry.items():
            if isinstance(g, dict):
                for n, v in sorted(g.items()):
                    w.writerow([scene, n] + ["" if v[k] is None else "%.6g" % v[k] for k in keys])


def median_of(rows, key):
    vals = [r[key] for r in rows if r.get(key) is not None]
    return statistics.median(vals) if vals else None


def write_markdown(path, sweep, args, meta):
    rows = sweep.rows
    L = []
    L.append("# Speed against error: %s" % ("--quick sweep" if args.quick else "sweep"))
    L.append("")
    L.append("Written by `bench/sweep.py` (bench/README.md explains every column). %s" % meta["when"])
    L.append("")
    L.append("- command: `%s`" % meta["command"])
    L.append("- abcube %s, commit %s; %s; %s logical CPUs; `--threads %d`" % (
        args.abcube, meta["commit"], meta["machine"], os.cpu_count(), args.threads))
    L.append("- GL renderer of the gpu runs: %s" % (meta["gl"] or "n/a"))
    L.append("- load average (1 min) at start %.2f, at end %.2f: above --threads, other work shared the cores and "
             "the times are noisy" % (meta["load_start"], meta["load_end"]))
    L.append("- times: `render ms` = the program's own total minus writing the image (`wall ms` in the CSV "
             "adds process start and the write); %s" % (
                 "one run each" if args.repeat == 1 else "the run of median render ms of %d" % args.repeat))
    L.append("- errors: PSNR and RMSE of the image against the exact tracer's (sRGB-encoded display values); "
             "Error_Parallax (EP) of the primary reflection rays: mean, p99, max; `within` = share of hits with "
             "EP <= 1/(2N^2); `miss` = share of reflection rays with an exact hit that the method missed")
    L.append("")
    scenes = []
    for r in rows:
        if r["scene"] not in scenes:
            scenes.append(r["scene"])
    order = {m: i for i, m in enumerate(ALL_METHODS)}
    header = ("| method | N | render ms | cube frags | cam frags | refl texels mean/max | frags tested | "
              "MiB | PSNR dB | matched rung: ms, ratio | CP mean | EP mean | EP p99 | EP max | 1/(2N^2) | within | "
              "miss |")
    for s in scenes:
        L.append("## %s" % s)
        L.append("")
        L.append(header)
        L.append("|" + "---|" * (header.count("|") - 1))
        srows = sorted([r for r in rows if r["scene"] == s and r["set"] == "sweep"],
                       key=lambda r: (order.get(r["method"], 99), r["N"] or 0))
        ladder = [(r["method"], r.get("render_ms"), r.get("psnr_db")) for r in srows
                  if r["status"] == "ok" and (r["method"] in LADDER or r["method"] == "raytrace")]
        for r in srows:
            if r["status"] != "ok":
                L.append("| %s | %s | %s: %s |%s" % (r["method"], r["N"], r["status"], r.get("error") or r.get("note"),
                                                    " |" * 14))
                continue
            matched = ""
            rivals = [x for x in ladder if x[2] is not None and r.get("psnr_db") is not None and x[2] >= r["psnr_db"]
                      and x[1]]
            if rivals and r["method"] not in LADDER and r["method"] != "raytrace" and r.get("render_ms"):
                name, ms, _ = min(rivals, key=lambda x: x[1])
                matched = "%s: %.0f, %.2f" % (name.replace("raytrace_", "").replace("raytrace", "32spp"), ms,
                                              r["render_ms"] / ms)
            texels = ("%s / %s" % (fmt(r.get("refl_texels_mean"), "f1"), fmt(r.get("refl_texels_max"), "int"))
                      if r.get("refl_rays") else "")
            L.append("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
                r["method"], r["N"], fmt(r.get("render_ms"), "ms"), fmt(r.get("cube_fragments"), "int"),
                fmt(r.get("camera_fragments"), "int"), texels,
                fmt(sum(r.get("%s_fragments_tested" % k) or 0 for k, _ in SEARCH_KINDS) or None, "int"),
                fmt(r.get("peak_rss_mib"), "mib"), fmt(r.get("psnr_db"), "db"), matched,
                fmt(r.get("cp_mean"), "e") if r.get("par_count") is not None else "", ep(r, "par_mean"),
                ep(r, "par_p99"), ep(r, "par_max"), fmt(r.get("bound"), "e"),
                ep(r, "within_bound", "pct"), fmt(r.get("par_miss_share"), "pct")))
        notes = sorted({"%s: %s" % (r["method"], r["note"]) for r in srows if r.get("note")})
        if notes:
            L.append("")
            for n in notes:
                L.append("- " + n)
        L.append("")

    thesis = [r for r in rows if r["set"] == "thesis" or (r["method"] == "abuffer_thesis" and r["set"] == "sweep")]
    if thesis:
        L.append("## The thesis's bound (thesis 9.3.4), abuffer_thesis")
        L.append("")
        L.append("Error_Parallax of the hits against 1/(2N^2); the thesis prints 5e-5, 1.25e-5, 5.5e-6 for "
                 "N = 100, 200, 300. `max/bound` > 1 is a break of the bound; theta_max^2/4 = %.3e is the "
                 "largest error an accepted hit can have (`--theta-max %g` degrees)." % (
                     math.radians(THETA_MAX_DEG) ** 2 / 4, THETA_MAX_DEG))
        L.append("")
        L.append("| scene | N | bound 1/(2N^2) | thesis figure | EP mean | EP p99 | EP max | p99/bound | max/bound | "
                 "within bound | hits | missed | wrong object |")
        L.append("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
        for r in sorted(thesis, key=lambda r: (r["scene"], r["N"])):
            if r["status"] != "ok":
                L.append("| %s | %s | %s: %s |%s" % (r["scene"], r["N"], r["status"], r.get("error"), " |" * 10))
                continue
            b = r.get("bound")
            L.append("| %s | %d | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
                r["scene"], r["N"], fmt(b, "e"), fmt(THESIS_FIGURES.get(r["N"]), "e"), fmt(r.get("par_mean"), "e"),
                fmt(r.get("par_p99"), "e"), fmt(r.get("par_max"), "e"),
                "%.1f" % (r["par_p99"] / b) if b and r.get("par_p99") is not None else "",
                "%.1f" % (r["par_max"] / b) if b and r.get("par_max") is not None else "",
                fmt(r.get("within_bound"), "pct"), fmt(r.get("par_count"), "int"), fmt(r.get("par_misses"), "int"),
                fmt(r.get("wrong_object"), "int")))
        L.append("")

    if sweep.geometry:
        L.append("## Where the bound breaks: the geometry of the hits (model)")
        L.append("")
        L.append("abcube's stats give no per-hit geometry (no S, no |S-C|/|S-W|), so `sweep.py` re-traces the "
                 "scene in Python (`bound_geometry`, one pixel in %d along x and along y, reflection rays of "
                 "camera-visible mirrors) and takes for each ray the thesis mode's ideal candidate: the texel "
                 "holding the true point S seen from C, its centre's point on S's plane, and that point's angle "
                 "theta_0 seen from W (theta_c: the same seen from C, <= atan(sqrt(2)/N)). `model` columns are "
                 "that model's; `measured` are abcube's abuffer_thesis run at the same N. ratio = |S-C|/|S-W|; "
                 "amp = theta_0/theta_c." % GEOMETRY_STEP)
        L.append("")
        L.append("| scene | N | rays (model) | rejected: model / measured miss | within bound: model / measured | "
                 "median ratio: broken / within | ratio > 1: broken / within | median amp: broken / within |")
        L.append("|---|---|---|---|---|---|---|---|")
        measured = {(r["scene"], r["N"]): r for r in rows
                    if r["method"] == "abuffer_thesis" and r["status"] == "ok" and r["set"] in ("sweep", "thesis")}
        for s, g in sweep.geometry.items():
            if not isinstance(g, dict) or not any(v["rays"] for v in g.values()):
                why = g if isinstance(g, str) else ("not modelled (a mesh in the scene)" if g is None
                                                    else "no camera-visible reflecting surface")
                L.append("| %s | | %s |%s" % (s, why, " |" * 5))
                continue
            for n, v in sorted(g.items()):
                m = measured.get((s, n))
                if m is None:
                    continue
                pair = lambda a, b, kind: "%s / %s" % (fmt(a, kind) or "-", fmt(b, kind) or "-")
                L.append("| %s | %d | %d | %s | %s | %s | %s | %s |" % (
                    s, n, v["rays"], pair(v["rejected"], m.get("par_miss_share"), "pct"),
                    pair(v["within"], m.get("within_bound"), "pct"),
                    pair(v["ratio_broken"], v["ratio_within"], "f2"),
                    pair(v["ratio_gt1_broken"], v["ratio_gt1_within"], "pct"),
                    pair(v["amp_broken"], v["amp_within"], "f2")))
        L.append("")

    skips = [r for r in rows if r["set"] == "skips"]
    if skips:
        L.append("## What the plan's skips save (abuffer_crossing at the scene's N)")
        L.append("")
        L.append("Median of %d runs each, interleaved. `--plan everything` walks the shadows of lights that cast "
                 "none (result unused) and builds the cube map even where nothing needs it; the image does not "
                 "change. Difference per pass: everything minus needed." % SKIP_REPEATS)
        L.append("")
        L.append("| scene | N | skipped by --plan needed | needed ms median [min] | everything ms median [min] | "
                 "saved ms (median; min) | saved | cube_abuffer | shade_and_resolve | shadow rays (everything) |")
        L.append("|---|---|---|---|---|---|---|---|---|---|")
        for s in scenes:
            need = [r for r in skips if r["scene"] == s and r["plan"] == "needed" and r["status"] == "ok"]
            every = [r for r in skips if r["scene"] == s and r["plan"] == "everything" and r["status"] == "ok"]
            if not need or not every:
                bad = [r for r in skips if r["scene"] == s and r["status"] != "ok"]
                if bad:
                    L.append("| %s | %s | failed: %s |%s" % (s, bad[0]["N"], bad[0].get("error"), " |" * 7))
                continue
            tn, te = median_of(need, "render_ms"), median_of(every, "render_ms")
            d = {p: (median_of(every, "ms_" + p) or 0) - (median_of(need, "ms_" + p) or 0)
                 for p in ("cube_abuffer", "shade_and_resolve")}
            mn, me = min(r["render_ms"] for r in need), min(r["render_ms"] for r in every)
            L.append("| %s | %s | %s | %s [%s] | %s [%s] | %s; %s | %s | %+.1f | %+.1f | %s (needed: %s) |" % (
                s, need[0]["N"], need[0].get("skipped_steps") or "nothing", fmt(tn, "ms"), fmt(mn, "ms"),
                fmt(te, "ms"), fmt(me, "ms"), fmt(te - tn, "ms"), fmt(me - mn, "ms"),
                fmt((te - tn) / te, "pct") if te else "", d["cube_abuffer"],
                d["shade_and_resolve"], fmt(every[0].get("shad_rays"), "int"), fmt(need[0].get("shad_rays"), "int")))
        L.append("")

    failed = [r for r in rows if r["status"] == "failed"]
    L.append("## Failures")
    L.append("")
    if failed:
        for r in failed:
            L.append("- %s %s N=%s %s: %s" % (r["scene"], r["method"], r["N"], r["plan"], r["error"]))
    else:
        L.append("None.")
    L.append("")
    with open(path, "w") as f:
        f.write("\n".join(L))


# ---------------------------------------------------------------------------------------------
# SVG plots (hand-written: log-log axes with decade ticks, a legend, one colour per method)

COLOURS = {"gpu": "#1f77b4", "envmap_R": "#ff7f0e", "envmap_bisector": "#bcbd22", "zbuffer": "#2ca02c",
           "abuffer_thesis": "#d62728", "abuffer_crossing": "#9467bd", "abuffer_plane": "#7f7f7f", "thick_lens": "#8c564b",
           "thin_lens": "#e377c2", "raytrace": "#000000", "povray": "#17becf", "ladder": "#444444"}
SCENE_COLOURS = ["#d62728", "#1f77b4", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf"]
SUPERSCRIPT = str.maketrans("-0123456789", "\u207b\u2070\u00b9\u00b2\u00b3\u2074\u2075\u2076\u2077\u2078\u2079")


def esc(s):
    return str(s).replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


def decade_label(k, unit=None):
    if unit == "ms":
        v = 10.0 ** k
        return ("%g ms" % v) if v < 1000 else ("%g s" % (v / 1000))
    if 0 <= k <= 3:
        return "%d" % (10 ** k)
    return "10" + str(k).translate(SUPERSCRIPT)


class LogPanel:
    """A log-log panel at (x0, y0) of size w x h; the data range is widened to whole decades."""
    count = 0  # panels drawn so far, for unique clip-path ids

    def __init__(self, out, x0, y0, w, h, xs, ys, title, xlabel, ylabel, xunit=None, ylinear=None):
        self.o, self.x0, self.y0, self.w, self.h = out, x0, y0, w, h
        xs = [v for v in xs if v and v > 0 and math.isfinite(v)] or [1, 10]
        self.xa, self.xb = math.floor(math.log10(min(xs))), math.ceil(math.log10(max(xs)))
        if self.xb == self.xa:
            self.xb += 1
        self.ylinear = ylinear
        if ylinear:
            self.ya, self.yb = ylinear
        else:
            ys = [v for v in ys if v and v > 0 and math.isfinite(v)] or [1e-3, 1]
            self.ya, self.yb = math.floor(math.log10(min(ys))), math.ceil(math.log10(max(ys)))
            if self.yb == self.ya:
                self.yb += 1
        o = out
        LogPanel.count += 1
        self.clip = 'clip-path="url(#panel%d)"' % LogPanel.count
        o.append('<clipPath id="panel%d"><rect x="%g" y="%g" width="%g" height="%g"/></clipPath>'
                 % (LogPanel.count, x0, y0, w, h))
        o.append('<rect x="%g" y="%g" width="%g" height="%g" fill="#fff" stroke="#333"/>' % (x0, y0, w, h))
        o.append('<text x="%g" y="%g" font-size="14" font-weight="bold" text-anchor="middle">%s</text>'
                 % (x0 + w / 2, y0 - 8, esc(title)))
        for k in range(self.xa, self.xb + 1):
            for m in range(1, 10):
                if k == self.xb and m > 1:
                    break
                x = self.px(m * 10.0 ** k)
                o.append('<line x1="%.1f" y1="%g" x2="%.1f" y2="%g" stroke="%s"/>' % (
                    x, y0, x, y0 + h, "#ccc" if m == 1 else "#eee"))
                o.append('<line x1="%.1f" y1="%g" x2="%.1f" y2="%g" stroke="#333"/>' % (
                    x, y0 + h, x, y0 + h + (6 if m == 1 else 3)))
            o.append('<text x="%.1f" y="%g" font-size="11" text-anchor="middle">%s</text>'
                     % (self.px(10.0 ** k), y0 + h + 18, esc(decade_label(k, xunit))))
        if ylinear:
            for i in range(0, 11, 2):
                v = ylinear[0] + (ylinear[1] - ylinear[0]) * i / 10
                y = self.py(v)
                o.append('<line x1="%g" y1="%.1f" x2="%g" y2="%.1f" stroke="#ddd"/>' % (x0, y, x0 + w, y))
                o.append('<text x="%g" y="%.1f" font-size="11" text-anchor="end">%g%%</text>'
                         % (x0 - 6, y + 4, 100 * v))
        else:
            for k in range(self.ya, self.yb + 1):
                for m in range(1, 10):
                    if k == self.yb and m > 1:
                        break
                    y = self.py(m * 10.0 ** k)
                    o.append('<line x1="%g" y1="%.1f" x2="%g" y2="%.1f" stroke="%s"/>' % (
                        x0, y, x0 + w, y, "#ccc" if m == 1 else "#eee"))
                    o.append('<line x1="%g" y1="%.1f" x2="%g" y2="%.1f" stroke="#333"/>' % (
                        x0 - (6 if m == 1 else 3), y, x0, y))
                o.append('<text x="%g" y="%.1f" font-size="11" text-anchor="end">%s</text>'
                         % (x0 - 8, self.py(10.0 ** k) + 4, esc(decade_label(k))))
        o.append('<text x="%g" y="%g" font-size="12" text-anchor="middle">%s</text>'
                 % (x0 + w / 2, y0 + h + 36, esc(xlabel)))
        o.append('<text transform="translate(%g,%g) rotate(-90)" font-size="12" text-anchor="middle">%s</text>'
                 % (x0 - 48, y0 + h / 2, esc(ylabel)))

    def px(self, v):
        return self.x0 + (math.log10(v) - self.xa) / (self.xb - self.xa) * self.w

    def py(self, v):
        if self.ylinear:
            t = (v - self.ylinear[0]) / (self.ylinear[1] - self.ylinear[0])
        else:
            t = (math.log10(v) - self.ya) / (self.yb - self.ya)
        return self.y0 + self.h - t * self.h

    def inside(self, x, y):
        return (x > 0 and math.isfinite(x) and (self.ylinear or (y > 0 and math.isfinite(y))))

    def polyline(self, pts, colour, dash=None, marker="circle", width=1.8, labels=None):
        pts = [(x, y) for x, y in pts if self.inside(x, y)]
        if not pts:
            return
        if len(pts) > 1:
            self.o.append('<polyline %s fill="none" stroke="%s" stroke-width="%g"%s points="%s"/>' % (
                self.clip, colour, width, ' stroke-dasharray="%s"' % dash if dash else "",
                " ".join("%.1f,%.1f" % (self.px(x), self.py(y)) for x, y in pts)))
        if marker:
            for x, y in pts:
                self.marker(x, y, colour, marker)
        if labels:  # the first label left of its point, the others right
            for j, ((x, y), text) in enumerate(zip(pts, labels)):
                if text:
                    self.o.append('<text x="%.1f" y="%.1f" font-size="9" fill="%s" text-anchor="%s">%s</text>' % (
                        self.px(x) + (-5 if j == 0 else 5), self.py(y) + 3, colour, "end" if j == 0 else "start",
                        esc(text)))

    def marker(self, x, y, colour, kind):
        X, Y = self.px(x), self.py(y)
        if kind == "circle":
            self.o.append('<circle cx="%.1f" cy="%.1f" r="3" fill="%s"/>' % (X, Y, colour))
        elif kind == "square":
            self.o.append('<rect x="%.1f" y="%.1f" width="6" height="6" fill="none" stroke="%s" stroke-width="1.5"/>'
                          % (X - 3, Y - 3, colour))
        elif kind == "diamond":
            self.o.append('<polygon points="%.1f,%.1f %.1f,%.1f %.1f,%.1f %.1f,%.1f" fill="%s"/>' % (
                X, Y - 5, X + 5, Y, X, Y + 5, X - 5, Y, colour))
        elif kind == "star":
            self.o.append('<text x="%.1f" y="%.1f" font-size="16" text-anchor="middle" fill="%s">\u2605</text>'
                          % (X, Y + 5, colour))
        elif kind == "triangle":
            self.o.append('<polygon points="%.1f,%.1f %.1f,%.1f %.1f,%.1f" fill="none" stroke="%s" stroke-width="1.5"/>'
                          % (X, Y - 4, X + 4, Y + 3, X - 4, Y + 3, colour))


def legend(out, x, y, items, columns=1, col_w=190):
    """items: (label, colour, dash, marker)"""
    for i, (label, colour, dash, marker) in enumerate(items):
        cx, cy = x + (i % columns) * col_w, y + (i // columns) * 16
        out.append('<line x1="%g" y1="%g" x2="%g" y2="%g" stroke="%s" stroke-width="2"%s/>' % (
            cx, cy, cx + 22, cy, colour, ' stroke-dasharray="%s"' % dash if dash else ""))
        if marker == "circle":
            out.append('<circle cx="%g" cy="%g" r="3" fill="%s"/>' % (cx + 11, cy, colour))
        elif marker == "diamond":
            out.append('<polygon points="%g,%g %g,%g %g,%g %g,%g" fill="%s"/>' % (
                cx + 11, cy - 5, cx + 16, cy, cx + 11, cy + 5, cx + 6, cy, colour))
        elif marker == "square":
            out.append('<rect x="%g" y="%g" width="6" height="6" fill="none" stroke="%s"/>' % (cx + 8, cy - 3, colour))
        elif marker == "star":
            out.append('<text x="%g" y="%g" font-size="14" text-anchor="middle" fill="%s">\u2605</text>'
                       % (cx + 11, cy + 5, colour))
        out.append('<text x="%g" y="%g" font-size="12">%s</text>' % (cx + 28, cy + 4, esc(label)))


def svg_doc(w, h, body, title):
    return ('<?xml version="1.0" encoding="UTF-8"?>\n<svg xmlns="http://www.w3.org/2000/svg" width="%d" height="%d" '
            'viewBox="0 0 %d %d" font-family="DejaVu Sans, Arial, sans-serif">\n<title>%s</title>\n'
            '<rect width="100%%" height="100%%" fill="#fff"/>\n%s\n</svg>\n' % (w, h, w, h, esc(title), "\n".join(body)))


def plot_error_vs_time(path, rows, quick, threads):
    """Per scene one panel: image RMSE against render ms, log-log, one polyline per method across N."""
    ok = [r for r in rows if r["status"] == "ok" and r["set"] == "sweep"]
    scenes = []
    for r in ok:
        if r["scene"] not in scenes:
            scenes.append(r["scene"])
    # The tracer's ladder is one curve, "ladder" (its rungs labelled by their samples).
    methods = [m for m in ALL_METHODS if m not in LADDER and any(r["method"] == m for r in ok)]
    if any(r["method"] in LADDER for r in ok):
        methods.append("ladder")
    cols = 2 if len(scenes) > 1 else 1
    pw, ph, mx, top = 440, 320, 90, 84 + 16 * math.ceil(len(methods) / 3)
    W = max(cols * (pw + mx) + 40, 640)
    H = top + math.ceil(max(len(scenes), 1) / cols) * (ph + 90)
    body = ['<text x="%g" y="22" font-size="16" font-weight="bold" text-anchor="middle">Image error against time%s'
            '</text>' % (W / 2, " (--quick)" if quick else ""),
            '<text x="%g" y="38" font-size="11" text-anchor="middle">RMSE of the image against the exact tracer '
            '(sRGB display values) against render ms, --threads %d</text>' % (W / 2, threads),
            '<text x="%g" y="52" font-size="11" text-anchor="middle">one point per N, N written at both ends of '
            'each curve; dashed line: the exact tracer\'s own time</text>' % (W / 2)]
    items = []
    for m in methods:
        if m == "raytrace":
            items.append(("raytrace (reference time)", COLOURS[m], "5,3", None))
        elif m == "povray":
            items.append(("povray (same size, 4x4 AA)", COLOURS[m], None, "diamond"))
        elif m == "ladder":
            items.append(("raytrace at 1 to 16 samples a pixel", COLOURS[m], None, "square"))
        else:
            items.append((m, COLOURS[m], None, "circle"))
    legend(body, 60, 72, items, columns=3, col_w=min(230, (W - 80) // 3))
    for i, s in enumerate(scenes):
        x0 = (W - cols * (pw + mx) + mx) / 2 + (i % cols) * (pw + mx)
        y0 = top + 10 + (i // cols) * (ph + 90)
        srows = [r for r in ok if r["scene"] == s]
        xs = [r.get("render_ms") for r in srows]
        ys = [r.get("rmse") for r in srows if r["method"] != "raytrace"]
        p = LogPanel(body, x0, y0, pw, ph, xs, ys, s, "render time (program total minus image write)", "image RMSE", "ms")
        for m in methods:
            if m == "ladder":
                mr = sorted([r for r in srows if r["method"] in LADDER], key=lambda r: r.get("render_ms") or 0)
                p.polyline([(r.get("render_ms"), r.get("rmse")) for r in mr], COLOURS[m], marker="square",
                           labels=[r["method"].replace("raytrace_", "") for r in mr])
                continue
            mr = sorted([r for r in srows if r["method"] == m], key=lambda r: r["N"] or 0)
            if m == "raytrace":
                for r in mr:
                    x = p.px(r["render_ms"])
                    body.append('<line x1="%.1f" y1="%g" x2="%.1f" y2="%g" stroke="#000" stroke-dasharray="5,3"/>'
                                % (x, y0, x, y0 + ph))
                continue
            pts = [(r.get("render_ms"), r.get("rmse")) for r in mr]
            labels = [str(r["N"]) if j in (0, len(mr) - 1) and r["N"] else "" for j, r in enumerate(mr)]
            p.polyline(pts, COLOURS[m], marker="diamond" if m == "povray" else "circle", labels=labels)
    with open(path, "w") as f:
        f.write(svg_doc(W, H, body, "abcube: image error against time"))


def plot_parallax(path, rows, quick):
    """Error_Parallax of abuffer_thesis against N (log-log) with the bound 1/(2N^2), the thesis's
    figures and theta_max^2/4; beside it the share of hits within the bound."""
    ok = [r for r in rows if r["status"] == "ok" and r["method"] == "abuffer_thesis" and r["set"] in ("sweep", "thesis")
          and r.get("par_count")]
    scenes = []
    for r in ok:
        if r["scene"] not in scenes:
            scenes.append(r["scene"])
    pw, ph = 460, 360
    W, H = 2 * pw + 230, ph + 140 + 16 * math.ceil((len(scenes) * 3 + 3) / 3)
    body = ['<text x="%g" y="24" font-size="16" font-weight="bold" text-anchor="middle">abuffer_thesis: Error_Parallax '
            'against N, and the thesis bound 1/(2N\u00b2)%s</text>' % (W / 2, " (--quick)" if quick else "")]
    ns = [r["N"] for r in ok] + list(THESIS_FIGURES)
    cap = math.radians(THETA_MAX_DEG) ** 2 / 4
    ys = [v for r in ok for v in (r.get("par_mean"), r.get("par_max"))] + [cap, 0.5 / max(ns) ** 2]
    x0, y0 = 90, 60
    p = LogPanel(body, x0, y0, pw, ph, ns, ys, "Error_Parallax of hits (mean, p99, max)", "N (texels per face edge)",
                 "Error_Parallax")
    lo, hi = 10.0 ** p.xa, 10.0 ** p.xb
    bound_pts = [(lo * (hi / lo) ** (i / 40), 0.5 / (lo * (hi / lo) ** (i / 40)) ** 2) for i in range(41)]
    p.polyline(bound_pts, "#000", marker=None, width=2.2)
    p.polyline([(lo, cap), (hi, cap)], "#666", dash="2,3", marker=None, width=1.2)
    body.append('<text x="%.1f" y="%.1f" font-size="10" fill="#444" text-anchor="end">\u03b8max\u00b2/4 = %.2e '
                '(--theta-max %g\u00b0): largest accepted error</text>' % (x0 + pw - 6, p.py(cap) - 12, cap, THETA_MAX_DEG))
    for n, v in THESIS_FIGURES.items():
        p.marker(n, v, "#000", "star")
    items = [("bound 1/(2N\u00b2)", "#000", None, None), ("thesis 9.3.4 figures (N = 100, 200, 300)", "#000", None, "star"),
             ("\u03b8max\u00b2/4 cap", "#666", "2,3", None)]
    x1 = x0 + pw + 110
    q = LogPanel(body, x1, y0, pw, ph, ns, [], "share of hits within 1/(2N\u00b2)", "N (texels per face edge)",
                 "hits with Error_Parallax \u2264 bound", ylinear=(0.0, 1.0))
    for i, s in enumerate(scenes):
        c = SCENE_COLOURS[i % len(SCENE_COLOURS)]
        sr = sorted([r for r in ok if r["scene"] == s], key=lambda r: r["N"])
        p.polyline([(r["N"], r.get("par_p99")) for r in sr], c, marker="circle")
        p.polyline([(r["N"], r.get("par_max")) for r in sr], c, dash="6,3", marker="square", width=1.2)
        p.polyline([(r["N"], r.get("par_mean")) for r in sr], c, dash="1,3", marker="triangle", width=1.2)
        q.polyline([(r["N"], r.get("within_bound")) for r in sr], c, marker="circle")
        items += [("%s p99" % s, c, None, "circle"), ("%s max" % s, c, "6,3", "square"), ("%s mean" % s, c, "1,3", None)]
    legend(body, 60, y0 + ph + 60, items, columns=3, col_w=330)
    with open(path, "w") as f:
        f.write(svg_doc(W, H, body, "abcube: Error_Parallax against N"))


# ---------------------------------------------------------------------------------------------


def parse_args(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--abcube", default=os.path.join(REPO, "build", "abcube"))
    ap.add_argument("--scenes", help="comma-separated scene files (default: scenes/*.json and scenes/bench/*.json)")
    ap.add_argument("--sizes", help="comma-separated N (default 64,128,256,512,1024,2048)")
    ap.add_argument("--methods", help="comma-separated, of: " + ",".join(ALL_METHODS) + " (default all)")
    ap.add_argument("--out", default=os.path.join(REPO, "bench", "results"))
    ap.add_argument("--name", help="output base name (default sweep, or sweep_quick with --quick)")
    ap.add_argument("--threads", type=int, default=2, help="abcube --threads and POV-Ray +WT (default 2)")
    ap.add_argument("--quick", action="store_true", help="hidden_point and cornell at N = 64,128,256 (to try it out)")
    ap.add_argument("--repeat", type=int, default=1,
                    help="runs per (scene, method, N); the row is the run of median render ms (default 1)")
    ap.add_argument("--timeout", type=float, default=7200, help="seconds per run (default 7200)")
    ap.add_argument("--no-thesis", action="store_true", help="leave out the N = 100, 200, 300 runs")
    ap.add_argument("--no-skips", action="store_true", help="leave out the --plan everything/needed runs")
    ap.add_argument("--keep", action="store_true", help="keep images and stats of every run in the work folder")
    ap.add_argument("--work", help="parent folder of the temporary work folders (default: the system's)")
    a = ap.parse_args(argv)
    if a.scenes:
        a.scenes = [s for s in a.scenes.split(",") if s]
    elif a.quick:
        a.scenes = [os.path.join(REPO, s) for s in QUICK_SCENES]
    else:
        a.scenes = sorted(glob.glob(os.path.join(REPO, "scenes", "*.json"))) + \
            sorted(glob.glob(os.path.join(REPO, "scenes", "bench", "*.json"))) + \
            [os.path.join(REPO, s) for s in MODEL_SCENES]
    try:
        a.sizes = [int(s) for s in a.sizes.split(",") if s] if a.sizes else (QUICK_SIZES if a.quick else DEFAULT_SIZES)
    except ValueError:
        ap.error("--sizes: comma-separated integers")
    a.methods = [m for m in a.methods.split(",") if m] if a.methods else list(ALL_METHODS)
    unknown = [m for m in a.methods if m not in ALL_METHODS]
    if unknown:
        ap.error("--methods: unknown %s (known: %s)" % (", ".join(unknown), ", ".join(ALL_METHODS)))
    a.name = a.name or ("sweep_quick" if a.quick else "sweep")
    missing = [s for s in a.scenes if not os.path.isfile(s)]
    if missing:
        ap.error("no such scene: " + ", ".join(missing))
    if not (os.path.isfile(a.abcube) and os.access(a.abcube, os.X_OK)):
        ap.error("%s: not an executable (build it: cmake --build build)" % a.abcube)
    return a


def git_commit():
    """HEAD, and the tracked source files changed in the working tree (the binary may hold them)."""
    try:
        head = subprocess.run(["git", "-C", REPO, "rev-parse", "--short", "HEAD"], stdout=subprocess.PIPE,
                              stderr=subprocess.DEVNULL, text=True).stdout.strip() or "?"
        dirty = subprocess.run(["git", "-C", REPO, "status", "--porcelain", "--untracked-files=no", "--", "cpu_core",
                                "host", "shaders", "CMakeLists.txt"], stdout=subprocess.PIPE,
                               stderr=subprocess.DEVNULL, text=True).stdout.split("\n")
    except OSError:
        return "?"
    dirty = [l[3:] for l in dirty if l.strip()]
    return head + (" with uncommitted changes to %s" % ", ".join(dirty) if dirty else "")


def main(argv):
    a = parse_args(argv)
    os.makedirs(a.out, exist_ok=True)
    meta = {"command": " ".join(["python3", "bench/sweep.py"] + argv), "commit": git_commit(),
            "machine": "%s %s" % (platform.system(), platform.machine()),
            "when": time.strftime("%Y-%m-%d %H:%M %Z"), "load_start": os.getloadavg()[0]}
    sweep = Sweep(a)
    log("sweep: %d scenes, N = %s, methods %s, --threads %d -> %s/%s.*" % (
        len(a.scenes), ",".join(map(str, a.sizes)), ",".join(a.methods), a.threads, a.out, a.name))
    for s in a.scenes:
        sweep.scene(s)
    sweep.stats_log.close()
    meta["load_end"] = os.getloadavg()[0]
    meta["gl"] = next((r.get("gl_renderer") for r in sweep.rows if r["method"] == "gpu" and r.get("gl_renderer")), None)
    write_csv(os.path.join(a.out, a.name + ".csv"), sweep.rows)
    write_markdown(os.path.join(a.out, a.name + ".md"), sweep, a, meta)
    write_geometry_csv(os.path.join(a.out, a.name + ".bound_geometry.csv"), sweep.geometry)
    plot_error_vs_time(os.path.join(a.out, a.name + ".error_vs_time.svg"), sweep.rows, a.quick, a.threads)
    plot_parallax(os.path.join(a.out, a.name + ".parallax_vs_N.svg"), sweep.rows, a.quick)
    log("wrote %s/%s.{csv,md,error_vs_time.svg,parallax_vs_N.svg,bound_geometry.csv,stats.jsonl}; %d runs, %d failed" % (
        a.out, a.name, len(sweep.rows), sweep.failures))
    return 1 if sweep.failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
