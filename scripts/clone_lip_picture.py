#!/usr/bin/python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Before / after picture of CANDIDE-3's lip keys cloned onto the MakeHuman head (docs/clone.md).

The keys are cloned as samples/build_samples.py clones them, with whichever build of the
Python module is on PYTHONPATH; run `keys` once per build, then `plot` both:

    PYTHONPATH=OLD/build/release/python /usr/bin/python3 scripts/clone_lip_picture.py keys before.npz
    PYTHONPATH=build/release/python /usr/bin/python3 scripts/clone_lip_picture.py keys after.npz
    /usr/bin/python3 scripts/clone_lip_picture.py plot before.npz after.npz docs/images/clone_lip_keys.png
"""
import pathlib
import sys

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
KEYS = {6: "FAP 6 stretch_l_cornerlip", 3: "FAP 3 open_jaw"}  # fap -> row label
WINDOW = ("9.15", "2.1", "8.3", "8.4")  # the picture spans these feature points


def keys(out: pathlib.Path) -> None:
    sys.path.insert(0, str(ROOT / "samples"))
    import build_samples  # noqa: E402 (needs mpeg4face on PYTHONPATH)

    head = build_samples.makehuman_neutral()
    cloned = build_samples.cloned_keys(build_samples.candide3(), head)
    skin = head.meshes[0]
    triangles = []
    face = []
    for corner in skin.coord_index:
        if corner >= 0:
            face.append(int(corner))
            continue
        triangles += [(face[0], face[k], face[k + 1]) for k in range(1, len(face) - 1)]
        face = []
    motion = {}
    for name, displacement in cloned.items():
        fap = int(name[3:name.index("_")]) if name.startswith("fap") else 0
        if fap in KEYS and fap not in motion:
            motion[fap] = displacement[0]
    points = {i: head.feature_points[i].vertex for i in WINDOW}
    np.savez(out, coord=skin.coord, triangles=np.array(triangles),
             faps=np.array(sorted(motion)), motion=np.array([motion[f] for f in sorted(motion)]),
             window=np.array([points[i] for i in WINDOW]))


def draw(ax, coord: np.ndarray, triangles: np.ndarray, box: tuple[float, ...]) -> None:
    """Front view (x, y), Lambert-shaded, far triangles first, edges drawn thin."""
    from matplotlib.collections import PolyCollection

    corners = coord[triangles]
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True) + 1e-30
    light = np.array([-0.3, 0.4, 1.0]) / np.linalg.norm([-0.3, 0.4, 1.0])
    shade = np.clip(np.abs(normal @ light), 0.05, 1.0)
    centre = corners.mean(axis=1)
    x0, x1, y0, y1 = box
    keep = (centre[:, 0] > x0) & (centre[:, 0] < x1) & (centre[:, 1] > y0) & (centre[:, 1] < y1)
    keep &= normal[:, 2] > -0.2  # the front of the face
    order = np.argsort(centre[keep, 2])
    polygons = corners[keep][order][:, :, :2]
    colours = np.outer(shade[keep][order], [0.93, 0.78, 0.68])
    ax.add_collection(PolyCollection(polygons, facecolors=colours, edgecolors=(0, 0, 0, 0.25),
                                     linewidths=0.15))
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])


def plot(before: pathlib.Path, after: pathlib.Path, out: pathlib.Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    runs = [np.load(before), np.load(after)]
    coord, triangles = runs[1]["coord"], runs[1]["triangles"]
    nose, chin, left, right = coord[runs[1]["window"]]
    margin = 0.35 * (left[0] - right[0])
    box = (right[0] - margin, left[0] + margin, chin[1] - 0.1 * margin, nose[1] + 0.3 * margin)
    faps = list(runs[1]["faps"])
    fig, axes = plt.subplots(len(faps), 2, figsize=(7, 3.2 * len(faps)), dpi=80)
    for row, fap in enumerate(faps):
        for col, (run, title) in enumerate(zip(runs, ("before", "after"))):
            motion = run["motion"][list(run["faps"]).index(fap)]
            draw(axes[row, col], coord + motion, triangles, box)
            axes[row, col].set_title(f"{KEYS[int(fap)]}: {title}", fontsize=9)
    fig.tight_layout()
    fig.savefig(out)


if __name__ == "__main__":
    if sys.argv[1:2] == ["keys"]:
        keys(pathlib.Path(sys.argv[2]))
    elif sys.argv[1:2] == ["plot"]:
        plot(*map(pathlib.Path, sys.argv[2:5]))
    else:
        sys.exit(__doc__)
