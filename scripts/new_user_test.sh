#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# A new user's path, tested: clones this repository (its committed state) into a temporary
# folder, runs the README's two commands there exactly as the README's first code block
# writes them, and checks what the demo made (tests/new_user/check_demo_output.py:
# gltf-validator clean, the VRML face read back by us and by tovrmlx3d, the decoded streams'
# PSNR as printed, the preview's frames, contact sheet and video). The demo runs twice: a
# second run must work too. Prints how long each run took.
#
# Environment: MPEG4FACE_NEW_USER_STEPS  "demo tests" (default) or "demo". The README's test
# command runs this script with "demo" as its last step: it is itself the other command, so
# it does not start itself again in the clone.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
steps=${MPEG4FACE_NEW_USER_STEPS:-demo tests}

say() { printf 'new_user_test: %s\n' "$*"; }
fail() { say "FAILED: $*" >&2; exit 1; }

# The README's first ```sh block, comments dropped: the demo command, then the tests'.
mapfile -t commands < <(awk '/^```sh$/ { inside = 1; next } /^```$/ { if (inside) exit }
                             inside' README.md | sed 's/[[:space:]]*#.*//' | grep -v '^[[:space:]]*$')
[ "${#commands[@]}" -eq 2 ] || fail "README.md's first sh block should hold two commands"
git -C "$root" rev-parse --git-dir >/dev/null 2>&1 || fail "$root is not a git checkout"

work=$(mktemp -d "${TMPDIR:-/tmp}/mpeg4face-new-user.XXXXXX")
git clone --quiet "$root" "$work/mpeg4face"
cd "$work/mpeg4face"
say "fresh clone of $(git rev-parse --short HEAD) in $PWD"

run() {  # run NAME COMMAND: the command as the README writes it, its output in a log
  local log="$work/$1.log" started=$SECONDS
  say "$1: $2"
  if ! bash -c "$2" >"$log" 2>&1; then
    tail -n 60 "$log"
    fail "$1 failed after $((SECONDS - started)) s (the log is $log)"
  fi
  say "$1 took $((SECONDS - started)) s"
}

if [[ " $steps " == *" demo "* ]]; then
  run "demo, first run" "${commands[0]}"
  run "demo, second run" "${commands[0]}"
  PYTHONPATH=build/release/python /usr/bin/python3 tests/new_user/check_demo_output.py out/demo \
    || fail "the demo's output (above)"
fi
if [[ " $steps " == *" tests "* ]]; then
  export MPEG4FACE_NEW_USER_STEPS=demo  # the test command's own new-user step: the demo only
  run "tests" "${commands[1]}"
fi
rm -rf "$work"
say "passed ($steps)"
