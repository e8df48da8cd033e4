#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Installs everything mpeg4face needs on Debian 12, from Debian's packages, npm and PyPI.
# Does nothing (and needs no network) when all of it is already there. docs/dependencies.md
# says why each package is needed.
# Usage: scripts/setup.sh [--demo]   (--demo: what the demo needs, without the Blender
# modules that only the tests use)
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  cmake make g++ clang libclang-rt-14-dev   # build, sanitizers, libFuzzer
  ccache                                    # rebuilds of unchanged sources (scripts/build.sh)
  libeigen3-dev libtinygltf-dev nlohmann-json3-dev libgtest-dev
  libopenmesh-dev                           # mesh_resample: decimation and subdivision
  python3 python3-dev python3-venv python3-numpy python3-pytest
  python3-mypy                              # stubtest: the .pyi stubs against the module (tests/python/test_stubs.py)
  python3-matplotlib                        # rate-distortion plots (scripts/rd_plot.py), clone grid (scripts/clone_grid.py)
  blender xvfb xauth                        # the add-on, headless and under a virtual display
  nodejs npm                                # gltf-validator
  view3dscene                               # tovrmlx3d, a third-party VRML97 reader for our .wrl
  flite                                     # speech synthesis with phone timings (mpeg4face speak)
  libcgal-dev                               # self-intersections of a face in motion (mpeg4face check)
  libopencv-dev ffmpeg                      # 2D mesh object: images, tracking, video (mpeg4face mesh2d)
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# A node from elsewhere on PATH (nvm, image-provided) is as good as Debian's.
if command -v node >/dev/null && command -v npm >/dev/null; then
  missing=("${missing[@]/nodejs}"); missing=("${missing[@]/npm}")
  read -r -a missing <<<"${missing[*]}"
fi

if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}"
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -q
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
else
  echo "setup: all Debian packages present"
fi

# gltf-validator (Khronos), its exact version pinned in tests/tools/package.json (it has no dependencies).
if [ ! -d tests/tools/node_modules/gltf-validator ]; then
  echo "setup: installing gltf-validator from npm"
  npm install --prefix tests/tools --no-package-lock --no-audit --no-fund --loglevel=error
fi

# PyPI's packages, each set pinned in scripts/requirements/, in virtual environments of
# Debian's Python under build/: the build tools, and Blender 4.5 LTS and 5.0 as Python modules
# (bpy) for the Blender tests. A set is installed again only when its requirements change.
venv() {  # venv NAME: build/venv-NAME from scripts/requirements/NAME.txt
  local dir=build/venv-$1 req=scripts/requirements/$1.txt
  if [ -f "$dir/.requirements" ] && cmp -s "$req" "$dir/.requirements"; then
    return
  fi
  echo "setup: installing $(grep -v '^#' "$req" | tr '\n' ' ')into $dir"
  rm -rf "$dir"
  /usr/bin/python3 -m venv "$dir"
  "$dir/bin/pip" install -q --disable-pip-version-check -r "$req"
  cp "$req" "$dir/.requirements"
}
mkdir -p build
venv build
if [ "${1:-}" != --demo ]; then
  venv bpy-4.5
  venv bpy-5.0
fi
