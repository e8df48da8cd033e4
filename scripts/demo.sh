#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The README's demo command: installs what is missing, builds, and runs the main job on the
# bundled sample head, writing everything to out/demo/. It grows with the project; today it
# describes the CANDIDE-3 head (meshes, FAP units, feature points, the measured FAPU, the
# Table 6 location checks), makes its FaceDefTables from its FAP units with the viseme and
# expression FIT in the Face node, and has it say a sentence: flite speaks it, the phones
# become visemes, a bookmark smiles, and the stream is played on the face as glTF.
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

# The FaceDefTables, with the FIT that turns visemes and expressions into CANDIDE's FAPs.
echo
"$cli" fit preset viseme,expression -o "$out/candide3_fit.json"
"$cli" fat generate "$head" --feature-points "$points" --fit "$out/candide3_fit.json" \
  -o "$out/candide3.wrl" >"$out/candide3_fat.txt"
head -n 4 "$out/candide3_fat.txt"
echo "  ... (all of it in $out/candide3_fat.txt)"

# The head says a sentence.
echo
"$cli" speak "Hello! <FAP 2 1 50 1 50 900 3> I am an MPEG-4 face, and I can talk." \
  -o "$out/hello.fap" --audio "$out/hello.wav"
"$cli" encode "$out/hello.fap" -o "$out/hello.fba"
"$cli" apply "$out/candide3.wrl" "$out/hello.fba" -o "$out/hello.glb"

echo
echo "demo: wrote to $out/"
echo "  info.txt, info.json          the head described"
echo "  candide3.wrl, _fat.txt       its FaceDefTables (VRML97) with the FIT, and the report"
echo "  hello.fap, hello.fba, .wav   the sentence as a FAP stream, coded, and its audio"
echo "  hello.glb                    the head saying it (glTF animation; play it with the .wav)"
