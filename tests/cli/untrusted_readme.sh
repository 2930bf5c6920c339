#!/usr/bin/env bash
# docs/untrusted-scenes.md "Running renders confined": its block of commands runs as written, with its first
# three lines (ABCUBE, UPLOADS, RENDERS) pointed at a scratch folder and its /srv/abcube-ro
# at one inside it, as root in a private mount namespace (the bind mount vanishes with it).
# Then the same confinement is tried from the stranger's side: a job whose scene names a
# file outside its folder, one that writes into the read-only view, one over the caps.
# Skipped (with the reason) where the script is not root or has no mount namespace.
# Usage (ctest runs it so): bash untrusted_readme.sh /path/to/abcube /path/to/repo
set -u
if [ -z "${ABCUBE_UNTRUSTED_IN_NAMESPACE:-}" ] && [ "$(id -u)" -eq 0 ] &&
   unshare --mount --propagation private true 2>/dev/null; then
  exec env ABCUBE_UNTRUSTED_IN_NAMESPACE=1 unshare --mount --propagation private bash "$0" "$@"
fi
ABCUBE=$1
REPO=$2
CLI_TEST=untrusted_readme
. "$(dirname "$0")/lib/check.sh"
if [ -z "${ABCUBE_UNTRUSTED_IN_NAMESPACE:-}" ]; then
  echo "SKIPPED: needs root and a private mount namespace (mount --bind, setpriv)"
  exit 0
fi
chmod 755 "$WORK"

# The block, from the page: the fenced block after the section's heading.
block=$(awk '/^## Running renders confined/ {in_section = 1}
             in_section && /^```/ {if (in_block) exit; in_block = 1; next}
             in_block {print}' "$REPO/docs/untrusted-scenes.md")
check "docs/untrusted-scenes.md has the block" [ -n "$block" ]
check "its first lines set ABCUBE, UPLOADS, RENDERS" \
  [ "$(printf '%s\n' "$block" | head -3 | cut -d= -f1 | tr '\n' ' ')" = "ABCUBE UPLOADS RENDERS " ]

# The program where nobody can run it, an upload (a scene and its mesh), the scratch paths.
mkdir -p "$WORK/bin" "$WORK/uploads/job42/meshes" "$WORK/secret"
cp "$ABCUBE" "$WORK/bin/abcube"
chmod 755 "$WORK/bin" "$WORK/bin/abcube"
cp "$REPO/scenes/meshes/octahedron.obj" "$REPO/scenes/meshes/octahedron.mtl" "$WORK/uploads/job42/meshes/"
cat > "$WORK/uploads/job42/scene.json" <<'JSON'
{ "version": 1, "camera": {"position": [0, 1, 4], "look_at": [0, 0, 0], "width": 64, "height": 48},
  "lights": [{"type": "point", "position": [2, 4, 3], "color": [1, 1, 1]}],
  "objects": [{"type": "mesh", "file": "meshes/octahedron.obj"}] }
JSON
chmod -R a+rX "$WORK/uploads"
script=$(printf '%s\n' "$block" | tail -n +4 | sed "s|/srv/abcube-ro|$WORK/ro|g")
{
  echo "set -eu"
  echo "ABCUBE=$WORK/bin/abcube"
  echo "UPLOADS=$WORK/uploads"
  echo "RENDERS=$WORK/renders"
  printf '%s\n' "$script"
} > "$WORK/block.sh"
bash "$WORK/block.sh" > "$WORK/out" 2> "$WORK/err"
status=$?
check "the block runs as written ($(tail -2 "$WORK/err"))" [ $status -eq 0 ]
check "it rendered job42" test -s "$WORK/renders/job42.png"
check "the render is owned by nobody" [ "$(stat -c %U "$WORK/renders/job42.png")" = nobody ]

# From the stranger's side, through the same view and user.
as_nobody() { setpriv --reuid=nobody --regid=nogroup --clear-groups "$WORK/bin/abcube" "$@"; }
printf 'v 0 0 0 # TOPSECRET-CONTENT' > "$WORK/secret/key.obj"
umount "$WORK/ro" 2>/dev/null
mkdir -p "$WORK/uploads/job43"
cat > "$WORK/uploads/job43/scene.json" <<'JSON'
{ "version": 1, "camera": {"position": [0, 1, 4], "look_at": [0, 0, 0], "width": 64, "height": 48},
  "objects": [{"type": "mesh", "file": "../../secret/key.obj"}] }
JSON
ln -s "$WORK/secret/key.obj" "$WORK/uploads/job43/link.obj"
sed 's|../../secret/key.obj|link.obj|' "$WORK/uploads/job43/scene.json" > "$WORK/uploads/job43/linked.json"
chmod -R a+rX "$WORK/uploads"
mount --bind -o ro "$WORK/uploads" "$WORK/ro"
for scene in scene linked; do
  as_nobody render "$WORK/ro/job43/$scene.json" -o "$WORK/renders/job43.png" --gl none --root "$WORK/ro/job43" \
    > /dev/null 2> "$WORK/err"
  status=$?
  check "a $scene file outside the job's folder: exit 2 (got $status)" [ $status -eq 2 ]
  check "a $scene file outside: named, outside --root, nothing of it shown" \
    grep -q 'objects\[0\].file: .* resolves outside --root' "$WORK/err"
  check "a $scene file outside: its content not shown" bash -c "! grep -q TOPSECRET '$WORK/err'"
done
as_nobody render "$WORK/ro/job42/scene.json" -o "$WORK/ro/job42/out.png" --gl none --root "$WORK/ro/job42" \
  > /dev/null 2> "$WORK/err"
check "writing into the read-only view: exit 2" [ $? -eq 2 ]
check "writing into the read-only view: says not writable" grep -q "is not writable" "$WORK/err"
as_nobody render "$WORK/ro/job42/scene.json" -o "$WORK/renders/big.png" --gl none --root "$WORK/ro/job42" \
  --max-pixels 1000 > /dev/null 2> "$WORK/err"
check "over --max-pixels: exit 2" [ $? -eq 2 ]
check "no output for the refused jobs" test ! -e "$WORK/renders/job43.png" -a ! -e "$WORK/renders/big.png"
umount "$WORK/ro"

echo "untrusted_readme: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
