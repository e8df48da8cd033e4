#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Draws what the motion check finds (docs/motion-check.md): the mouth of a head in its worst
key and its worst stream frame, front view, the neutral's edges in light blue under the
pose's in grey, the offending vertices in red.

    PYTHONPATH=build/release/python /usr/bin/python3 scripts/motion_check_figure.py \\
        samples/build/makehuman_head.glb --stream samples/build/streams/hello.fap \\
        -o docs/images/motion-check-makehuman.png

Needs python3-matplotlib."""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import mpeg4face  # noqa: E402


def worst(poses: list[dict]) -> dict | None:
    failed = [p for p in poses if p["failures"]]
    return max(failed, key=lambda p: (len(p["failures"]), p["edge_ratio_p99"]), default=None)


def pose_coords(model, face, stream, pose: dict, mesh: int) -> np.ndarray:
    neutral = model.meshes[mesh].coord
    if pose["stream"] < 0:
        for target in model.meshes[mesh].morph_targets:
            if target.name == pose["name"]:
                return neutral + target.displacements
        return neutral
    index = int(np.flatnonzero(stream.frame_numbers == pose["frame"])[0])
    return mpeg4face.FatEvaluator(face).evaluate(stream, index)["coord"][mesh]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("head")
    parser.add_argument("--stream")
    parser.add_argument("-o", "--output", required=True)
    args = parser.parse_args()
    model = mpeg4face.read_model(args.head)
    streams = [mpeg4face.read_fap_stream(args.stream)] if args.stream else []
    if streams:
        streams[0].name = Path(args.stream).name
    result = mpeg4face.check_motion(model, streams)
    face = mpeg4face.generate_face(model)["face"]
    lips = [model.feature_point_position(f"{g}.{i}") for g, n in ((2, 9), (8, 10))
            for i in range(2, n + 1)]
    lips = np.array([p for p in lips if p is not None])
    centre, half = lips.mean(axis=0), 0.9 * np.ptp(lips[:, 0])

    panels = [(p, kind) for p, kind in ((worst(result["keys"]), "key"),
                                        (worst(result["frames"]), "frame")) if p]
    fig, axes = plt.subplots(1, len(panels), figsize=(6 * len(panels), 5), squeeze=False)
    for ax, (pose, kind) in zip(axes[0], panels):
        motion = max(pose["meshes"], key=lambda m: len(m["offending_vertices"]))
        mesh = motion["mesh"]
        world = model.mesh_world_matrices()[mesh]
        tris = model.meshes[mesh].triangles().reshape(-1, 3)

        def to_world(c: np.ndarray) -> np.ndarray:
            return c @ world[:3, :3].T + world[:3, 3]

        rest = to_world(model.meshes[mesh].coord)
        tris = tris[rest[tris, 2].min(axis=1) > centre[2] - 0.3 * half]  # the front only
        moved = to_world(pose_coords(model, face, streams[0] if streams else None, pose, mesh))
        ax.triplot(rest[:, 0], rest[:, 1], tris, color="#9cc3e6", lw=0.4)
        ax.triplot(moved[:, 0], moved[:, 1], tris, color="0.35", lw=0.5)
        bad = motion["offending_vertices"]
        ax.plot(moved[bad, 0], moved[bad, 1], "o", color="red", ms=2.5)
        ax.set_xlim(centre[0] - half, centre[0] + half)
        ax.set_ylim(centre[1] - 0.75 * half, centre[1] + 0.75 * half)
        ax.set_aspect("equal")
        ax.set_xticks([]), ax.set_yticks([])
        ax.set_title(f"worst {kind}: {pose['name']}\n" + "\n".join(pose["failures"][:3]),
                     fontsize=8)
    fig.suptitle(f"{Path(args.head).name}: " + ("PASS" if result["passed"] else "FAIL") +
                 f" (lower lip under FAP 3: {result['lower_lip_share'] or 0:.0%} of the chin)",
                 fontsize=10)
    fig.tight_layout(rect=(0, 0, 1, 0.93))
    fig.savefig(args.output, dpi=110)
    print(f"wrote {args.output}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
