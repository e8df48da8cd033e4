#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Builds the samples into samples/build/ from the project's copies of the third-party data
# (tests/data/candide3, tests/data/makehuman, tests/data/xface-fap, samples/makehuman,
# tests/data/ict-facekit; their notices beside them): CANDIDE-3 as glTF, the MakeHuman head
# and the ICT-FaceKit head as .glb and .blend, and the FAP streams (the Xface ones, and
# samples/streams/hello.txt spoken). docs/samples.md says what each holds. Needs the build
# (scripts/build.sh); takes a few seconds.
# Environment: MPEG4FACE_BUILD_DIR (default build/release), BLENDER (default blender).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${MPEG4FACE_BUILD_DIR:-build/release}
out=samples/build
mkdir -p "$out/streams"

PYTHONPATH="$build/python" /usr/bin/python3 samples/build_samples.py --out "$out"
for head in "makehuman_head:MakeHuman head" "ict_head:ICT head"; do
  if ! MPEG4FACE_PYTHONPATH="$PWD/$build/python" "${BLENDER:-blender}" -b --factory-startup \
      --python-exit-code 1 --python samples/make_blend.py -- \
      "$out/${head%%:*}.glb" "$out/${head%%:*}.blend" --name "${head#*:}" \
      >"$out/make_blend.log" 2>&1; then
    cat "$out/make_blend.log"
    echo "samples: Blender could not make ${head%%:*}.blend (its output is above)" >&2
    exit 1
  fi
  grep '^make_blend:' "$out/make_blend.log"
done

cp tests/data/xface-fap/*.fap "$out/streams/"
"$build/bin/mpeg4face" speak "$(cat samples/streams/hello.txt)" \
  -o "$out/streams/hello.fap" --audio "$out/streams/hello.wav"
