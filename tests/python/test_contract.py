"""Every form docs/python.md promises, on small images."""
import copy
import math
import shutil

import numpy as np
import pytest

import abcube
from conftest import CUBE_RES, HEIGHT, SCENES, WIDTH, small_scene_dict, write_scene


@pytest.fixture(scope="module")
def renderer():
    return abcube.Renderer(gl="none")


def test_version():
    assert isinstance(abcube.__version__, str) and abcube.__version__[0].isdigit()
    assert abcube.version_string().startswith("abcube " + abcube.__version__)


def test_load_scene_from_path(tmp_path, scene_dict):
    # A file written from the dict loads to the same scene as the dict itself.
    path = write_scene(tmp_path / "small.json", scene_dict)
    from_file = abcube.load_scene(str(path))
    from_dict = abcube.scene_from_dict(copy.deepcopy(scene_dict))
    for s in (from_file, from_dict):
        assert (s.width, s.height) == (WIDTH, HEIGHT)
        assert s.method == "abuffer" and s.cube_resolution == CUBE_RES and s.max_depth == 2
        assert s.triangle_count > 0
    assert from_file.name == str(path)
    assert from_dict.name == "<dict>"
    assert from_file.triangle_count == from_dict.triangle_count
    # os.PathLike is a path too.
    assert abcube.load_scene(path).triangle_count == from_file.triangle_count


def test_repository_scene_loads():
    scene = abcube.load_scene(str(SCENES / "cornell.json"))
    assert (scene.width, scene.height) == (512, 512) and scene.method == "abuffer"


def test_render_defaults(scene):
    # The scene's own method and options; a float32 linear image of the scene's size.
    img = abcube.Renderer(gl="none").render(scene)
    assert img.dtype == np.float32 and img.shape == (scene.height, scene.width, 3)
    assert img.flags.c_contiguous and img.flags.writeable
    assert np.isfinite(img).all() and img.max() > 0


def test_render_overrides(renderer, scene):
    img = renderer.render(scene, method="abuffer", cube_res=48, max_depth=3,
                          camera={"position": [0, 1, -3], "look_at": [0, 1, 0]})
    assert img.dtype == np.float32 and img.shape == (scene.height, scene.width, 3)
    # The overrides change the image (another view); the scene itself is unchanged.
    assert not np.array_equal(img, renderer.render(scene))
    assert scene.cube_resolution == CUBE_RES


def test_camera_overrides_only_given_keys(renderer, scene, scene_dict):
    # An override equal to the scene's camera changes nothing.
    cam = scene_dict["camera"]
    same = renderer.render(scene, camera={"position": cam["position"], "fov_y": cam["fov_y"]})
    assert np.array_equal(same, renderer.render(scene))
    # The image shape follows a width/height override.
    img = renderer.render(scene, method="raytrace", camera={"width": 20, "height": 10})
    assert img.shape == (10, 20, 3)


def test_result_with_aovs_and_stats(renderer, scene):
    res = renderer.render(scene, method="abuffer", aovs=["distance", "normal", "object_id"],
                          stats=True)
    h, w = scene.height, scene.width
    assert res.image.dtype == np.float32 and res.image.shape == (h, w, 3)
    assert np.array_equal(res.image, renderer.render(scene, method="abuffer"))
    assert set(res.aovs) == {"distance", "normal", "object_id"}
    assert res.aovs["distance"].shape == (h, w) and res.aovs["distance"].dtype == np.float32
    assert res.aovs["normal"].shape == (h, w, 3)
    assert res.aovs["object_id"].shape == (h, w)
    # The floor fills the bottom row: finite distance, a real object id, unit normals.
    assert np.isfinite(res.aovs["distance"][-1]).all()
    assert (res.aovs["object_id"][-1] >= 0).all()
    norms = np.linalg.norm(res.aovs["normal"][-1], axis=-1)
    np.testing.assert_allclose(norms, 1, atol=1e-3)
    assert isinstance(res.stats, dict) and "timings_ms" in res.stats
    assert isinstance(res.stats["timings_ms"], dict)
    # AOVs alone also return a result, its stats None.
    assert renderer.render(scene, aovs=["distance"]).stats is None


def test_compare(renderer, scene):
    a = renderer.render(scene, method="raytrace")
    same = abcube.compare(a, a.copy())
    assert same["rmse"] == 0 and same["max_abs"] == 0 and same["psnr_db"] == math.inf
    for key in ("share_over_1_255", "share_over_2_255"):
        assert same[key] == 0
    b = a.copy()
    b[0, 0] += 0.5
    diff = abcube.compare(a, b)
    assert 0 < diff["rmse"] and math.isfinite(diff["psnr_db"]) and diff["max_abs"] > 0.1
    assert diff["share_over_2_255"] == pytest.approx(1 / (a.shape[0] * a.shape[1]))
    with pytest.raises(abcube.SceneError, match="shape"):
        abcube.compare(a, a[:-1])


def test_write_read_round_trip(tmp_path, renderer, scene):
    img = renderer.render(scene, method="raytrace")
    # EXR keeps the float values exactly.
    abcube.write_image(str(tmp_path / "out.exr"), img)
    back = abcube.read_image(str(tmp_path / "out.exr"))
    assert back.dtype == np.float32 and np.array_equal(back, img)
    # PNG is sRGB-encoded 8 bit: the values come back within one code step.
    abcube.write_image(tmp_path / "out.png", img)
    png = abcube.read_image(tmp_path / "out.png")
    assert png.shape == img.shape
    assert abcube.compare(png, img)["share_over_1_255"] == 0
    # Nothing but the two images (the writes are atomic: no temporary left behind).
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.exr", "out.png"]
    # One-channel arrays round-trip as H x W.
    gray = np.linspace(0, 1, 12, dtype=np.float32).reshape(3, 4)
    abcube.write_image(str(tmp_path / "gray.exr"), gray)
    assert np.array_equal(abcube.read_image(str(tmp_path / "gray.exr")), gray)


def test_write_image_errors(tmp_path):
    with pytest.raises(abcube.SceneError):
        abcube.write_image(str(tmp_path / "out.nosuchformat"), np.zeros((2, 2, 3), np.float32))
    with pytest.raises(abcube.SceneError, match="shape"):
        abcube.write_image(str(tmp_path / "out.exr"), np.zeros((2, 2, 7), np.float32))
    with pytest.raises(abcube.SceneError):
        abcube.read_image(str(tmp_path / "missing.exr"))
    with pytest.raises(abcube.SceneError, match="float"):
        abcube.write_image(str(tmp_path / "out.png"), np.zeros((2, 2, 3), np.uint8))
    with pytest.raises(abcube.SceneError):
        abcube.compare("a", "b")
    # Lists of numbers are arrays too.
    assert abcube.compare([[[0.5, 0.5, 0.5]]], np.full((1, 1, 3), 0.5))["rmse"] == 0


def test_root_confinement(tmp_path):
    # uploads/a/scene.json names a mesh outside uploads/a: refused under root, loads without.
    upload = tmp_path / "uploads" / "a"
    upload.mkdir(parents=True)
    shutil.copy(SCENES / "meshes" / "octahedron.obj", tmp_path / "outside.obj")
    shutil.copy(SCENES / "meshes" / "octahedron.mtl", tmp_path / "octahedron.mtl")
    scene = small_scene_dict()
    mesh = next(o for o in scene["objects"] if o["type"] == "mesh")
    mesh["file"] = "../../outside.obj"
    path = write_scene(upload / "scene.json", scene)
    assert abcube.load_scene(str(path)).triangle_count > 0
    with pytest.raises(abcube.SceneError) as error:
        abcube.load_scene(str(path), root=str(upload))
    assert isinstance(error.value, ValueError) and "outside.obj" in str(error.value)
    # Inside the root it loads.
    shutil.copy(tmp_path / "outside.obj", upload / "inside.obj")
    shutil.copy(tmp_path / "octahedron.mtl", upload / "octahedron.mtl")
    mesh["file"] = "inside.obj"
    write_scene(path, scene)
    assert abcube.load_scene(str(path), root=str(upload)).triangle_count > 0


def test_max_triangles(scene_dict):
    with pytest.raises(abcube.SceneError):
        abcube.scene_from_dict(copy.deepcopy(scene_dict), max_triangles=10)


def test_timeout(renderer):
    # A render big enough to take far longer than a microsecond.
    big = abcube.scene_from_dict(small_scene_dict(width=320, height=240, cube_res=256))
    with pytest.raises(abcube.RenderTimeout) as error:
        renderer.render(big, method="abuffer", timeout=1e-6)
    assert isinstance(error.value, RuntimeError) and not isinstance(error.value, ValueError)
    # The Renderer still works after a timeout.
    small = abcube.scene_from_dict(small_scene_dict())
    assert renderer.render(small, method="raytrace", timeout=60).shape == (HEIGHT, WIDTH, 3)


def test_renderer_properties(scene):
    r = abcube.Renderer(gl="none", threads=1)
    assert r.renders == 0
    r.render(scene, method="raytrace")
    assert r.renders == 1 and r.gl_path in ("", "none")
    assert isinstance(r.gl_renderer, str)


def test_bad_arguments_raise_scene_error(renderer, scene):
    cases = [
        dict(method="nosuch"),
        dict(method=3),
        dict(cube_res="big"),
        dict(cube_res=2.5),
        dict(camera={"positon": [0, 1, 2]}),
        dict(camera={"position": [0, 1]}),
        dict(camera={"fov_y": 0}),
        dict(camera={"width": 0}),
        dict(camera=[0, 1, 2]),
        dict(aovs="distance"),
        dict(aovs=["nosuch"]),
        dict(timeout=-1),
        dict(stats="yes"),
        dict(search="nosuch"),
        dict(max_layers=-1),
    ]
    for kwargs in cases:
        with pytest.raises(abcube.SceneError):
            renderer.render(scene, **kwargs)
    with pytest.raises(abcube.SceneError, match="cube_resolution"):
        renderer.render(scene, cube_resolution=64)
    with pytest.raises(abcube.SceneError, match="camera.positon"):
        renderer.render(scene, camera={"positon": [0, 1, 2]})
    with pytest.raises(abcube.SceneError, match="scene"):
        renderer.render("scenes/default.json")
    with pytest.raises(abcube.SceneError):
        abcube.Renderer(gl="nosuch").render(scene, method="gpu")


def test_renderer_options_keywords(renderer, scene):
    # Every RenderOptions keyword is accepted by name.
    img = renderer.render(scene, method="abuffer", search="thesis", refine="plane",
                          theta_max_deg=3.0, refraction="thin_lens", error_target=None,
                          fresnel=True, max_layers=8, max_memory_mib=256,
                          max_pixels=10_000, plan_everything=True, threads=1)
    assert img.shape == (scene.height, scene.width, 3)
    env = renderer.render(scene, method="envmap", envmap_lookup="bisector")
    assert env.shape == img.shape
    with pytest.raises(abcube.SceneError):
        renderer.render(scene, max_pixels=10)  # 32 x 24 > 10


def test_target_db(renderer, scene):
    # python.md: N and the work chosen for a PSNR target; the stats say what was chosen,
    # and the chosen N rendered directly is the same image.
    res = renderer.render(scene, method="abuffer", target_db=30, stats=True)
    chosen = res.stats["target_db"]
    assert chosen["target"] == 30 and chosen["reached"]
    direct = renderer.render(scene, method="abuffer", cube_res=chosen["cube_resolution"],
                             shading_points=chosen["shading_points"], shadow_edges=chosen["shadow_edges"],
                             secondary_edges=chosen["secondary_edges"])
    assert np.array_equal(res.image, direct)
    with pytest.raises(abcube.SceneError, match="and so does cube_res"):
        renderer.render(scene, target_db=40, cube_res=64)
    with pytest.raises(abcube.SceneError, match="target_db"):
        renderer.render(scene, method="zbuffer", target_db=40)
    # raytrace: its samples a pixel chosen for the target, the same image as that rung.
    res = renderer.render(scene, method="raytrace", target_db=30, stats=True)
    samples = res.stats["target_db"]["samples"]
    assert samples in (1, 2, 4, 8, 16, 32)
    assert np.array_equal(res.image, renderer.render(scene, method="raytrace", samples=samples))
    with pytest.raises(abcube.SceneError, match="samples"):
        renderer.render(scene, method="abuffer", samples=4)


def find_key(tree, key):
    """The values of `key` anywhere in a nested dict."""
    if isinstance(tree, dict):
        for k, v in tree.items():
            if k == key:
                yield v
            yield from find_key(v, key)


def test_reference_stats(renderer, scene):
    # With reference=True the stats carry the error against the exact tracer's image.
    res = renderer.render(scene, method="abuffer", reference=True, stats=True)
    assert "timings_ms" in res.stats and "reference" in res.stats
    psnr = list(find_key(res.stats["reference"], "psnr_db"))
    assert psnr and all(math.isfinite(p) and p > 10 for p in psnr)
    # Without it, no reference section.
    assert "reference" not in renderer.render(scene, method="abuffer", stats=True).stats


def test_progress(renderer, scene):
    # python.md: progress(stage, done) on the rendering thread for every method, each pass
    # to 1; an exception it raises comes out of render; a value that is no callable refused.
    with_gl = abcube.Renderer(gl="auto")
    for method in ("abuffer", "raytrace", "gpu", "hybrid"):
        seen = []
        with_gl.render(scene, method=method, progress=lambda stage, done: seen.append((stage, done)))
        assert seen and all(0 <= d <= 1 for _, d in seen), (method, seen)
        assert all(any(d == 1 for s2, d in seen if s2 == s) for s, _ in seen), (method, seen)
    stages = []
    renderer.render(scene, method="abuffer", progress=lambda stage, done: stages.append(stage))
    assert "shading" in stages and "cube A-buffer" in stages, stages

    def fails(stage, done):
        raise ValueError("stop here")

    with pytest.raises(ValueError, match="stop here"):
        renderer.render(scene, method="raytrace", progress=fails)
    with pytest.raises(abcube.SceneError, match="progress"):
        renderer.render(scene, progress=3)
