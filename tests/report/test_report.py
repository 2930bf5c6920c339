"""abcube report: the page a person looks at. Its files, its figures against each
render's stats, and the page itself in a real browser (headless Chromium): no script
error, every image loaded, every figure on the page equal to report.json's."""
import json
import os
import re
import shutil
import subprocess
from html.parser import HTMLParser
from pathlib import Path

import pytest

SRC = Path(os.environ["ABCUBE_SOURCE_DIR"])
BIN = os.environ["ABCUBE_BIN"]
METHODS = ["abuffer", "gpu", "hybrid", "zbuffer", "envmap"]


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    out = tmp_path_factory.mktemp("report") / "cornell report"  # a blank in the path, as users have
    r = subprocess.run([BIN, "report", str(SRC / "scenes" / "cornell.json"), "-o", str(out), "--width", "160",
                        "--height", "120", "--cube-res", "64", "--sweep", "32,64"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return out, json.loads((out / "report.json").read_text())


def lookup(data, key):
    for part in key.split("."):
        data = data[int(part)] if isinstance(data, list) else data[part]
    return data


def test_files_and_figures_equal_the_stats(report):
    out, j = report
    assert (out / "index.html").stat().st_size > 1000
    assert sorted(j["methods"]) == sorted(METHODS)
    for m in METHODS:
        x = j["methods"][m]
        assert "failed" not in x, x.get("failed")  # llvmpipe gives every method GL
        stats = json.loads((out / x["stats"]).read_text())
        assert x["error"]["psnr_db"] == stats["reference"]["image_error"]["psnr_db"], m
        assert x["error"]["rmse"] == stats["reference"]["image_error"]["rmse"], m
        assert x["total_ms"] == stats["timings_ms"]["total"], m
        for image in (x["image"], x["heat"]):
            assert (out / image).stat().st_size > 0
        kinds = x["regions"]["kinds"]
        assert sum(k["pixels"] for name, k in kinds.items() if name != "in shadow") == 160 * 120
        assert {"mirror", "glass", "diffuse", "in shadow"} <= set(kinds), kinds  # cornell has all four
        assert 0 < kinds["in shadow"]["pixels"] < 160 * 120
        w = x["error"]["worst_pixel"]
        assert 0 <= w["x"] < 160 and 0 <= w["y"] < 120
    assert [p["n"] for p in j["sweep"]["points"]] == [32, 64]
    # The tracer's ladder: 1 to 32 samples, nearer the reference as it climbs; each method held
    # to its matched rung, the fastest rung at least as close; the front named.
    ladder = j["ladder"]
    assert [r["samples"] for r in ladder] == [1, 2, 4, 8, 16, 32]
    db = [r["error"]["psnr_db"] for r in ladder[:-1]]
    assert db == sorted(db) and ladder[-1]["error"]["psnr_db"] == "inf", db
    for m in METHODS:
        rung = j["methods"][m]["matched_rung"]
        match = next(r for r in ladder if r["samples"] == rung["samples"])
        assert match["error"]["psnr_db"] == "inf" or match["error"]["psnr_db"] >= j["methods"][m]["error"]["psnr_db"]
        faster_and_close = [r for r in ladder if r["total_ms"] < match["total_ms"] and r["error"]["psnr_db"] != "inf"
                            and r["error"]["psnr_db"] >= j["methods"][m]["error"]["psnr_db"]]
        assert not faster_and_close, (m, faster_and_close)
        assert abs(rung["time_ratio"] - j["methods"][m]["total_ms"] / rung["total_ms"]) < 1e-9
    assert j["front"] and set(j["front"]) <= set(METHODS) | {f"raytrace {r['samples']}" for r in ladder}
    assert j["crosscheck"]["pass"] is True, j["crosscheck"].get("failures")
    assert j["context"]["gl_renderer"] and j["context"]["cores"] >= 1


def test_the_heat_map_shows_where_gpu_and_abuffer_differ(report):
    import abcube
    out, j = report
    heat = abcube.read_image(str(out / j["methods"]["gpu"]["heat"]))
    image = abcube.read_image(str(out / j["methods"]["gpu"]["image"]))
    assert heat.shape[1] == image.shape[1] and heat.shape[0] > image.shape[0]  # the legend beneath
    assert heat[: image.shape[0]].max() > 0.2  # somewhere the two differ visibly (cornell's curved mirrors)


class Page(HTMLParser):
    def __init__(self):
        super().__init__()
        self.body, self.figures, self.images, self._key = {}, [], 0, None
        self.chart, self.in_chart, self.verdicts, self._in_verdict = {}, False, 0, False

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "body":
            self.body = a
        if tag == "svg" and a.get("id") == "front-chart":
            self.in_chart = True
        if self.in_chart and tag in ("circle", "path"):
            key = a.get("class", tag)
            self.chart[key] = self.chart.get(key, 0) + 1
        if tag == "h2":
            self._in_verdict = a.get("id") == "verdict"
        if tag == "li" and self._in_verdict:
            self.verdicts += 1
        if tag == "img":
            self.images += 1
        if "data-key" in a:
            self._key = a
            self.figures.append([a, ""])

    def handle_data(self, data):
        if self._key is not None:
            self.figures[-1][1] += data

    def handle_endtag(self, tag):
        self._key = None
        if tag == "svg":
            self.in_chart = False


def chromium():
    for name in ("chromium", "chromium-browser"):
        if shutil.which(name):
            return shutil.which(name)
    return None


@pytest.mark.skipif(chromium() is None, reason="no chromium (bash tools/setup.sh --test installs it)")
def test_the_page_in_a_browser(report, tmp_path):
    out, j = report
    r = subprocess.run([chromium(), "--headless=new", "--no-sandbox", "--disable-gpu", "--no-first-run",
                        f"--user-data-dir={tmp_path / 'profile'}", "--enable-logging=stderr", "--v=0",
                        "--virtual-time-budget=15000", "--dump-dom", (out / "index.html").as_uri()],
                       capture_output=True, text=True, timeout=180)
    assert r.returncode == 0, r.stderr[-3000:]
    console = [line for line in r.stderr.splitlines() if "CONSOLE" in line or "Uncaught" in line]
    assert not console, console
    page = Page()
    page.feed(r.stdout)
    assert page.body.get("data-errors") == "0", page.body
    assert page.body.get("data-images-broken") == "0", page.body
    assert int(page.body.get("data-images-loaded", "-1")) == page.images > 10, page.body
    assert len(page.figures) > 50
    # The chart of time against error is drawn: a dot a method, the ladder's rungs, the front
    # ringed; one verdict a method.
    assert page.chart.get("point", 0) == len(METHODS), page.chart
    assert page.chart.get("rung", 0) == 5, page.chart
    assert page.chart.get("front", 0) == len(j["front"]) - ("raytrace 32" in j["front"]), page.chart
    assert page.verdicts == len(METHODS)
    for attrs, text in page.figures:
        value = lookup(j, attrs["data-key"])
        assert json.loads(attrs["data-value"]) == value, attrs
        if isinstance(value, (int, float)):
            shown = float(value) * float(attrs["data-scale"])
            assert abs(float(text) - shown) <= 0.5 * 10 ** -int(attrs["data-decimals"]) + 1e-9, (attrs, text)
    # the PSNR on the page is the stats file's
    for m in METHODS:
        stats = json.loads((out / j["methods"][m]["stats"]).read_text())
        shown = [t for a, t in page.figures if a["data-key"] == f"methods.{m}.error.psnr_db" and a["data-decimals"] == "2"]
        assert shown and abs(float(shown[0]) - stats["reference"]["image_error"]["psnr_db"]) <= 0.005


def test_python_report(tmp_path):
    import abcube
    scene = abcube.load_scene(str(SRC / "scenes" / "default.json"))
    r = abcube.report(scene, str(tmp_path / "r"), methods=["abuffer", "zbuffer"], width=80, height=60, cube_res=32,
                      crosscheck=False)
    assert Path(r["index_html"]).exists() and set(r["methods"]) == {"abuffer", "zbuffer"}
    assert r["crosscheck"]["skipped"] == "not asked for"
    with pytest.raises(abcube.SceneError, match="did you mean abuffer"):
        abcube.report(scene, str(tmp_path / "bad"), methods=["abufer"])


def test_options_the_report_decides_are_refused(tmp_path):
    # cli.md: report refuses, with exit 2 and one line, the render options it decides itself.
    scene = str(SRC / "scenes" / "cornell.json")
    for args, flag in ((["--method", "envmap"], "--method"), (["--aovs", "distance"], "--aovs"),
                       (["--reference-image", str(tmp_path / "ref.exr")], "--reference-image"),
                       (["--samples", "4"], "--samples")):
        out = tmp_path / flag.strip("-")
        r = subprocess.run([BIN, "report", scene, "-o", str(out), "--width", "32", "--height", "24", *args],
                           capture_output=True, text=True)
        assert r.returncode == 2, (args, r.stderr)
        assert r.stderr.count("\n") == 1 and f"{flag}: not used by report" in r.stderr, r.stderr
        assert not out.exists(), args
    import abcube
    with pytest.raises(abcube.SceneError, match="method: not used by report"):
        abcube.report(abcube.load_scene(scene), str(tmp_path / "py"), method="envmap")
