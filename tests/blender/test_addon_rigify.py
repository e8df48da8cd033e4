# SPDX-License-Identifier: GPL-3.0-or-later
"""Rigify's human meta-rig (its face bones) bound with automatic weights to the MakeHuman
head (the skin of samples/build_samples.py's head, made here from tests/data/makehuman),
posed to FAPs by "Pose FAPs with Bones": the jaw, lip corners, mid-lips, brows and eyelids
land within 5% of their amplitudes at their feature points, and the tables generated from
the posed rig export. Run through run_in_blender.py."""

import sys
from pathlib import Path

import numpy as np
import pytest

bpy = pytest.importorskip("bpy", reason="runs inside Blender only (see run_in_blender.py)")

import addon_utils  # noqa: E402
import mpeg4face  # noqa: E402
from mathutils import Vector  # noqa: E402

from mpeg4face_blender.logic import feature_points, shape_keys  # noqa: E402
from mpeg4face_blender.logic import rig as rig_logic  # noqa: E402
from mpeg4face_blender.scene import poses  # noqa: E402
from mpeg4face_blender.ui.operators import rig as operators_rig  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]

# Rigify ships with Blender as an add-on (in 4.2 and later a core add-on, still "rigify");
# a Blender without it cannot make the meta-rig.
pytestmark = pytest.mark.skipif(
    "rigify" not in {m.__name__ for m in addon_utils.modules()},
    reason="Rigify does not ship with this Blender")

AMPLITUDE = 256
# The acceptance's FAPs: jaw, lip corners, mid-lips, brows, eyelids.
FAPS = (3, 14, 15, 6, 7, 12, 13, 53, 54, 59, 60, 4, 5, 51, 52, 31, 32, 33, 34, 35, 36,
        19, 20, 21, 22)
# Meta-rig places (bone, "head"/"tail") and the feature points they sit at, for fitting the
# meta-rig's face to the head (a scale and an offset per axis).
LANDMARKS = {("lid.T.L.002", "head"): "3.1", ("lid.T.R.002", "head"): "3.2",
             ("lid.B.L.002", "head"): "3.3", ("lid.B.R.002", "head"): "3.4",
             ("lip.T.L.001", "tail"): "8.3", ("lip.T.R.001", "tail"): "8.4",
             ("lip.T.L", "head"): "8.1", ("lip.B.L", "head"): "8.2",
             ("chin", "head"): "2.1", ("nose.002", "head"): "9.3",
             ("brow.B.L.002", "head"): "4.3", ("brow.B.R.002", "head"): "4.4"}


def makehuman_skin():
    """The MakeHuman head's skin as a Blender mesh with its FP_ groups (standard axes to
    Blender's), and feature point -> vertex."""
    sys.path.insert(0, str(ROOT / "samples"))
    try:
        import build_samples
    finally:
        sys.path.remove(str(ROOT / "samples"))
    model = build_samples.makehuman_neutral()
    skin = model.meshes[0]
    offset = model.transforms[0].translation
    data = bpy.data.meshes.new("makehuman")
    data.from_pydata(feature_points.to_blender_axes(skin.coord + offset).tolist(), [],
                     skin.triangles().tolist())
    head = bpy.data.objects.new("makehuman", data)
    bpy.context.scene.collection.objects.link(head)
    fp_vertices = {fp: b.vertex for fp, b in model.feature_points.items() if b.mesh == 0}
    for fp, vertex in fp_vertices.items():
        head.vertex_groups.new(name=feature_points.group_name(fp)).add([vertex], 1.0, "REPLACE")
    return head, fp_vertices


def face_metarig(head, fp_vertices):
    """Rigify's human meta-rig cut to its face bones, fitted onto the head (per-axis scale
    and offset from LANDMARKS) and bound to it with automatic weights."""
    addon_utils.enable("rigify", default_set=True)
    bpy.ops.object.select_all(action="DESELECT")
    bpy.ops.object.armature_human_metarig_add()
    rig = bpy.context.active_object
    bpy.ops.object.mode_set(mode="EDIT")
    bones = rig.data.edit_bones
    face = bones["face"]
    keep = {face.name, *(b.name for b in face.children_recursive)}
    for bone in [b for b in bones if b.name not in keep]:
        bones.remove(bone)
    for bone in bones:  # free to slide, as the generated rig's face controls are
        bone.use_connect = False
    bpy.ops.object.mode_set(mode="OBJECT")
    coords = np.array([v.co[:] for v in head.data.vertices])
    places = np.array([getattr(rig.data.bones[b], f"{end}_local")[:]
                       for b, end in LANDMARKS])
    points = np.array([coords[fp_vertices[fp]] for fp in LANDMARKS.values()])
    scale, offset = np.zeros(3), np.zeros(3)
    for axis in range(3):
        scale[axis], offset[axis] = np.polyfit(places[:, axis], points[:, axis], 1)
    rig.scale, rig.location = Vector(scale), Vector(offset)
    bpy.ops.object.transform_apply(location=True, rotation=True, scale=True)
    head.select_set(True)
    rig.select_set(True)
    bpy.context.view_layer.objects.active = rig
    bpy.ops.object.parent_set(type="ARMATURE_AUTO")
    bpy.ops.object.select_all(action="DESELECT")
    head.select_set(True)
    bpy.context.view_layer.objects.active = head
    return rig


@pytest.fixture(scope="module")
def rigify_head():
    scene = bpy.context.scene
    scene.timeline_markers.clear()
    head, fp_vertices = makehuman_skin()
    rig = face_metarig(head, fp_vertices)
    yield head, rig, fp_vertices
    scene.timeline_markers.clear()
    for obj in (head, rig):
        bpy.data.objects.remove(obj)
    scene.frame_set(1)
    addon_utils.disable("rigify", default_set=True)


def landing(head, fp_vertices, frame, neutral, fap):
    """Where FAP's feature point is at the frame: its motion along the FAP's direction."""
    bpy.context.scene.frame_set(frame)
    coords = feature_points.to_standard_axes(
        poses.evaluated_coords(head, bpy.context.evaluated_depsgraph_get()))
    vertex = fp_vertices[mpeg4face.fap(fap).feature_point]
    return float((coords[vertex] - neutral[vertex]) @ rig_logic.fap_direction(fap))


def test_rigify_face_rig_posed_to_faps(rigify_head, tmp_path, capsys):
    head, rig, fp_vertices = rigify_head
    assert head.modifiers["Armature"].object == rig
    assert bpy.ops.mpeg4face.pose_faps_bones(amplitude=AMPLITUDE) == {"FINISHED"}
    report = operators_rig.pose_reports[head.name]
    with capsys.disabled():
        print("\n" + "\n".join(report.lines()))
    scene = bpy.context.scene
    markers = {m.name: m.frame for m in scene.timeline_markers}
    neutral_frame = markers[poses.NEUTRAL_MARKER]
    scene.frame_set(neutral_frame)
    neutral = feature_points.to_standard_axes(
        poses.evaluated_coords(head, bpy.context.evaluated_depsgraph_get()))
    faces = [i for p in head.data.polygons for i in (*p.vertices, -1)]
    fapu = mpeg4face.measure_fapu(
        feature_points.face_model_from_arrays(neutral, faces, fp_vertices))
    assert 0.1 < fapu.mns0.value < 0.6  # the head's mouth-nose separation (model units)
    missed = dict(report.missed)
    off = {}
    for fap in FAPS:
        if fap in missed:
            continue
        wanted = AMPLITUDE * fapu.unit(mpeg4face.fap(fap).fapu)  # the FAPU: distance / 1024
        got = landing(head, fp_vertices, markers[shape_keys.key_name("FAP", fap, AMPLITUDE)],
                      neutral, fap)
        if abs(got / wanted - 1.0) > 0.05:
            off[fap] = got / wanted
    assert not off, off
    assert not {f: missed[f] for f in FAPS if f in missed}  # every acceptance FAP posed

    # The tables from the posed rig: one per posed FAP, exported.
    glb = tmp_path / "rigify.glb"
    assert bpy.ops.mpeg4face.export_gltf(filepath=str(glb)) == {"FINISHED"}
    model = mpeg4face.read_gltf(glb)
    assert {int(t.name.split("_")[0][3:]) for t in model.meshes[0].morph_targets} == \
        {p.fap for p in report.posed}


def test_bad_mapping_is_reported(rigify_head, tmp_path):
    path = tmp_path / "map.json"
    path.write_text('{"3": {"bone": "jaw", "channel": "twist"}}')
    with pytest.raises(RuntimeError, match="map.json: FAP 3: channel must be location or "
                                           "rotation"):
        bpy.ops.mpeg4face.pose_faps_bones(mapping_file=str(path))
    path.write_text('{"31": "no_such_bone"}')
    with pytest.raises(RuntimeError, match="fap31 raise_l_i_eyebrow: metarig has no bone "
                                           "no_such_bone"):
        bpy.ops.mpeg4face.pose_faps_bones(mapping_file=str(path))
