#!/usr/bin/python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Rate at fixed PSNR for every Xface stream and coding mode (docs/rate-distortion.md); PCA
with either component coder (pca+predictive, pca+dct: docs/pca-mode.md) counts as a mode.

usage: rd_report.py MPEG4FACE [FAP_DIR]

Runs `MPEG4FACE rd` on every .fap in FAP_DIR (default tests/data/xface-fap), on "all9",
the nine streams concatenated in name order (frames renumbered, one 25 Hz stream), and on the
long 30 Hz streams of tests/data/long-30hz (scripts/make_long_stream.py), and prints
a Markdown table: for each stream, mode and PSNR target (20, 30, 35, 45 dB, Tao et al.'s
columns), the cheapest sweep point whose PSNR reaches the target, as bits per FAP sample and
bits/s ("0.984 / 1135 (q31)"); "<=" marks the coarsest fap_quant (31), where the target
is exceeded and the rate is only an upper bound of what the target needs. "-" where no
fap_quant reaches it; ", inf" where the point's PSNR is +inf (a FAP exact). No interpolation between sweep points: neither bits
nor PSNR is monotone in fap_quant step by step, so the cheapest reaching point is what an
encoder can actually deliver (it is what `encode --mode auto` picks for one mode).
"""
import csv
import math
import os
import subprocess
import sys
import tempfile

TARGETS = (20.0, 30.0, 35.0, 45.0)


def concatenate(paths, out_path):
    """The .fap streams one after the other: frame numbers renumbered, same rate (25 Hz)."""
    body, rate, frame = [], None, 0
    for path in paths:
        with open(path) as f:
            lines = [line.split() for line in f if line.strip()]
        header, rows = lines[0], lines[1:]
        if rate is None:
            rate = header[-2]
        elif header[-2] != rate:
            raise SystemExit("%s: frame rate %s differs from %s" % (path, header[-2], rate))
        for mask, values in zip(rows[0::2], rows[1::2]):
            body.append(" ".join(mask))
            body.append(" ".join([str(frame)] + values[1:]))
            frame += 1
    with open(out_path, "w") as f:
        f.write("2.1 all9 %s %d\n" % (rate, frame))
        f.write("\n".join(body) + "\n")


def sweep(tool, fap, workdir):
    csv_path = os.path.join(workdir, os.path.basename(fap) + ".csv")
    subprocess.run([tool, "rd", fap, "--csv", csv_path], check=True, stdout=subprocess.DEVNULL)
    with open(csv_path, newline="") as f:
        return list(csv.DictReader(f))


def cheapest(rows, mode, target):
    best = None
    for r in rows:
        if r["mode"] != mode or r["psnr_db"] == "" or float(r["psnr_db"]) < target:
            continue
        if best is None or int(r["bits"]) < int(best["bits"]):
            best = r
    return best


def main(argv):
    if len(argv) not in (2, 3):
        print(__doc__, file=sys.stderr)
        return 2
    tool = argv[1]
    fap_dir = argv[2] if len(argv) == 3 else os.path.join(
        os.path.dirname(__file__), "..", "tests", "data", "xface-fap")
    faps = sorted(os.path.join(fap_dir, n) for n in os.listdir(fap_dir) if n.endswith(".fap"))
    with tempfile.TemporaryDirectory() as work:
        all9 = os.path.join(work, "all9.fap")
        concatenate(faps, all9)
        long_dir = os.path.join(os.path.dirname(__file__), "..", "tests", "data", "long-30hz")
        longs = sorted(os.path.join(long_dir, n) for n in os.listdir(long_dir) if n.endswith(".fap"))
        streams = [(os.path.basename(p)[:-4], p) for p in faps + [all9] + longs]
        print("| stream | mode | " + " | ".join("%g dB" % t for t in TARGETS) + " |")
        print("|---|---|" + "---|" * len(TARGETS))
        for name, path in streams:
            rows = sweep(tool, path, work)
            for mode in ("predictive", "dct", "pca+predictive", "pca+dct"):
                cells = []
                for t in TARGETS:
                    b = cheapest(rows, mode, t)
                    if b is None:
                        cells.append("-")
                    else:
                        floor = "<=" if b["fap_quant"] == "31" else ""
                        cells.append("%s%.3f / %.0f (q%s%s)" % (
                            floor, float(b["bits_per_sample"]), float(b["bits_per_second"]),
                            b["fap_quant"], ", inf" if math.isinf(float(b["psnr_db"])) else ""))
                print("| %s | %s | %s |" % (name, mode, " | ".join(cells)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
