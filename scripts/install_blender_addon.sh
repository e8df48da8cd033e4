#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Installs the Blender add-on "MPEG-4 Face": builds the native module, copies
# blender_addon/mpeg4face_blender and the built python/mpeg4face (into the add-on's lib/)
# into Blender's user add-on folder, then enables the add-on and saves the preferences.
#
# Environment:
#   BLENDER               the Blender to install for (default: blender)
#   MPEG4FACE_BUILD_DIR   build folder holding python/mpeg4face (default: build/release)
#   MPEG4FACE_SKIP_BUILD  1: use the module already in MPEG4FACE_BUILD_DIR, do not build
#   MPEG4FACE_ADDON_DIR   add-on folder to install into (default: asked from Blender; it
#                         follows BLENDER_USER_SCRIPTS)
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
blender=${BLENDER:-blender}
build=${MPEG4FACE_BUILD_DIR:-build/release}
addon=mpeg4face_blender

say() { printf 'install_blender_addon: %s\n' "$*"; }
fail() { say "error: $*" >&2; exit 1; }

command -v "$blender" >/dev/null || fail "Blender not found (set BLENDER to its path)"

# One question to Blender: its Python version, the extension suffix that Python imports,
# and its user add-on folder (scene/compat.user_addon_dir, the one place that knows it).
answer=$("$blender" -b --factory-startup --python-exit-code 1 --python-expr "
import importlib.machinery, sys
sys.path.insert(0, '$root/blender_addon')
from $addon.scene import compat
print('PYTHON=%d.%d' % sys.version_info[:2])
print('SUFFIX=' + importlib.machinery.EXTENSION_SUFFIXES[0])
print('ADDONS=' + compat.user_addon_dir())
" 2>&1) || fail "could not ask Blender for its add-on folder: $answer"
python_version=$(sed -n 's/^PYTHON=//p' <<<"$answer")
suffix=$(sed -n 's/^SUFFIX=//p' <<<"$answer")
addons=${MPEG4FACE_ADDON_DIR:-$(sed -n 's/^ADDONS=//p' <<<"$answer")}
[[ -n $addons && -n $suffix ]] || fail "Blender gave no add-on folder: $answer"
say "Blender runs Python $python_version; add-on folder: $addons"

if [[ ${MPEG4FACE_SKIP_BUILD:-0} == 1 ]]; then
  say "not building (MPEG4FACE_SKIP_BUILD=1); using $build"
else
  say "building the native module into $build"
  scripts/build.sh "$build"
fi
module=$build/python/mpeg4face
[[ -f $module/_core$suffix ]] || fail "$module/_core$suffix is missing: the module must be \
built for Blender's Python $python_version (scripts/build.sh builds for /usr/bin/python3; \
Blender must run that Python, as Debian's does)"

say "copying $addon and the native module into $addons"
mkdir -p "$addons"
rm -rf "${addons:?}/$addon"
cp -r "blender_addon/$addon" "$addons/$addon"
mkdir -p "$addons/$addon/lib"
cp -r "$module" "$addons/$addon/lib/"
find "$addons/$addon" -name __pycache__ -type d -prune -exec rm -rf {} +

say "enabling the add-on and saving the preferences"
"$blender" -b --python-exit-code 1 --python-expr "
import addon_utils, bpy, sys
addon_utils.enable('$addon', default_set=True)
from $addon import native
from $addon.ui import preferences
if not preferences.status.ok:
    print('\n'.join(native.problem(preferences.status)), file=sys.stderr)
    sys.exit(1)
print('loaded: ' + native.description(preferences.status))
bpy.ops.wm.save_userpref()
" || fail "Blender could not enable the add-on (see above)"
say "done: in Blender, 3D Viewport > Sidebar (N) > MPEG-4"
