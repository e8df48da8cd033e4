#!/usr/bin/python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The cloning grid (docs/clone-grid.md): sources in rows, targets in columns, one block per
FAP or expression; the diagonal holds the sources themselves.

The clones are made by `mpeg4face clone`, the faces animated by `mpeg4face apply`, and drawn
with matplotlib (front orthographic view, Lambert shading, colour = how far each vertex
moves, relative to the largest motion in its block row).

usage: scripts/clone_grid.py [--cli build/dev/bin/mpeg4face] [--out docs/images/clone_grid.png]
                             [--work DIR] [--keep]
Needs Debian's python3-numpy and python3-matplotlib; run with /usr/bin/python3.
"""
import argparse
import base64
import json
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "tests" / "data"
CANDIDE_CSV = DATA / "candide3" / "feature_points.csv"
MAKEHUMAN_CSV = DATA / "makehuman" / "feature_points.csv"
VISIBLE_HELPERS = {"helper-l-eye", "helper-r-eye", "helper-upper-teeth", "helper-lower-teeth",
                   "helper-tongue"}

# The columns of the picture: (title, {FAP: value} sent alone in one frame; "expression" is
# FAP 2: (select, intensity)).
SHAPES = [
    ("open_jaw (FAP 3 = 700)", {3: 700}),
    ("stretch lip corners (FAP 6, 7 = 800)", {6: 800, 7: 800}),
    ("raise eyebrows (FAP 31-36 = 300)", {31: 300, 32: 300, 33: 300, 34: 300, 35: 300, 36: 300}),
    ("joy (expression 1 at 63)", {2: (1, 63)}),
]


def run(cli, *args):
    r = subprocess.run([str(cli), *map(str, args)], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"mpeg4face {' '.join(map(str, args))} failed:\n{r.stdout}{r.stderr}")
    return r.stdout


def read_wfm(path):
    """CANDIDE-3: vertices, triangles, and the MPEG-4 units {FAP: (fapu, [(vertex, d)])}."""
    lines = [l.strip() for l in path.read_text(encoding="latin-1").splitlines()]

    def section(title):
        i = lines.index(title) + 1
        while not lines[i] or lines[i].startswith("#"):
            i += 1
        return int(lines[i]), i + 1

    n, i = section("# VERTEX LIST:")
    vertices = np.array([[float(x) for x in lines[i + k].split()] for k in range(n)])
    n, i = section("# FACE LIST:")
    faces = np.array([[int(x) for x in lines[i + k].split()] for k in range(n)])
    count, i = section("# ANIMATION UNITS LIST:")
    units = {}
    for _ in range(count):
        while not lines[i].startswith("#"):
            i += 1
        comments = []
        while lines[i].startswith("#"):
            comments.append(lines[i][1:].strip())
            i += 1
        n = int(lines[i])
        rows = [lines[i + 1 + k].split() for k in range(n)]
        i += 1 + n
        named = [re.fullmatch(r"FAP\s*(\d+)\s+\w+", c) for c in comments]
        fapu = [c for c in comments if c in ("ES", "IRISD", "ENS", "MNS", "MW")]
        if any(named) and fapu:  # the MPEG-4 units with a linear FAPU (not the eyeballs)
            fap = int([m for m in named if m][-1].group(1))
            units[fap] = (fapu[0], [(int(r[0]), np.array(list(map(float, r[1:4])))) for r in rows])
    return vertices, faces, units


def write_gltf(path, vertices, faces, targets):
    """One mesh with morph targets {name: displacement array}, as .gltf with an embedded buffer."""
    chunks, views, accessors = [], [], []

    def add(array, target, kind, component, minmax=False):
        data = np.ascontiguousarray(array).tobytes()
        offset = sum(len(c) for c in chunks)
        chunks.append(data + b"\0" * (-len(data) % 4))
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(data), "target": target})
        acc = {"bufferView": len(views) - 1, "componentType": component, "count": len(array),
               "type": kind}
        if minmax:
            acc["min"] = array.min(axis=0).tolist()
            acc["max"] = array.max(axis=0).tolist()
        accessors.append(acc)
        return len(accessors) - 1

    position = add(vertices.astype(np.float32), 34962, "VEC3", 5126, True)
    indices = add(faces.astype(np.uint32).reshape(-1), 34963, "SCALAR", 5125)
    morph = [{"POSITION": add(d.astype(np.float32), 34962, "VEC3", 5126, True)}
             for d in targets.values()]
    blob = b"".join(chunks)
    mesh = {"name": "candide3",
            "primitives": [{"attributes": {"POSITION": position}, "indices": indices}]}
    if targets:
        mesh["weights"] = [0.0] * len(targets)
        mesh["extras"] = {"targetNames": list(targets)}
        mesh["primitives"][0]["targets"] = morph
    gltf = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"name": "candide3", "mesh": 0}],
        "meshes": [mesh],
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
        "bufferViews": views,
        "accessors": accessors,
    }
    path.write_text(json.dumps(gltf))


def candide_source(cli, work):
    """CANDIDE-3 with one shape key per MPEG-4 unit at +500 FAPU and a joy expression, turned
    into tables by `fat generate`."""
    vertices, faces, units = read_wfm(DATA / "candide3" / "candide3.wfm")
    info = json.loads(run(cli, "info", DATA / "candide3" / "candide3.wfm", "--feature-points",
                          CANDIDE_CSV, "--json"))
    unit = {name: value / 1024 for name, value in info["fapu"].items() if value}
    targets = {}
    for fap, (fapu, rows) in sorted(units.items()):
        d = np.zeros_like(vertices)
        for v, m in rows:
            d[v] += 500 * unit[fapu + "0"] * m
        targets[f"fap{fap}@500"] = d
    joy = sum(targets[f"fap{f}@500"] * w for f, w in [(12, 2.0), (13, 2.0), (6, 1.2), (7, 1.2),
                                                      (33, 0.6), (34, 0.6), (5, -0.4)])
    targets["expression1_joy"] = joy
    keys = work / "candide_keys.gltf"
    write_gltf(keys, vertices, faces, targets)
    face = work / "source_candide.wrl"
    run(cli, "fat", "generate", keys, "--feature-points", CANDIDE_CSV, "-o", face)
    return vertices, faces, face


def write_variant(path, vertices, faces):
    """CANDIDE-3 made wider and shorter, subdivided twice at edge midpoints (old vertex numbers
    kept, so CANDIDE's CSV binds it): a face of another shape and density. As glTF: an OBJ
    reader drops CANDIDE's unused vertices, and the numbers with them."""
    v = vertices * np.array([1.25, 0.9, 1.1])
    f = faces
    for _ in range(2):
        mid = {}
        verts = list(v)

        def m(a, b):
            key = (min(a, b), max(a, b))
            if key not in mid:
                mid[key] = len(verts)
                verts.append(0.5 * (verts[a] + verts[b]))
            return mid[key]

        out = []
        for a, b, c in f:
            ab, bc, ca = m(a, b), m(b, c), m(c, a)
            out += [(a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca)]
        v, f = np.array(verts), np.array(out)
    write_gltf(path, v, f, {})


def write_stream(path):
    """One frame per shape (its FAPs sent, the previous frame's set back to 0), then a neutral
    frame; returns the frame number of each shape, in SHAPES order. The visemes and
    expressions come first: values are held, and a low-level FAP held even at 0 has priority
    over them on the vertices it moves (docs/fat.md), so after the FAP frames joy's lip
    corners and brows would stay still."""
    order = sorted(range(len(SHAPES)), key=lambda k: not ({1, 2} & SHAPES[k][1].keys()))
    frames, previous = [], {}
    for _, values in [SHAPES[k] for k in order] + [("neutral", {})]:
        sent = {fap: (0 if fap != 2 else (1, 0)) for fap in previous}
        sent.update(values)
        frames.append(sent)
        previous = values
    lines = [f"2.1 clone_grid 25 {len(frames)}"]
    for n, sent in enumerate(frames):
        lines.append(" ".join("1" if fap in sent else "0" for fap in range(1, 69)))
        values = [str(n)]
        for fap in sorted(sent):
            if fap == 2:
                select, intensity = sent[fap]
                values += [str(select), str(intensity), "0", "0", "0", "0"]
            else:
                values.append(str(sent[fap]))
        lines.append(" ".join(values))
    path.write_text("\n".join(lines) + "\n")
    return [order.index(k) for k in range(len(SHAPES))]


def read_obj(path):
    """Vertices and triangles of an OBJ from `apply`, without MakeHuman's helper meshes (joints,
    tights, hair, eyelashes...) but with its eyes, teeth and tongue."""
    vertices, triangles, skip = [], [], False
    for line in path.read_text().splitlines():
        parts = line.split()
        if not parts:
            continue
        if parts[0] == "o" or parts[0] == "g":
            name = parts[1] if len(parts) > 1 else ""
            skip = name.startswith(("helper", "joint")) and name not in VISIBLE_HELPERS
        elif parts[0] == "v":
            vertices.append([float(x) for x in parts[1:4]])
        elif parts[0] == "f" and not skip:
            idx = [int(p.split("/")[0]) - 1 for p in parts[1:]]
            triangles += [(idx[0], idx[k], idx[k + 1]) for k in range(1, len(idx) - 1)]
    return np.array(vertices), np.array(triangles)


def feature_points(wrl):
    """The bound feature points of a face we wrote (FDP featurePointsCoord, docs/vrml.md)."""
    lines = wrl.read_text().splitlines()
    i = next(k for k, l in enumerate(lines) if "featurePointsCoord Coordinate" in l) + 2
    points = []
    while not lines[i].strip().startswith("]"):
        values, _, comment = lines[i].partition("#")
        if "none" not in comment:
            points.append([float(x) for x in values.replace(",", " ").split()])
        i += 1
    return np.array(points)


def draw(ax, vertices, triangles, motion, view, scale):
    from matplotlib import cm
    from matplotlib.collections import PolyCollection

    tri = vertices[triangles]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(normal, axis=1)
    keep = length > 0
    tri, normal, length = tri[keep], normal[keep], length[keep]
    moved = motion[triangles[keep]].mean(axis=1)
    normal /= length[:, None]
    light = np.array([0.35, 0.45, 1.0])
    shade = 0.25 + 0.75 * np.abs(normal @ (light / np.linalg.norm(light)))
    order = np.argsort(tri[:, :, 2].mean(axis=1))  # far first: painter's algorithm
    heat = cm.inferno(np.clip(moved / scale, 0, 1) * 0.85 + 0.1)[:, :3]
    skin = np.array([0.86, 0.80, 0.74])
    amount = np.clip(moved / scale, 0, 1)[:, None] ** 0.5
    colour = (skin * (1 - amount) + heat * amount) * shade[:, None]
    ax.add_collection(PolyCollection(tri[order][:, :, :2], facecolors=colour[order],
                                     edgecolors="none", antialiased=False))
    (x0, y0), (x1, y1) = view
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cli", default=ROOT / "build" / "dev" / "bin" / "mpeg4face", type=Path)
    parser.add_argument("--out", default=ROOT / "docs" / "images" / "clone_grid.png", type=Path)
    parser.add_argument("--work", type=Path, help="folder for the intermediate files")
    parser.add_argument("--keep", action="store_true", help="keep the intermediate files")
    args = parser.parse_args()
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    work = args.work or Path(tempfile.mkdtemp(prefix="clone_grid_"))
    work.mkdir(parents=True, exist_ok=True)
    cli = args.cli.resolve()

    vertices, faces, candide = candide_source(cli, work)
    variant = work / "candide_variant.gltf"
    write_variant(variant, vertices, faces)
    # (name, neutral model, its feature points, its source face .wrl or None)
    faces_ = [("CANDIDE-3", DATA / "candide3" / "candide3.wfm", CANDIDE_CSV, candide)]
    if MAKEHUMAN_CSV.exists():
        faces_.append(("MakeHuman", DATA / "makehuman" / "base.obj", MAKEHUMAN_CSV, None))
    faces_.append(("CANDIDE-3 wide, x16", variant, CANDIDE_CSV, None))
    # The other faces' own motion: cloned from CANDIDE-3 (the only face with sculpted units).
    for k, (name, model, csv, source) in enumerate(faces_):
        if source is None:
            out = work / f"source_{k}.wrl"
            print(f"source {name}: clone from CANDIDE-3", flush=True)
            run(cli, "clone", candide, model, "--target-feature-points", csv, "-o", out)
            faces_[k] = (name, model, csv, out)

    stream = work / "grid.fap"
    numbers = write_stream(stream) + [len(SHAPES)]  # the shapes', then the neutral frame
    n = len(faces_)
    # frames[i][j]: per shape the (vertices, triangles, motion) of source i cloned onto j.
    frames = [[None] * n for _ in range(n)]
    for i, (sname, _, _, source) in enumerate(faces_):
        for j, (tname, model, csv, own) in enumerate(faces_):
            face = own
            if i != j:
                face = work / f"clone_{i}_{j}.wrl"
                print(f"clone {sname} -> {tname}", flush=True)
                run(cli, "clone", source, model, "--target-feature-points", csv, "-o", face)
            objs = []
            for k in numbers:
                obj = work / f"frame_{i}_{j}_{k}.obj"
                run(cli, "apply", face, stream, "--frame", k, "-o", obj)
                objs.append(read_obj(obj))
            neutral = objs[-1][0]
            frames[i][j] = [(v, t, np.linalg.norm(v - neutral, axis=1)) for v, t in objs[:-1]]

    # The view of each target column: its feature points (the face, not a body below it).
    views = []
    for _, _, _, face in faces_:
        pts = feature_points(face)
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        # Widened, and lowered a little: the jaw opens below the chin point.
        centre, half = (lo + hi) / 2, (hi - lo)[:2].max() / 2 * 1.25
        centre[1] -= 0.1 * half
        views.append(((centre[0] - half, centre[1] - half), (centre[0] + half, centre[1] + half)))

    blocks = len(SHAPES)
    cols = 2
    rows = (blocks + cols - 1) // cols
    fig = plt.figure(figsize=(cols * n * 2.1 + 0.4, rows * (n * 2.1 + 0.6)), dpi=110)
    outer = fig.add_gridspec(rows, cols, wspace=0.06, hspace=0.12)
    for b, (title, _) in enumerate(SHAPES):
        inner = outer[b // cols, b % cols].subgridspec(n, n, wspace=0.02, hspace=0.02)
        for i in range(n):
            # One colour scale per source row and shape: the largest motion in that row.
            scale = max(frames[i][j][b][2].max() / (views[j][1][0] - views[j][0][0])
                        for j in range(n))
            for j in range(n):
                ax = fig.add_subplot(inner[i, j])
                v, t, m = frames[i][j][b]
                width = views[j][1][0] - views[j][0][0]
                draw(ax, v, t, m / width, views[j], scale)
                if i == j:
                    for spine in ax.spines.values():
                        spine.set_edgecolor("#1f77b4")
                        spine.set_linewidth(2.5)
                else:
                    for spine in ax.spines.values():
                        spine.set_visible(False)
                if i == 0:
                    ax.set_title(f"to {faces_[j][0]}", fontsize=8)
                if j == 0:
                    ax.set_ylabel(f"from {faces_[i][0]}", fontsize=8)
        fig.text(0, 0, "")  # keeps tight bbox stable
        top = inner[0, 0].get_position(fig)
        right = inner[0, n - 1].get_position(fig)
        fig.text((top.x0 + right.x1) / 2, top.y1 + 0.022, title, ha="center", fontsize=11,
                 weight="bold")
    fig.suptitle("Facial Motion Cloning: sources in rows, targets in columns (diagonal: the "
                 "source), colour = motion", fontsize=12)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, bbox_inches="tight")
    print(f"wrote {args.out}")
    if not args.work and not args.keep:
        shutil.rmtree(work)


if __name__ == "__main__":
    main()
