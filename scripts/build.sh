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
cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPython_EXECUTABLE=/usr/bin/python3 "$@" >/dev/null
targets=()
for target in ${MPEG4FACE_BUILD_TARGETS:-}; do targets+=(--target "$target"); done
cmake --build "$dir" -j"$(nproc)" "${targets[@]}"
