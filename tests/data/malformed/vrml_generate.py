#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Writes the VRML samples that are easier to generate than to type (same bytes every run):
vrml_garbage.wrl  512 bytes of SHA-256 chain output seeded with the file name (binary noise);
vrml_gzip.wrl     a gzip stream of a valid VRML97 file (fixed mtime), which must be gunzipped first;
vrml_deep_nesting.wrl  300 Groups nested in each other, deeper than the reader's limit of 256."""
import gzip
import hashlib
import pathlib

here = pathlib.Path(__file__).parent

def garbage(name, size=512):
    out, block = b"", name.encode()
    while len(out) < size:
        block = hashlib.sha256(block).digest()
        out += block
    return out[:size]

(here / "vrml_garbage.wrl").write_bytes(garbage("vrml_garbage.wrl"))
(here / "vrml_gzip.wrl").write_bytes(
    gzip.compress(b"#VRML V2.0 utf8\nTransform { }\n", mtime=0))
depth = 300
(here / "vrml_deep_nesting.wrl").write_text(
    "#VRML V2.0 utf8\n" + "Group { children [ " * depth + "]}" * depth + "\n")
