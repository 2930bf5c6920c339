#!/usr/bin/env bash
# abcube batch end to end (cli.md "Batch"): the same bytes as abcube render for the same
# job, camera overrides, AOVs and stats, a malformed file refused before any render
# (exit 2), a failing job reported by line while the others render (exit 1), shards that
# together make the whole batch, --skip-existing. Usage: bash batch_cli.sh ABCUBE REPO
set -u
ABCUBE=$(realpath "$1")
REPO=$(realpath "$2")
WORK=$(mktemp -d "${TMPDIR:-/tmp}/abcube_batch_cli.XXXXXX")
trap 'rm -rf "$WORK"' EXIT
passed=0
failed=0
check() { local what=$1; shift; if "$@"; then passed=$((passed + 1)); else failed=$((failed + 1)); echo "FAIL: $what"; fi; }

cp "$REPO/tests/golden/cornell.json" "$REPO/tests/golden/hidden_point.json" "$WORK/"
# The cornell scene with the camera the override below gives (for abcube render).
/usr/bin/python3 - "$WORK" <<'PY'
import json, sys
w = sys.argv[1]
d = json.load(open(w + "/cornell.json"))
d["camera"]["position"] = [0.5, 1.2, -2.5]
d["camera"]["width"] = 40
json.dump(d, open(w + "/cornell_moved.json", "w"))
PY
cat > "$WORK/jobs.jsonl" <<'EOF2'
{"scene": "cornell.json", "out": "out/a.png", "method": "abuffer"}
{"scene": "cornell.json", "out": "out/b.exr", "method": "raytrace", "stats": "out/b.json"}

{"scene": "hidden_point.json", "out": "out/c.png", "method": "zbuffer", "cube_res": 64, "max_depth": 1}
{"scene": "cornell.json", "out": "out/d.png", "camera": {"position": [0.5, 1.2, -2.5], "width": 40}, "aovs": ["distance", "object_id"]}
{"scene": "cornell.json", "out": "out/e.png", "method": "gpu"}
EOF2
"$ABCUBE" batch "$WORK/jobs.jsonl" --gl egl > "$WORK/summary" 2> "$WORK/err"
status=$?
check "batch exits 0 ($(cat "$WORK/err"))" [ $status -eq 0 ]
check "summary counts 5 rendered" grep -q "5 jobs, 5 rendered, 0 failed, 0 skipped; 2 scenes loaded" "$WORK/summary"
cd "$WORK" || exit 1
"$ABCUBE" render cornell.json -o ra.png --method abuffer
"$ABCUBE" render cornell.json -o rb.exr --method raytrace
"$ABCUBE" render hidden_point.json -o rc.png --method zbuffer --cube-res 64 --max-depth 1
"$ABCUBE" render cornell_moved.json -o rd.png
"$ABCUBE" render cornell.json -o re.png --method gpu --gl egl
for k in a c d e; do check "job $k: the same PNG bytes as abcube render" cmp -s "out/$k.png" "r$k.png"; done
check "job b: the same EXR bytes as abcube render" cmp -s out/b.exr rb.exr
check "job b wrote its stats" grep -q '"primary_rays"' out/b.json
check "job d: the distance AOV" [ -s out/d.distance.exr ]
check "job d: the object_id AOV" [ -s out/d.object_id.exr ]
check "no normal AOV unasked" [ ! -e out/d.normal.exr ]

# --- a malformed jobs file: exit 2, FILE:LINE, nothing rendered
printf '{"scene": "cornell.json", "out": "m/1.png"}\n{"scene": "cornell.json", "out": "m/2.png", "colour": 1}\n' > bad.jsonl
"$ABCUBE" batch bad.jsonl 2> err; status=$?
check "malformed: exit 2" [ $status -eq 2 ]
check "malformed: names file and line" grep -q "bad.jsonl:2: \"colour\": unknown key" err
check "malformed: nothing rendered" [ ! -e m/1.png ]
check "malformed: one line" [ "$(wc -l < err)" -eq 1 ]
# Options each valid alone that contradict one another: a malformed line too.
printf '{"scene": "cornell.json", "out": "m/1.png"}\n{"scene": "cornell.json", "out": "m/2.png", "target_db": 40, "cube_res": 64}\n' > both.jsonl
"$ABCUBE" batch both.jsonl 2> err; status=$?
check "target_db with cube_res: exit 2" [ $status -eq 2 ]
check "target_db with cube_res: names line 2 ($(cat err))" grep -q 'both.jsonl:2: "target_db": chooses the cube map' err
check "target_db with cube_res: nothing rendered" [ ! -e m/1.png ]
printf '{"scene": "cornell.json", "out": "m/1.png"}\nnot json\n' > bad2.jsonl
"$ABCUBE" batch bad2.jsonl 2> err; status=$?
check "not JSON: exit 2 naming line 2" [ $status -eq 2 ]
check "not JSON: exit 2 naming line 2 (2)" grep -q "bad2.jsonl:2: not JSON" err
# Numbers past a double (found by tests/fuzz: exit 1 with nlohmann's message, no line) and
# integers past 32 bits (used to wrap: 4294967808 rendered at 512) are malformed lines.
printf '{"scene": "cornell.json", "out": "m/1.png", "cube_res": 1e999}\n' > big1.jsonl
"$ABCUBE" batch big1.jsonl 2> err; status=$?
check "number overflow: exit 2 naming line 1" [ $status -eq 2 ]
check "number overflow: exit 2 naming line 1 (2)" grep -q "big1.jsonl:1: not JSON" err
printf '{"scene": "cornell.json", "out": "m/1.png", "cube_res": 4294967808}\n' > big2.jsonl
"$ABCUBE" batch big2.jsonl 2> err; status=$?
check "integer past 32 bits: exit 2 naming line 1" [ $status -eq 2 ]
check "integer past 32 bits: exit 2 naming line 1 (2)" grep -q 'big2.jsonl:1: "cube_res": must be an integer' err
printf '{"out": "m/1.png"}\n' > bad3.jsonl
"$ABCUBE" batch bad3.jsonl 2> err
check "missing scene key named" grep -q 'bad3.jsonl:1: "scene": required' err
# A jobs "file" with no line break (/dev/zero) is refused once its first line passes 1 MiB,
# instead of being read until memory runs out.
"$ABCUBE" batch /dev/zero 2> err; status=$?
check "/dev/zero: exit 2 naming line 1" [ $status -eq 2 ]
check "/dev/zero: exit 2 naming line 1 (2)" grep -q "/dev/zero:1: longer than 1 MiB" err
check "/dev/zero: one line" [ "$(wc -l < err)" -eq 1 ]
# A job key holding terminal escapes is shown escaped.
printf '{"\\u001b]0;pwned\\u0007": 1}\n' > esc.jsonl
"$ABCUBE" batch esc.jsonl 2> err
check "escaped job key" grep -qF 'esc.jsonl:1: "\e]0;pwned\x07": unknown key' err
check "no control byte on stderr" [ -z "$(tr -d '\n' < err | tr -d '[:print:]')" ]
# A scene with an empty mesh: its warning once, on the line of the first job that renders it.
: > empty.obj
printf '{"version": 1, "camera": {"position": [0, 1, 5], "look_at": [0, 0, 0], "width": 16, "height": 12}, "objects": [{"type": "mesh", "file": "empty.obj"}]}\n' > empty_mesh.json
printf '{"scene": "empty_mesh.json", "out": "w/1.png", "method": "raytrace"}\n{"scene": "empty_mesh.json", "out": "w/2.png", "method": "raytrace"}\n' > warn.jsonl
"$ABCUBE" batch warn.jsonl > /dev/null 2> err; status=$?
check "empty mesh: exit 0, both rendered" [ $status -eq 0 ]
check "empty mesh: exit 0, both rendered (2)" [ -s w/1.png ]
check "empty mesh: exit 0, both rendered (3)" [ -s w/2.png ]
check "empty mesh: one warning naming job line 1" [ "$(cat err)" = "warn.jsonl:1: empty_mesh.json: objects[0].file: warning: mesh \"empty.obj\" has no triangles" ]

# --- a failing job: its line on stderr, the others rendered, exit 1; a key its scene's own
# method does not use fails that job when it renders
printf '{"scene": "cornell.json", "out": "f/1.png", "method": "raytrace"}\n{"scene": "nowhere.json", "out": "f/2.png"}\n{"scene": "cornell.json", "out": "f/3.png", "set": {"render.method": "raytrace"}, "cube_res": 64}\n{"scene": "cornell.json", "out": "f/4.png", "method": "raytrace", "camera": {"position": [0, 1, 0]}}\n' > fail.jsonl
"$ABCUBE" batch fail.jsonl > summary 2> err; status=$?
check "failing jobs: exit 1" [ $status -eq 1 ]
check "failing job 2 named by line" grep -q "fail.jsonl:2: .*nowhere.json" err
check "failing job 3 named by line" grep -q "fail.jsonl:3: \"cube_res\": not used by method raytrace" err
check "the other jobs rendered" [ -s f/1.png ]
check "the other jobs rendered (2)" [ -s f/4.png ]
check "summary counts failures" grep -q "4 jobs, 2 rendered, 2 failed" summary

# --- a key a job's named method does not use: exit 2 before anything renders
printf '{"scene": "cornell.json", "out": "o/1.png"}\n{"scene": "cornell.json", "out": "o/2.png", "method": "raytrace", "cube_res": 64}\n' > own.jsonl
"$ABCUBE" batch own.jsonl > /dev/null 2> err; status=$?
check "a job's own unused key: exit 2 ($(cat err))" [ $status -eq 2 ]
check "a job's own unused key: named by line" grep -q 'own.jsonl:2: "cube_res": not used by method raytrace' err
check "a job's own unused key: nothing rendered" [ ! -e o/1.png ]

# --- a command-line default a job's method does not use is left out for that job: the
# raytrace job renders as abcube render --method raytrace, the abuffer job takes --cube-res
printf '{"scene": "cornell.json", "out": "d/rt.png", "method": "raytrace"}\n{"scene": "cornell.json", "out": "d/ab.png"}\n' > defaults.jsonl
"$ABCUBE" batch defaults.jsonl --cube-res 48 --width 40 --height 30 > /dev/null 2> err; status=$?
check "defaults a method does not use: exit 0 ($(cat err))" [ $status -eq 0 ]
"$ABCUBE" render cornell.json -o d_rt.png --method raytrace --width 40 --height 30
"$ABCUBE" render cornell.json -o d_ab.png --cube-res 48 --width 40 --height 30
check "the raytrace job without --cube-res" cmp -s d/rt.png d_rt.png
check "the abuffer job with --cube-res" cmp -s d/ab.png d_ab.png

# --- a bad option value is a malformed line: exit 2 before anything renders, the table's
# message under the line's own key, with the nearest name
printf '{"scene": "cornell.json", "out": "g/1.png", "method": "raytrace"}\n{"scene": "cornell.json", "out": "g/2.png", "method": "photon"}\n' > badvalue.jsonl
"$ABCUBE" batch badvalue.jsonl > /dev/null 2> err; status=$?
check "bad value: exit 2" [ $status -eq 2 ]
check "bad value: nothing rendered" [ ! -e g/1.png ]
check "bad value: named by line and key" grep -q 'badvalue.jsonl:2: "method": must be one of abuffer, zbuffer, envmap, raytrace, gpu, hybrid, gpu_abuffer, got "photon"' err
printf '{"scene": "cornell.json", "out": "g/1.png", "cube_rez": 64}\n' > typo.jsonl
"$ABCUBE" batch typo.jsonl > /dev/null 2> err; status=$?
check "unknown key: exit 2" [ $status -eq 2 ]
check "unknown key: did you mean" grep -q 'typo.jsonl:1: "cube_rez": unknown key; did you mean cube_res?' err

# --- shards make the whole batch; --skip-existing resumes
"$ABCUBE" batch jobs.jsonl --shard 0/2 --gl egl > s0 2>&1 && "$ABCUBE" batch jobs.jsonl --shard 1/2 --gl egl > s1 2>&1
check "both shards exit 0" [ $? -eq 0 ]
check "shard 0/2 takes jobs 0, 2, 4" grep -q "shard 0/2: 3 jobs" s0
check "shard 1/2 takes jobs 1, 3" grep -q "shard 1/2: 2 jobs" s1
rm out/c.png
"$ABCUBE" batch jobs.jsonl --skip-existing --gl egl > s2 2>&1
check "--skip-existing renders only the missing job" grep -q "5 jobs, 1 rendered, 0 failed, 4 skipped" s2
check "the missing job is back, same bytes" cmp -s out/c.png rc.png
"$ABCUBE" batch jobs.jsonl --shard 2/2 2> err; status=$?
check "--shard 2/2: exit 2" [ $status -eq 2 ]
check "--shard 2/2: exit 2 (2)" grep -q -- "--shard" err

# --- --job-timeout: the middle job (cornell traced at 512 x 512, seconds) is stopped past 1 s
# with its line; the quick jobs before and after it render; it leaves no output.
printf '%s\n' '{"scene": "hidden_point.json", "out": "t/1.png", "method": "raytrace", "camera": {"width": 32, "height": 24}}' \
  '{"scene": "cornell.json", "out": "t/2.png", "method": "raytrace", "camera": {"width": 512, "height": 512}}' \
  '{"scene": "hidden_point.json", "out": "t/3.png", "method": "raytrace", "camera": {"width": 32, "height": 24}}' > timeout.jsonl
"$ABCUBE" batch timeout.jsonl --job-timeout 1 > summary 2> err; status=$?
check "job timeout: exit 1" [ $status -eq 1 ]
check "job timeout: 'JOBS:2: timed out after 1 s'" [ "$(cat err)" = "timeout.jsonl:2: timed out after 1 s" ]
check "job timeout: the jobs around it rendered" test -s t/1.png -a -s t/3.png
check "job timeout: the stopped job left no output" test ! -e t/2.png
check "job timeout: no temporary file" [ -z "$(find . -name '.*.tmp*' -print -quit)" ]
check "job timeout: summary" grep -q "3 jobs, 2 rendered, 1 failed" summary

echo "cli batch_cli: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
