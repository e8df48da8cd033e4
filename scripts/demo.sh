#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The README's demo command: installs what is missing, builds, and runs the main job on the
# bundled MakeHuman head (docs/user-guide.md walks through it):
#   1. the samples, built from the project's copies of the third-party data (samples/build.sh)
#   2. the head's FaceDefTables from its shape keys and poses, exported as an MPEG-4 face
#      (VRML97 .wrl with the BIFS face nodes, and glTF .glb)
#   3. a FAP stream (a spoken sentence with expressions, blinks, brows, eyes and head)
#      encoded in predictive and DCT mode (bits/s and PSNR printed) and decoded
#   4. the decoded stream previewed in Blender through the add-on: every frame rendered, a
#      contact sheet and a video with the sound
#   5. a talking portrait: a still picture of the head says the sentence as an MPEG-4 2D mesh
#      animation (the head's feature points played and projected, coded as .m2d, warped)
#   6. a real iPhone capture (Live Link Face's ARKit weights) converted to a FAP stream on the
#      ICT head, encoded (bits/s and PSNR printed), decoded and played on the MakeHuman head;
#      a few of its frames side by side on both heads (contact sheet)
#   7. a summary of what was made and where.
# Everything goes to MPEG4FACE_DEMO_OUT (default out/demo/); running it again redoes it.
set -euo pipefail
cd "$(dirname "$0")/.."
out=${MPEG4FACE_DEMO_OUT:-out/demo}
fap_quant=8
started=$SECONDS

step() { printf '\n=== %s\n' "$*"; }

step "setup (what is missing from Debian's packages, npm and PyPI)"
scripts/setup.sh --demo
step "build (the CLI and the Python module)"
MPEG4FACE_BUILD_TARGETS="mpeg4face_cli _core" scripts/build.sh build/release
cli=build/release/bin/mpeg4face
export MPEG4FACE_PYTHONPATH=$PWD/build/release/python

step "samples (samples/build/)"
samples/build.sh
mkdir -p "$out"
head=samples/build/makehuman_head.glb

step "the head: meshes, feature points, FAPU"
"$cli" info "$head" >"$out/info.txt"
sed -n '/^FAPU/,/^warnings/{/^warnings/!p}' "$out/info.txt"

step "FaceDefTables from the head's shape keys and poses; export as an MPEG-4 face"
"$cli" fat generate "$head" -o "$out/makehuman_head.wrl" >"$out/makehuman_head_fat.txt"
head -n 1 "$out/makehuman_head_fat.txt"
"$cli" export "$out/makehuman_head.wrl" -o "$out/makehuman_head.glb"

step "a FAP stream: the sentence of samples/streams/hello.txt, spoken"
cp samples/build/streams/hello.fap samples/build/streams/hello.wav "$out/"
for mode in predictive dct; do
  echo
  "$cli" encode "$out/hello.fap" --mode "$mode" --fap-quant "$fap_quant" \
    -o "$out/hello_$mode.fba" | tee "$out/coding_$mode.txt"
  "$cli" decode "$out/hello_$mode.fba" -o "$out/hello_${mode}_decoded.fap" | tee -a "$out/coding_$mode.txt"
done
coded() {  # coded MODE: "842.1 bits/s, PSNR 55.64 dB" from what encode printed
  echo "$(grep -o '[0-9.]* bits/s' "$out/coding_$1.txt"), $(grep -o '^PSNR [0-9.inf]* dB' "$out/coding_$1.txt")"
}
# The decoded stream played on the face by the core, as glTF animation (any glTF viewer).
"$cli" apply "$out/makehuman_head.wrl" "$out/hello_dct.fba" -o "$out/hello_animated.glb" >/dev/null

step "preview in Blender: the decoded DCT stream on the head, live through the add-on"
# Blender's own chatter goes to the log; the preview's progress lines are shown.
if ! blender -b samples/build/makehuman_head.blend --python-exit-code 1 \
    --python samples/preview.py -- "$out/hello_dct.fba" "$out/preview" \
    --audio "$out/hello.wav" --title "hello_dct.fba (DCT, fap_quant $fap_quant)" 2>&1 \
    | tee "$out/preview.log" | grep --line-buffered '^preview:'; then
  tail -n 40 "$out/preview.log"
  exit 1
fi

step "a talking portrait: a picture of the head says the sentence as a 2D mesh animation"
# Blender renders the neutral head and projects its feature points in every frame of the
# sentence played on it; the CLI meshes the picture, codes the motion (.m2d) and warps it.
portrait=$out/portrait
mkdir -p "$portrait"
if ! blender -b samples/build/makehuman_head.blend --python-exit-code 1 \
    --python samples/portrait.py -- "$portrait/portrait.png" "$portrait/feature_points.csv" \
    --stream "$out/hello.fap" --tracks "$portrait/tracks.csv" >"$portrait/portrait.log" 2>&1; then
  tail -n 40 "$portrait/portrait.log"
  exit 1
fi
grep '^portrait:' "$portrait/portrait.log"
"$cli" mesh2d portrait "$portrait/portrait.png" --feature-points "$portrait/feature_points.csv" \
  --tracks "$portrait/tracks.csv" --m2d "$portrait/portrait.m2d" -o "$portrait/portrait.mp4" \
  --audio "$out/hello.wav" 2>"$portrait/coding.txt"
grep -o '^portrait: .* bits' "$portrait/coding.txt"
"$cli" mesh2d decode "$portrait/portrait.m2d" -o "$portrait/portrait.json"
# 12 frames across the sentence, the lower face (pixels 110..430 x 230..510 of 540 x 540).
ffmpeg -y -loglevel error -i "$portrait/portrait.mp4" \
  -vf "select='not(mod(n\,16))',crop=320:280:110:230,tile=4x3:padding=4:color=white" \
  -frames:v 1 -fps_mode vfr "$portrait/contact_sheet.part.png"
mv "$portrait/contact_sheet.part.png" "$portrait/contact_sheet.png"

step "a real capture: Live Link Face's ARKit weights to FAPs, coded, on both heads"
capture=tests/data/livelink-face/MySlate_3_Jason_Millers_iPhone.csv
"$cli" arkit to-fap "$capture" --face samples/build/ict_head.glb --fps 25 \
  -o "$out/capture.fap" >"$out/capture_to_fap.txt"
converted() {  # "328 frames at 60 fps -> 137 frames at 25 fps" from what to-fap printed
  sed -En 's/^.*: ([0-9]+ frames at [0-9.]+ fps) -> .*: ([0-9]+ frames at [0-9.]+ fps)$/\1 -> \2/p' \
    "$out/capture_to_fap.txt"
}
echo "capture: $(converted)"
"$cli" encode "$out/capture.fap" --mode dct --fap-quant "$fap_quant" \
  -o "$out/capture_dct.fba" | tee "$out/coding_capture.txt"
"$cli" decode "$out/capture_dct.fba" -o "$out/capture_dct_decoded.fap" | tee -a "$out/coding_capture.txt"
"$cli" apply "$out/makehuman_head.wrl" "$out/capture_dct.fba" -o "$out/capture_animated.glb" >/dev/null
# Six frames: the capture on the ICT head through its ARKit shapes | the decoded stream on the
# ICT head through its tables | on the MakeHuman head (Blender, the add-on's live preview).
if ! blender -b samples/build/ict_head.blend --python-exit-code 1 \
    --python samples/capture_sheet.py -- "$capture" "$out/capture_dct_decoded.fap" \
    samples/build/makehuman_head.blend "$out/capture_sheet.png" --rows 6 --resolution 520 \
    >"$out/capture_sheet.log" 2>&1; then
  tail -n 40 "$out/capture_sheet.log"
  exit 1
fi
grep '^capture_sheet:' "$out/capture_sheet.log"

step "summary ($((SECONDS - started)) s)"
tee "$out/summary.txt" <<EOF
demo: everything is in $out/
  makehuman_head.wrl        the MakeHuman head as an MPEG-4 face: scene, feature points,
                            FaceDefTables ($(head -n 1 "$out/makehuman_head_fat.txt" | sed 's/.*-> //'))
  makehuman_head.glb        the same face as glTF: one morph target per table interval
  makehuman_head_fat.txt    the tables, FAP by FAP;  info.txt: the head described
  hello.fap, hello.wav      the sentence as a FAP stream, and its sound
  hello_predictive.fba      coded in predictive mode, fap_quant $fap_quant: $(coded predictive)
  hello_dct.fba             coded in DCT mode, fap_quant $fap_quant: $(coded dct)
  hello_*_decoded.fap       the two bitstreams decoded;  coding_*.txt: what encode printed
  hello_animated.glb        the head playing the decoded stream (glTF animation)
  preview/frames/           every frame rendered in Blender ($(ls "$out/preview/frames" | wc -l) PNGs)
  preview/contact_sheet.png 12 frames across the sentence
  preview/preview.mp4       the frames and the sound as a video (H.264 + AAC)
  portrait/portrait.mp4     a still picture of the head saying the sentence as a 2D mesh
                            animation, with the sound; portrait/contact_sheet.png: 12 frames
  portrait/portrait.m2d     the mesh and its motion coded: $(grep -o '[0-9]* bits' "$portrait/coding.txt")
                            (portrait.json decoded; portrait.png, feature_points.csv and
                            tracks.csv: the picture and its feature points, still and moving)
  capture.fap               a real iPhone capture (tests/data/livelink-face) as FAPs, made on
                            the ICT head: $(converted)
  capture_dct.fba           coded in DCT mode, fap_quant $fap_quant: $(coded capture)
  capture_dct_decoded.fap   decoded;  coding_capture.txt: what encode printed
  capture_animated.glb      the MakeHuman head playing it (glTF animation)
  capture_sheet.png         6 frames: the capture on ICT (its ARKit shapes) | the decoded
                            FAPs on ICT | on MakeHuman (through their tables)
The heads: samples/build/makehuman_head.blend and ict_head.blend (open them in Blender with the
add-on, scripts/install_blender_addon.sh) and their .glb; docs/user-guide.md explains it all.
EOF
