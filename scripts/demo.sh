#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The README's demo command: installs what is missing, builds, and runs the main job on the
# bundled sample head, writing everything to out/demo/. It grows with the project; today it
# describes the CANDIDE-3 head: meshes, its FAP units, feature points, the measured FAPU and
# the Table 6 location checks.
set -euo pipefail
cd "$(dirname "$0")/.."
out=${MPEG4FACE_DEMO_OUT:-out/demo}

scripts/setup.sh
scripts/build.sh build/release
mkdir -p "$out"

cli=build/release/bin/mpeg4face
head=tests/data/candide3/candide3.wfm
points=tests/data/candide3/feature_points.csv

echo
"$cli" info "$head" --feature-points "$points" | tee "$out/info.txt"
"$cli" info "$head" --feature-points "$points" --json >"$out/info.json"

echo
echo "demo: wrote $out/info.txt and $out/info.json"
