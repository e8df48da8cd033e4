#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Writes the broken .fap inputs fap_*.fap next to this script for
tests/cpp/io/test_fap_file.cpp (each test checks the line and field the error names). All are
made from scratch (not from the Xface streams): a header `2.1 broken 25 N` and frames sending
FAP 3 open_jaw, FAP 23 yaw_l_eyeball and FAP 48 head_pitch.

- fap_empty.fap               zero bytes
- fap_garbage.fap             512 bytes of SHA-256 chain output (seed: the file name)
- fap_truncated.fap           the header announces 10 frames, the file ends after 4
- fap_truncated_mask.fap      the file ends after a mask line (line 8), its values line missing
- fap_bad_mask_token.fap      line 4: the mask token of FAP 23 is 2
- fap_short_mask.fap          line 6: a mask of 67 tokens
- fap_wrong_value_count.fap   line 5: the values of FAP 48 are missing
- fap_too_many_values.fap     line 3: one value more than the mask sends
- fap_huge_frame_count.fap    line 1: the header announces 99,999,999 frames
- fap_int_overflow_count.fap  line 1: the header announces 4,000,000,000 frames
- fap_huge_value.fap          line 5: FAP 3 = 5,000,000
- fap_non_numeric.fap         line 3: FAP 23 = "1O" (letter O)
- fap_bad_version.fap         line 1: version 3.0
- fap_bad_frame_rate.fap      line 1: frame rate 0
- fap_frame_number_backwards.fap  line 7: frame 1 after frame 2

Run: python3 tests/data/malformed/fap_generate.py
"""
import hashlib
import pathlib

HERE = pathlib.Path(__file__).resolve().parent
SENT = (3, 23, 48)


def noise(name, size=512):
    out, block = b"", name.encode()
    while len(out) < size:
        block = hashlib.sha256(block).digest()
        out += block
    return out[:size]


def mask(faps=SENT, count=68, override=None):
    tokens = ["1" if fap in faps else "0" for fap in range(1, count + 1)]
    if override:
        fap, token = override
        tokens[fap - 1] = token
    return " ".join(tokens) + "\n"


def values(number, vals=None):
    vals = vals if vals is not None else [10 * number, -5 * number, 100 * number]
    return " ".join(str(v) for v in [number] + vals) + "\n"


def frames(count, start=0):
    return "".join(mask() + values(n) for n in range(start, start + count))


def header(count, version="2.1", rate="25"):
    return f"{version} broken {rate} {count}\n"


def main():
    files = {
        "fap_empty.fap": b"",
        "fap_garbage.fap": noise("fap_garbage.fap"),
        "fap_truncated.fap": header(10) + frames(4),
        "fap_truncated_mask.fap": header(4) + frames(3) + mask(),
        "fap_bad_mask_token.fap": header(2) + frames(1) + mask(override=(23, "2")) + values(1),
        "fap_short_mask.fap": header(3) + frames(2) + mask(count=67) + values(2),
        "fap_wrong_value_count.fap": header(2) + frames(1) + mask() + values(1, [10, -5]),
        "fap_too_many_values.fap": header(1) + mask() + values(0, [0, 0, 0, 7]),
        "fap_huge_frame_count.fap": header(99999999) + frames(1),
        "fap_int_overflow_count.fap": header(4000000000) + frames(1),
        "fap_huge_value.fap": header(2) + frames(1) + mask() + values(1, [5000000, 0, 0]),
        "fap_non_numeric.fap": header(1) + mask() + "0 10 1O 100\n",
        "fap_bad_version.fap": header(1, version="3.0") + frames(1),
        "fap_bad_frame_rate.fap": header(1, rate="0") + frames(1),
        "fap_frame_number_backwards.fap": header(3) + frames(1) + frames(1, 2) + frames(1, 1),
    }
    for name, content in files.items():
        data = content if isinstance(content, bytes) else content.encode()
        (HERE / name).write_bytes(data)


if __name__ == "__main__":
    main()
