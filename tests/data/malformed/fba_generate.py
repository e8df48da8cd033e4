#!/usr/bin/python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Writes the broken FBA bitstreams fba_*.fba for tests/cpp/codec/test_fba_codec.cpp.

Most are built bit by bit from the syntax (docs/bitstream.md), independently of the C++
encoder; the cut and flipped ones start from ../../fuzz_corpus/fba/mixed.fba (the project's
own synthetic stream). Running it again gives the same bytes.

- fba_empty.fba: no bytes.
- fba_bad_start_code.fba: mixed.fba starting with 0x000001B3 instead of 0x000001BA (0x000001B0
  would start a visual_object_sequence).
- fba_truncated.fba: mixed.fba cut 12 bytes before its end, inside the last plane's
  low-level arithmetic-coded segment.
- fba_no_end_code.fba: an intra plane and three inter planes ending on a byte boundary, then
  nothing: no fba_object_end_code.
- fba_huge_skip.fba: an intra plane skipping 21000 frames (1400 chunks of 15, then 0), an
  inter plane, the end code: valid, but beyond a decoder limit of 20000 frame numbers.
- fba_body_animation.fba: a plane whose fba_paramset_mask is 2 (BAPs only).
- fba_inter_first.fba: the first plane is an inter plane.
- fba_bad_marker.fba: the marker bit before group 4's fap_mask_type is 0.
- fba_zero_frame_rate.fba: frame_rate 0 and seconds 0.
- fba_rate_change.fba: two intra planes at 25 and 30 frames per second.
- fba_flipped_bits.fba: mixed.fba with one bit flipped in each of 8 bytes.
- fba_trailing_bytes.fba: mixed.fba followed by the 3 bytes "abc".
"""

import pathlib
import random

HERE = pathlib.Path(__file__).resolve().parent
MIXED = (HERE / "../../fuzz_corpus/fba/mixed.fba").read_bytes()


class Bits:
    def __init__(self):
        self.bits = []

    def put(self, value, count):
        for i in reversed(range(count)):
            self.bits.append((value >> i) & 1)
        return self

    def start_code(self, code):
        # next_start_code(): a 0, then 1s to the byte boundary (a whole byte when aligned).
        self.put(0, 1)
        while len(self.bits) % 8:
            self.put(1, 1)
        return self.put(code, 32)

    def bytes(self):
        padded = self.bits + [0] * (-len(self.bits) % 8)
        return bytes(
            int("".join(map(str, padded[i:i + 8])), 2) for i in range(0, len(padded), 8))


OBJECT, PLANE, END = 0x000001BA, 0x000001BB, 0x000001B1


def intra_plane(b, rate=None, skip=0, paramset=1, markers=(1,) * 10):
    """An intra plane sending no FAP: all ten mask types 0, no new ranges, and an empty
    low-level coder segment (the flush bits 01)."""
    b.start_code(PLANE)
    b.put(1, 1).put(paramset, 2)
    b.put(rate is not None, 1)
    if rate is not None:
        b.put(rate, 8).put(0, 4).put(0, 1)
    b.put(0, 1)  # is_time_code
    skip_frames(b, skip)
    b.put(1, 5)  # fap_quant
    for marker in markers:
        b.put(marker, 1).put(0, 2)
    b.put(0, 6)  # suggested_gender, coding_type 0 (predictive), no new ranges
    return b.put(0b01, 2)


def inter_plane(b, skip=0):
    b.put(0, 1).put(1, 2)
    skip_frames(b, skip)
    return b.put(0b01, 2)


def skip_frames(b, skip):
    b.put(skip > 0, 1)
    if skip > 0:
        while skip >= 15:
            b.put(15, 4)
            skip -= 15
        b.put(skip, 4)


def stream(*planes):
    b = Bits().put(OBJECT, 32)
    for plane in planes:
        plane(b)
    return b.start_code(END).bytes()


def main():
    out = {}
    out["fba_empty.fba"] = b""
    out["fba_bad_start_code.fba"] = bytes([0, 0, 1, 0xB3]) + MIXED[4:]
    out["fba_truncated.fba"] = MIXED[:-12]
    no_end = Bits().put(OBJECT, 32)
    intra_plane(no_end, rate=25)
    for _ in range(3):
        inter_plane(no_end)
    assert len(no_end.bits) % 8 == 0
    out["fba_no_end_code.fba"] = no_end.bytes()
    out["fba_huge_skip.fba"] = stream(lambda b: intra_plane(b, skip=21000), inter_plane)
    out["fba_body_animation.fba"] = stream(lambda b: intra_plane(b, paramset=2))
    out["fba_inter_first.fba"] = stream(inter_plane)
    out["fba_bad_marker.fba"] = stream(
        lambda b: intra_plane(b, markers=(1, 1, 1, 0, 1, 1, 1, 1, 1, 1)))
    out["fba_zero_frame_rate.fba"] = stream(lambda b: intra_plane(b, rate=0))
    out["fba_rate_change.fba"] = stream(lambda b: intra_plane(b, rate=25),
                                        lambda b: intra_plane(b, rate=30))
    rng = random.Random("fba_flipped_bits")
    flipped = bytearray(MIXED)
    for position in sorted(rng.sample(range(8, len(MIXED) - 8), 8)):
        flipped[position] ^= 1 << rng.randrange(8)
    out["fba_flipped_bits.fba"] = bytes(flipped)
    out["fba_trailing_bytes.fba"] = MIXED + b"abc"
    for name, data in out.items():
        (HERE / name).write_bytes(data)


if __name__ == "__main__":
    main()
