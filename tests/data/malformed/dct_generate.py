#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Writes the broken DCT FAP streams dct_*.m4fd next to this script for
tests/cpp/test_dct_codec.cpp (each test checks the element and byte the error names). All
but the first two start from ../dct/irregular.m4fd, a valid stream (docs/dct-mode.md):

- dct_empty.m4fd             zero bytes
- dct_garbage.m4fd           512 bytes of SHA-256 chain output (seed: the file name)
- dct_bad_version.m4fd       version 2
- dct_bad_fap_quant.m4fd     fap_quant 0
- dct_nan_frame_rate.m4fd    frame_rate a NaN
- dct_huge_frame_count.m4fd  frame_count 2^32 - 1, far more than the data can hold
- dct_name_past_end.m4fd     name_length 65535
- dct_truncated.m4fd         cut to 60 % of its length
- dct_trailing_bytes.m4fd    8 bytes of noise appended
- dct_bit_flipped.m4fd       one bit of a level flipped: it decodes, and the CRC-32 says no
- dct_bad_crc.m4fd           the last bit of the CRC-32 flipped

Run: python3 tests/data/malformed/dct_generate.py
"""
import pathlib
import struct

from gltf_generate import noise

HERE = pathlib.Path(__file__).resolve().parent


def patched(data, offset, new):
    return data[:offset] + new + data[offset + len(new):]


def flipped(data, bit):
    out = bytearray(data)
    out[bit // 8] ^= 0x80 >> (bit % 8)
    return bytes(out)


def main():
    valid = (HERE.parent / "dct" / "irregular.m4fd").read_bytes()
    files = {
        "dct_empty.m4fd": b"",
        "dct_garbage.m4fd": noise("dct_garbage.m4fd"),
        "dct_bad_version.m4fd": patched(valid, 4, b"\x02"),
        "dct_bad_fap_quant.m4fd": patched(valid, 5, b"\x00"),
        "dct_nan_frame_rate.m4fd": patched(valid, 7, struct.pack(">d", float("nan"))),
        "dct_huge_frame_count.m4fd": patched(valid, 15, b"\xff\xff\xff\xff"),
        "dct_name_past_end.m4fd": patched(valid, 19, b"\xff\xff"),
        "dct_truncated.m4fd": valid[: len(valid) * 6 // 10],
        "dct_trailing_bytes.m4fd": valid + noise("dct_trailing_bytes.m4fd", 8),
        "dct_bit_flipped.m4fd": flipped(valid, 60 * 8 + 3),
        "dct_bad_crc.m4fd": flipped(valid, len(valid) * 8 - 1),
    }
    for name, data in files.items():
        (HERE / name).write_bytes(data)


if __name__ == "__main__":
    main()
