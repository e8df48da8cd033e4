# SPDX-License-Identifier: GPL-3.0-or-later
"""The motion check's result (mpeg4face.check_motion, docs/motion-check.md) as the "Motion
Check" panel shows it: a headline, the spikes, the worst keys and frames, and the vertices to
select. bpy-free, so plain pytest can test it."""

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
    """As `mpeg4face check` ranks: limits passed, then edge ratio, then flips, intersections
    and spikes."""
    return (len(pose["failures"]), pose["edge_ratio_p99"],
            pose["normal_flips"] + pose["new_self_intersections"] + pose["spikes"])


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


def spikes(result: Result) -> str | None:
    """"Spikes: 3 keys, 12 frames; worst 1.62 x the local motion (fap6 ...)", or None when no
    pose has a spike vertex (a vertex moved apart from its neighbours)."""
    keys = sum(1 for p in result["keys"] if p["spikes"])
    frames = sum(1 for p in result["frames"] if p["spikes"])
    if not keys and not frames:
        return None
    poses = [p for p in (*result["keys"], *result["frames"]) if p["spikes"]]
    worst_pose = max(poses, key=lambda p: (p["bump_ratio_max"], p["spikes"]))
    counts = [f"{keys} {'key' if keys == 1 else 'keys'}"] if keys else []
    if frames:
        counts.append(f"{frames} {'frame' if frames == 1 else 'frames'}")
    return (f"Spikes: {', '.join(counts)}; worst {worst_pose['bump_ratio_max']:.2f} x the local "
            f"motion ({worst_pose['name']}, {worst_pose['spikes']} "
            f"{'vertex' if worst_pose['spikes'] == 1 else 'vertices'})")


def _mesh_vertices(result: Result, kind: str, index: int, mesh: int, field: str) -> list[int]:
    """`field` of mesh `mesh` in pose `index` of `kind`; [] when the pose is not there (a
    result from before an edit)."""
    poses = result.get(kind, ())
    if not 0 <= index < len(poses):
        return []
    for motion in poses[index]["meshes"]:
        if motion["mesh"] == mesh:
            return [int(v) for v in motion[field]]
    return []


def spike_vertices(result: Result, kind: str, index: int, mesh: int = 0) -> list[int]:
    """The spike vertices of mesh `mesh` in pose `index` of `kind` (also among its
    offending_vertices)."""
    return _mesh_vertices(result, kind, index, mesh, "spike_vertices")


def offending_vertices(result: Result, kind: str, index: int, mesh: int = 0) -> list[int]:
    """The vertices of mesh `mesh` that pose `index` of `kind` stretches, flips, makes
    intersect or moves as spikes."""
    return _mesh_vertices(result, kind, index, mesh, "offending_vertices")
