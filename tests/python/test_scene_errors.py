"""Bad scenes raise abcube.SceneError (a ValueError) whose message names the place, as the
CLI's one line does; nothing exits the interpreter."""
import copy
import math

import pytest

import abcube
from conftest import small_scene_dict, write_scene


def bad_dict(edit):
    scene = small_scene_dict()
    edit(scene)
    return scene


def sphere_index(scene):
    return next(i for i, o in enumerate(scene["objects"]) if o["type"] == "sphere")


def test_field_path_in_message():
    def negative_radius(s):
        s["objects"][0] = {"type": "sphere", "center": [0, 1, 0], "radius": -1}
    with pytest.raises(abcube.SceneError) as error:
        abcube.scene_from_dict(bad_dict(negative_radius))
    assert isinstance(error.value, ValueError)
    assert "objects[0].radius" in str(error.value)
    assert str(error.value).startswith("<dict>")


@pytest.mark.parametrize("edit,where", [
    (lambda s: s["camera"].update(fov_y=0), "camera.fov_y"),
    (lambda s: s["camera"].update(width=-4), "camera.width"),
    (lambda s: s["camera"].update(up=[p - q for p, q in zip(s["camera"]["position"],
                                                            s["camera"]["look_at"])]), "camera"),
    (lambda s: s["objects"][1].update(material="nosuch"), "objects[1].material"),
    (lambda s: s["objects"][1].update(colour=[1, 0, 0]), "objects[1].colour"),
    (lambda s: s.update(lights=[{"type": "point", "position": [0, 1]}]), "lights[0].position"),
    (lambda s: s["materials"]["glass"].update(ior=0.5), "materials.glass.ior"),
    (lambda s: s["render"].update(method="nosuch"), "render.method"),
    (lambda s: s["objects"].append({"type": "mesh", "file": "/nonexistent/x.obj"}), "x.obj"),
])
def test_bad_values(edit, where):
    with pytest.raises(abcube.SceneError, match=r".*" + where.replace("[", r"\[").replace("]", r"\]")):
        abcube.scene_from_dict(bad_dict(edit), name="bad.json")


def test_nan_is_refused():
    def nan_center(s):
        s["objects"][sphere_index(s)]["center"] = [0, math.nan, 0]
    with pytest.raises(abcube.SceneError):
        abcube.scene_from_dict(bad_dict(nan_center))


def test_not_a_dict():
    with pytest.raises(abcube.SceneError):
        abcube.scene_from_dict([1, 2, 3])
    with pytest.raises(abcube.SceneError):
        abcube.scene_from_dict({"objects": object()})


def test_json_syntax_error_has_line_and_column(tmp_path):
    path = tmp_path / "broken.json"
    path.write_text('{\n  "version": 1,\n  "camera": {,\n}\n')
    with pytest.raises(abcube.SceneError, match=r"broken\.json:3:\d+"):
        abcube.load_scene(str(path))
    with pytest.raises(abcube.SceneError, match=r"text:3:\d+"):
        abcube.scene_from_json('{\n "version": 1,\n ]', name="text")


def test_missing_file(tmp_path):
    with pytest.raises(abcube.SceneError, match="missing.json"):
        abcube.load_scene(str(tmp_path / "missing.json"))


def test_mesh_relative_to_base_dir(tmp_path):
    # A relative mesh path resolves against base_dir; a wrong base_dir names the file.
    from conftest import SCENES
    scene = small_scene_dict()
    mesh = next(o for o in scene["objects"] if o["type"] == "mesh")
    mesh["file"] = "meshes/octahedron.obj"
    assert abcube.scene_from_dict(copy.deepcopy(scene), base_dir=str(SCENES)).triangle_count > 0
    with pytest.raises(abcube.SceneError, match="octahedron.obj"):
        abcube.scene_from_dict(scene, base_dir=str(tmp_path))


def test_empty_mesh_loads_with_a_warning(tmp_path):
    # An empty OBJ is no error: the scene loads, and Scene.warnings names the object's file.
    (tmp_path / "empty.obj").write_text("")
    scene = small_scene_dict()
    mesh = next(i for i, o in enumerate(scene["objects"]) if o["type"] == "mesh")
    scene["objects"][mesh]["file"] = "empty.obj"
    loaded = abcube.scene_from_dict(scene, name="s.json", base_dir=str(tmp_path))
    assert loaded.warnings == [f's.json: objects[{mesh}].file: warning: mesh "empty.obj" has no triangles']
    assert abcube.scene_from_dict(small_scene_dict()).warnings == []


def test_error_then_success(tmp_path):
    # The interpreter and the module survive errors: a good scene still loads and renders.
    for _ in range(20):
        with pytest.raises(abcube.SceneError):
            abcube.scene_from_dict({"version": 1, "objects": [{"type": "nosuch"}]})
    scene = abcube.load_scene(str(write_scene(tmp_path / "ok.json", small_scene_dict())))
    assert abcube.Renderer(gl="none").render(scene, method="raytrace").shape == (24, 32, 3)


def test_load_threads_give_the_same_scene(tmp_path):
    # threads= is the cores the load may use: any number gives the same triangles; a count
    # out of range names the keyword.
    n = 130  # 33,800 triangles: the OBJ parts and the soup's runs split between threads
    rows = ["v %d %.3f %d" % (i, 0.1 * ((i * 7 + j * 3) % 5), j) for j in range(n + 1) for i in range(n + 1)]
    rows += ["f %d %d %d %d" % (j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 2,
                                j * (n + 1) + i + 2) for j in range(n) for i in range(n)]
    (tmp_path / "grid.obj").write_text("\n".join(rows) + "\n")
    scene = small_scene_dict(method="raytrace")
    mesh = next(i for i, o in enumerate(scene["objects"]) if o["type"] == "mesh")
    scene["objects"][mesh]["file"] = "grid.obj"
    scene["objects"][mesh]["transform"] = {"scale": 0.01}
    renderer = abcube.Renderer(gl="none")
    images = []
    for threads in (1, 3, 0):
        loaded = abcube.scene_from_dict(copy.deepcopy(scene), base_dir=str(tmp_path), threads=threads)
        assert loaded.triangle_count > 2 * n * n
        images.append(renderer.render(loaded))
    assert (images[0] == images[1]).all() and (images[0] == images[2]).all()
    for bad in (5000, -1):
        with pytest.raises((abcube.SceneError, ValueError, TypeError), match="threads"):
            abcube.scene_from_dict(copy.deepcopy(scene), base_dir=str(tmp_path), threads=bad)
