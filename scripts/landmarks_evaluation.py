#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""How well `mpeg4face.find_feature_points` places each sample head's feature points with the
other sample head as template (docs/landmarks.md): the ICT head from the MakeHuman head and
the MakeHuman head from the ICT head, each as it is, turned (Z up, facing +X), rescaled
and moved, decimated to half its vertices and subdivided once. Prints, per point group, the
median, p90 and largest distance from the head's own points in % of its ES0, and the FAPU
against those from its own points; with --cloned also how the shapes cloned through the
points found differ from those cloned through the head's own.

    PYTHONPATH=build/release/python python3 scripts/landmarks_evaluation.py
"""

from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path

import mpeg4face
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "samples"))
import build_samples  # noqa: E402
import ict_head  # noqa: E402

GROUPS = {
    "lips": "2.2 2.3 2.4 2.5 2.6 2.7 2.8 2.9 8.1 8.2 8.3 8.4 8.5 8.6 8.7 8.8 8.9 8.10",
    "eyes": "3.1 3.2 3.3 3.4 3.5 3.6 3.7 3.8 3.9 3.10 3.11 3.12 3.13 3.14",
    "brows": "4.1 4.2 4.3 4.4 4.5 4.6",
    "nose": "9.1 9.2 9.3 9.4 9.5 9.6 9.7 9.12 9.13 9.14 9.15",
    "chin": "2.1 2.10 2.11 2.12 2.13 2.14",
    "cheeks": "5.1 5.2 5.3 5.4",
    "ears": "10.1 10.2 10.3 10.4 10.5 10.6 10.7 10.8 10.9 10.10",
    "head": "11.1 11.2 11.3 11.4 11.5 11.6 7.1 7.2",
    "mouth inside": "6.1 6.2 6.3 6.4 9.8 9.9 9.10 9.11",
}
# The named points: lip corners and contact points, outer lip mid points, eye
# corners, brow ends, nose tip and subnasale.
NAMED = "8.3 8.4 2.2 2.3 8.1 8.2 3.7 3.11 3.8 3.12 4.1 4.2 4.5 4.6 9.3 9.15".split()
# Z up and the face looking along +x: x <- z, y <- x, z <- y.
TURN = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])


@dataclass
class Case:
    name: str
    target: mpeg4face.FaceModel
    found: dict[str, np.ndarray]  # id -> position found
    truth: dict[str, np.ndarray]
    errors: dict[str, float]  # id -> distance in ES0 of the head's own points
    fapu: dict[str, float]  # FAPU name -> relative difference from the own points' FAPU
    seconds: float
    # id -> (the mesh found on, the mesh of the head's own point), for the points on a mesh
    # other than the face (eyes, teeth, tongue)
    parts: dict[str, tuple[str, str]]


def heads() -> dict[str, mpeg4face.FaceModel]:
    """The two samples with their own feature points, built in memory."""
    return {"ICT": ict_head.build(with_keys=False)[0],
            "MakeHuman": build_samples.makehuman_neutral()}


def moved(head: mpeg4face.FaceModel, linear: np.ndarray, shift: np.ndarray
          ) -> tuple[mpeg4face.FaceModel, dict[str, np.ndarray]]:
    """The head's meshes under `linear` and `shift` in model space, without feature points,
    and the true points moved the same way."""
    truth = {fp: np.asarray(head.feature_point_position(fp)) @ linear.T + shift
             for fp in head.feature_points}
    out = mpeg4face.FaceModel()
    for mesh, matrix in zip(head.meshes, head.mesh_world_matrices()):
        coord = mesh.coord @ matrix[:3, :3].T + matrix[:3, 3]
        out.add_mesh_with_transform(mpeg4face.IndexedFaceSet(
            mesh.name, coord @ linear.T + shift, mesh.coord_index))
    return out, truth


def evaluate(target: mpeg4face.FaceModel, truth: dict[str, np.ndarray],
             template: mpeg4face.FaceModel, name: str, own_meshes: dict[str, str]) -> Case:
    import time
    start = time.perf_counter()
    points, _ = mpeg4face.find_feature_points(target, template)
    seconds = time.perf_counter() - start
    found = mpeg4face.FaceModel(meshes=list(target.meshes), transforms=list(target.transforms),
                                roots=list(target.roots))
    found.feature_points = {fp: b for fp, (b, _, _) in points.items()}
    es0 = np.linalg.norm(truth["3.5"] - truth["3.6"])
    errors = {fp: float(np.linalg.norm(np.asarray(found.feature_point_position(fp)) - p)) / es0
              for fp, p in truth.items() if fp in points}
    own = mpeg4face.FaceModel(meshes=list(target.meshes), transforms=list(target.transforms),
                              roots=list(target.roots))
    own.feature_points = {fp: mpeg4face.FeaturePointBinding(position=p) for fp, p in truth.items()}
    a, b = mpeg4face.measure_fapu(found), mpeg4face.measure_fapu(own)
    # FAPU measure along y (MPEG-4's up): only a head in MPEG-4's axes has all five.
    fapu = {n: abs(getattr(a, n).value / getattr(b, n).value - 1)
            for n in ("es0", "irisd0", "ens0", "mns0", "mw0")
            if getattr(a, n).measured and getattr(b, n).measured}
    placed = {fp: np.asarray(found.feature_point_position(fp)) for fp in points}
    parts = {fp: (target.meshes[b.mesh].name if b.mesh >= 0 else "", mesh)
             for fp, mesh in own_meshes.items() if (b := points.get(fp, (None,))[0])}
    return Case(name, target, placed, truth, errors, fapu, seconds, parts)


def part_meshes(head: mpeg4face.FaceModel) -> dict[str, str]:
    """The head's points on a mesh other than its face (eyes, teeth, tongue): id -> mesh."""
    face = max(range(len(head.meshes)), key=lambda m: len(head.meshes[m].triangles()))
    return {fp: head.meshes[b.mesh].name for fp, b in head.feature_points.items()
            if b.mesh >= 0 and b.mesh != face}


def cases() -> list[Case]:
    h = heads()
    out = []
    for target, template in (("MakeHuman", "ICT"), ("ICT", "MakeHuman")):
        size = np.ptp(np.array([np.asarray(h[target].feature_point_position(fp))
                                for fp in h[target].feature_points]), axis=0).max()
        # As it is; turned, in centimetres if it was in metres (else in metres), moved onto
        # a body's height; remeshed: decimated to half its vertices, subdivided once (the
        # points stripped first, so that no true vertex is kept on purpose).
        scale = 100.0 if size < 1 else 0.01
        for label, linear, shift, remesh in (
                ("as it is", np.eye(3), np.zeros(3), None),
                ("turned, rescaled, moved", scale * TURN, scale * np.array([0.3, 1.6, -0.2]),
                 None),
                ("decimated to 50%", np.eye(3), np.zeros(3),
                 lambda m: mpeg4face.decimate_face_model(m, 0.5)),
                ("subdivided once", np.eye(3), np.zeros(3),
                 lambda m: mpeg4face.subdivide_face_model(m, 1))):
            head, truth = moved(h[target], linear, shift)
            if remesh is not None:
                head = remesh(head)
            out.append(evaluate(head, truth, h[template], f"{target} from {template}, {label}",
                                part_meshes(h[target])))
    return out


def stats(values: list[float]) -> tuple[float, float, float]:
    v = 100 * np.asarray(values)
    return float(np.median(v)), float(np.percentile(v, 90)), float(v.max())


def report(all_cases: list[Case]) -> str:
    lines = []
    for case in all_cases:
        lines.append(f"{case.name} ({case.seconds:.1f} s): % of ES0, median / p90 / max")
        for group, ids in [*GROUPS.items(), ("named points", " ".join(NAMED))]:
            values = [case.errors[i] for i in ids.split() if i in case.errors]
            if values:
                lines.append(f"  {group:14s} {len(values):3d}  %5.1f / %5.1f / %5.1f"
                             % stats(values))
        if case.fapu:
            lines.append("  FAPU off by " + ", ".join(f"{n.upper()} {100 * d:.1f}%"
                                                      for n, d in case.fapu.items()))
    return "\n".join(lines)


def cloned_difference(with_keys: mpeg4face.FaceModel) -> np.ndarray:
    """The MakeHuman head's FAP, viseme and expression shapes cloned from the ICT sample
    (`with_keys`: built with its keys) with the points found against those cloned with its
    own points: per shape, the p95 over the vertices of the difference in % of the shape's
    largest displacement (animate's acceptance in issue 42)."""
    source = build_samples.clone_source(with_keys)
    own = build_samples.makehuman_neutral()
    bare = mpeg4face.FaceModel(meshes=list(own.meshes), transforms=list(own.transforms),
                               roots=list(own.roots))
    points, _ = mpeg4face.find_feature_points(bare, with_keys)
    bare.feature_points = {fp: b for fp, (b, _, _) in points.items()}

    def motion(head: mpeg4face.FaceModel) -> dict[str, np.ndarray]:
        out = {}
        for copy in mpeg4face.clone_face(source, head)["copies"]:
            d = [np.zeros((m.vertex_count, 3)) for m in head.meshes]
            for moved in copy["meshes"]:
                d[moved["mesh"]][moved["vertices"]] = moved["displacement"]
            out[copy["name"]] = np.concatenate(d)
        return out

    truth, found = motion(own), motion(bare)
    out = []
    for name, d in truth.items():
        peak = np.linalg.norm(d, axis=1).max()
        if name in found and peak > 0:
            out.append(100 * np.percentile(np.linalg.norm(found[name] - d, axis=1), 95) / peak)
    return np.array(out)


def figure(all_cases: list[Case], path: Path) -> None:
    """Front views of the heads as they are: the skin's vertices, each head's own points
    (green) and the points found (red), joined where they differ."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    shown = [c for c in all_cases if c.name.endswith("as it is")]
    fig, axes = plt.subplots(1, len(shown), figsize=(6 * len(shown), 7))
    for ax, case in zip(np.atleast_1d(axes), shown):
        skin = case.target.meshes[0]
        front = skin.coord[:, 2] > np.percentile(skin.coord[:, 2], 35)
        ax.scatter(skin.coord[front, 0], skin.coord[front, 1], s=0.3, c="0.75")
        for fp, p in case.found.items():
            if fp not in case.truth or fp.startswith("7."):
                continue
            t = case.truth[fp]
            ax.plot([t[0], p[0]], [t[1], p[1]], c="k", lw=0.6)
            ax.scatter(*t[:2], s=14, c="tab:green")
            ax.scatter(*p[:2], s=14, c="tab:red")
            ax.annotate(fp, p[:2], fontsize=5)
        ax.set_title(f"{case.name}\ngreen: its own points, red: found", fontsize=9)
        ax.set_aspect("equal")
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(path, dpi=130)


if __name__ == "__main__":
    import argparse
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--figure", type=Path, help="also draw the points found (PNG)")
    parser.add_argument("--cloned", action="store_true",
                        help="also the MakeHuman head's cloned shapes, found points against "
                        "its own")
    args = parser.parse_args()
    results = cases()
    print(report(results))
    if args.cloned:
        import tempfile
        with tempfile.TemporaryDirectory() as out:
            ict_head.main(["--out", out])
            diff = cloned_difference(mpeg4face.read_gltf(Path(out) / "ict_head.glb"))
        print(f"MakeHuman's {len(diff)} shapes cloned from ICT, found points against its own: "
              f"p95 over vertices in % of the shape's peak, median {np.median(diff):.1f}, p90 "
              f"{np.percentile(diff, 90):.1f}, max {diff.max():.1f}; within 5%: "
              f"{np.mean(diff <= 5):.0%}")
    if args.figure:
        figure(results, args.figure)
