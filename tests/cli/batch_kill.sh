#!/usr/bin/env bash
# A batch killed outright (SIGKILL: a preempted machine) loses nothing (cli.md "Batch"):
# rerun with --skip-existing, every view exists once, byte-equal to an uninterrupted batch's,
# with its AOVs (byte-equal too) and stats; no partial file was ever at a final name, and the temporaries
# the killed process left are removed by the rerun (as is one planted by a process long
# gone), while another host's stays. Usage: bash batch_kill.sh ABCUBE REPO
set -u
ABCUBE=$(realpath "$1")
REPO=$(realpath "$2")
CLI_TEST=batch_kill
. "$REPO/tests/cli/lib/check.sh"
cd "$WORK" || exit 1
cp "$REPO/tests/golden/cornell.json" .
VIEWS=40
# Fewer in the checked builds (ABCUBE_CHECKED_BUILD, tools/sanitize.sh), where each is many
# times slower: the kill still lands after 5 of them and before the last.
[ "${ABCUBE_CHECKED_BUILD:-0}" = 1 ] && VIEWS=16
# One job a view: an orbit around the box, every fourth with AOVs and stats.
/usr/bin/python3 - "$VIEWS" <<'PY'
import json, math, sys
n = int(sys.argv[1])
for folder in ("out", "ref"):
    with open(f"jobs_{folder}.jsonl", "w") as f:
        for k in range(n):
            a = 2 * math.pi * k / n
            job = {"scene": "cornell.json", "out": f"{folder}/view_{k:02d}.png", "cube_res": 48,
                   "camera": {"position": [0.9 * math.sin(a), 1.0, -2.5 + 0.3 * math.cos(a)], "width": 80, "height": 60}}
            if k % 4 == 0:
                job["aovs"] = ["distance"]
                job["stats"] = f"{folder}/view_{k:02d}.json"
            f.write(json.dumps(job) + "\n")
PY
"$ABCUBE" batch jobs_ref.jsonl --threads 1 > /dev/null 2> err || { echo "FAIL: the uninterrupted batch ($(cat err))"; exit 1; }

HOST=$(hostname | tr -cd 'A-Za-z0-9_-' | cut -c1-32)
gone=$(sh -c 'echo $$')  # a process that has ended
mkdir -p out
echo partial > "out/.view_07.tmp$gone-$HOST.png"
echo partial > "out/.view_08.tmp$gone-elsewhere.png"

# Killed outright once a few views are written, mid-run.
"$ABCUBE" batch jobs_out.jsonl --shard 0/1 --threads 1 > /dev/null 2>&1 &
pid=$!
for _ in $(seq 1 600); do
  [ "$(ls out/view_*.png 2> /dev/null | wc -l)" -ge 5 ] && break
  sleep 0.05
done
kill -9 $pid
wait $pid 2> /dev/null
at_kill=$(ls out/view_*.png | wc -l)
check "killed mid-run ($at_kill of $VIEWS views written)" [ "$at_kill" -ge 5 ] && [ "$at_kill" -lt "$VIEWS" ]
# Whole: the image, and for a view with AOVs and stats those too (the kill may land between
# the image's rename and theirs: that view is rendered again).
whole=0
for f in out/view_*.png; do
  stem=${f%.png}
  k=$((10#${stem##*_}))
  if [ $((k % 4)) -ne 0 ] || { [ -e "$stem.distance.exr" ] && [ -e "$stem.json" ]; }; then whole=$((whole + 1)); fi
done
for f in out/view_*.png out/view_*.exr; do
  check "no partial file at a final name: $f" cmp -s "$f" "ref/${f#out/}"
done
for f in out/view_*.json; do
  check "no partial file at a final name: $f" /usr/bin/python3 -c "import json, sys; json.load(open(sys.argv[1]))" "$f"
done
check "the killed run removed the temporary of a process long gone" [ ! -e "out/.view_07.tmp$gone-$HOST.png" ]
echo partial > "out/.view_09.tmp$gone-$HOST.png"  # and one more, for the rerun

"$ABCUBE" batch jobs_out.jsonl --shard 0/1 --skip-existing --threads 1 > summary 2> err
status=$?
check "the rerun exits 0 ($(cat err))" [ $status -eq 0 ]
check "the rerun skips what was whole ($(cat summary))" grep -q "$VIEWS jobs, $((VIEWS - whole)) rendered, 0 failed, $whole skipped" summary
check "the rerun removes the temporaries of dead processes ($(cat summary))" grep -q "temporaries of killed runs removed" summary
check "every view once, with its AOVs and stats" [ "$(cd ref && ls | sort)" = "$(cd out && ls | sort)" ]
for f in ref/*.png ref/*.exr; do  # the stats hold times: they differ
  check "byte-equal: ${f#ref/}" cmp -s "$f" "out/${f#ref/}"
done
check "no temporary of this host left" [ -z "$(find out -name ".*.tmp*-$HOST*" -print -quit)" ]
check "another host's temporary stays" [ -e "out/.view_08.tmp$gone-elsewhere.png" ]

echo "batch_kill: $passed passed, $failed failed"
[ $failed -eq 0 ]
