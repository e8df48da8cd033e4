#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Writes the broken PCA-mode FBA streams pca_*.fba next to this script for
tests/cpp/codec/test_pca_mode.cpp (each test checks the element and message the error names). All
start from ../../fuzz_corpus/fba/pca_joy_q8.fba (`mpeg4face encode joy.fap --mode pca
--fap-quant 8`); the PCA header (docs/pca-mode.md) is parsed, changed and written again in
front of the unchanged component planes:

- pca_zero_basis_bits.fba      pca_basis_bits 0
- pca_too_many_components.fba  group 2 claims one component more than it has FAPs
- pca_huge_basis_entry.fba     group 2's first basis entry 2^25 (the bound is 2^24)
- pca_long_code.fba            group 2's first mean starts with 45 zero bits
- pca_missing_component.fba    group 2 claims one more component (basis entries 0) than the
                               planes carry: its slot is never sent
- pca_truncated.fba            cut inside group 8's basis

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


def parse(data):
    """The header's fields and the byte where the first plane's stuffing ends."""
    bits = Bits(data)
    assert bits.read(32) == 0x1BA and bits.read(8) == 0x7F and bits.read(32) == 0x1B2
    header = {"basis_bits": bits.read(4), "groups": []}
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


def write(header, rest, raw_group=None):
    """raw_group: (index, bit string) written in place of that group's fields after its mask."""
    out = "{:04b}".format(header["basis_bits"])
    for index, group in enumerate(header["groups"]):
        out += "".join(str(b) for b in group["mask"])
        if raw_group and raw_group[0] == index:
            out += raw_group[1]
        elif "k" in group:
            out += ue(group["k"]) + "".join(se(v) for v in group["mean"] + group["basis"])
    stuffing = 8 - len(out) % 8
    out += "0" + "1" * (stuffing - 1)
    body = int(out, 2).to_bytes(len(out) // 8, "big")
    return bytes.fromhex("000001BA7F000001B2") + body + rest


def main():
    valid = (HERE.parent.parent / "fuzz_corpus" / "fba" / "pca_joy_q8.fba").read_bytes()
    header, planes = parse(valid)
    rest = valid[planes:]
    assert write(header, rest) == valid, "the parser does not reproduce the stream"
    g2 = header["groups"][0]
    m, k = sum(g2["mask"]), g2["k"]
    assert k < m

    def changed(**fields):
        h = {"basis_bits": header["basis_bits"], "groups": [dict(g) for g in header["groups"]]}
        h.update(fields.get("top", {}))
        h["groups"][0].update(fields.get("g2", {}))
        return h

    files = {
        "pca_zero_basis_bits.fba": write(changed(top={"basis_bits": 0}), rest),
        "pca_too_many_components.fba": write(changed(g2={"k": m + 1}), rest),
        "pca_huge_basis_entry.fba": write(changed(g2={"basis": [1 << 25] + g2["basis"][1:]}),
                                          rest),
        "pca_long_code.fba": write(header, rest, (0, ue(k) + "0" * 45 + "1")),
        "pca_missing_component.fba": write(
            changed(g2={"k": k + 1, "basis": [w for i in range(m) for w in
                                              g2["basis"][i * k:(i + 1) * k] + [0]]}), rest),
    }
    # Cut inside group 8 (index 6): after its mask, k and means, within the basis.
    full = write(header, rest)
    bits = Bits(full)
    bits.pos = 32 + 8 + 32 + 4
    for index, group in enumerate(header["groups"]):
        bits.pos += len(group["mask"])
        if "k" not in group:
            continue
        bits.ue()
        for _ in group["mean"]:
            bits.se()
        if index == 6:
            assert group["k"] > 0
            files["pca_truncated.fba"] = full[: bits.pos // 8 + 1]
            break
        for _ in group["basis"]:
            bits.se()
    for name, data in files.items():
        (HERE / name).write_bytes(data)
    print("group 2: %d FAPs, %d components" % (m, k))


if __name__ == "__main__":
    main()
