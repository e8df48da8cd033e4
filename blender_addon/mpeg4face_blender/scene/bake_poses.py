# SPDX-License-Identifier: GPL-3.0-or-later
"""Baking the poses a stream drives (eyes, head, the jaw's parts: FAPs 23-26, 48-50, 3 ...,
docs/fat.md "Poses") as object keyframes beside the shape-key animation, so that the bake
shows what the live preview shows: the core places each part (object_coordinates) at each scene
frame (sample and hold, as the live preview) and each object of the face is keyed where
the live preview shows it (location, rotation, scale, every frame of the stream).

An object parented other than to an object (to a bone, say) cannot be keyed this way: it
is named in the report instead."""

from __future__ import annotations

from dataclasses import dataclass, field

import bpy
import mpeg4face
import numpy as np
from mathutils import Matrix

from ..logic import live as live_logic
from ..logic import stream as stream_logic
from . import compat, poses
from .stream_data import ACTION_GROUP  # the group of the shape-key curves too


@dataclass
class PoseBake:
    """What key_poses() did: the FAPs shown by poses, the objects keyed, what it could not."""

    faps: list[int] = field(default_factory=list)
    keyed: list[str] = field(default_factory=list)
    problems: list[str] = field(default_factory=list)


def marker_faps(scene: bpy.types.Scene) -> set[int]:
    """The FAPs the scene's pose markers name."""
    out = set()
    for marker in poses.pose_markers(scene):
        try:
            parsed = mpeg4face.parse_shape_key_name(marker.name)
        except mpeg4face.Error:
            continue
        if parsed is not None:
            out.add(parsed["fap"])
    return out


def _blender(placement: np.ndarray) -> Matrix:
    """object_coordinates' placement (standard-axes coordinates in, Blender's out) as the
    matrix acting on Blender-axes coordinates."""
    out = np.array(placement, dtype=float)
    out[:3, :3] = out[:3, :3] @ live_logic.TO_BLENDER.T
    return Matrix(out.tolist())


def key_poses(head: bpy.types.Object, scene: bpy.types.Scene, key_names,
              stream: mpeg4face.FapStream, start: int, frames: int, fps: float) -> PoseBake:
    """Keys the head and its parts where the evaluated Transforms put them, at the scene
    frames start .. start + frames - 1, when the stream sends a FAP a pose marker names;
    earlier keys of those objects in that range are replaced, other keys stay."""
    out = PoseBake()
    active = np.asarray(stream.resolved()["active"]).any(axis=0)
    driven = sorted(f for f in marker_faps(scene) if active[f - 1])
    if not driven:
        return out
    objects = [head, *poses.parts(head)]
    model, _ = poses.read_posed_face_model(head, key_names, scene)
    evaluator = mpeg4face.FatEvaluator(mpeg4face.generate_face(model)["face"])
    was = scene.frame_current
    scene.frame_set(poses.neutral_frame(scene))
    worlds = [o.matrix_world.copy() for o in objects]
    scene.frame_set(was)

    # The live preview's chains and placements (live_preview.py): the core places each part.
    chains = [[0]] + [[0, i] for i in range(1, len(objects))]
    numbers = stream.frame_numbers
    placed: list[list[Matrix]] = [[] for _ in objects]  # world matrix per object per frame
    for k in range(frames):
        index = stream_logic.live_index(numbers, stream.frame_rate, k / fps)
        result = evaluator.object_coordinates(stream, index, chains, live_logic.TO_BLENDER)
        for i, placement in enumerate(result["placement"]):
            placed[i].append(worlds[i] @ _blender(placement))

    # Parents before children: a child's keys hold it where the live preview shows it
    # under its keyed parent.
    def depth(obj: bpy.types.Object) -> int:
        return 0 if obj.parent is None else 1 + depth(obj.parent)

    order = sorted(range(len(objects)), key=lambda i: depth(objects[i]))
    for i in order:
        obj = objects[i]
        parent = obj.parent
        inside = parent is not None and parent in objects
        bases = []
        for k in range(frames):
            if parent is None:
                bases.append(placed[i][k].copy())
                continue
            parent_world = placed[objects.index(parent)][k] if inside else parent.matrix_world
            bases.append((parent_world @ obj.matrix_parent_inverse).inverted() @ placed[i][k])
        if all(_close(b, obj.matrix_basis) for b in bases):
            continue  # it does not move
        if parent is not None and obj.parent_type != "OBJECT":
            out.problems.append(f"{obj.name}: parented to a {obj.parent_type.lower()}, its "
                                "pose is not baked (Live shows it)")
            continue
        _key(obj, bases, start)
        out.keyed.append(obj.name)
    out.faps = driven if out.keyed else []
    return out


def _close(a: Matrix, b: Matrix) -> bool:
    return max(abs(x - y) for ra, rb in zip(a, b) for x, y in zip(ra, rb)) < 1e-6


def _key(obj: bpy.types.Object, bases: list[Matrix], start: int) -> None:
    """Keys location, rotation (in the object's rotation mode) and scale of `bases` (one
    matrix_basis per frame from `start`), replacing keys in that range."""
    end = start + len(bases) - 1
    rotation = "rotation_quaternion" if obj.rotation_mode == "QUATERNION" else "rotation_euler"
    if obj.rotation_mode == "AXIS_ANGLE":
        obj.rotation_mode = "QUATERNION"
        rotation = "rotation_quaternion"
    paths = ("location", rotation, "scale")
    animation = obj.animation_data
    if animation is not None:
        for curve in compat.action_fcurves(animation):
            if curve.data_path in paths:
                for point in [p for p in curve.keyframe_points if start <= p.co.x <= end]:
                    curve.keyframe_points.remove(point, fast=True)
                curve.update()
    previous = None
    for offset, basis in enumerate(bases):
        location, quaternion, scale = basis.decompose()
        obj.location, obj.scale = location, scale
        if rotation == "rotation_quaternion":
            if previous is not None:
                quaternion.make_compatible(previous)
            obj.rotation_quaternion = previous = quaternion
        else:
            euler = quaternion.to_euler(obj.rotation_mode, *(() if previous is None
                                                            else (previous,)))
            obj.rotation_euler = previous = euler
        for path in paths:
            obj.keyframe_insert(path, frame=start + offset, group=ACTION_GROUP)
