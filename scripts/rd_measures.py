#!/usr/bin/python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Each coding mode at 20, 25, 30 and 35 dB on both PSNRs (docs/rate-distortion.md, "Both
measures"): bits per FAP sample of the cheapest encoding reaching the target, summed over the
nine Xface streams (each stream's cheapest fap_quant, bits added, divided by all their FAP
samples), by the robust PSNR and by Tao et al.'s eq. (8).

usage: rd_measures.py MPEG4FACE [FAP_DIR]

Runs `MPEG4FACE rd` on every .fap in FAP_DIR (default tests/data/xface-fap) and prints a
Markdown table; "-" where some stream reaches the target in no fap_quant of that mode (the
count of streams that do is given then).
"""
import csv
import os
import subprocess
import sys
import tempfile

TARGETS = (20.0, 25.0, 30.0, 35.0)
MODES = ("predictive", "dct", "pca+predictive", "pca+dct")
COLUMNS = (("robust", "robust_psnr_db"), ("Tao eq. (8)", "psnr_db"))


def main(argv):
    if len(argv) not in (2, 3):
        print(__doc__, file=sys.stderr)
        return 2
    tool = argv[1]
    fap_dir = argv[2] if len(argv) == 3 else os.path.join(
        os.path.dirname(__file__), "..", "tests", "data", "xface-fap")
    faps = sorted(os.path.join(fap_dir, n) for n in os.listdir(fap_dir) if n.endswith(".fap"))
    sweeps = []
    with tempfile.TemporaryDirectory() as work:
        for fap in faps:
            out = os.path.join(work, os.path.basename(fap) + ".csv")
            subprocess.run([tool, "rd", fap, "--csv", out], check=True, stdout=subprocess.DEVNULL)
            with open(out, newline="") as f:
                sweeps.append(list(csv.DictReader(f)))
    print("| mode | measure | " + " | ".join("%g dB" % t for t in TARGETS) + " |")
    print("|---|---|" + "---|" * len(TARGETS))
    for mode in MODES:
        for label, column in COLUMNS:
            cells = []
            for target in TARGETS:
                bits = samples = 0.0
                reached = 0
                for rows in sweeps:
                    ok = [r for r in rows if r["mode"] == mode and r[column] != ""
                          and float(r[column]) >= target]
                    if not ok:
                        continue
                    best = min(ok, key=lambda r: int(r["bits"]))
                    bits += int(best["bits"])
                    samples += int(best["bits"]) / float(best["bits_per_sample"])
                    reached += 1
                cells.append("%.3f" % (bits / samples) if reached == len(sweeps)
                             else "- (%d of %d)" % (reached, len(sweeps)))
            print("| %s | %s | %s |" % (mode, label, " | ".join(cells)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
