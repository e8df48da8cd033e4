#!/usr/bin/python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Plots the CSV of `mpeg4face rd`: PSNR against bit rate, one curve per coding mode.

usage: rd_plot.py RD.csv OUT.png [TITLE [COLUMN]]

COLUMN is the PSNR drawn: psnr_db (Tao et al. eq. 8, the default) or robust_psnr_db
(docs/rate-distortion.md). Tao's PSNR is +inf when the decoder reproduces one FAP exactly, the
robust one only when all are (docs/fap-format.md). Such points are drawn at a cap, 5 dB above the highest finite PSNR, with hollow markers, and
the cap is labelled. Rows with an undefined PSNR (empty field) are left out. Exit status 3
when matplotlib is missing (Debian: python3-matplotlib).
"""
import csv
import math
import sys


def main(argv):
    if len(argv) not in (3, 4, 5):
        print(__doc__, file=sys.stderr)
        return 2
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("rd_plot.py: matplotlib is missing (apt-get install python3-matplotlib)",
              file=sys.stderr)
        return 3
    csv_path, png_path = argv[1], argv[2]
    title = argv[3] if len(argv) >= 4 else csv_path
    column = argv[4] if len(argv) == 5 else "psnr_db"
    curves = {}
    with open(csv_path, newline="") as f:
        for row in csv.DictReader(f):
            if row[column] == "":
                continue
            curves.setdefault(row["mode"], []).append(
                (float(row["bits_per_second"]), float(row[column]), int(row["fap_quant"])))
    finite = [p for pts in curves.values() for _, p, _ in pts if math.isfinite(p)]
    cap = (max(finite) if finite else 0.0) + 5.0
    fig, ax = plt.subplots(figsize=(7, 4.5))
    any_inf = False
    for mode, pts in curves.items():
        pts.sort()
        xs = [r for r, _, _ in pts]
        ys = [p if math.isfinite(p) else cap for _, p, _ in pts]
        line, = ax.plot(xs, ys, "-", label=mode)
        fin = [(x, y) for (x, y, (_, p, _)) in zip(xs, ys, pts) if math.isfinite(p)]
        inf = [(x, y) for (x, y, (_, p, _)) in zip(xs, ys, pts) if not math.isfinite(p)]
        if fin:
            ax.plot(*zip(*fin), "o", color=line.get_color(), markersize=4)
        if inf:
            any_inf = True
            ax.plot(*zip(*inf), "o", color=line.get_color(), markersize=6, fillstyle="none")
    if any_inf:
        ax.axhline(cap, color="grey", linewidth=0.5, linestyle=":")
        ax.annotate("inf (exact), drawn at %.1f dB" % cap, (0.01, cap),
                    xycoords=("axes fraction", "data"), va="bottom", fontsize=8, color="grey")
    ax.set_xscale("log")
    ax.set_xlabel("bit rate (bits/s)")
    ax.set_ylabel("robust PSNR (dB)" if column == "robust_psnr_db"
                  else "PSNR (dB, Tao et al. eq. 8)")
    ax.set_title(title)
    ax.grid(True, which="both", linewidth=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(png_path, dpi=100)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
