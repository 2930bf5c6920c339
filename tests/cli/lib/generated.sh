# Sourced by the tests/cli scripts on the gpu method and generated scenes (after check.sh,
# with ABCUBE and REPO set).
#   require_gl              exits 0 ("SKIPPED") where abcube finds no GL path
#   generate TOOL SEED COUNT OUT
#                           tools/TOOL.py's scenes for SEED into OUT, small: 128 x 96, N = 128
require_gl() {
  if ! "$ABCUBE" info 2>/dev/null | grep -q 'auto picks: [eo]'; then
    echo "SKIPPED: no GL path here (the gpu method needs one)"
    exit 0
  fi
}
generate() {
  /usr/bin/python3 "$REPO/tools/$1.py" --seed "$2" --count "$3" --out "$4" --size 128x96 --cube-res 128 > /dev/null ||
    { echo "FAIL: tools/$1.py --seed $2"; exit 1; }
}
