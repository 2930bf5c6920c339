#!/usr/bin/env bash
# The third-party corpus: every OBJ, glTF and GLB file of Debian's
# assimp-testmodels (installed by tools/setup.sh) given to `abcube render` as the scene,
# as a new user would. The expected outcome of each file is data: corpus.tsv beside this
# script (path under the corpus, exit status, what the image must show, a fragment of
# stderr). Checked per file:
#   exit 2: exactly one stderr line holding the fragment, no image written;
#   exit 0: an EXR without NaN or Inf (oiiotool --stats), stderr only warning lines (holding
#           the fragment when one is given, empty when it is "-"), and the view:
#           framed  something drawn and the image's border rows and columns background,
#           camera  something drawn (the file's own camera frames it, not abcube),
#           empty   nothing drawn (the file has no triangles);
#   never a crash or a hang (each render stopped after 300 s by timeout(1): a failure).
# Every file of the corpus must be listed and every listed file present: a file the package
# adds or drops fails the test, so none is skipped silently.
#
# Each file renders by the exact tracer at 4 samples a pixel, a rung of its ladder, at an
# eighth of the rays of all 32, and at 320 x 240: what is checked is the file's loading and
# framing, which a smaller image frames alike (the view is fitted to the model's bounds).
#
# Usage (ctest runs it so): bash corpus.sh /path/to/abcube /path/to/repo [CORPUS_DIR]
# ABCUBE_CORPUS_ARGS, when set, replaces --size 320x240 in every render's arguments: the
# ASan stage of tools/sanitize.sh renders at --size 96x72, since what it checks is the
# loading of each file, not the tracer's millions of rays; and ABCUBE_CORPUS_EVERY (below).
set -u

if [ $# -lt 2 ]; then
  echo "usage: bash corpus.sh /path/to/abcube /path/to/repo [CORPUS_DIR]" >&2
  exit 2
fi
ABCUBE=$1
REPO=$2
CORPUS=${3:-/usr/share/assimp/models}
TABLE="$REPO/tests/models/corpus.tsv"
if [ ! -d "$CORPUS" ]; then
  echo "models corpus: $CORPUS missing: install assimp-testmodels (bash tools/setup.sh)"
  exit 1
fi

WORK=$(mktemp -d "${TMPDIR:-/tmp}/abcube_corpus.XXXXXX")
trap 'rm -rf "$WORK"' EXIT

# The listed paths against the corpus's files.
grep -v '^#' "$TABLE" | cut -f1 | sed '/^$/d' | sort > "$WORK/listed"
(cd "$CORPUS" && find . -type f \( -iname '*.obj' -o -iname '*.gltf' -o -iname '*.glb' \) | sed 's|^\./||' | sort) > "$WORK/present"
failed=0
if ! diff -u "$WORK/listed" "$WORK/present" > "$WORK/diff"; then
  echo "FAIL corpus.tsv does not list exactly the corpus's files:"
  cat "$WORK/diff"
  failed=1
fi

# check_one PATH EXIT VIEW FRAGMENT: renders and checks one file; prints one result line.
check_one() {
  local path=$1 want=$2 view=$3 fragment=$4
  local name out status problems=()
  name=$(echo "$path" | tr '/' '_')
  out="$WORK/$name.exr"
  # shellcheck disable=SC2086 # ABCUBE_CORPUS_ARGS is a list of words
  timeout 300 "$ABCUBE" render "$CORPUS/$path" -o "$out" --method raytrace --samples 4 --gl none --threads 1 \
    ${ABCUBE_CORPUS_ARGS:---size 320x240} \
    > "$WORK/$name.stdout" 2> "$WORK/$name.stderr"
  status=$?
  [ "$status" -eq 124 ] && problems+=("still running after 300 s")
  [ "$status" -eq "$want" ] || problems+=("exit status $status, expected $want")
  if [ "$want" -eq 2 ]; then
    [ "$(wc -l < "$WORK/$name.stderr")" -eq 1 ] || problems+=("stderr has $(wc -l < "$WORK/$name.stderr") lines")
    [ -e "$out" ] && problems+=("an image was written")
  elif [ "$status" -eq 0 ]; then
    local stats max nan
    stats=$(oiiotool -v --stats "$out" 2>&1)
    nan=$(echo "$stats" | awk '/NanCount|InfCount/ {for (i = 3; i <= NF; ++i) s += $i} END {print s + 0}')
    [ "$nan" -eq 0 ] || problems+=("$nan NaN or Inf values")
    max=$(echo "$stats" | awk '/Stats Max/ {m = $3; for (i = 4; i <= 5; ++i) if ($i > m) m = $i; print m}')
    case "$view" in
      framed|camera) awk -v m="$max" 'BEGIN {exit !(m > 0)}' || problems+=("nothing drawn") ;;
      empty) awk -v m="$max" 'BEGIN {exit !(m == 0)}' || problems+=("something drawn, expected an empty image") ;;
      *) problems+=("unknown view '$view' in corpus.tsv") ;;
    esac
    if [ "$view" = framed ]; then
      local w h edge
      w=$(echo "$stats" | awk '/ x / {print $3; exit}')
      h=$(echo "$stats" | awk '/ x / {print $5; exit}' | tr -d ',')
      for edge in "${w}x1+0+0" "${w}x1+0+$((h - 1))" "1x${h}+0+0" "1x${h}+$((w - 1))+0"; do
        if ! oiiotool "$out" --cut "$edge" --printstats 2>&1 | awk '/Stats Max/ {exit !($3 == 0 && $4 == 0 && $5 == 0)}'; then
          problems+=("drawn on the image border ($edge): not framed")
        fi
      done
    fi
    if grep -qv ': warning: ' "$WORK/$name.stderr"; then problems+=("stderr holds more than warnings"); fi
    [ "$fragment" = "-" ] && [ -s "$WORK/$name.stderr" ] && problems+=("unexpected stderr")
  fi
  [ "$fragment" = "-" ] || grep -qF -- "$fragment" "$WORK/$name.stderr" || problems+=("stderr does not hold '$fragment'")
  [ -s "$WORK/$name.stdout" ] && problems+=("stdout not empty")
  if [ ${#problems[@]} -eq 0 ]; then
    echo "ok   $path: exit $status $(head -c 160 "$WORK/$name.stderr" | tr '\n' '|')"
  else
    echo "FAIL $path: ${problems[*]}; stderr: $(head -c 300 "$WORK/$name.stderr" | tr '\n' '|')"
  fi
}
export -f check_one
export ABCUBE CORPUS WORK

# Two renders at a time, one thread each. ABCUBE_CORPUS_EVERY=N (the ASan stage) renders the
# first file of each kind (OBJ, glTF, GLB) and every Nth after it.
grep -v '^#' "$TABLE" | sed '/^$/d' |
  awk -F'\t' -v every="${ABCUBE_CORPUS_EVERY:-1}" '{ kind = tolower($1); sub(/.*\./, "", kind); if (n[kind]++ % every == 0) print }' |
  while IFS=$'\t' read -r path want view fragment; do printf '%s\0%s\0%s\0%s\0' "$path" "$want" "$view" "$fragment"; done |
  xargs -0 -n 4 -P 2 bash -c 'check_one "$@"' _ > "$WORK/results"
sort "$WORK/results"
passed=$(grep -c '^ok ' "$WORK/results")
bad=$(grep -c '^FAIL ' "$WORK/results")
echo "models corpus: $passed passed, $bad failed"
[ "$bad" -eq 0 ] && [ "$failed" -eq 0 ]
