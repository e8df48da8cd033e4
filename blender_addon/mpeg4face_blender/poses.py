# SPDX-License-Identifier: GPL-3.0-or-later
"""A head with its parts and poses as one FaceModel, for the FaceDefTables and the export.

The parts are the mesh objects below the head in the hierarchy (eyes, teeth, tongue;
through armatures and bones too), each a Transform of the head holding its mesh. A pose is
a timeline marker named in the shape-key grammar (`fap23_yaw_l_eyeball@100000`,
`fap48_head_pitch@-20000`, `fap3_open_jaw@512`): at the marker's frame the head and its
parts are where the animation (objects, bones, constraints) puts them, and the core reads
that as a pose of the Transforms (docs/fat.md, "Poses"). The neutral face is the frame of
the marker named "neutral", else the scene's start frame. A pose and shape keys of the same
name are one deformed copy, as the jaw opens the skin and lowers the teeth."""

from __future__ import annotations

from collections.abc import Callable, Iterable

import bpy
import mpeg4face
from mathutils import Matrix

from . import mesh_data

NEUTRAL_MARKER = "neutral"
# Blender's Z-up axes to the standard's Y-up ones, (x, y, z) -> (x, z, -y), as for vertices.
_TO_STANDARD = Matrix(((1, 0, 0, 0), (0, 0, 1, 0), (0, -1, 0, 0), (0, 0, 0, 1)))
_GRAMMAR_PREFIXES = ("fap", "viseme", "expression")


def parts(head: bpy.types.Object) -> list[bpy.types.Object]:
    """The mesh objects below the head, by name."""
    return sorted((o for o in head.children_recursive if o.type == "MESH"), key=lambda o: o.name)


def pose_markers(scene: bpy.types.Scene) -> list[bpy.types.TimelineMarker]:
    """The markers that name a pose: ours or meant to be (a malformed one is the core's
    error, with the grammar), by frame."""
    return sorted((m for m in scene.timeline_markers
                   if m.name.lower().startswith(_GRAMMAR_PREFIXES)), key=lambda m: m.frame)


def neutral_frame(scene: bpy.types.Scene) -> int:
    marker = next((m for m in scene.timeline_markers if m.name.lower() == NEUTRAL_MARKER), None)
    return scene.frame_start if marker is None else marker.frame


def _standard(matrix: Matrix) -> Matrix:
    return _TO_STANDARD @ matrix @ _TO_STANDARD.inverted()


def _fields(matrix: Matrix) -> tuple[list[float], list[float], list[float]]:
    """Translation, rotation (quaternion x y z w, as glTF) and scale of a standard matrix."""
    translation, rotation, scale = _standard(matrix).decompose()
    return list(translation), [rotation.x, rotation.y, rotation.z, rotation.w], list(scale)


def _pose_channels(matrices: list[Matrix]) -> list[mpeg4face.TransformChannel]:
    """One-key channels putting each Transform (by index) at its matrix."""
    Path = mpeg4face.TransformChannel.Path
    channels = []
    for index, matrix in enumerate(matrices):
        for path, values in zip((Path.TRANSLATION, Path.ROTATION, Path.SCALE), _fields(matrix)):
            channels.append(mpeg4face.TransformChannel(index, path, times=[0.0], values=values))
    return channels


def face_model(head: bpy.types.Object, key_names: Callable[[bpy.types.Object], Iterable[str]],
               scene: bpy.types.Scene) -> tuple[mpeg4face.FaceModel, list[str]]:
    """The head and its parts (meshes, feature points, the shape keys key_names(object)
    gives) with the pose markers as animations; and the warnings about FP_ groups. The
    scene's frame is back where it was afterwards."""
    objects = [head, *parts(head)]
    meshes, bindings, warnings = [], {}, []
    for index, obj in enumerate(objects):
        coords, faces, fp_vertices, group_warnings = mesh_data.mesh_and_points(obj)
        mesh = mpeg4face.IndexedFaceSet(obj.name, coords, faces)
        mesh.morph_targets = [
            mpeg4face.MorphTarget(name, d)
            for name, d in mesh_data.shape_key_displacements(obj, key_names(obj)).items()]
        meshes.append(mesh)
        warnings += [w if obj is head else f"{obj.name}: {w}" for w in group_warnings]
        for fp, vertex in sorted(fp_vertices.items()):
            if fp in bindings:
                first = objects[bindings[fp].mesh].name
                warnings.append(f"FP_{fp} is on {first} and {obj.name}: {first}'s is used")
                continue
            bindings[fp] = mpeg4face.FeaturePointBinding(index, vertex)

    def transform_matrices(neutral_head: Matrix) -> list[Matrix]:
        """At the current frame: the head's matrix from its neutral one, and each part's
        from the head's."""
        now = head.matrix_world
        return [neutral_head.inverted() @ now] + [now.inverted() @ o.matrix_world
                                                 for o in objects[1:]]

    was = scene.frame_current, scene.frame_subframe
    try:
        scene.frame_set(neutral_frame(scene))
        neutral_head = head.matrix_world.copy()
        # The head is its own neutral: exactly the identity, not a float32 round trip.
        neutral = [Matrix.Identity(4), *transform_matrices(neutral_head)[1:]]
        posed = []
        for marker in pose_markers(scene):
            scene.frame_set(marker.frame)
            posed.append((marker.name, transform_matrices(neutral_head)))
    finally:
        scene.frame_set(was[0], subframe=was[1])

    transforms = []
    for index, (obj, matrix) in enumerate(zip(objects, neutral)):
        translation, rotation, scale = _fields(matrix)
        transforms.append(mpeg4face.Transform(
            obj.name, translation=translation, rotation=rotation, scale=scale, meshes=[index],
            children=list(range(1, len(objects))) if index == 0 else []))
    animations = [mpeg4face.MorphWeightAnimation(name, transform_channels=_pose_channels(m))
                  for name, m in posed]
    model = mpeg4face.FaceModel(meshes=meshes, transforms=transforms, roots=[0],
                                feature_points=bindings, animations=animations)
    return model, warnings
