#!/usr/bin/env bash
# Runs the libFuzzer harnesses of tests/fuzz (docs/robustness.md) for SECONDS each
# (default 60), each on one core, as many side by side as there are cores.
#   tools/fuzz.sh [SECONDS] [HARNESS[:SECONDS]...]   HARNESS: scene_json obj gltf batch_jobs (default
#                                                    all), each for its own SECONDS where given
# Builds build-fuzz with clang-14 (address and undefined-behaviour checks, ABCUBE_FUZZ=ON),
# seeds each harness with its committed seeds (tests/fuzz/corpus), the inputs that once
# crashed (tests/fuzz/regressions), the repository's scenes and meshes and, when installed,
# the OBJ/MTL and glTF files of assimp-testmodels. What a run finds new is kept in
# build-fuzz/corpus/HARNESS and seeds the next run. A crash, a leak, a failed check or an
# input slower than 10 s: exit 1, the input saved as build-fuzz/artifacts/HARNESS/crash-*
# (copy it into tests/fuzz/regressions/HARNESS/ with the fix, docs/robustness.md).
# For hours: tools/fuzz.sh 14400 obj (or run build-fuzz/tests/fuzz/fuzz_obj with -jobs=N -workers=N).
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_EACH=${1:-60}
shift || true
HARNESSES=("$@")
[[ ${#HARNESSES[@]} -gt 0 ]] || HARNESSES=(scene_json obj gltf batch_jobs)
BUILD=${ABCUBE_FUZZ_BUILD:-build-fuzz}

export CCACHE_BASEDIR=${CCACHE_BASEDIR:-$PWD}
if [[ ! -f $BUILD/build.ninja ]]; then
  CC=clang-14 CXX=clang++-14 cmake -S . -B "$BUILD" -G Ninja -DABCUBE_FUZZ=ON -DABCUBE_BUILD_TESTS=OFF \
    -DABCUBE_BUILD_BENCH=OFF > "$BUILD.configure.log" 2>&1 || { cat "$BUILD.configure.log"; exit 1; }
fi
NAMES=("${HARNESSES[@]%%:*}")
cmake --build "$BUILD" --target "${NAMES[@]/#/fuzz_}"

# One OBJ as the obj harness's input: the file, and after a line "#MTL" the MTL file its
# first mtllib names (renamed in.mtl, the name the harness writes it under).
obj_seed() {
  local obj=$1 out=$2 mtl
  mtl=$(sed -n 's/^mtllib[[:space:]]\{1,\}\([^[:space:]]*\).*$/\1/p' "$obj" | head -1)
  if [[ -n $mtl && -f $(dirname "$obj")/$mtl ]]; then
    { sed 's/^mtllib[[:space:]].*$/mtllib in.mtl/' "$obj"; printf '\n#MTL\n'; cat "$(dirname "$obj")/$mtl"; } > "$out"
  else
    cp "$obj" "$out"
  fi
}

# One glTF as the gltf harness's input: a .glb as it is; a .gltf, and after a line "#BIN" its
# first buffer's file when that is a file (its uri renamed in.bin, the name the harness
# writes it under). Models over 64 KiB are left out (libFuzzer's -max_len).
gltf_seed() {
  local model=$1 out=$2 bin
  [[ $(stat -c %s "$model") -le 65536 ]] || return 0
  case $model in
    *.glb) cp "$model" "$out" ;;
    *)
      bin=$(/usr/bin/python3 -c 'import json, sys
try:
    b = json.load(open(sys.argv[1])).get("buffers", [{}])[0].get("uri", "")
except Exception:
    b = ""
print("" if b.startswith("data:") else b)' "$model")
      if [[ -n $bin && -f $(dirname "$model")/$bin && $(stat -c %s "$(dirname "$model")/$bin") -le 65536 ]]; then
        { sed "s|\"$bin\"|\"in.bin\"|" "$model"; printf '\n#BIN\n'; cat "$(dirname "$model")/$bin"; } > "$out"
      else
        cp "$model" "$out"
      fi ;;
  esac
}

seeds() {  # HARNESS FOLDER: fills FOLDER with the inputs gathered from installed files
  local name=$1 dir=$2 f
  rm -rf "$dir"
  mkdir -p "$dir"
  case $name in
    scene_json)
      for f in scenes/*.json scenes/bench/*.json tests/golden/*.json tests/hard/regressions/*.json; do
        cp "$f" "$dir/${f//\//_}"
      done ;;
    obj)
      for f in scenes/*/*.obj /usr/share/assimp/models/OBJ/*.obj /usr/share/assimp/models/invalid/*.obj; do
        if [[ -f $f ]]; then obj_seed "$f" "$dir/${f//\//_}"; fi
      done ;;
    gltf)
      while IFS= read -r f; do gltf_seed "$f" "$dir/${f//\//_}"; done \
        < <(find /usr/share/assimp/models/glTF2 -name '*.gltf' -o -name '*.glb' 2>/dev/null | sort) ;;
    batch_jobs) ;;
  esac
}

# new_delete_type_mismatch=0: tools/sanitizers/README.md says why (OpenImageIO 2.4's
# TextureSystem::destroy; abcube's own deletes are checked by -Wdelete-non-virtual-dtor).
export ASAN_OPTIONS=${ASAN_OPTIONS:-abort_on_error=1:detect_leaks=1:new_delete_type_mismatch=0}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$PWD/tools/sanitizers/lsan.supp:print_suppressions=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
# One harness's run: its seeds, then libFuzzer on one core for its seconds; its summary line
# goes to $BUILD/fuzz_NAME.summary, its failure report to the output, and the exit status
# says whether it failed.
run_harness() {  # NAME SECONDS
  local name=$1 seconds=$2 corpus=$BUILD/corpus/$1 artifacts=$BUILD/artifacts/$1 log=$BUILD/fuzz_$1.log
  local rc=0 runs corpus_size first unwind="" inputs
  mkdir -p "$corpus" "$artifacts"
  seeds "$name" "$BUILD/seeds/$name"
  inputs=("$corpus" tests/fuzz/corpus/$name "$BUILD/seeds/$name")
  [[ -d tests/fuzz/regressions/$name ]] && inputs+=(tests/fuzz/regressions/$name)
  echo "fuzz: $name for ${seconds} s (log $log)"
  # gltf decodes images through OpenImageIO: whole stacks for LeakSanitizer
  # (fast_unwind_on_malloc=0, 6x slower), which libstdc++ (no frame pointers) otherwise cuts
  # at two frames, too few for the PNG reader's entry in tools/sanitizers/lsan.supp to match.
  [[ $name == gltf ]] && unwind=":fast_unwind_on_malloc=0"
  ASAN_OPTIONS="$ASAN_OPTIONS$unwind" "$BUILD/tests/fuzz/fuzz_$name" -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=10 -max_len=65536 \
    -print_final_stats=1 -artifact_prefix="$artifacts/" "${inputs[@]}" > "$log" 2>&1 || rc=$?
  runs=$(sed -n 's/^stat::number_of_executed_units:[[:space:]]*//p' "$log" | tail -1)
  corpus_size=$(find "$corpus" -type f | wc -l)
  if [[ $rc -ne 0 ]]; then
    # The report's head (its kind and the innermost frames), then the log's end, in one write
    # so that a harness beside it does not interleave.
    {
      first=$(grep -n -m1 -E '==ERROR:|runtime error:|ERROR: libFuzzer' "$log" | cut -d: -f1 || true)
      [[ -n $first ]] && sed -n "${first},$((first + 40))p" "$log" && echo "..."
      tail -n 15 "$log"
      echo "fuzz: $name FAILED (exit $rc); input: $(ls -t "$artifacts" | head -1 | sed "s|^|$artifacts/|")"
    } > "$log.report"
    cat "$log.report"
    echo "$name: FAILED after ${runs:-?} inputs" > "$BUILD/fuzz_$name.summary"
    return 1
  fi
  echo "$name: ${runs:-?} inputs in ${seconds} s, no failure; corpus $corpus_size files" > "$BUILD/fuzz_$name.summary"
}

# The harnesses run side by side, each on one core (libFuzzer's own process, one thread),
# ABCUBE_FUZZ_JOBS at once (default: the cores, at most the harnesses), the longest first so
# that the wall time is close to the total over the cores. Each keeps its own seconds.
jobs=${ABCUBE_FUZZ_JOBS:-$(nproc)}
order=()
for harness in "${HARNESSES[@]}"; do
  seconds=$SECONDS_EACH
  [[ $harness == *:* ]] && seconds=${harness#*:}
  order+=("$seconds ${harness%%:*}")
done
mapfile -t order < <(printf '%s\n' "${order[@]}" | sort -s -k1,1nr)
status=0
running=0
for entry in "${order[@]}"; do
  if [[ $running -ge $jobs ]]; then
    wait -n || status=1
    running=$((running - 1))
  fi
  rm -f "$BUILD/fuzz_${entry#* }.summary"
  run_harness "${entry#* }" "${entry%% *}" &
  running=$((running + 1))
done
while [[ $running -gt 0 ]]; do
  wait -n || status=1
  running=$((running - 1))
done
for harness in "${HARNESSES[@]}"; do
  cat "$BUILD/fuzz_${harness%%:*}.summary" 2>/dev/null | sed 's/^/fuzz: /' || echo "fuzz: ${harness%%:*}: no summary"
done
exit $status
