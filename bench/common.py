"""What the benchmark scripts share: running a program, the PSNR as `abcube compare` gives
it, and a whole process's peak memory and wall time.

Every figure a script reports is read from abcube itself (its compare, its stats), so two
scripts that measure the same images print the same dB.
"""
import math
import re
import subprocess
import sys


def run(cmd, **kw):
    """Runs cmd and returns its stdout; a failure ends the script with the command and the end
    of its stderr, since a benchmark with a missing row would mislead."""
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kw)
    if p.returncode != 0:
        sys.exit("failed (%d): %s\n%s" % (p.returncode, " ".join(map(str, cmd)), p.stderr.strip()[-2000:]))
    return p.stdout


def parse_psnr(compare_stdout):
    """The PSNR line of `abcube compare`'s output in dB (inf for identical images), or None."""
    m = re.search(r"^PSNR\s+(\S+)", compare_stdout, re.M)
    if not m:
        return None
    return math.inf if m.group(1).startswith("inf") else float(m.group(1))


def psnr(abcube, image, reference):
    """PSNR dB of image against reference, from `abcube compare` (displayed values). Its exit
    status says pass or fail at its pixel threshold; only the figure is used."""
    p = subprocess.run([abcube, "compare", image, reference], stdout=subprocess.PIPE,
                       stderr=subprocess.PIPE, text=True)
    db = parse_psnr(p.stdout)
    if db is None:
        sys.exit("no PSNR from abcube compare %s %s: %s" % (image, reference, p.stderr.strip()[-500:]))
    return db


def peak_rss_kib(cmd):
    """Runs cmd under /usr/bin/time -v; returns (exit status, peak RSS in KiB, wall seconds)."""
    p = subprocess.run(["/usr/bin/time", "-v"] + cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    rss = re.search(r"Maximum resident set size \(kbytes\): (\d+)", p.stderr)
    wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): (?:(\d+):)?(\d+):([\d.]+)", p.stderr)
    seconds = 0.0
    if wall:
        seconds = int(wall.group(1) or 0) * 3600 + int(wall.group(2)) * 60 + float(wall.group(3))
    if p.returncode != 0:
        sys.stderr.write("FAILED (%d): %s\n%s\n" % (p.returncode, " ".join(cmd), p.stderr[-2000:]))
    return p.returncode, int(rss.group(1)) if rss else 0, seconds
