"""Caps from a count (scene_count.cpp): a scene over --max-memory or --max-triangles is refused
before its first object is built, so the refused run peaks within 16 MiB of a run refused at
once. Peak memory is each process's own (wait4's maxrss), printed with the figures."""
import base64
import json
import os
import struct
import subprocess

BIN = os.environ.get("ABCUBE_BIN", "abcube")
SLACK_MIB = 16


def scene(segments, fov_y=60):
    """60 boxes and 3 spheres of `segments`: 422,592 triangles at 376 segments."""
    objects = [{"type": "box", "min": [i % 10 - 5, 0, i // 10 - 3], "max": [i % 10 - 4.5, 0.5, i // 10 - 2.5]}
               for i in range(60)]
    objects += [{"type": "sphere", "center": [2 * k - 2, 2, 0], "radius": 0.8, "segments": segments}
                for k in range(3)]
    return {"version": 1, "camera": {"position": [0, 3, 9], "look_at": [0, 0, 0], "fov_y": fov_y,
                                     "width": 64, "height": 48},
            "lights": [{"type": "point", "position": [2, 6, 3]}], "objects": objects}


def run(args, tmp_path):
    """(exit status, stderr, peak resident MiB) of one abcube process. GNU time measures it:
    a child of this process would count this process's own pages from before its exec."""
    peak = tmp_path / "peak"
    r = subprocess.run(["/usr/bin/time", "-f", "%M", "-o", str(peak), BIN, *args], capture_output=True, text=True)
    return r.returncode, r.stderr, int(peak.read_text().split()[-1]) / 1024.0


def test_a_scene_over_the_memory_cap_is_refused_before_it_is_built(tmp_path):
    big, at_once = tmp_path / "big.json", tmp_path / "at_once.json"
    big.write_text(json.dumps(scene(376)))
    at_once.write_text(json.dumps(scene(376, fov_y=500)))  # refused when the camera is read
    status, err, capped = run(["render", str(big), "-o", str(tmp_path / "x.png"), "--max-memory", "64"], tmp_path)
    assert status == 2, err
    assert err.count("\n") == 1 and "objects[62].segments: the scene would have 422592 triangles" in err, err
    status, err, immediate = run(["render", str(at_once), "-o", str(tmp_path / "x.png"), "--max-memory", "64"], tmp_path)
    assert status == 2 and "camera.fov_y" in err, err
    print(f"422,592 triangles under --max-memory 64: refused at a peak of {capped:.1f} MiB; "
          f"a scene refused at once: {immediate:.1f} MiB")
    assert capped - immediate < SLACK_MIB
    assert not (tmp_path / "x.png").exists()


def one_triangle_gltf(instances):
    """A glTF of one triangle (its buffer a data: URI), its mesh instanced by `instances` nodes."""
    positions = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
    uri = "data:application/octet-stream;base64," + base64.b64encode(positions).decode()
    return {"asset": {"version": "2.0"}, "buffers": [{"byteLength": 36, "uri": uri}],
            "bufferViews": [{"buffer": 0, "byteLength": 36}],
            "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                           "min": [0, 0, 0], "max": [1, 1, 0]}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
            "nodes": [{"mesh": 0, "translation": [k, 0, 0]} for k in range(instances)],
            "scenes": [{"nodes": list(range(instances))}], "scene": 0}


def test_mesh_files_are_counted_before_they_are_parsed(tmp_path):
    # An OBJ model and a glTF one after a sphere of 4,190,208 triangles, with --max-triangles
    # exactly the sphere's: refused naming the file's place before the sphere is built.
    (tmp_path / "tri.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n")
    (tmp_path / "tri.gltf").write_text(json.dumps(one_triangle_gltf(5)))
    sphere = {"type": "sphere", "center": [0, 0, 0], "radius": 1, "segments": 2048}
    for kind, file, count in (("mesh", "tri.obj", 2), ("gltf", "tri.gltf", 5)):
        s = scene(8)
        s["objects"] = [sphere, {"type": kind, "file": file}]
        path = tmp_path / f"{kind}.json"
        path.write_text(json.dumps(s))
        status, err, peak = run(["render", str(path), "-o", str(tmp_path / "x.png"),
                                 "--max-triangles", str(2 * 2048 * 1023)], tmp_path)
        print(f"{kind}: refused at a peak of {peak:.1f} MiB: {err.strip()}")
        assert status == 2, err
        assert f"objects[1].file: the scene would have {2 * 2048 * 1023 + count} triangles" in err, err
        assert peak < 64, peak  # the sphere alone would hold hundreds of MiB
