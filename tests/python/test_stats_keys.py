"""The stats JSON keeps its keys: for each method, and for the reference, --target-db and
the AOVs, every key path of `abcube render --stats` (values aside; a list's items under
"[]") equals the pinned list in tests/golden/stats_keys.json. A key renamed, dropped or
added by a change of the passes fails here; a deliberate change rewrites the list with
ABCUBE_UPDATE_STATS_KEYS=1 and says so in its commit."""
import json
import os
import subprocess

import pytest

SOURCE = os.environ["ABCUBE_SOURCE_DIR"]
BIN = os.environ["ABCUBE_BIN"]
PINNED = os.path.join(SOURCE, "tests", "golden", "stats_keys.json")
SCENE = os.path.join(SOURCE, "scenes", "cornell.json")
SMALL = ["--size", "48x36", "--cube-res", "48"]

# (name, arguments): the GL methods through OSMesa, whose stats hold the same keys on any
# machine (an EGL device adds its index).
CASES = {
    "abuffer_reference": ["--method", "abuffer", *SMALL, "--reference", "--gl", "none"],
    "abuffer_aovs": ["--method", "abuffer", *SMALL, "--aovs", "distance,fallback", "--gl", "none"],
    "abuffer_target_db": ["--method", "abuffer", "--size", "48x36", "--target-db", "30", "--gl", "none"],
    "zbuffer": ["--method", "zbuffer", *SMALL, "--gl", "none"],
    "envmap": ["--method", "envmap", *SMALL, "--gl", "none"],
    "raytrace": ["--method", "raytrace", "--size", "48x36", "--samples", "4", "--gl", "none"],
    "raytrace_target_db": ["--method", "raytrace", "--size", "48x36", "--target-db", "30", "--gl", "none"],
    "gpu": ["--method", "gpu", *SMALL, "--gl", "osmesa"],
    "hybrid": ["--method", "hybrid", *SMALL, "--gl", "osmesa"],
    "gpu_abuffer": ["--method", "gpu_abuffer", *SMALL, "--gl", "osmesa"],
}


def key_paths(value, prefix=""):
    """Every path to a leaf: "plan.skipped[].why"; an empty object or list is a leaf too."""
    if isinstance(value, dict):
        if not value:
            return {prefix + "{}"}
        return set().union(*(key_paths(v, f"{prefix}.{k}" if prefix else k) for k, v in value.items()))
    if isinstance(value, list):
        return set().union({prefix + "[]"}, *(key_paths(v, prefix + "[]") for v in value))
    return {prefix}


def stats_paths(tmp_path, name):
    out, stats = tmp_path / f"{name}.exr", tmp_path / f"{name}.json"
    args = [BIN, "render", SCENE, "-o", str(out), "--stats", str(stats), *CASES[name]]
    r = subprocess.run(args, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return sorted(key_paths(json.loads(stats.read_text())))


def test_every_case_is_pinned():
    with open(PINNED) as f:
        assert sorted(json.load(f)) == sorted(CASES)


@pytest.mark.parametrize("name", sorted(CASES))
def test_the_stats_keep_their_keys(tmp_path, name):
    paths = stats_paths(tmp_path, name)
    if os.environ.get("ABCUBE_UPDATE_STATS_KEYS") == "1":
        pinned = json.load(open(PINNED)) if os.path.exists(PINNED) else {}
        pinned[name] = paths
        with open(PINNED, "w") as f:
            json.dump(pinned, f, indent=1, sort_keys=True)
            f.write("\n")
        return
    with open(PINNED) as f:
        want = json.load(f)[name]
    assert paths == want, {"added": sorted(set(paths) - set(want)), "dropped": sorted(set(want) - set(paths))}
