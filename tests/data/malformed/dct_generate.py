#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Writes the broken DCT-mode FBA streams dct_*.fba next to this script for
tests/cpp/codec/test_dct_mode.cpp (each test checks the element and message the error names). All
start from ../dct/irregular.fba, a valid stream of one intra DCT plane and inter DCT planes
(docs/dct-mode.md); the fields are found by reading the plane header and intra settings as
docs/bitstream.md gives them:

- dct_truncated.fba        cut to 60 % of its length, inside an arithmetic-coded segment:
                           the segment runs past the end of the data
- dct_zero_dc_divisor.fba  dc_divisor 0 in the intra plane
- dct_zero_fap_quant.fba   fap_quant 0 (no quantisation) in a DCT intra plane
- dct_flipped_bit.fba      bit 189 (byte 23, bit 5), in the first segment's coded data,
                           flipped: FAP 3's step_index then lies outside 0..175

Run: python3 tests/data/malformed/dct_generate.py
"""
import pathlib

from fba_bits import Bits

HERE = pathlib.Path(__file__).resolve().parent
GROUP_SIZES = [2, 16, 12, 8, 4, 5, 3, 10, 4, 4]  # FAPs per group, groups 1..10


def intra_fields(data):
    """Bit offsets of fap_quant and dc_divisor in the first (intra) plane."""
    bits = Bits(data)
    assert bits.read(32) == 0x1BA and bits.read(8) == 0x7F and bits.read(32) == 0x1BB
    assert bits.read(1) == 1 and bits.read(2) == 1  # is_intra_frame, fba_paramset_mask
    if bits.read(1):  # is_frame_rate
        bits.read(13)
    if bits.read(1):  # is_time_code
        bits.read(18)
    if bits.read(1):  # skip_frames
        while bits.read(4) == 15:
            pass
    fap_quant = bits.pos
    bits.read(5)
    for size in GROUP_SIZES:
        assert bits.read(1) == 1  # marker_bit
        if bits.read(2) in (1, 2):
            bits.read(size)
    bits.read(1)  # suggested_gender
    assert bits.read(1) == 1  # coding_type: DCT
    return fap_quant, bits.pos


def with_bits(data, offset, count, value):
    out = bytearray(data)
    for i in range(count):
        bit = offset + i
        out[bit // 8] &= ~(0x80 >> (bit % 8)) & 0xFF
        if (value >> (count - 1 - i)) & 1:
            out[bit // 8] |= 0x80 >> (bit % 8)
    return bytes(out)


def main():
    valid = (HERE.parent / "dct" / "irregular.fba").read_bytes()
    fap_quant, dc_divisor = intra_fields(valid)
    flipped = bytearray(valid)
    flipped[189 // 8] ^= 0x80 >> (189 % 8)
    files = {
        "dct_truncated.fba": valid[: len(valid) * 6 // 10],
        "dct_zero_dc_divisor.fba": with_bits(valid, dc_divisor, 4, 0),
        "dct_zero_fap_quant.fba": with_bits(valid, fap_quant, 5, 0),
        "dct_flipped_bit.fba": bytes(flipped),
    }
    for name, data in files.items():
        (HERE / name).write_bytes(data)


if __name__ == "__main__":
    main()
