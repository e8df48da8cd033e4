#!/usr/bin/python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Draws the feature-point triangulation of Facial Motion Cloning (docs/clone.md).

The triangles, the required points and the lip contours are read from
core/src/clone/feature_points.cpp (the one place they are written); the points are placed where
CANDIDE-3 has them (tests/data/candide3), seen from the front.

    /usr/bin/python3 scripts/clone_triangulation_plot.py [OUT.png]
"""
import csv
import pathlib
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent
SOURCE = ROOT / "core/src/clone/feature_points.cpp"
CANDIDE = ROOT / "tests/data/candide3"


def block(text, name):
    """The brace-enclosed initialiser of the C++ array `name`."""
    start = text.index(name)
    open_brace = text.index("{", start)
    depth = 0
    for i in range(open_brace, len(text)):
        depth += {"{": 1, "}": -1}.get(text[i], 0)
        if depth == 0:
            return text[open_brace + 1 : i]
    raise ValueError(name)


def ids(text):
    return re.findall(r'"(\d+\.\d+)"', text)


def candide_points():
    lines = (CANDIDE / "candide3.wfm").read_text(encoding="latin-1").splitlines()
    start = lines.index("# VERTEX LIST:") + 1
    count = int(lines[start])
    vertices = [tuple(map(float, l.split())) for l in lines[start + 1 : start + 1 + count]]
    points = {}
    with open(CANDIDE / "feature_points.csv", newline="") as f:
        for row in csv.DictReader(f):
            points.setdefault(row["mpeg4_fp"], vertices[int(row["candide_vertex"])])
    return points


def main():
    out = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "docs/images/clone_triangulation.png"
    text = SOURCE.read_text()
    flat = ids(block(text, "kTriangles[]"))
    triangles = [flat[i : i + 3] for i in range(0, len(flat), 3)]
    required = ids(block(text, "kRequired[]"))
    upper, lower = ids(block(text, "kUpperLip[]")), ids(block(text, "kLowerLip[]"))
    nose, chin = ids(block(text, "kNoseSides[]")), ids(block(text, "kChinSides[]"))
    p = candide_points()

    fig, ax = plt.subplots(figsize=(8, 9.5))
    for tri in triangles:
        xs = [p[i][0] for i in tri + tri[:1]]
        ys = [p[i][1] for i in tri + tri[:1]]
        ax.fill(xs, ys, color="#dde8f5", edgecolor="#3a6ea5", linewidth=0.8)
    for contour, sides, colour, label in ((upper, nose, "#c0392b", "upper-lip region"),
                                          (lower, chin, "#27ae60", "lower-lip region")):
        poly = sorted(contour, key=lambda i: p[i][0]) + sorted(sides, key=lambda i: -p[i][0])
        xs = [p[i][0] for i in poly + poly[:1]]
        ys = [p[i][1] for i in poly + poly[:1]]
        ax.plot(xs, ys, color=colour, linewidth=1.6, linestyle="--", label=label)
    in_triangles = {i for tri in triangles for i in tri}
    for i in required:
        x, y = p[i][0], p[i][1]
        node = i in in_triangles
        ax.plot(x, y, "o" if node else "s", color="#1f3b5c" if node else "#8e44ad", markersize=4)
        ax.annotate(i, (x, y), textcoords="offset points", xytext=(3, 3), fontsize=7)
    ax.plot([], [], "o", color="#1f3b5c", markersize=4, label="triangulation point")
    ax.plot([], [], "s", color="#8e44ad", markersize=4, label="lip contour only")
    ax.set_aspect("equal")
    ax.set_title(f"Facial Motion Cloning: {len(triangles)} triangles over {len(in_triangles)} "
                 f"feature points\n(front view at CANDIDE-3's points; the face's left is +x)",
                 fontsize=10)
    ax.legend(loc="lower right", fontsize=8)
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)
    print(out)


if __name__ == "__main__":
    main()
