"""The option table: every render option through each door (abcube render, abcube batch,
Renderer.render) gets the same check and the same message; an option a method does not use
is refused the same way by all three; output folders follow one rule."""
import json
import os
import subprocess
from pathlib import Path

import pytest

import abcube

SRC = Path(os.environ["ABCUBE_SOURCE_DIR"])
BIN = os.environ["ABCUBE_BIN"]
CORNELL = str(SRC / "scenes" / "cornell.json")
TABLE = abcube.render_options()
JOB_OPTIONS = [o for o in TABLE if o["scope"] == "job"]


def bad_value(option):
    """A value the table must refuse, as the command line types it and as JSON holds it."""
    kind = option["kind"]
    if kind == "choice":
        return "nonsense", "nonsense"
    if kind == "integer":
        high = int(option["range"][1]) * 2 + 1
        return str(high), high
    if kind == "number":
        high = option["range"][1] * 2 + 1
        return repr(high), high
    if kind == "vec3":
        return "1,2", [1, 2]
    if kind == "names":
        return "nonsense", ["nonsense"]
    if kind == "path":
        return "", ""
    if kind == "text":
        return "12", "12"
    return None  # flags take no value on the command line; settings have their own form


def cli_reason(option, text):
    r = subprocess.run([BIN, "render", CORNELL, "-o", "/tmp/abcube-never-written/x.png", option["flag"], text],
                       capture_output=True, text=True)
    assert r.returncode == 2, (option["key"], r.stderr)
    prefix = "abcube: " + option["flag"] + ": "
    assert r.stderr.startswith(prefix), (option["key"], r.stderr)
    return r.stderr[len(prefix):].strip()


def batch_reason(option, value, tmp_path):
    jobs = tmp_path / "jobs.jsonl"
    jobs.write_text(json.dumps({"scene": CORNELL, "out": str(tmp_path / "x.png"), option["key"]: value}) + "\n")
    r = subprocess.run([BIN, "batch", str(jobs)], capture_output=True, text=True)
    assert r.returncode == 2, (option["key"], r.stderr)
    prefix = f'abcube: {jobs}:1: "{option["key"]}": '
    assert r.stderr.startswith(prefix), (option["key"], r.stderr)
    return r.stderr[len(prefix):].strip()


def python_reason(option, value):
    scene = abcube.load_scene(CORNELL)
    with pytest.raises(abcube.SceneError) as e:
        abcube.Renderer(gl="none").render(scene, **{option["key"]: value})
    message = str(e.value)
    assert message.startswith(option["key"] + ": "), message
    return message[len(option["key"]) + 2:]


def test_the_table_is_whole():
    keys = [o["key"] for o in TABLE]
    assert len(keys) == len(set(keys))
    for option in TABLE:
        assert option["flag"].startswith("--") and option["help"] and option["default"], option
        for method in option["methods"]:
            assert method in ("abuffer", "zbuffer", "envmap", "raytrace", "gpu", "hybrid", "gpu_abuffer"), option
    # the options the documents promise
    for key in ["method", "cube_res", "max_depth", "width", "height", "size", "fov_y", "camera_position", "look_at",
                "set", "search", "gpu_shadows", "aovs", "timeout", "threads", "max_memory"]:
        assert key in keys, key


@pytest.mark.parametrize("option", [o for o in JOB_OPTIONS if bad_value(o)], ids=lambda o: o["key"])
def test_a_bad_value_gets_one_message_through_every_door(option, tmp_path):
    text, value = bad_value(option)
    reasons = {cli_reason(option, text), batch_reason(option, value, tmp_path), python_reason(option, value)}
    assert len(reasons) == 1, reasons
    assert next(iter(reasons)).startswith(("must be", "unknown name")), reasons


@pytest.mark.parametrize("option", [o for o in JOB_OPTIONS if o["methods"]], ids=lambda o: o["key"])
def test_an_option_a_method_does_not_use_is_refused_through_every_door(option, tmp_path):
    method = next(m for m in ("raytrace", "abuffer", "gpu") if m not in option["methods"])
    kind = option["kind"]
    if kind == "choice":  # a value other than the default
        good = next(c for c in reversed(option["choices"]) if c != option["default"])
    elif kind == "integer":
        good = max(1, int(option["range"][1] // 2))
    elif kind == "number":
        good = option["range"][1] / 2
    else:
        assert kind == "flag", option
        good = True
    text = "true" if good is True else str(good)
    expected = f"not used by method {method}"
    # the command line
    args = [BIN, "render", CORNELL, "-o", str(tmp_path / "x.png"), "--method", method, option["flag"]]
    r = subprocess.run(args + ([] if option["kind"] == "flag" else [text]), capture_output=True, text=True)
    assert r.returncode == 2 and f"{option['flag']}: {expected}" in r.stderr, r.stderr
    # a batch job: its own key is refused before anything renders (exit 2), named by its line
    jobs = tmp_path / "jobs.jsonl"
    jobs.write_text(json.dumps({"scene": CORNELL, "out": str(tmp_path / "y.png"), "method": method,
                                option["key"]: good}) + "\n")
    r = subprocess.run([BIN, "batch", str(jobs)], capture_output=True, text=True)
    assert r.returncode == 2 and f'jobs.jsonl:1: "{option["key"]}": {expected}' in r.stderr, r.stderr
    # Python
    with pytest.raises(abcube.SceneError, match=f"{option['key']}: {expected}"):
        abcube.Renderer(gl="none").render(abcube.load_scene(CORNELL), method=method, **{option["key"]: good})
    assert not (tmp_path / "x.png").exists() and not (tmp_path / "y.png").exists()


def test_unknown_names_suggest_the_nearest():
    r = subprocess.run([BIN, "render", CORNELL, "-o", "x.png", "--widht", "3"], capture_output=True, text=True)
    assert r.returncode == 2 and "did you mean --width?" in r.stderr, r.stderr
    with pytest.raises(abcube.SceneError, match="did you mean cube_res"):
        abcube.Renderer(gl="none").render(abcube.load_scene(CORNELL), cube_rez=3)
    bad = json.loads((SRC / "scenes" / "cornell.json").read_text())
    bad["camera"]["fovy"] = 30
    with pytest.raises(abcube.SceneError, match="did you mean fov_y"):
        abcube.scene_from_dict(bad)
    r = subprocess.run([BIN, "render", CORNELL, "-o", "x.pgn"], capture_output=True, text=True)
    assert r.returncode == 2 and "(" in r.stderr and " png," in r.stderr and "exr" in r.stderr, r.stderr


def test_size_and_set_through_every_door(tmp_path):
    """--width/--height and --set on the command line, as batch keys and as keywords: the
    same image, and a bad --set value gets the scene's own message."""
    out = tmp_path / "cli.exr"
    subprocess.run([BIN, "render", CORNELL, "-o", str(out), "--method", "raytrace", "--size", "40x30",
                    "--set", "camera.fov_y=30", "--set", "render.max_depth=1"], check=True)
    jobs = tmp_path / "jobs.jsonl"
    jobs.write_text(json.dumps({"scene": CORNELL, "out": str(tmp_path / "deep" / "er" / "batch.exr"),
                                "method": "raytrace", "width": 40, "height": 30,
                                "set": {"camera.fov_y": 30, "render.max_depth": 1}}) + "\n")
    subprocess.run([BIN, "batch", str(jobs)], check=True, capture_output=True)
    scene = abcube.load_scene(CORNELL)
    image = abcube.Renderer(gl="none").render(scene, method="raytrace", width=40, height=30,
                                               set={"camera.fov_y": 30, "render.max_depth": 1})
    a, b = abcube.read_image(str(out)), abcube.read_image(str(tmp_path / "deep" / "er" / "batch.exr"))
    assert a.shape == (30, 40, 3) and (a == b).all() and (a == image).all()
    wide = abcube.Renderer(gl="none").render(scene, method="raytrace", width=40, height=30)
    assert not (wide == image).all()  # the field of view changed the view
    r = subprocess.run([BIN, "render", CORNELL, "-o", str(tmp_path / "bad.png"), "--set", "camera.fov_y=200"],
                       capture_output=True, text=True)
    assert r.returncode == 2 and r.stderr.strip() == f"abcube: {CORNELL}: camera.fov_y: must be > 0 and < 180 (degrees), got 200"
    with pytest.raises(abcube.SceneError, match="camera.fov_y: must be > 0 and < 180"):
        abcube.Renderer(gl="none").render(scene, set={"camera.fov_y": 200})
    assert not (tmp_path / "bad.png").exists()


def test_a_model_file_takes_the_size(tmp_path):
    glb = Path("/usr/share/assimp/models/glTF2/BoxTextured-glTF-Binary/BoxTextured.glb")
    if not glb.exists():
        pytest.skip("assimp-testmodels not installed")
    out = tmp_path / "model.png"
    subprocess.run([BIN, "render", str(glb), "-o", str(out), "--width", "320", "--height", "240", "--method", "raytrace"],
                   check=True)
    image = abcube.read_image(str(out))
    assert image.shape == (240, 320, 3) and image.mean() > 0.02
