#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Writes the broken glTF inputs gltf_*.gltf / gltf_*.glb next to this script for
tests/cpp/io/test_gltf.cpp (each test checks the field the error names). All start from one
valid indexed triangle with an embedded buffer:

- gltf_empty.gltf                 zero bytes
- gltf_garbage.glb                512 bytes of SHA-256 chain output (seed: the file name)
- gltf_garbage_magic.glb          "glTF" followed by such noise (bad GLB version)
- gltf_truncated.glb              the triangle as GLB, cut to 60 % of its length
- gltf_truncated.gltf             the triangle's JSON, cut in the middle
- gltf_glb_bin_overrun.glb        GLB whose BIN chunk (and buffer) claims 8 bytes more than
                                  the file holds (tinygltf 2.7 itself reads past the end)
- gltf_accessor_past_buffer.gltf  POSITION accessor with 100 elements in a 36-byte view
- gltf_index_out_of_range.gltf    index 7 for a 3-vertex primitive
- gltf_position_wrong_type.gltf   POSITION as UNSIGNED_SHORT
- gltf_missing_buffer.gltf        buffer URI gltf_missing_buffer.bin, which does not exist
- gltf_shear_matrix.gltf          a node whose matrix has shear

Run: python3 tests/data/malformed/gltf_generate.py
"""
import base64
import copy
import hashlib
import json
import pathlib
import struct

HERE = pathlib.Path(__file__).resolve().parent


def noise(name, size=512):
    out, block = b"", name.encode()
    while len(out) < size:
        block = hashlib.sha256(block).digest()
        out += block
    return out[:size]


def triangle():
    positions = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)  # 36 bytes
    indices = struct.pack("<3H", 0, 1, 2) + b"\0\0"  # padded to 8
    data = positions + indices
    gltf = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"name": "Triangle", "mesh": 0}],
        "meshes": [{"name": "Triangle", "primitives": [{"attributes": {"POSITION": 0},
                                                        "indices": 1}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
             "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"},
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 36, "target": 34962},
            {"buffer": 0, "byteOffset": 36, "byteLength": 6, "target": 34963},
        ],
        "buffers": [{"byteLength": len(data)}],
    }
    return gltf, data


def embedded(gltf, data):
    g = copy.deepcopy(gltf)
    g["buffers"][0]["uri"] = "data:application/octet-stream;base64," + \
        base64.b64encode(data).decode()
    return json.dumps(g, indent=1).encode()


def glb(gltf, data, bin_length_delta=0):
    gltf = copy.deepcopy(gltf)
    # The buffer claims the whole (possibly overlong) chunk, so a reader trusting the chunk
    # length copies past the end of the file.
    gltf["buffers"][0]["byteLength"] = len(data) + (-len(data) % 4) + bin_length_delta
    text = json.dumps(gltf).encode()
    text += b" " * (-len(text) % 4)
    data += b"\0" * (-len(data) % 4)
    body = struct.pack("<I4s", len(text), b"JSON") + text
    body += struct.pack("<I4s", len(data) + bin_length_delta, b"BIN\0") + data
    return struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body


def main():
    gltf, data = triangle()
    files = {}
    files["gltf_empty.gltf"] = b""
    files["gltf_garbage.glb"] = noise("gltf_garbage.glb")
    files["gltf_garbage_magic.glb"] = b"glTF" + noise("gltf_garbage_magic.glb")[4:]
    whole = glb(gltf, data)
    files["gltf_truncated.glb"] = whole[: len(whole) * 6 // 10]
    text = embedded(gltf, data)
    files["gltf_truncated.gltf"] = text[: len(text) // 2]
    files["gltf_glb_bin_overrun.glb"] = glb(gltf, data, bin_length_delta=8)

    g = copy.deepcopy(gltf)
    g["accessors"][0]["count"] = 100
    files["gltf_accessor_past_buffer.gltf"] = embedded(g, data)

    files["gltf_index_out_of_range.gltf"] = embedded(
        gltf, data[:36] + struct.pack("<3H", 0, 1, 7) + b"\0\0")

    g = copy.deepcopy(gltf)
    g["accessors"][0]["componentType"] = 5123
    del g["accessors"][0]["min"], g["accessors"][0]["max"]
    files["gltf_position_wrong_type.gltf"] = embedded(g, data)

    g = copy.deepcopy(gltf)
    g["buffers"][0]["uri"] = "gltf_missing_buffer.bin"
    files["gltf_missing_buffer.gltf"] = json.dumps(g, indent=1).encode()

    g = copy.deepcopy(gltf)
    g["nodes"][0]["matrix"] = [1, 0, 0, 0, 0.5, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]
    files["gltf_shear_matrix.gltf"] = embedded(g, data)

    for name, content in files.items():
        (HERE / name).write_bytes(content)
        print("wrote", name, len(content), "bytes")


if __name__ == "__main__":
    main()
