#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Configures and builds mpeg4face (library, CLI, Python module, tests) into build/release.
# Usage: scripts/build.sh [BUILD_DIR] [extra cmake arguments...]
# Environment: MPEG4FACE_BUILD_TARGETS: build only these targets (the demo needs the CLI
# "mpeg4face_cli" and the Python module "_core", not the tests).
set -euo pipefail
cd "$(dirname "$0")/.."
dir=${1:-build/release}
shift || true
# ccache, when installed (scripts/setup.sh installs it), makes a rebuild of unchanged sources
# quick, in this checkout or another: the new-user test's fresh clone builds the demo in half
# a minute instead of ten (docs/testing.md). CCACHE_BASEDIR turns paths inside this checkout
# into relative ones and CCACHE_NOHASHDIR keeps the build directory out of the hash of a -g
# build, so that another checkout of the same sources finds the same entries.
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=1
fi
# pybind11 is the pinned one of scripts/requirements/build.txt (scripts/setup.sh installs it in
# build/venv-build), the one the wheel is built with: numpy 1 and 2 from one binary.
if [ ! -x build/venv-build/bin/python ]; then
  echo "build: build/venv-build (the pinned pybind11) is missing: run scripts/setup.sh first" >&2
  exit 1
fi
cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPython_EXECUTABLE=/usr/bin/python3 \
  -Dpybind11_DIR="$(build/venv-build/bin/python -m pybind11 --cmakedir)" \
  "${launcher[@]}" "$@" >/dev/null
targets=()
for target in ${MPEG4FACE_BUILD_TARGETS:-}; do targets+=(--target "$target"); done
cmake --build "$dir" -j"$(nproc)" "${targets[@]}"
