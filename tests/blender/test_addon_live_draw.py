# SPDX-License-Identifier: GPL-3.0-or-later
"""The live preview drawn with the gpu module (live_draw), run headless: the buffers hold
the exact FAT result of every frame while no mesh is written or re-evaluated and the
objects are hidden in the viewport; a render writes the live keys (the exact shape-key
path); renaming the head keeps the preview; a preview that has to stop says so. The
drawing itself is checked under Xvfb (test_viewport.py). Run through run_in_blender.py."""

import numpy as np
import pytest

bpy = pytest.importorskip("bpy", reason="runs inside Blender only (see run_in_blender.py)")

import mpeg4face  # noqa: E402
from mathutils import Matrix  # noqa: E402
from test_addon_stream import (  # noqa: E402,F401 - fixtures
    EYE_TURN, JOY, coords, eye, head, live_coords, moved, write_stream)

from mpeg4face_blender.logic import feature_points  # noqa: E402
from mpeg4face_blender.logic import live as live_logic  # noqa: E402
from mpeg4face_blender.scene import (  # noqa: E402
    compat, live_draw, live_preview, poses, stream_data)
from mpeg4face_blender.ui.operators import faces as operators_faces  # noqa: E402


def start_drawn(obj, path):
    keys = stream_data.grammar_keys(obj)
    stream = mpeg4face.read_fap_stream(path)
    live_preview.start_live(obj, bpy.context.scene, keys, stream, 1, draw=True)
    return live_preview._live[obj.name]  # noqa: SLF001


def test_drawn_preview_fills_buffers_and_tags_no_mesh(head, eye, tmp_path):
    faps = {3: [0, 256, 400], 23: [0, 20000, -12000]}
    path = write_stream(tmp_path / "eye.fap", faps)
    scene = bpy.context.scene
    model, _ = poses.read_posed_face_model(head, operators_faces.key_names, scene)
    evaluator = mpeg4face.FatEvaluator(mpeg4face.generate_face(model)["face"])
    stream = mpeg4face.read_fap_stream(path)
    eye_basis, head_basis = coords(eye.data), coords(head.data)
    state = start_drawn(head, path)
    # The originals give way to the drawing in the viewport, not in a render, and stay the
    # objects the panels work on.
    depsgraph = bpy.context.evaluated_depsgraph_get()
    for obj in (head, eye):
        assert len(obj.evaluated_get(depsgraph).data.vertices) == 0
        assert not obj.modifiers[live_draw.HIDE_MODIFIER].show_render
    updated = []

    def note(_scene, depsgraph):
        updated.extend(u.id.name for u in depsgraph.updates if u.is_updated_geometry)

    bpy.app.handlers.depsgraph_update_post.append(note)
    try:
        for index in (1, 2):
            scene.frame_set(1 + index)
            head_drawn, eye_drawn = (o.drawn for o in state.objects)
            turn = Matrix.Rotation(EYE_TURN * faps[23][index] / 30000, 4, "Z")
            np.testing.assert_allclose(eye_drawn.positions, moved(turn, eye_basis), atol=1e-6)
            core = evaluator.evaluate(stream, index)["coord"][0]
            np.testing.assert_allclose(head_drawn.positions, feature_points.to_blender_axes(core),
                                       atol=1e-6)
            for drawn in (head_drawn, eye_drawn):  # the normals of the shown shape
                expected = mpeg4face.vertex_normals(drawn.positions, drawn.triangles)
                used = np.unique(drawn.triangles)  # CANDIDE-3 has vertices on no face
                np.testing.assert_allclose(drawn.vertex_normals[used], expected[used],
                                           atol=1e-5)
            # the live keys stay at rest while drawing
            np.testing.assert_allclose(live_coords(head), head_basis, atol=1e-7)
            np.testing.assert_allclose(live_coords(eye), eye_basis, atol=1e-7)
    finally:
        bpy.app.handlers.depsgraph_update_post.remove(note)
    assert not {head.name, eye.name, head.data.name, eye.data.name} & set(updated), updated

    # A render shows the frame through the live keys, as the shape-key path does.
    scene.render.resolution_x = scene.render.resolution_y = 16
    scene.render.engine = "BLENDER_WORKBENCH"
    bpy.ops.render.render()
    np.testing.assert_allclose(live_coords(eye), state.objects[1].drawn.positions, atol=1e-6)
    np.testing.assert_allclose(live_coords(head), state.objects[0].drawn.positions, atol=1e-6)

    assert not head.modifiers[live_draw.HIDE_MODIFIER].show_in_editmode

    live_preview.stop_live(head)
    assert not head.modifiers and not eye.modifiers
    assert live_draw.HIDE_GROUP not in bpy.data.node_groups
    assert live_preview.LIVE_KEY not in head.data.shape_keys.key_blocks


def test_renamed_head_keeps_its_preview(head, tmp_path):
    path = write_stream(tmp_path / "jaw.fap", {3: [0, 512]})
    bpy.context.scene.frame_set(1)
    assert bpy.ops.mpeg4face.import_fap_stream(filepath=str(path), preview="LIVE") == {
        "FINISHED"}
    before = live_coords(head)
    head.name = "renamed head"
    bpy.context.scene.frame_set(2)
    assert "renamed head" in live_preview._live  # noqa: SLF001
    assert live_preview.is_live(head)
    assert np.abs(live_coords(head) - before).max() > 0.05  # the jaw opened


def test_a_stopped_preview_says_why(head):
    live_preview._stopped.clear()  # noqa: SLF001
    bpy.ops.mpeg4face.import_fap_stream(filepath=str(JOY), preview="LIVE")
    head.shape_key_remove(head.data.shape_keys.key_blocks[live_preview.LIVE_KEY])
    bpy.context.scene.frame_set(3)
    assert not live_preview._live  # noqa: SLF001
    assert live_preview._stopped and head.name in live_preview._stopped[-1]  # noqa: SLF001


def test_normals_turn_with_the_placement():
    """A part's normals computed before its placement and turned with it are those of the
    placed part (the rigid parts' shortcut)."""
    rng = np.random.default_rng(1)
    points = rng.normal(size=(30, 3))
    triangles = rng.permuted(np.tile(np.arange(30), (3, 4)), axis=1).T  # each vertex used
    matrix = np.array(Matrix.Rotation(0.7, 4, "X") @ Matrix.Translation((0.1, 0.2, 0.3)))
    placement = np.eye(4)  # as object_coordinates gives it: into Blender's axes too
    placement[:3] = live_logic.TO_BLENDER @ matrix[:3]
    placed = points @ placement[:3, :3].T + placement[:3, 3]
    turned = live_logic.placed_normals(mpeg4face.vertex_normals(points, triangles), placement)
    np.testing.assert_allclose(turned, mpeg4face.vertex_normals(placed, triangles), atol=1e-4)


def world_vertices(obj):
    """The object's evaluated vertices in world space (Blender's axes)."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    evaluated = obj.evaluated_get(depsgraph)
    return moved(evaluated.matrix_world, coords(evaluated.data))


def test_bake_keeps_the_eye_and_head_poses_live_shows(head, eye, tmp_path):
    """A stream turning the eye (FAP 23), the head (FAP 49) and opening the jaw (FAP 3)
    baked: the head and the eye are keyed as objects beside the shape keys, and every frame
    puts their vertices where the live preview shows them."""
    faps = {3: [0, 256, 400, 100], 23: [0, 20000, -12000, 5000], 49: [0, 0, 8000, -15000]}
    path = write_stream(tmp_path / "poses.fap", faps)
    scene = bpy.context.scene
    scene.frame_set(1)
    assert bpy.ops.mpeg4face.import_fap_stream(filepath=str(path), preview="LIVE") == {
        "FINISHED"}
    live = {}
    for frame in range(1, 5):
        scene.frame_set(frame)
        live[frame] = [world_vertices(o) for o in (head, eye)]
    assert bpy.ops.mpeg4face.live_preview(action="STOP") == {"FINISHED"}
    assert bpy.ops.mpeg4face.import_fap_stream(filepath=str(path), preview="BAKE") == {
        "FINISHED"}
    for obj in (head, eye):
        curves = {c.data_path for c in compat.action_fcurves(obj.animation_data)
                  if any(1 <= p.co.x <= 4 for p in c.keyframe_points)}
        assert {"location", "rotation_euler", "scale"} <= curves, (obj.name, curves)
    for frame in range(1, 5):
        scene.frame_set(frame)
        for obj, expected in zip((head, eye), live[frame]):
            np.testing.assert_allclose(world_vertices(obj), expected, atol=1e-5,
                                       err_msg=f"{obj.name} at frame {frame}")
    # the poses at the markers are still there for the tables
    scene.frame_set(210)
    assert eye.rotation_euler.z == pytest.approx(EYE_TURN)


def test_a_file_saved_while_drawing_shows_its_head_after_loading(head):
    live_draw.hide(head)
    live_preview._clean_after_load()  # noqa: SLF001 - the load_post handler
    assert not head.modifiers and live_draw.HIDE_GROUP not in bpy.data.node_groups


def test_a_preview_that_cannot_draw_writes_keys_and_says_so_once(head, eye, tmp_path, monkeypatch,
                                                                 capsys):
    """Where no shader can be made (no GPU, a Blender refusing it), the preview falls back
    to the live shape key and says why, once a session."""
    monkeypatch.setattr(live_draw, "cannot_draw", lambda: "SystemError: no GPU here")
    monkeypatch.setattr(live_preview, "_cannot_draw_said", False)
    path = write_stream(tmp_path / "eye.fap", {3: [0, 256, 400], 23: [0, 20000, -12000]})
    stream = mpeg4face.read_fap_stream(path)
    keys = stream_data.grammar_keys(head)
    warnings = live_preview.start_live(head, bpy.context.scene, keys, stream, 1, draw=True)
    state = live_preview._live[head.name]  # noqa: SLF001
    assert not state.draw and all(o.drawn is None for o in state.objects)
    assert warnings[0] == ("MPEG-4: the live preview writes shape keys, as it cannot draw the "
                           "face here (SystemError: no GPU here)")
    assert capsys.readouterr().out.count("cannot draw") == 1
    assert live_draw.HIDE_MODIFIER not in head.modifiers
    basis = live_coords(head).copy()
    bpy.context.scene.frame_set(3)
    assert not np.allclose(live_coords(head), basis)  # the live key holds the frame
    again = live_preview.start_live(head, bpy.context.scene, keys, stream, 1, draw=True)
    assert not any("cannot draw" in w for w in again)
    live_preview.stop_live(head)


def test_background_mode_makes_no_shader():
    """Blender 3.4 crashes making a shader in -b: the preview never tries there."""
    assert live_draw.cannot_draw() is None
    assert live_draw._registry.shader is None  # noqa: SLF001
