# SPDX-License-Identifier: GPL-3.0-or-later
"""A head with its parts and poses as one FaceModel, for the FaceDefTables and the export.

The parts are the mesh objects below the head in the hierarchy (eyes, teeth, tongue;
through armatures and bones too), each a Transform of the head holding its mesh. A pose is
a timeline marker named in the shape-key grammar (`fap23_yaw_l_eyeball@100000`,
`fap48_head_pitch@-20000`, `fap3_open_jaw@512`): at the marker's frame the head and its
parts are where the animation (objects, bones, constraints) puts them, and the core reads
that as a pose of the Transforms (docs/fat.md, "Poses"). The neutral face is the frame of
the marker named "neutral", else the scene's start frame. A pose and shape keys of the same
name are one deformed copy, as the jaw opens the skin and lowers the teeth.

A rigged head's skin moves too: at the neutral marker and at each pose marker every mesh of
the face is evaluated through its modifier stack (armature skinning, shape keys set by
drivers or animation: correctives) by the depsgraph, and the evaluated mesh at a marker
minus the evaluated neutral is that marker's deformed copy (added to a shape key of the
same name, if any). Shape keys that are not the rig's (grammar keys, keys without a driver
or animation) are muted meanwhile, so a slider left up does not leak in. A modifier that
changes the vertex count is refused (rig_logic.topology_message)."""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager

import bpy
import mpeg4face
import numpy as np
from mathutils import Matrix

from ..logic import feature_points, shape_keys
from ..logic import rig as rig_logic
from . import compat, mesh_data

NEUTRAL_MARKER = "neutral"
# Blender's Z-up axes to the standard's Y-up ones, (x, y, z) -> (x, z, -y), as for vertices.
_TO_STANDARD = Matrix(((1, 0, 0, 0), (0, 0, 1, 0), (0, -1, 0, 0), (0, 0, 0, 1)))
_GRAMMAR_PREFIXES = ("fap", "viseme", "expression")


def parts(head: bpy.types.Object) -> list[bpy.types.Object]:
    """The mesh objects below the head, by name."""
    return sorted((o for o in head.children_recursive if o.type == "MESH"), key=lambda o: o.name)


def pose_markers(scene: bpy.types.Scene, head: bpy.types.Object | None = None
                 ) -> list[bpy.types.TimelineMarker]:
    """The markers that name a pose: ours or meant to be (a malformed one is the core's
    error, with the grammar), by frame: the scene's, and with `head` the pose markers of
    the actions of the armatures deforming its face (a pose library's named frames; a
    scene marker of the same name wins)."""
    markers = {m.name: m for m in _rig_action_markers(head)} if head is not None else {}
    markers.update((m.name, m) for m in scene.timeline_markers)
    return sorted((m for m in markers.values() if m.name.lower().startswith(_GRAMMAR_PREFIXES)),
                  key=lambda m: m.frame)


def _rig_action_markers(head: bpy.types.Object) -> list[bpy.types.TimelineMarker]:
    out = []
    for obj in (head, *parts(head)):
        for modifier in obj.modifiers:
            rig = modifier.object if modifier.type == "ARMATURE" else None
            animation = rig.animation_data if rig is not None else None
            if animation is not None and animation.action is not None:
                out += list(animation.action.pose_markers)
    return out


def neutral_frame(scene: bpy.types.Scene) -> int:
    marker = next((m for m in scene.timeline_markers if m.name.lower() == NEUTRAL_MARKER), None)
    return scene.frame_start if marker is None else marker.frame


class RigError(mpeg4face.Error):
    """A rig the FaceDefTables cannot take; the message says why and what to do."""


def check_armatures(objects: Iterable[bpy.types.Object]) -> None:
    """Refuses an Armature modifier (enabled in the viewport) without its armature."""
    for obj in objects:
        for modifier in obj.modifiers:
            if modifier.type == "ARMATURE" and modifier.show_viewport \
                    and modifier.object is None:
                raise RigError(rig_logic.missing_armature_message(obj.name, modifier.name))


@contextmanager
def rig_only(objects: Iterable[bpy.types.Object],
             key_names: Callable[[bpy.types.Object], Iterable[str]]) -> Iterator[None]:
    """Inside: the shape keys that are not the rig's muted (the grammar keys key_names
    gives, and keys no driver or action sets) and show_only_shape_key off, so the evaluated
    mesh is the Basis moved by the rig alone; as they were afterwards."""
    saved = []
    try:
        for obj in objects:
            key = obj.data.shape_keys
            if key is None:
                continue
            saved.append((obj, obj.show_only_shape_key, [(b, b.mute) for b in key.key_blocks]))
            obj.show_only_shape_key = False
            paths = []
            if key.animation_data is not None:
                paths = [d.data_path for d in key.animation_data.drivers]
                paths += [c.data_path for c in compat.action_fcurves(key.animation_data)]
            animated = rig_logic.animated_key_names(paths)
            grammar = {n for n in key_names(obj) if shape_keys.parse(n) is not None}
            for block in key.key_blocks:
                if block != key.reference_key and (block.name in grammar
                                                   or block.name not in animated):
                    block.mute = True
        yield
    finally:
        for obj, only, mutes in saved:
            obj.show_only_shape_key = only
            for block, mute in mutes:
                block.mute = mute


_SUSPENDED = "mpeg4face_suspended_modifiers"  # saved with the file, as the live key is


def suspend_rig(obj: bpy.types.Object) -> None:
    """Turns the object's deform modifiers (the rig: Armature, ...) off in the viewport,
    remembering which in the object, while something else shows the rig's motion (the live
    preview's key, which is the evaluated tables)."""
    names = [m.name for m in obj.modifiers
             if m.show_viewport and m.type in rig_logic.DEFORM_MODIFIERS]
    for name in names:
        obj.modifiers[name].show_viewport = False
    if names:
        obj[_SUSPENDED] = names


def resume_rig(obj: bpy.types.Object) -> None:
    """Turns the modifiers suspend_rig turned off back on."""
    for name in obj.get(_SUSPENDED, ()):
        modifier = obj.modifiers.get(name)
        if modifier is not None:
            modifier.show_viewport = True
    if _SUSPENDED in obj:
        del obj[_SUSPENDED]


def evaluated_coords(obj: bpy.types.Object, depsgraph: bpy.types.Depsgraph) -> np.ndarray:
    """The object's vertices through its modifier stack (object space, Blender's axes);
    RigError when the stack changes the vertex count."""
    evaluated = obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    try:
        count = len(mesh.vertices)
        if count != len(obj.data.vertices):
            raise RigError(rig_logic.topology_message(
                obj.name, len(obj.data.vertices), count,
                [(m.name, m.type) for m in obj.modifiers if m.show_viewport]))
        co = np.empty(count * 3, dtype=np.float32)
        mesh.vertices.foreach_get("co", co)
    finally:
        evaluated.to_mesh_clear()
    return co.reshape(-1, 3).astype(np.float64)


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


def read_posed_face_model(head: bpy.types.Object,
                          key_names: Callable[[bpy.types.Object], Iterable[str]],
                          scene: bpy.types.Scene,
                          progress: Callable[[float], None] | None = None,
                          wanted: Callable[[str], bool] | None = None
                          ) -> tuple[mpeg4face.FaceModel, list[str]]:
    """The head and its parts (meshes as the rig has them at the neutral marker, feature
    points, the shape keys key_names(object) gives plus the rig's deformed copies at the
    pose markers) with the pose markers as animations; and the warnings about FP_ groups.
    With `wanted`, only the shape keys and pose markers whose names it accepts become
    targets and poses (the live preview: those of its stream's FAPs); key_names still says
    which keys are the grammar's, muted while the rig is read. progress(fraction) follows
    the markers. The scene's frame and the shape keys' mutes are back as they were
    afterwards; RigError (an mpeg4face.Error) for a rig refused."""
    objects = [head, *parts(head)]
    check_armatures(objects)
    wanted = wanted or (lambda _name: True)
    markers = [m for m in pose_markers(scene, head) if wanted(m.name)]

    def transform_matrices(neutral_head: Matrix) -> list[Matrix]:
        """At the current frame: the head's matrix from its neutral one, and each part's
        from the head's."""
        now = head.matrix_world
        return [neutral_head.inverted() @ now] + [now.inverted() @ o.matrix_world
                                                 for o in objects[1:]]

    was = scene.frame_current, scene.frame_subframe
    try:
        with rig_only(objects, key_names):
            scene.frame_set(neutral_frame(scene))
            depsgraph = bpy.context.evaluated_depsgraph_get()
            neutral_head = head.matrix_world.copy()
            # The head is its own neutral: exactly the identity, not a float32 round trip.
            neutral = [Matrix.Identity(4), *transform_matrices(neutral_head)[1:]]
            neutral_coords = [evaluated_coords(o, depsgraph) for o in objects]
            posed, deformed = [], []
            for done, marker in enumerate(markers, 1):
                scene.frame_set(marker.frame)
                posed.append((marker.name, transform_matrices(neutral_head)))
                deformed.append([evaluated_coords(o, depsgraph) - c
                                 for o, c in zip(objects, neutral_coords)])
                if progress is not None:
                    progress(done / len(markers))
    finally:
        scene.frame_set(was[0], subframe=was[1])

    size = float(np.linalg.norm(np.ptp(neutral_coords[0], axis=0)))
    meshes, bindings, warnings = [], {}, []
    fp_objects: dict[str, tuple[str, int]] = {}
    for index, obj in enumerate(objects):
        _, faces, fp_vertices, group_warnings = mesh_data.mesh_and_points(obj)
        targets = mesh_data.shape_key_displacements(obj, filter(wanted, key_names(obj)))
        for (name, _), copies in zip(posed, deformed):
            if rig_logic.moves(copies[index], size):
                d = feature_points.to_standard_axes(copies[index])
                targets[name] = targets[name] + d if name in targets else d
        mesh = mpeg4face.IndexedFaceSet(obj.name, feature_points.to_standard_axes(
            neutral_coords[index]), faces)
        mesh.morph_targets = [mpeg4face.MorphTarget(name, d) for name, d in targets.items()]
        meshes.append(mesh)
        warnings += [w if obj is head else f"{obj.name}: {w}" for w in group_warnings]
        for fp, vertex in sorted(fp_vertices.items()):
            if fp in bindings:
                first = objects[bindings[fp].mesh].name
                warnings.append(f"FP_{fp} is on {first} and {obj.name}: {first}'s is used")
                continue
            bindings[fp] = mpeg4face.FeaturePointBinding(index, vertex)
            fp_objects[fp] = (obj.name, vertex)
    _check_feature_points_move(objects, key_names, posed, deformed, fp_objects, size)

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


def _check_feature_points_move(objects, key_names, posed, deformed, fp_objects, size) -> None:
    """RigError for a pose marker whose rig moves the skin but not its FAP's feature point
    (unless a shape key of the marker's name moves it)."""
    keyed = {n for o in objects for n in key_names(o)}
    for (name, _), copies in zip(posed, deformed):
        if name in keyed:
            continue
        parsed = shape_keys.parse(name)
        fp = mpeg4face.fap(parsed["fap"]).feature_point \
            if parsed is not None and parsed["fap"] >= shape_keys.FIRST_LOW_LEVEL_FAP else ""
        point = (fp, *fp_objects[fp]) if fp in fp_objects else None
        moved = {o.name: c for o, c in zip(objects, copies) if rig_logic.moves(c, size)}
        message = rig_logic.unmoved_feature_point_message(name, moved, point)
        if message is not None:
            raise RigError(message)


def head_model(head: bpy.types.Object, key_names: Callable[[bpy.types.Object], Iterable[str]],
               scene: bpy.types.Scene) -> tuple[mpeg4face.FaceModel, list[str]]:
    """The head alone as read_posed_face_model sees it (its mesh at the neutral marker, its
    shape keys and the rig's deformed copies as morph targets, its feature points), for
    cloning."""
    model, warnings = read_posed_face_model(head, key_names, scene)
    mesh = model.meshes[0]
    fp_vertices = {fp: b.vertex for fp, b in model.feature_points.items() if b.mesh == 0}
    return feature_points.face_model_from_arrays(mesh.coord, mesh.coord_index, fp_vertices,
                               {t.name: t.displacements for t in mesh.morph_targets}), warnings
