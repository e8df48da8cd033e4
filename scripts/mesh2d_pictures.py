#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The pictures of docs/mesh2d.md, made with the CLI and matplotlib.

Usage: PYTHONPATH=BUILD_DIR/python scripts/mesh2d_pictures.py BUILD_DIR OUT_DIR [DEMO_OUT]
Draws a cartoon portrait (its feature points known by construction), designs meshes on it,
makes it talk with an Xface FAP stream (tests/data/xface-fap/joy.fap) through `mpeg4face
mesh2d portrait`, and draws contact sheets: the uniform topology codes, the traversal order, the designed meshes,
the portrait's frames with their mesh; the mesh built from the text of the paper's Fig. 24
(test_mesh2d's TraversalMatchesTheTextOfFig24). With DEMO_OUT (scripts/demo.sh's output), the
demo's MakeHuman portrait: its mesh, and frames of the sentence.
"""
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import Ellipse  # noqa: E402

import mpeg4face  # noqa: E402  (PYTHONPATH=BUILD_DIR/python)

ROOT = Path(__file__).resolve().parent.parent
W, H = 320, 400

# Feature points of the cartoon face, pixels, y down (the face's left is the image's right).
FEATURE_POINTS = {
    "2.1": (160, 352), "2.2": (160, 283), "2.3": (160, 297), "2.4": (196, 290), "2.5": (124, 290),
    "2.6": (178, 285), "2.7": (142, 285), "2.8": (178, 296), "2.9": (142, 296),
    "8.1": (160, 276), "8.2": (160, 306), "8.3": (202, 290), "8.4": (118, 290),
    "3.1": (206, 160), "3.2": (114, 160), "3.3": (206, 176), "3.4": (114, 176),
    "3.5": (206, 168), "3.6": (114, 168), "4.1": (186, 134), "4.2": (134, 134),
    "4.3": (208, 128), "4.4": (112, 128), "4.5": (230, 136), "4.6": (90, 136),
    "9.15": (160, 240), "2.10": (160, 330), "5.1": (236, 250), "5.2": (84, 250),
}


def draw_portrait(path: Path) -> None:
    fig = plt.figure(figsize=(W / 100, H / 100), dpi=100)
    ax = fig.add_axes([0, 0, 1, 1])
    ax.set_xlim(0, W)
    ax.set_ylim(H, 0)
    ax.axis("off")
    ax.add_patch(plt.Rectangle((0, 0), W, H, color="#7fa7c9"))
    for i in range(0, W, 16):  # a patterned background, so motion would show
        ax.plot([i, i + 60], [0, H], color="#6f97b9", lw=2)
    ax.add_patch(Ellipse((160, 230), 190, 270, color="#e8b896"))
    ax.add_patch(Ellipse((160, 120), 200, 110, color="#4a3020"))
    for x in (114, 206):
        ax.add_patch(Ellipse((x, 168), 40, 20, color="white"))
        ax.add_patch(Ellipse((x, 168), 14, 14, color="#3a5a2a"))
        ax.add_patch(Ellipse((x, 168), 6, 6, color="black"))
    for a, b in (("4.6", "4.4"), ("4.4", "4.2"), ("4.1", "4.3"), ("4.3", "4.5")):
        (x0, y0), (x1, y1) = FEATURE_POINTS[a], FEATURE_POINTS[b]
        ax.plot([x0, x1], [y0, y1], color="#3a2010", lw=5, solid_capstyle="round")
    ax.plot([160, 150, 170], [190, 240, 240], color="#c08870", lw=3)
    ax.add_patch(Ellipse((160, 290), 84, 30, color="#b0484a"))
    ax.plot([118, 160, 202], [290, 292, 290], color="#601010", lw=2)
    fig.savefig(path, dpi=100)
    plt.close(fig)


def cli(build: Path, *args: str) -> None:
    subprocess.run([str(build / "bin" / "mpeg4face"), "mesh2d", *args], check=True)


def draw_mesh(ax, nodes, triangles, color="k", lw=0.6):
    for t in triangles:
        xs = [nodes[i][0] for i in t] + [nodes[t[0]][0]]
        ys = [nodes[i][1] for i in t] + [nodes[t[0]][1]]
        ax.plot(xs, ys, color=color, lw=lw)


def main() -> None:
    build, out = Path(sys.argv[1]), Path(sys.argv[2])
    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp_name:
        tmp = Path(tmp_name)
        portrait = tmp / "portrait.png"
        draw_portrait(portrait)
        csv = tmp / "fp.csv"
        csv.write_text("fp,x,y\n" + "".join(f"{k},{x},{y}\n" for k, (x, y) in FEATURE_POINTS.items()))
        # Uniform topology codes (Fig. 20).
        fig, axes = plt.subplots(1, 4, figsize=(12, 3))
        for code, ax in enumerate(axes):
            cli(build, "design", str(portrait), "--uniform", "4x3", "--topology", str(code),
                "-o", str(tmp / f"u{code}.json"))
            mesh = json.loads((tmp / f"u{code}.json").read_text())
            draw_mesh(ax, mesh["frames"][0], mesh["triangles"], lw=1)
            ax.set_title(f"topology code {code:02b}")
            ax.set_aspect("equal")
            ax.invert_yaxis()
            ax.axis("off")
        fig.tight_layout()
        fig.savefig(out / "mesh2d_uniform_codes.png", dpi=80)
        plt.close(fig)
        # The breadth-first traversal (section 3.3.2.1) on a small designed mesh.
        cli(build, "design", str(portrait), "--delaunay", "24", "-o", str(tmp / "small.json"))
        small = mpeg4face.read_mesh2d(tmp / "small.json")
        traversal = mpeg4face.mesh2d_traversal(small)
        nodes = small["frames"][0]
        fig, ax = plt.subplots(figsize=(5, 6))
        draw_mesh(ax, nodes, small["triangles"], color="0.6", lw=0.8)
        for label, (l, m, n) in enumerate(traversal["vertices"]):
            ax.plot(*zip(nodes[l], nodes[m]), color="tab:red", lw=1.5)  # base edge
            centre = (nodes[l] + nodes[m] + nodes[n]) / 3
            ax.text(*centre, str(label), ha="center", va="center", fontsize=8, color="tab:red")
        for order, n in enumerate(traversal["node_order"]):
            ax.text(*nodes[n], str(order), fontsize=8, ha="center", va="center",
                    bbox=dict(boxstyle="square,pad=0.15", fc="white", ec="tab:blue"))
        ax.set_title("triangle labels (red, base edges) and node order (boxes)", fontsize=9)
        ax.set_aspect("equal")
        ax.invert_yaxis()
        ax.axis("off")
        fig.tight_layout()
        fig.savefig(out / "mesh2d_traversal.png", dpi=80)
        plt.close(fig)
        # Designed meshes and the portrait's.
        cli(build, "design", str(portrait), "--delaunay", "250", "-o", str(tmp / "d.json"))
        image = plt.imread(portrait)
        stream = ROOT / "tests/data/xface-fap/joy.fap"
        cli(build, "portrait", str(portrait), "--feature-points", str(csv), str(stream),
            "-o", str(tmp / "frames"))
        # The mesh the portrait used: rebuilt the same way by encode/decode of its plane 0.
        frames = sorted((tmp / "frames").glob("frame_*.png"))
        picks = [0, 20, 45, 70, 100]
        fig, axes = plt.subplots(1, 2 + len(picks), figsize=(3 * (2 + len(picks)), 4))
        d = json.loads((tmp / "d.json").read_text())
        axes[0].imshow(image)
        draw_mesh(axes[0], d["frames"][0], d["triangles"], color="yellow", lw=0.5)
        axes[0].set_title("design --delaunay 250")
        axes[1].imshow(image)
        xs, ys = zip(*FEATURE_POINTS.values())
        axes[1].scatter(xs, ys, s=8, c="red")
        axes[1].set_title("feature points")
        for ax, k in zip(axes[2:], picks):
            ax.imshow(plt.imread(frames[min(k, len(frames) - 1)]))
            ax.set_title(f"joy.fap frame {k}")
        for ax in axes:
            ax.axis("off")
        fig.tight_layout()
        fig.savefig(out / "mesh2d_portrait.png", dpi=80)
        plt.close(fig)
        # Close-ups of the mouth: neutral and the widest frame.
        fig, axes = plt.subplots(1, len(picks), figsize=(2.6 * len(picks), 2))
        for ax, k in zip(axes, picks):
            ax.imshow(plt.imread(frames[min(k, len(frames) - 1)])[220:340, 80:240])
            ax.set_title(f"frame {k}")
            ax.axis("off")
        fig.tight_layout()
        fig.savefig(out / "mesh2d_portrait_mouth.png", dpi=80)
        plt.close(fig)
    draw_fig24_text(out / "mesh2d_fig24_text.png")
    if len(sys.argv) > 3:
        draw_demo_portrait(Path(sys.argv[3]) / "portrait", out / "mesh2d_makehuman_portrait.png")


def draw_fig24_text(path: Path) -> None:
    """test_mesh2d's mesh for the text of Fig. 24, after five labels: triangle 3 current."""
    names = "ABEJHIGCDF"
    nodes = [(0, 0), (4, 0), (6, 3), (7, 6), (4, 7), (1.5, 7.5), (0, 7), (3, 2), (2, 4), (0.5, 5)]
    mesh = {"width": 10, "height": 10, "mesh": "delaunay", "boundary": 7, "frames": [nodes]}
    traversal = mpeg4face.mesh2d_traversal(mesh)
    triangles = mpeg4face.mesh2d_triangles(mesh)
    fig, ax = plt.subplots(figsize=(5, 5))
    draw_mesh(ax, nodes, triangles, color="0.6", lw=0.8)
    for label, (l, m, n) in enumerate(traversal["vertices"][:7]):
        centre = [sum(nodes[i][k] for i in (l, m, n)) / 3 for k in (0, 1)]
        ax.text(*centre, str(label), ha="center", va="center", fontsize=11,
                color="tab:red" if label < 5 else "tab:orange")
    l, m, n = traversal["vertices"][3]
    for (a, b), name in (((l, m), "b"), ((l, n), "r"), ((m, n), "l")):
        ax.plot(*zip(nodes[a], nodes[b]), color="tab:red", lw=2)
        ax.text((nodes[a][0] + nodes[b][0]) / 2 + 0.15, (nodes[a][1] + nodes[b][1]) / 2, name,
                fontsize=11, color="tab:red", fontweight="bold")
    for order, i in enumerate(traversal["node_order"][:6]):
        ax.text(*nodes[i], f"{names[i]} {order}", fontsize=9, ha="center", va="center",
                bbox=dict(boxstyle="square,pad=0.15", fc="white", ec="tab:blue"))
    for i in traversal["node_order"][6:]:
        ax.text(*nodes[i], names[i], fontsize=9, ha="center", va="center", color="0.4")
    ax.set_title("built from the text of Fig. 24 (not its drawing): labels 0-4 set,\n"
                 "3 current (b, r, l), 5 and 6 next (orange); nodes coded so far boxed",
                 fontsize=9)
    ax.set_aspect("equal")
    ax.invert_yaxis()
    ax.axis("off")
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def draw_demo_portrait(folder: Path, path: Path) -> None:
    """The demo's portrait: its mesh and feature points, then frames of the sentence."""
    image = plt.imread(folder / "portrait.png")
    sequence = mpeg4face.read_mesh2d(folder / "portrait.json")
    frames = sequence["frames"]
    # The widest-open mouth, then a few frames across the sentence.
    opening = (frames - frames[0])[:, :, 1].max(axis=1)
    picks = [int(opening.argmax()), 30, 75, 140]
    crop = (slice(215, 515), slice(120, 420))
    with tempfile.TemporaryDirectory() as tmp_name:
        rendered = Path(tmp_name)
        mpeg4face.render_mesh2d(folder / "portrait.png",
                                dict(sequence, frames=frames[[0, *picks]]), rendered)
        shots = [plt.imread(f) for f in sorted(rendered.glob("frame_*.png"))]
    fig, axes = plt.subplots(1, 2 + len(picks), figsize=(2.6 * (2 + len(picks)), 2.8))
    points = [line.split(",") for line in (folder / "feature_points.csv").read_text().split()[1:]]
    axes[0].imshow(image[crop])
    shift = [[x - crop[1].start, y - crop[0].start] for x, y in frames[0]]
    draw_mesh(axes[0], shift, sequence["triangles"], color="yellow", lw=0.4)
    axes[0].scatter([float(x) - crop[1].start for _, x, _ in points],
                    [float(y) - crop[0].start for _, _, y in points], s=5, c="red", zorder=3)
    axes[0].set_xlim(0, 300)
    axes[0].set_ylim(300, 0)
    axes[0].set_title("mesh, feature points", fontsize=9)
    axes[1].imshow(shots[1][crop])
    moved = [[x - crop[1].start, y - crop[0].start] for x, y in frames[picks[0]]]
    draw_mesh(axes[1], moved, sequence["triangles"], color="yellow", lw=0.4)
    axes[1].set_xlim(0, 300)
    axes[1].set_ylim(300, 0)
    axes[1].set_title(f"frame {picks[0]}, its mesh", fontsize=9)
    for ax, k, shot in zip(axes[2:], picks, shots[1:]):
        ax.imshow(shot[crop])
        ax.set_title(f"frame {k}", fontsize=9)
    for ax in axes:
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


if __name__ == "__main__":
    main()
