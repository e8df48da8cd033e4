# SPDX-License-Identifier: GPL-3.0-or-later
"""Builds samples/build/makehuman_head.blend from makehuman_head.glb (and ict_head.blend from
ict_head.glb), in the form the add-on
works with (docs/blender.md): the skin as the head object, the eyelashes, eyes, teeth and
tongue as its child objects, the feature points as FP_ vertex groups, every morph target as
a shape key, and every pose as a timeline marker at whose frame the parts are keyed where
the pose puts them (the "neutral" marker first). Materials, a camera and a light make it
ready to render.

    blender -b --factory-startup --python-exit-code 1 --python samples/make_blend.py -- \\
        samples/build/makehuman_head.glb samples/build/makehuman_head.blend [--name NAME]

NAME is the head object's (default "MakeHuman head").
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import blender_session  # noqa: E402

ARGS = blender_session.start()

import bpy  # noqa: E402
import mpeg4face  # noqa: E402
import numpy as np  # noqa: E402
from mathutils import Euler, Matrix, Quaternion, Vector  # noqa: E402
from mpeg4face_blender.logic import feature_points  # noqa: E402
from mpeg4face_blender.scene import poses  # noqa: E402

NEUTRAL_FRAME = 1000  # poses after it, out of the way of an animation from frame 1
COLOURS = {  # mesh -> base colour (linear RGB), roughness
    "skin": ((0.80, 0.55, 0.45), 0.55),
    "eyelashes": ((0.03, 0.02, 0.02), 0.8),
    "eye": ((0.90, 0.90, 0.88), 0.15),
    "iris": ((0.10, 0.06, 0.03), 0.15),
    "teeth": ((0.90, 0.88, 0.80), 0.3),
    "tongue": ((0.65, 0.25, 0.25), 0.5),
    "gums": ((0.65, 0.25, 0.25), 0.5),  # ICT's gums and tongue are one mesh
}


def blender_matrix(translation, rotation, scale) -> Matrix:
    """A Transform's standard (Y-up) fields as a Blender (Z-up) matrix."""
    x, y, z, w = rotation
    standard = Matrix.LocRotScale(Vector(translation), Quaternion((w, x, y, z)), Vector(scale))
    to_standard = poses._TO_STANDARD  # noqa: SLF001 (the add-on's axis change, inverted here)
    return to_standard.inverted() @ standard @ to_standard


def material(name: str) -> bpy.types.Material:
    colour, roughness = COLOURS[name]
    mat = bpy.data.materials.get(name) or bpy.data.materials.new(name)
    mat.diffuse_color = (*colour, 1.0)  # Workbench's material colour
    mat.roughness = roughness
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*colour, 1.0)
    bsdf.inputs["Roughness"].default_value = roughness
    return mat


def mesh_object(mesh: mpeg4face.IndexedFaceSet, name: str) -> bpy.types.Object:
    """The mesh with its morph targets as shape keys (coordinates in the object's frame)."""
    data = bpy.data.meshes.new(name)
    faces = np.split(mesh.coord_index, np.flatnonzero(mesh.coord_index == -1) + 1)
    data.from_pydata(feature_points.to_blender_axes(mesh.coord).tolist(), [],
                     [f[:-1].tolist() for f in faces if len(f) > 1])
    data.polygons.foreach_set("use_smooth", [True] * len(data.polygons))
    obj = bpy.data.objects.new(name, data)
    bpy.context.scene.collection.objects.link(obj)
    if mesh.morph_targets:
        obj.shape_key_add(name="Basis", from_mix=False)
        basis = feature_points.to_blender_axes(mesh.coord)
        for target in mesh.morph_targets:
            block = obj.shape_key_add(name=target.name, from_mix=False)
            block.data.foreach_set(
                "co", (basis + feature_points.to_blender_axes(target.displacements)).ravel())
    kind = next((k for k in COLOURS if mesh.name.startswith(k)), "skin")
    obj.data.materials.append(material(kind))
    if kind == "eye":  # the iris: the faces at the front of the eyeball
        obj.data.materials.append(material("iris"))
        ys = np.array([v.co.y for v in data.vertices])
        front = ys.min() + 0.25 * (ys.max() - ys.min())  # -y is forward in Blender
        for polygon in data.polygons:
            if max(data.vertices[i].co.y for i in polygon.vertices) < front:
                polygon.material_index = 1
    return obj


def build(model: mpeg4face.FaceModel, head_name: str) -> bpy.types.Object:
    head_transform = model.find_transform("head")
    objects: dict[int, bpy.types.Object] = {}  # mesh index -> object
    for t_index, transform in enumerate(model.transforms):
        for m_index in transform.meshes:
            mesh = model.meshes[m_index]
            is_skin = t_index == head_transform and m_index == transform.meshes[0]
            objects[m_index] = mesh_object(mesh, head_name if is_skin else mesh.name)
    head = objects[model.transforms[head_transform].meshes[0]]
    for t_index, transform in enumerate(model.transforms):
        local = blender_matrix(transform.translation, transform.rotation, transform.scale)
        for m_index in transform.meshes:
            obj = objects[m_index]
            if obj is head:
                obj.matrix_world = local
            else:
                obj.parent = head
                obj.matrix_parent_inverse = Matrix.Identity(4)
                obj.matrix_basis = Matrix.Identity(4) if t_index == head_transform else local
    for fp, binding in model.feature_points.items():
        if binding.vertex >= 0:  # 7.1 / 7.2 are free coordinates: Blender has no place for them
            group = objects[binding.mesh].vertex_groups.new(name=feature_points.group_name(fp))
            group.add([binding.vertex], 1.0, "REPLACE")
    add_poses(model, objects)
    return head


def add_poses(model: mpeg4face.FaceModel, objects: dict[int, bpy.types.Object]) -> None:
    """Each pose a marker; at its frame every object of a Transform is keyed (CONSTANT), at
    the pose's value where the pose has one, else at the neutral value."""
    scene = bpy.context.scene
    movable = {t: objects[tr.meshes[0]] for t, tr in enumerate(model.transforms)}
    neutral = {t: (tr.translation, tr.rotation, tr.scale) for t, tr in enumerate(model.transforms)}
    Path = mpeg4face.TransformChannel.Path
    frames = [(poses.NEUTRAL_MARKER, {})]
    for animation in model.animations:
        values: dict[int, list] = {}
        for channel in animation.transform_channels:
            fields = list(values.get(channel.transform, neutral[channel.transform]))
            width = 4 if channel.path == Path.ROTATION else 3
            slot = {Path.TRANSLATION: 0, Path.ROTATION: 1, Path.SCALE: 2}[channel.path]
            fields[slot] = channel.values[-width:]  # the pose is the last key's value
            values[channel.transform] = tuple(fields)
        frames.append((animation.name, values))
    for offset, (name, values) in enumerate(frames):
        frame = NEUTRAL_FRAME + offset
        scene.timeline_markers.new(name, frame=frame)
        for t, obj in movable.items():
            obj.rotation_mode = "QUATERNION"
            obj.matrix_basis = blender_matrix(*values.get(t, neutral[t]))  # local to the head
            for path in ("location", "rotation_quaternion", "scale"):
                obj.keyframe_insert(path, frame=frame)
    for obj in movable.values():
        for curve in obj.animation_data.action.fcurves:
            for point in curve.keyframe_points:
                point.interpolation = "CONSTANT"
    scene.frame_set(NEUTRAL_FRAME)


def ready(head: bpy.types.Object, height: float) -> None:
    """The file as a user first sees it: at frame 1 (the poses' frames from 1000 are out of
    the animation's way), the head the active, selected object (the add-on's panels work
    on it), and every 3D view looking at the face from the front, closer than the camera,
    so the camera's wireframe is behind the view, not over the face."""
    scene = bpy.context.scene
    scene.frame_set(1)
    for obj in scene.objects:
        obj.select_set(obj == head)
    bpy.context.view_layer.objects.active = head
    centre = head.matrix_world @ (sum((Vector(c) for c in head.bound_box), Vector()) / 8)
    for screen in bpy.data.screens:
        for area in screen.areas:
            for space in area.spaces:
                if space.type == "VIEW_3D":
                    view = space.region_3d
                    view.view_perspective = "PERSP"
                    view.view_location = centre
                    view.view_rotation = Euler((math.radians(90), 0, 0)).to_quaternion()
                    view.view_distance = height * 1.6


def stage(head: bpy.types.Object, model: mpeg4face.FaceModel) -> None:
    """A camera looking at the face from the front, slightly from the side and above, a key
    light and a fill, and Workbench set up to show the materials."""
    scene = bpy.context.scene
    top, chin = model.feature_point_position("11.4"), model.feature_point_position("2.1")
    # Aimed a little below the middle of skull top and chin (the mouth matters most), close
    # enough for the face to fill the frame.
    middle = (0.0, chin[1] + 0.45 * (top[1] - chin[1]), chin[2])
    centre = Vector(feature_points.to_blender_axes(middle)[0])
    height = top[1] - chin[1]
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(camera)
    camera.data.lens = 85
    distance = height * 2.5
    # Its wireframe (display_size long) stays behind the 3D views' eye (ready(): 1.6 heights).
    camera.data.display_size = 0.3 * height
    direction = Vector((0.25, -1.0, 0.12)).normalized()
    camera.location = centre + direction * distance
    camera.rotation_euler = (-direction).to_track_quat("-Z", "Y").to_euler()
    scene.camera = camera
    for name, energy, rotation in (("Key", 3.0, (math.radians(50), 0, math.radians(30))),
                                   ("Fill", 1.0, (math.radians(70), 0, math.radians(-50)))):
        light = bpy.data.objects.new(name, bpy.data.lights.new(name, "SUN"))
        light.data.energy = energy
        light.rotation_euler = rotation
        scene.collection.objects.link(light)
    scene.render.engine = "BLENDER_WORKBENCH"
    scene.display.shading.light = "STUDIO"
    scene.display.shading.color_type = "MATERIAL"
    scene.display.shading.show_cavity = True
    scene.render.resolution_x = scene.render.resolution_y = 540
    scene.frame_start, scene.frame_end = 1, 100


def main() -> None:
    parser = argparse.ArgumentParser(prog="make_blend.py")
    parser.add_argument("source", type=Path, help="HEAD.glb")
    parser.add_argument("out", type=Path, help="OUT.blend")
    parser.add_argument("--name", default="MakeHuman head", help="the head object's name")
    args = parser.parse_args(ARGS)
    source, out = args.source, args.out.resolve()
    bpy.ops.wm.read_factory_settings(use_empty=True)
    model = mpeg4face.read_gltf(source)
    head = build(model, args.name)
    stage(head, model)
    top, chin = model.feature_point_position("11.4"), model.feature_point_position("2.1")
    ready(head, top[1] - chin[1])
    part = out.with_name(out.name + ".part.blend")
    bpy.ops.wm.save_as_mainfile(filepath=str(part), compress=True)
    part.replace(out)
    print(f"make_blend: {out}: {len(bpy.data.objects)} objects, "
          f"{len(head.data.shape_keys.key_blocks) - 1} shape keys on the head, "
          f"{len(bpy.context.scene.timeline_markers)} markers")


main()
