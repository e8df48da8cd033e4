#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The install test (docs/packaging.md): the packages of scripts/package.sh in dist/, installed
# as an artist installs them and used on the MakeHuman sample head (artist_workflow.py):
#   - the extension zip in Blender 4.5 and 5.0 (PyPI's bpy in build/venv-bpy-4.5 and -5.0,
#     virtual environments holding bpy and pytest only: nothing of this project);
#   - the add-on zip in Debian's Blender 3.4 (blender), when installed.
# Each Blender runs with a clean environment (env -i: no PYTHONPATH, no LD_LIBRARY_PATH, no
# build folder on any path) and a new, empty home folder, so its user folder (preferences,
# add-ons, extensions and their wheels) is a temporary one. The .glb written is checked by the
# Khronos glTF validator, the .wrl by its header. Prints one line per step; exits 1 on the
# first failure.
# Needs: dist/ (scripts/package.sh), samples/build/ (samples/build.sh), the CLI of
# MPEG4FACE_BUILD_DIR (default build/release) to encode the .fba, tests/tools/node_modules
# (scripts/setup.sh).
set -euo pipefail
cd "$(dirname "$0")/../.."
root=$PWD
build=${MPEG4FACE_BUILD_DIR:-build/release}

say() { printf 'install-test: %s\n' "$*"; }
fail() { say "FAILED: $*" >&2; exit 1; }

version=$(sed -n 's/^project(mpeg4face VERSION \([0-9][0-9.]*\).*/\1/p' CMakeLists.txt)
extension_zip=$root/dist/mpeg4face-$version-linux_x64.zip
addon_zip=$root/dist/mpeg4face_blender-$version-blender3.4-linux_x64.zip
blend=$root/samples/build/makehuman_head.blend
for file in "$extension_zip" "$addon_zip"; do
  [ -f "$file" ] || fail "$file is missing: run scripts/package.sh"
done
[ -f "$blend" ] || fail "$blend is missing: run samples/build.sh"
[ -x "$build/bin/mpeg4face" ] || fail "$build/bin/mpeg4face is missing: run scripts/build.sh"
[ -d tests/tools/node_modules/gltf-validator ] || fail "no gltf-validator: run scripts/setup.sh"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
started=$SECONDS
"$build/bin/mpeg4face" encode samples/build/streams/hello.fap -o "$tmp/hello.fba" >/dev/null \
  || fail "could not encode samples/build/streams/hello.fap"
say "encoded samples/build/streams/hello.fap -> hello.fba ($((SECONDS - started)) s)"

# install_and_use NAME ZIP KIND COMMAND...: the workflow in a Blender started by COMMAND.
install_and_use() {
  local name=$1 zip=$2 kind=$3
  shift 3
  local out=$tmp/$name/out home=$tmp/$name/home
  mkdir -p "$out" "$home"
  started=$SECONDS
  # From the temporary folder: no checkout on sys.path through the working directory either.
  (cd "$tmp" && env -i PATH=/usr/bin:/bin HOME="$home" LANG=C.UTF-8 "$@" \
    "$root/tests/install/artist_workflow.py" "${separator[@]}" --zip "$zip" --kind "$kind" \
    --blend "$blend" --fba "$tmp/hello.fba" --out "$out" >"$tmp/$name.log" 2>&1) || {
    grep -v '^install-test:' "$tmp/$name.log" | tail -30 >&2
    grep '^install-test:' "$tmp/$name.log"
    fail "$name: the workflow failed (its output is above)"
  }
  grep '^install-test:' "$tmp/$name.log"
  local report
  report=$(node tests/tools/validate_gltf.mjs "$out/head.glb" 2>&1) \
    || fail "$name: head.glb is not valid glTF: $report"
  say "$name: head.glb passes the glTF validator: $(head -1 <<<"$report")"
  [ "$(head -c 15 "$out/head.wrl")" = "#VRML V2.0 utf8" ] || fail "$name: head.wrl is not VRML97"
  # Read back by the project's own VRML reader: the face and its tables, not only a header.
  report=$("$build/bin/mpeg4face" info "$out/head.wrl" 2>&1) \
    || fail "$name: head.wrl does not read back: $report"
  say "$name: head.wrl is VRML97 and reads back ($(wc -l <"$out/head.wrl") lines; $(grep -m1 -i 'mesh' <<<"$report"))"
  say "$name: passed ($((SECONDS - started)) s)"
}

separator=()
for v in 4.5 5.0; do
  python=$root/build/venv-bpy-$v/bin/python
  [ -x "$python" ] || fail "build/venv-bpy-$v is missing: run scripts/setup.sh"
  install_and_use "bpy-$v" "$extension_zip" extension "$python"
done
if command -v blender >/dev/null; then
  separator=(--)
  install_and_use debian-blender "$addon_zip" addon \
    "$(command -v blender)" -b --factory-startup --python-exit-code 1 --python
else
  say "Debian's Blender is not installed: its add-on zip is not tested"
fi

# The same stream moves the sample head the same in every Blender, baked and live: the face
# at 12 frames, against the first Blender's, within float precision of the head's size.
same=$(/usr/bin/python3 "$root/tests/install/same_motion.py" "$tmp") || fail "$same"
say "$same"
say "passed"
