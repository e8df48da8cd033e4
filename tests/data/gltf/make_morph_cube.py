#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Writes morph_cube.gltf: a small morph-target cube in the style of the Khronos
AnimatedMorphCube sample, built without mpeg4face so that the reader is tested against an
independent writer.

Contents (what tests/cpp/io/test_gltf.cpp checks):
- mesh "Cube", 24 vertices (4 per face, per-face normals), two primitives:
  0: the 5 faces other than +Y as indexed TRIANGLES (UNSIGNED_SHORT indices),
  1: the +Y face as a non-indexed TRIANGLE_STRIP;
  TEXCOORD_0 as normalized UNSIGNED_SHORT, NORMAL and POSITION as FLOAT;
- two morph targets named by mesh.extras.targetNames = ["thin", "angle"]:
  "thin" (dense POSITION + NORMAL deltas) halves x, "angle" (a sparse accessor without a
  buffer view) moves the top (+Y) vertices by +0.5 in x; mesh.weights = [0.25, 0.0];
- nodes: "AnimatedMorphCube" (root, rotation) -> "Cube" (mesh, translation + scale) and
  "Marker" (a TRS given as a column-major matrix);
- animation "Square": a LINEAR weights channel on "Cube" (5 keys) and a rotation channel on
  the root;
- one buffer, embedded as a base64 data: URI.

Run from anywhere: python3 tests/data/gltf/make_morph_cube.py
"""
import base64
import json
import math
import pathlib
import struct

FLOAT, USHORT = 5126, 5123
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963

# Cube faces: outward normal and the 4 corners counter-clockwise seen from outside.
FACES = [
    ((1, 0, 0), [(1, -1, 1), (1, -1, -1), (1, 1, -1), (1, 1, 1)]),
    ((-1, 0, 0), [(-1, -1, -1), (-1, -1, 1), (-1, 1, 1), (-1, 1, -1)]),
    ((0, -1, 0), [(-1, -1, -1), (1, -1, -1), (1, -1, 1), (-1, -1, 1)]),
    ((0, 0, 1), [(-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1)]),
    ((0, 0, -1), [(1, -1, -1), (-1, -1, -1), (-1, 1, -1), (1, 1, -1)]),
    ((0, 1, 0), [(-1, 1, 1), (1, 1, 1), (1, 1, -1), (-1, 1, -1)]),  # the strip primitive
]
UVS = [(0.0, 1.0), (1.0, 1.0), (1.0, 0.0), (0.0, 0.0)]  # glTF orientation (origin top left)


class Blob:
    def __init__(self):
        self.data = bytearray()
        self.views = []
        self.accessors = []

    def view(self, payload, target=None):
        while len(self.data) % 4:
            self.data.append(0)
        view = {"buffer": 0, "byteOffset": len(self.data), "byteLength": len(payload)}
        if target:
            view["target"] = target
        self.data += payload
        self.views.append(view)
        return len(self.views) - 1

    def accessor(self, **fields):
        self.accessors.append(fields)
        return len(self.accessors) - 1

    def floats(self, rows, kind, target=ARRAY_BUFFER, bounds=False):
        flat = [x for row in rows for x in row] if kind != "SCALAR" else list(rows)
        view = self.view(struct.pack("<%df" % len(flat), *flat), target)
        acc = {"bufferView": view, "componentType": FLOAT, "count": len(rows), "type": kind}
        if bounds:
            width = len(rows[0]) if kind != "SCALAR" else 1
            cols = [flat[i::width] for i in range(width)]
            # Bounds of the float32 values actually stored.
            f32 = lambda x: struct.unpack("<f", struct.pack("<f", x))[0]
            acc["min"] = [f32(min(c)) for c in cols]
            acc["max"] = [f32(max(c)) for c in cols]
        return self.accessor(**acc)


def primitive(blob, faces, mode, face_uvs):
    positions, normals, uvs = [], [], []
    for normal, corners in faces:
        for corner, uv in zip(corners, face_uvs):
            positions.append([0.5 * c for c in corner])
            normals.append(list(normal))
            uvs.append(uv)
    n = len(positions)
    attributes = {
        "POSITION": blob.floats(positions, "VEC3", bounds=True),
        "NORMAL": blob.floats(normals, "VEC3"),
    }
    packed = b"".join(struct.pack("<2H", round(u * 65535), round(v * 65535)) for u, v in uvs)
    attributes["TEXCOORD_0"] = blob.accessor(
        bufferView=blob.view(packed, ARRAY_BUFFER), componentType=USHORT, normalized=True,
        count=n, type="VEC2")

    # "thin": halve x (dense), with zero normal deltas like the Khronos sample.
    thin = [[-0.5 * p[0], 0.0, 0.0] for p in positions]
    thin_target = {
        "POSITION": blob.floats(thin, "VEC3", bounds=True),
        "NORMAL": blob.floats([[0.0, 0.0, 0.0]] * n, "VEC3"),
    }
    # "angle": sparse, only the top vertices move.
    top = [i for i, p in enumerate(positions) if p[1] > 0]
    indices_view = blob.view(struct.pack("<%dH" % len(top), *top))
    values_view = blob.view(struct.pack("<%df" % (3 * len(top)), *([0.5, 0.0, 0.0] * len(top))))
    angle_target = {
        "POSITION": blob.accessor(
            componentType=FLOAT, count=n, type="VEC3",
            min=[0.5 if len(top) == n else 0.0, 0.0, 0.0], max=[0.5, 0.0, 0.0],
            sparse={"count": len(top),
                    "indices": {"bufferView": indices_view, "componentType": USHORT},
                    "values": {"bufferView": values_view}})
    }
    prim = {"attributes": attributes, "targets": [thin_target, angle_target], "mode": mode}
    if mode == 4:
        idx = []
        for f in range(len(faces)):
            a, b, c, d = (4 * f + k for k in range(4))
            idx += [a, b, c, a, c, d]
        prim["indices"] = blob.accessor(
            bufferView=blob.view(struct.pack("<%dH" % len(idx), *idx), ELEMENT_ARRAY_BUFFER),
            componentType=USHORT, count=len(idx), type="SCALAR")
    return prim


def strip_order(quad):
    # Quad a b c d (counter-clockwise) as the strip a b d c: triangles (a b d), (b c d).
    return [quad[0], quad[1], quad[3], quad[2]]


def main():
    blob = Blob()
    prims = [
        primitive(blob, FACES[:5], 4, UVS),
        primitive(blob, [(n, strip_order(c)) for n, c in FACES[5:]], 5, strip_order(UVS)),
    ]

    times = [0.0, 1.0, 2.0, 3.0, 4.0]
    weights = [0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0, 0.0, 0.0]  # (thin, angle) per key
    rot_times = [0.0, 4.0]
    half = math.sqrt(0.5)
    rotations = [[0.0, 0.0, 0.0, 1.0], [0.0, half, 0.0, half]]
    anim = {
        "name": "Square",
        "samplers": [
            {"input": blob.floats(times, "SCALAR", target=None, bounds=True),
             "output": blob.floats(weights, "SCALAR", target=None), "interpolation": "LINEAR"},
            {"input": blob.floats(rot_times, "SCALAR", target=None, bounds=True),
             "output": blob.floats(rotations, "VEC4", target=None), "interpolation": "LINEAR"},
        ],
        "channels": [
            {"sampler": 0, "target": {"node": 1, "path": "weights"}},
            {"sampler": 1, "target": {"node": 0, "path": "rotation"}},
        ],
    }

    # Marker: translate (0, 2, 0) * rotate 90 degrees about z * scale 0.5, column-major.
    marker = [0.0, 0.5, 0.0, 0.0,
              -0.5, 0.0, 0.0, 0.0,
              0.0, 0.0, 0.5, 0.0,
              0.0, 2.0, 0.0, 1.0]
    s = math.sin(math.radians(15))
    c = math.cos(math.radians(15))
    gltf = {
        "asset": {"version": "2.0", "generator": "make_morph_cube.py (mpeg4face tests)"},
        "scene": 0,
        "scenes": [{"name": "Scene", "nodes": [0]}],
        "nodes": [
            {"name": "AnimatedMorphCube", "rotation": [0.0, s, 0.0, c], "children": [1, 2]},
            {"name": "Cube", "mesh": 0, "translation": [0.0, 0.5, 0.0], "scale": [1.0, 2.0, 1.0]},
            {"name": "Marker", "matrix": marker},
        ],
        "meshes": [{
            "name": "Cube",
            "primitives": prims,
            "weights": [0.25, 0.0],
            "extras": {"targetNames": ["thin", "angle"]},
        }],
        "animations": [anim],
        "accessors": blob.accessors,
        "bufferViews": blob.views,
        "buffers": [{
            "byteLength": len(blob.data),
            "uri": "data:application/octet-stream;base64," +
                   base64.b64encode(bytes(blob.data)).decode("ascii"),
        }],
    }
    out = pathlib.Path(__file__).resolve().parent / "morph_cube.gltf"
    out.write_text(json.dumps(gltf, indent=1) + "\n")
    print("wrote", out)


if __name__ == "__main__":
    main()
