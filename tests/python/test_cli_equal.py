"""The module's images equal those `abcube render SCENE -o x.exr` writes for the same
inputs (python.md: identical, as float EXR)."""
import subprocess

import pytest

import abcube
from conftest import assert_same_image, write_scene

CASES = [
    # (method, extra CLI options, the same as render() keywords, Renderer gl)
    ("raytrace", [], {}, "none"),
    ("abuffer", [], {}, "none"),
    ("abuffer", ["--cube-res", "48", "--max-depth", "1"], {"cube_res": 48, "max_depth": 1}, "none"),
    ("zbuffer", [], {}, "none"),
    ("envmap", ["--envmap-lookup", "bisector"], {"envmap_lookup": "bisector"}, "none"),
    ("gpu", [], {}, "egl"),
    ("gpu", ["--gpu-shading", "samples"], {"gpu_shading": "samples"}, "egl"),
    ("gpu", ["--gpu-mirrors", "envmap", "--gpu-shadows", "maps", "--gpu-max-views", "4"],
     {"gpu_mirrors": "envmap", "gpu_shadows": "maps", "gpu_max_views": 4}, "egl"),
    ("hybrid", [], {}, "egl"),
]


@pytest.mark.parametrize("method,cli_args,kwargs,gl", CASES,
                         ids=[f"{c[0]}{'_' + c[1][0].strip('-') if c[1] else ''}" for c in CASES])
def test_same_as_cli(tmp_path, abcube_bin, scene_dict, method, cli_args, kwargs, gl):
    scene_path = write_scene(tmp_path / "scene.json", scene_dict)
    out = tmp_path / "cli.exr"
    command = [abcube_bin, "render", str(scene_path), "-o", str(out), "--method", method,
               "--gl", gl, *cli_args]
    done = subprocess.run(command, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, f"{' '.join(command)}: {done.stderr}"
    from_cli = abcube.read_image(str(out))

    scene = abcube.load_scene(str(scene_path))
    image = abcube.Renderer(gl=gl).render(scene, method=method, **kwargs)
    assert_same_image(image, from_cli, f"cli_{method}")


def test_scene_method_is_the_default(tmp_path, abcube_bin, scene_dict):
    # No --method, no method=: both use render.method of the file.
    scene_path = write_scene(tmp_path / "scene.json", scene_dict)
    out = tmp_path / "cli.exr"
    done = subprocess.run([abcube_bin, "render", str(scene_path), "-o", str(out), "--gl", "none"],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    image = abcube.Renderer(gl="none").render(abcube.load_scene(str(scene_path)))
    assert_same_image(image, abcube.read_image(str(out)), "cli_default")
