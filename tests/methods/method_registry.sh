#!/usr/bin/env bash
# A method registered in one file (normals_method.cpp) renders through every door of a
# program that links it: the CLI's render, a scene file's render.method, a batch job and
# Python. Its option is its own to read: --samples is taken with it and refused with a
# method that does not read it, naming both readers; an option it does not read is refused.
# The program without it (abcube) does not know the name.
# Usage: method_registry.sh ABCUBE_WITH_NORMALS ABCUBE [PYTHONPATH_OF_ITS_MODULE]
set -u
CLI_TEST=methods
source "$ABCUBE_SOURCE_DIR/tests/cli/lib/check.sh"
BIN=$1
PLAIN=$2
PYDIR=${3:-}
SCENE=$ABCUBE_SOURCE_DIR/scenes/cornell.json
cd "$WORK" || exit 1

# The pixel (x, y) of a PNG as "R G B" (0-255).
pixel() {
  /usr/bin/python3 - "$1" "$2" "$3" <<'PY'
import struct, sys, zlib
data = open(sys.argv[1], "rb").read()
pos, chunks = 8, {}
width = height = 0
idat = b""
while pos < len(data):
    n, kind = struct.unpack(">I4s", data[pos:pos + 8])
    body = data[pos + 8:pos + 8 + n]
    if kind == b"IHDR":
        width, height, depth, colour = struct.unpack(">IIBB", body[:10])
        assert depth == 8 and colour == 2, (depth, colour)
    elif kind == b"IDAT":
        idat += body
    pos += 12 + n
raw = zlib.decompress(idat)
stride = 3 * width
rows, prev = [], bytearray(stride)
for y in range(height):
    f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
    for i in range(stride):
        a = line[i - 3] if i >= 3 else 0
        b, c = prev[i], prev[i - 3] if i >= 3 else 0
        p = a + b - c
        pred = a if abs(p - a) <= abs(p - b) and abs(p - a) <= abs(p - c) else (b if abs(p - b) <= abs(p - c) else c)
        line[i] = (line[i] + [0, a, b, (a + b) // 2, pred][f]) & 255
    rows.append(line)
    prev = line
x, y = int(sys.argv[2]), int(sys.argv[3])
print(*rows[y][3 * x:3 * x + 3])
PY
}

# CLI: the floor of the Cornell box (its normal +y: colour (0.5, 1, 0.5), sRGB-encoded) and
# its back wall (+z: (0.5, 0.5, 1)).
check "render --method normals" "$BIN" render "$SCENE" --method normals --size 64x48 --gl none -o n.png \
  --stats n.json
check "the stats name the method" grep -q '"method": "normals"' n.json
floor=$(pixel n.png 32 46)
wall=$(pixel n.png 32 20)
check "floor pixel is the +y normal's colour ($floor)" test "$floor" = "188 255 188"
check "back wall pixel is the +z normal's colour ($wall)" test "$wall" = "188 188 255"

# Its own option: --samples (read by raytrace and normals) is taken, refused with abuffer.
check "--samples 4 with normals" "$BIN" render "$SCENE" --method normals --samples 4 --size 64x48 --gl none -o n4.png
"$BIN" render "$SCENE" --method abuffer --samples 4 --size 64x48 --gl none -o x.png 2> err
check "--samples with abuffer: exit 2" test $? -eq 2
check "names the readers ($(cat err))" grep -q -- "--samples: not used by method abuffer (read by raytrace, normals)" err
"$BIN" render "$SCENE" --method normals --search thesis --gl none -o x.png 2> err
check "--search with normals: exit 2" test $? -eq 2
check "an option it does not read ($(cat err))" grep -q -- "--search: not used by method normals (read by abuffer" err
check "its name in --help" bash -c "'$BIN' render --help | grep -q 'abuffer | zbuffer | envmap | raytrace | gpu | hybrid | gpu_abuffer | normals'"

# A scene file's render.method.
/usr/bin/python3 -c 'import json, sys
s = json.load(open(sys.argv[1]))
s["render"]["method"] = "normals"
json.dump(s, open("scene.json", "w"))' "$SCENE"
check "render.method normals" "$BIN" render scene.json --size 64x48 --gl none -o s.png
check "the same image as --method normals" cmp s.png n.png

# A batch.
printf '{"scene": "%s", "method": "normals", "size": "64x48", "out": "b.png"}\n' "$SCENE" > jobs.jsonl
check "batch job with method normals" "$BIN" batch jobs.jsonl --gl none
check "the batch's image is render's" cmp b.png n.png

# The program without the unit does not know it.
"$PLAIN" render "$SCENE" --method normals --gl none -o x.png 2> err
check "abcube alone: exit 2" test $? -eq 2
check "abcube alone names its methods ($(cat err))" grep -q -- "--method: must be one of abuffer, zbuffer, envmap, raytrace, gpu, hybrid, gpu_abuffer, got \"normals\"" err

# Python, through the module built with the unit.
if [[ -n $PYDIR ]]; then
  check "python: method=normals" env PYTHONPATH="$PYDIR" "${ABCUBE_PYTHON:-/usr/bin/python3}" - "$SCENE" <<'PY'
import sys
import numpy as np
import abcube
scene = abcube.load_scene(sys.argv[1])
r = abcube.Renderer(gl="none")
img = r.render(scene, method="normals", width=64, height=48)
floor, wall = img[46, 32], img[20, 32]
assert np.allclose(floor, [0.5, 1.0, 0.5], atol=1e-6), floor
assert np.allclose(wall, [0.5, 0.5, 1.0], atol=1e-6), wall
table = {o["key"]: o for o in abcube.render_options()}
assert "normals" in table["method"]["choices"], table["method"]
assert table["samples"]["methods"] == ["raytrace", "normals"], table["samples"]
try:
    r.render(scene, method="normals", search="thesis")
except abcube.SceneError as e:
    assert "search: not used by method normals" in str(e), e
else:
    raise AssertionError("search= was taken by normals")
PY
else
  echo "methods: no Python module in this build: the Python door is not checked here"
fi

echo "methods: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
