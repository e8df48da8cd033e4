# SPDX-License-Identifier: GPL-3.0-or-later
"""Eyes, jaw and head as object transforms: CANDIDE-3 with an eye and teeth as child
objects, posed by keyframes at timeline markers named in the shape-key grammar; the
FaceDefTables get FaceDefTransforms that the exported face follows. Run through
run_in_blender.py."""

import math

import numpy as np
import pytest

bpy = pytest.importorskip("bpy", reason="runs inside Blender only (see run_in_blender.py)")

import mpeg4face  # noqa: E402

from mpeg4face_blender.scene import poses  # noqa: E402
from mpeg4face_blender.ui.operators import faces as operators_faces  # noqa: E402

EYE_TURN = 0.3  # radians about Blender's Z (the standard's Y) at fap23@100000
HEAD_TURN = 0.2  # radians at fap49@20000
TEETH_DROP = 0.02  # Blender -Z at fap3@512


def part(head, name, location):
    """A small tetrahedron parented to the head."""
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([(0, 0, 0), (0.01, 0, 0), (0, 0.01, 0), (0, 0, 0.01)], [],
                     [(0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)])
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    obj.parent = head
    obj.location = location
    return obj


def pose(obj, frame, path, value):
    setattr(obj, path, value)
    obj.keyframe_insert(path, frame=frame)


@pytest.fixture
def posed_head(candide_head):
    """The head with a left eye and teeth; markers neutral (1), fap23 (10), fap3 (20, also
    a shape key dropping the chin), fap49 (30); the scene at frame 5 (a frame no pose is at)."""
    head, _, fp_vertices = candide_head
    scene = bpy.context.scene
    eye = part(head, "eye_l", (0.1, -0.05, 0.2))
    teeth = part(head, "teeth", (0.0, -0.05, -0.15))
    markers = {"neutral": 1, "fap23_yaw_l_eyeball@100000": 10, "fap3_open_jaw@512": 20,
               "fap49_head_yaw@20000": 30}
    for name, frame in markers.items():
        scene.timeline_markers.new(name, frame=frame)
    for frame in markers.values():
        pose(eye, frame, "rotation_euler", (0, 0, EYE_TURN if frame == 10 else 0))
        pose(teeth, frame, "location", (0, -0.05, -0.15 - (TEETH_DROP if frame == 20 else 0)))
        pose(head, frame, "rotation_euler", (0, 0, HEAD_TURN if frame == 30 else 0))
    bpy.context.view_layer.objects.active = head
    assert bpy.ops.mpeg4face.add_fap_shape_key(fap="3", amplitude=512) == {"FINISHED"}
    key = head.data.shape_keys.key_blocks["fap3_open_jaw@512"]
    key.data[fp_vertices["2.1"]].co.z -= 0.05
    scene.frame_set(5)
    yield head, eye, teeth
    for obj in (eye, teeth):
        bpy.data.objects.remove(obj)
    scene.timeline_markers.clear()
    head.animation_data_clear()
    scene.frame_set(1)


def rotation_about_y(quaternion):
    """The angle of a quaternion (x, y, z, w) that turns about the standard's +Y."""
    x, y, z, w = quaternion
    assert abs(x) < 1e-6 and abs(z) < 1e-6, quaternion
    return 2 * math.atan2(y, w)


def test_poses_become_face_def_transforms(posed_head, tmp_path):
    head, eye, teeth = posed_head
    assert poses.parts(head) == [eye, teeth]
    assert bpy.ops.mpeg4face.generate_tables() == {"FINISHED"}
    assert bpy.context.scene.frame_current == 5  # back where the user was
    report = operators_faces.table_reports[head.name]
    tables = dict(zip(report.covered, zip(report.moved, report.transforms)))
    assert tables["fap23 yaw_l_eyeball"] == (0, 1)  # the eye turns, nothing else
    assert tables["fap49 head_yaw"] == (0, 1)  # the head's transform
    moved, transforms = tables["fap3 open_jaw"]  # the key and the pose: one copy
    assert moved >= 1 and transforms == 1
    assert report.copies == 3
    assert "fap3 open_jaw: 1 vertices, 1 transforms" in report.lines()

    wrl = tmp_path / "posed.wrl"
    assert bpy.ops.mpeg4face.export_vrml(filepath=str(wrl)) == {"FINISHED"}
    face = mpeg4face.read_vrml(wrl)
    names = [t.name for t in face.scene_graph.transforms]
    assert names == [head.name, "eye_l", "teeth"]
    # The neutral teeth sit where Blender has them, in the standard's axes.
    assert np.allclose(face.scene_graph.transforms[2].translation, (0, -0.15, 0.05))
    mask, values = np.zeros((1, 68), dtype=bool), np.zeros((1, 68), dtype=np.int32)
    for fap, value in ((23, 50000), (49, 10000), (3, 256)):  # half of each pose
        mask[0, fap - 1], values[0, fap - 1] = True, value
    state = mpeg4face.FatEvaluator(face).evaluate(
        mpeg4face.FapStream.from_arrays([0], mask, values), 0)
    assert rotation_about_y(state["rotation"][1]) == pytest.approx(EYE_TURN / 2, abs=1e-5)
    assert rotation_about_y(state["rotation"][0]) == pytest.approx(HEAD_TURN / 2, abs=1e-5)
    assert np.allclose(state["translation"][2], (0, -0.15 - TEETH_DROP / 2, 0.05), atol=1e-6)


def test_the_neutral_marker_chooses_the_neutral_frame(posed_head):
    head, eye, _ = posed_head
    scene = bpy.context.scene
    scene.timeline_markers["neutral"].frame = 10  # the turned eye is now the neutral one
    model, _ = poses.read_posed_face_model(head, operators_faces.key_names, scene)
    assert rotation_about_y(model.transforms[1].rotation) == pytest.approx(EYE_TURN, abs=1e-6)
    scene.timeline_markers.remove(scene.timeline_markers["neutral"])
    assert poses.neutral_frame(scene) == scene.frame_start


def test_poses_alone_make_tables_and_bad_names_are_reported(posed_head):
    head, _, _ = posed_head
    head.shape_key_clear()  # poses only: still something to generate from
    assert bpy.ops.mpeg4face.generate_tables() == {"FINISHED"}
    assert operators_faces.table_reports[head.name].copies == 3
    bpy.context.scene.timeline_markers.new("fap23@", frame=40)
    with pytest.raises(RuntimeError, match=r"animation 'fap23@'.*fap<N>\[_<name>\]@<amplitude>"):
        bpy.ops.mpeg4face.generate_tables()
    bpy.context.scene.timeline_markers.clear()
    with pytest.raises(RuntimeError, match="no shape keys besides the Basis and the scene no "
                                           "pose markers"):
        bpy.ops.mpeg4face.generate_tables()
