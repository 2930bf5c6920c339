#!/usr/bin/env python3
"""The mutation check: one-line changes to the rules the method decides, each applied alone,
built, and run against the labelled tests. A change the tests do not notice (SURVIVED) is a
rule no test pins.

    /usr/bin/python3 tools/mutate.py [--build DIR] [--only NAME,...] [--out FILE.md] [--list]

Each change replaces one exact text, found exactly once in its file (else the check stops:
the list is stale). The file is restored after each change, and on any exit but SIGKILL
(a run then refuses to start until the file is git's again). The build
folder (default build-mutate, configured on first use) is the project's, built with the
change; the tests run by label, fastest first (core, api, gl, hard, cli), and stop at the
first failure: a change is KILLED by that test. About 3 to 10 minutes a change on 2 cores,
most of it the rebuild of what includes the changed file.

Changes marked EQUIVALENT are expected to survive: the note says why no test can tell them
apart, and the check reports them as "equivalent" when they survive, "killed" otherwise.
"""
import argparse
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

# name, file, the exact text, its replacement, what the change means, equivalent (why) or None
MUTATIONS = [
    ("origin_rule", "cpu_core/reference/triangle_test.hpp",
     "  if (std::fabs(s) <= s_error_bound(x, y, z, e)) return false;\n", "",
     "THE ORIGIN RULE dropped: a hit at t ~ 0 decided by the sign of the rounding", None),
    ("t_zero_accepted", "cpu_core/reference/triangle_test.hpp",
     "(t_scaled <= 0.0 || t_scaled >= tmax * det)", "(t_scaled < 0.0 || t_scaled >= tmax * det)",
     "a hit at exactly t = 0 accepted (before the origin rule)",
     "THE ORIGIN RULE rejects every t within rounding of 0, exact 0 included: this test never decides"),
    ("t_zero_and_rule", "cpu_core/reference/triangle_test.hpp",
     "  if (std::fabs(s) <= s_error_bound(x, y, z, e)) return false;\n"
     "  const double inv_det",
     "  if (det > 0.0 ? t_scaled < 0.0 : t_scaled > 0.0) return false;\n  const double inv_det",
     "hits at t = 0 accepted: the origin rule dropped, t >= 0 kept", None),
    ("merge_overlapping_masks", "cpu_core/raster/abuffer.cpp",
     "(a.mask & b.mask) == 0 && b.zmin <= a.zmax", "b.zmin <= a.zmax",
     "thesis 5.2 merge: fragments merged where their masks overlap", None),
    ("self_intersection_offset", "cpu_core/material/shading.hpp",
     "constexpr double SELF_INTERSECTION_REL = 1e-9;", "constexpr double SELF_INTERSECTION_REL = 1e-3;",
     "secondary and shadow rays start 1e-3 of the scene off their surface", None),
    ("snell_sign", "cpu_core/material/shading.hpp",
     "*t = eta * i + (eta * c1 - std::sqrt(k)) * n;", "*t = eta * i + (eta * c1 + std::sqrt(k)) * n;",
     "Snell's law: the wrong sign of the normal term", None),
    ("eta_inverted", "cpu_core/material/shading.hpp",
     "r.eta = n_from / n_to;", "r.eta = n_to / n_from;",
     "eta = n_to / n_from instead of n_from / n_to", None),
    ("phong_exponent", "cpu_core/material/shading.hpp",
     "std::pow(rdotv, m.shininess)", "std::pow(rdotv, m.shininess + 1.0)",
     "Phong's specular exponent off by one", None),
    ("schlick_power", "cpu_core/material/shading.hpp",
     "std::pow(1.0 - std::min(c, 1.0), 5.0)", "std::pow(1.0 - std::min(c, 1.0), 4.0)",
     "Schlick's Fresnel power 4 instead of 5", None),
    ("resolve_area", "cpu_core/shading/resolve.cpp",
     "const double w_in = item.weight * (mask_count(in) / total);",
     "const double w_in = item.weight * (mask_count(f.mask) / total);",
     "Pack_Under_Mask: the inside's area from the fragment's mask, not the searched part of it", None),
    ("cube_face_tie", "cpu_core/raster/cube_map.cpp",
     "if (ax >= ay && ax >= az) {", "if (ax > ay && ax >= az) {",
     "a direction on the x = y diagonal goes to the y faces, not the x faces", None),
    ("sample_positions", "cpu_core/base/samples.hpp",
     "constexpr double sample_dx(int k) { return ((k % MASK_COLUMNS) + 0.5) / MASK_COLUMNS; }",
     "constexpr double sample_dx(int k) { return ((k % MASK_COLUMNS) + 0.25) / MASK_COLUMNS; }",
     "the 4x8 sample positions shifted a quarter column", None),
    ("sample_ladder", "cpu_core/base/samples.hpp",
     "{17, 14, 2,  29,", "{17, 2, 14,  29,",
     "THE SAMPLE LADDER: rung 2 no longer a symmetric pair", None),
    ("thesis_threshold", "cpu_core/search/search_rays.cpp",
     "const bool accepted = best.fragment && best.angle <= o.theta_max;",
     "const bool accepted = best.fragment && best.angle <= 2.0 * o.theta_max;",
     "thesis 7.4: the acceptance angle theta_max doubled", None),
]

LABELS = ["core", "api", "gl", "hard", "cli"]


def run(cmd):
    """The command's result. It runs in a process group of its own, which is killed whole if
    this script is stopped meanwhile: a ninja left running under a stopped cmake could
    compile a mutated file after the file was restored, and leave that object looking newer
    than its source."""
    proc = subprocess.Popen(cmd, cwd=ROOT, text=True, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            start_new_session=True)
    try:
        out, err = proc.communicate()
    except BaseException:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
        raise
    return subprocess.CompletedProcess(cmd, proc.returncode, out, err)


def configure(build):
    if not (ROOT / build / "build.ninja").exists():
        r = run(["cmake", "-S", ".", "-B", build, "-G", "Ninja"])
        if r.returncode != 0:
            sys.exit("mutate: configure failed:\n" + r.stdout[-2000:] + r.stderr[-2000:])


# What the labelled tests run: the program and the three test programs (no Python module,
# benchmarks or fuzz replays: fewer files to rebuild a change).
TARGETS = ["abcube", "test_core", "test_api", "test_gl"]


def build_all(build):
    return run(["cmake", "--build", build, "--target", *TARGETS])


def first_failure(build):
    """The first failing test, label by label; None when every test passes."""
    for label in LABELS:
        r = run(["ctest", "--test-dir", build, "-L", f"^{label}$", "-j2", "--stop-on-failure",
                 "--output-on-failure"])
        if r.returncode != 0:
            m = re.search(r"Test\s+#\d+: (\S+) \.+\*+(Failed|Exception|Timeout)", r.stdout)
            return f"{label}: {m.group(1)}" if m else f"{label}: (see ctest output)"
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--build", default="build-mutate")
    ap.add_argument("--only", default="")
    ap.add_argument("--out", default="")
    ap.add_argument("--list", action="store_true")
    a = ap.parse_args()
    chosen = [m for m in MUTATIONS if not a.only or m[0] in a.only.split(",")]
    # A run killed mid-change (SIGKILL, a power cut) leaves its change in the file: refuse to
    # start on a file that differs from git's, so that no later run measures a mutated tree.
    changed = run(["git", "diff", "--name-only", "--", *sorted({m[1] for m in chosen})]).stdout.split()
    if changed:
        sys.exit(f"mutate: {', '.join(changed)} differ from git (a change of a killed run?): "
                 "git checkout -- FILE, then run again")
    # SIGTERM and SIGHUP end the run through the `finally` below, which restores the file.
    for sig in (signal.SIGTERM, signal.SIGHUP):
        signal.signal(sig, lambda number, frame: sys.exit(f"mutate: stopped by signal {number}"))
    for name, path, old, new, _, _ in chosen:  # the list must match the sources
        text = (ROOT / path).read_text()
        if text.count(old) != 1:
            sys.exit(f"mutate: {name}: the text to change occurs {text.count(old)} times in {path}")
    if a.list:
        for name, path, _, _, what, eq in chosen:
            print(f"{name:26} {path:40} {what}" + (" (equivalent)" if eq else ""))
        return 0
    configure(a.build)
    b = build_all(a.build)
    if b.returncode != 0:
        sys.exit("mutate: the unchanged build fails:\n" + b.stdout[-3000:])
    rows = []
    for name, path, old, new, what, equivalent in chosen:
        file = ROOT / path
        original = file.read_text()
        start = time.time()
        try:
            file.write_text(original.replace(old, new, 1))
            b = build_all(a.build)
            if b.returncode != 0:
                verdict, by = "killed", "the build"
            else:
                failed = first_failure(a.build)
                if failed:
                    verdict, by = "killed", failed
                else:
                    verdict, by = ("equivalent" if equivalent else "SURVIVED"), (equivalent or "")
        finally:
            file.write_text(original)
            os.utime(file)
        seconds = time.time() - start
        rows.append((name, path, what, verdict, by, seconds))
        print(f"mutate: {name}: {verdict} {by} ({seconds:.0f} s)", flush=True)
    build_all(a.build)  # leave the build matching the sources
    lines = ["| change | file | what it means | verdict | by | seconds |", "|---|---|---|---|---|---|"]
    for name, path, what, verdict, by, seconds in rows:
        lines.append(f"| {name} | `{path}` | {what} | {verdict} | {by} | {seconds:.0f} |")
    table = "\n".join(lines)
    print(table)
    if a.out:
        Path(a.out).write_text(table + "\n")
    return 1 if any(r[3] == "SURVIVED" for r in rows) else 0


if __name__ == "__main__":
    sys.exit(main())
