#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Writes the broken PCA-mode FBA streams pca_*.fba next to this script for
tests/cpp/codec/test_pca_mode.cpp (each test checks the element and message the error names). All
start from ../pca/legacy_joy_q8.fba (`mpeg4face encode joy.fap --mode pca --fap-quant 8
--pca-basis-bits 10`, written before issue 44 with the header unstuffed); the PCA header
(docs/pca-mode.md) is parsed, changed and written again, stuffed as it is now, in front of the
unchanged component planes:

- pca_zero_basis_bits.fba      pca_basis_bits 0
- pca_too_many_components.fba  group 2 claims one component more than it has FAPs
- pca_huge_basis_entry.fba     group 2's first basis entry 2^25 (the bound is 2^24)
- pca_long_code.fba            group 2's first mean starts with 45 zero bits
- pca_missing_component.fba    group 2 claims one more component (basis entries 0) than the
                               planes carry: its slot is never sent
- pca_truncated.fba            cut inside group 8's basis
- pca_stuffing_bit_zero.fba    pca_long_code.fba with its first stuffing bit 0

Run: python3 tests/data/malformed/pca_generate.py
"""
import pathlib

from fba_bits import Bits

HERE = pathlib.Path(__file__).resolve().parent
GROUPS = [(3, 18), (19, 30), (31, 38), (39, 42), (43, 47), (48, 50), (51, 60), (61, 64),
          (65, 68)]  # FAP groups 2..10


def ue(value):
    v = bin(value + 1)[2:]
    return "0" * (len(v) - 1) + v


def se(value):
    return ue(2 * value - 1 if value > 0 else -2 * value)


STUFFING_RUN = 16  # kPcaStuffingRun: a 1 after 16 zeros in a row
PREFIX = bytes.fromhex("000001B97F000001B2")  # pca_object_start_code, stuffing, header code


def parse(data):
    """The header's fields and the byte where the first plane's stuffing ends. Reads the
    header as written before issue 44 (no pca_header_format, not stuffed)."""
    bits = Bits(data)
    assert data.startswith(PREFIX)
    bits.pos = len(PREFIX) * 8
    header = {"basis_bits": bits.read(4), "groups": []}
    assert header["basis_bits"] != 0, "a stuffed header; this parser reads the old one"
    for first, last in GROUPS:
        mask = [bits.read(1) for _ in range(first, last + 1)]
        group = {"mask": mask}
        if any(mask):
            m = sum(mask)
            group["k"] = bits.ue()
            group["mean"] = [bits.se() for _ in range(m)]
            group["basis"] = [bits.se() for _ in range(m * group["k"])]
        header["groups"].append(group)
    return header, (bits.pos + 8) // 8  # next_start_code(): 1..8 bits


def stuff(bits, bad=False):
    """bits with a 1 after every STUFFING_RUN zeros in a row (the first one 0 if bad)."""
    out, zeros = "", 0
    for b in bits:
        out += b
        zeros = zeros + 1 if b == "0" else 0
        if zeros == STUFFING_RUN:
            out += "0" if bad else "1"
            bad, zeros = False, 0
    return out


def header_bits(header, raw_group=None, upto=None):
    """The header's fields, pca_header_format 0 first, not yet stuffed. raw_group: (index,
    bit string) written in place of that group's fields after its mask. upto: (index, means)
    ends the bits after that group's k and means (to cut the stream there)."""
    out = "0000" + "{:04b}".format(header["basis_bits"])
    for index, group in enumerate(header["groups"]):
        out += "".join(str(b) for b in group["mask"])
        if raw_group and raw_group[0] == index:
            out += raw_group[1]
        elif "k" in group:
            out += ue(group["k"]) + "".join(se(v) for v in group["mean"])
            if upto == index:
                return out
            out += "".join(se(v) for v in group["basis"])
    return out


def write(header, rest, raw_group=None, bad_stuffing=False):
    out = stuff(header_bits(header, raw_group), bad_stuffing)
    stuffing = 8 - len(out) % 8
    out += "0" + "1" * (stuffing - 1)
    return PREFIX + int(out, 2).to_bytes(len(out) // 8, "big") + rest


def main():
    legacy = (HERE.parent / "pca" / "legacy_joy_q8.fba").read_bytes()
    header, planes = parse(legacy)
    rest = legacy[planes:]
    assert rest.startswith(bytes.fromhex("000001BB")), "the header does not end where parsed"
    g2 = header["groups"][0]
    m, k = sum(g2["mask"]), g2["k"]
    assert k < m

    def changed(**fields):
        h = {"basis_bits": header["basis_bits"], "groups": [dict(g) for g in header["groups"]]}
        h.update(fields.get("top", {}))
        h["groups"][0].update(fields.get("g2", {}))
        return h

    long_code = (0, ue(k) + "0" * 45 + "1")
    # Cut inside group 8 (index 6), within its basis: one byte after its means.
    assert header["groups"][6]["k"] > 0
    cut = len(PREFIX) + len(stuff(header_bits(header, upto=6))) // 8 + 1
    files = {
        "pca_zero_basis_bits.fba": write(changed(top={"basis_bits": 0}), rest),
        "pca_too_many_components.fba": write(changed(g2={"k": m + 1}), rest),
        "pca_huge_basis_entry.fba": write(changed(g2={"basis": [1 << 25] + g2["basis"][1:]}),
                                          rest),
        "pca_long_code.fba": write(header, rest, long_code),
        "pca_missing_component.fba": write(
            changed(g2={"k": k + 1, "basis": [w for i in range(m) for w in
                                              g2["basis"][i * k:(i + 1) * k] + [0]]}), rest),
        "pca_truncated.fba": write(header, rest)[:cut],
        "pca_stuffing_bit_zero.fba": write(header, rest, long_code, bad_stuffing=True),
    }
    for name, data in files.items():
        (HERE / name).write_bytes(data)
    print("group 2: %d FAPs, %d components" % (m, k))


if __name__ == "__main__":
    main()
