# SPDX-License-Identifier: GPL-3.0-or-later
"""The motion check's result (mpeg4face.check_motion, docs/motion-check.md) as the "Motion
Check" panel shows it: a headline, the worst keys and frames, and the vertices to select.
bpy-free, so plain pytest can test it."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

Result = Mapping[str, Any]  # what mpeg4face.check_motion returns
WORST = 5  # rows per list in the panel


@dataclass(frozen=True)
class Row:
    kind: str  # "keys" or "frames"
    index: int  # into result[kind]
    name: str
    text: str  # the limits passed, e.g. "edge ratio p99 3.10 > 2"


def _badness(pose: Mapping[str, Any]) -> tuple[int, float, int]:
    """As `mpeg4face check` ranks: limits passed, then edge ratio, then flips and
    intersections."""
    return (len(pose["failures"]), pose["edge_ratio_p99"],
            pose["normal_flips"] + pose["new_self_intersections"])


def worst(result: Result, kind: str, count: int = WORST) -> list[Row]:
    """The `count` worst poses of `kind` ("keys" or "frames") past a limit, worst first."""
    poses: Sequence[Mapping[str, Any]] = result[kind]
    failed = [i for i, pose in enumerate(poses) if pose["failures"]]
    failed.sort(key=lambda i: _badness(poses[i]), reverse=True)
    return [Row(kind, i, poses[i]["name"], "; ".join(poses[i]["failures"]))
            for i in failed[:count]]


def headline(result: Result) -> str:
    """"FAIL: 3 of 73 keys, 40 of 190 frames past the limits" (or PASS)."""
    keys = sum(1 for p in result["keys"] if p["failures"])
    frames = sum(1 for p in result["frames"] if p["failures"])
    verdict = "PASS" if result["passed"] else "FAIL"
    text = f"{verdict}: {keys} of {len(result['keys'])} keys"
    if result["frames"]:
        text += f", {frames} of {len(result['frames'])} frames"
    return text + " past the limits"


def offending_vertices(result: Result, kind: str, index: int, mesh: int = 0) -> list[int]:
    """The vertices of mesh `mesh` that pose `index` of `kind` stretches, flips or makes
    intersect; [] when the pose is not there (a result from before an edit)."""
    poses = result.get(kind, ())
    if not 0 <= index < len(poses):
        return []
    for motion in poses[index]["meshes"]:
        if motion["mesh"] == mesh:
            return [int(v) for v in motion["offending_vertices"]]
    return []
