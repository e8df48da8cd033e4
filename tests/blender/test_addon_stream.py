# SPDX-License-Identifier: GPL-3.0-or-later
"""The add-on's FAP stream operators on CANDIDE-3 with a shape key fap3_open_jaw@512:
import and bake (values, sliders, frame range and rate, resampling, a FIT filling in an
unsent FAP), the live preview against the expected FAT result (with an eye as a part and
poses of the eye and the head too), encoding, speech and bad input. Run through
run_in_blender.py."""

import json
import shutil
from types import SimpleNamespace

import numpy as np
import pytest

bpy = pytest.importorskip("bpy", reason="runs inside Blender only (see run_in_blender.py)")

import mpeg4face  # noqa: E402
from conftest import DATA  # noqa: E402
from mathutils import Matrix  # noqa: E402

from mpeg4face_blender.logic import feature_points  # noqa: E402
from mpeg4face_blender.scene import (  # noqa: E402
    compat, live_preview, mesh_data, poses, stream_data)
from mpeg4face_blender.ui.operators import bake  # noqa: E402
from mpeg4face_blender.ui.operators import faces as operators_faces  # noqa: E402
from mpeg4face_blender.ui.panels import stream as panels_stream  # noqa: E402

JOY = DATA / "xface-fap" / "joy.fap"
KEY = "fap3_open_jaw@512"
JAW = slice(0, 20)  # the vertices the key moves
DROP = np.array([0.0, 0.0, -0.1])  # their displacement at FAP 3 = 512, Blender axes


def coords(block_or_mesh):
    data = block_or_mesh.data if hasattr(block_or_mesh, "data") else block_or_mesh.vertices
    co = np.empty(len(data) * 3, dtype=np.float32)
    data.foreach_get("co", co)
    return co.reshape(-1, 3).astype(np.float64)


def add_key(obj, name, moved=JAW, by=DROP):
    if obj.data.shape_keys is None:
        obj.shape_key_add(name="Basis")
    key = obj.shape_key_add(name=name, from_mix=False)
    key.value = 0.0  # the head at rest (5.0 adds a key at 1, earlier Blenders at 0)
    co = coords(key)
    co[moved] += by
    key.data.foreach_set("co", co.astype(np.float32).ravel())
    return key


@pytest.fixture
def head(candide_head):
    """CANDIDE-3 with the shape key fap3_open_jaw@512, the scene at 30 fps; afterwards the
    live preview is stopped and the scene's animation and strips removed."""
    obj, _, _ = candide_head
    add_key(obj, KEY)
    scene = bpy.context.scene
    scene.render.fps, scene.render.fps_base = 30, 1.0
    yield obj
    live_preview.stop_live(obj)
    if scene.sequence_editor:
        scene.sequence_editor_clear()
    for action in list(bpy.data.actions):
        bpy.data.actions.remove(action)


@pytest.fixture(scope="module")
def joy():
    stream = mpeg4face.read_fap_stream(JOY)
    return stream, stream.resolved()["values"][:, 2]


def fcurve(obj, name=KEY):
    animation = obj.data.shape_keys.animation_data
    return compat.action_fcurves(animation).find(f'key_blocks["{name}"].value')


def key_value(obj, frame, name=KEY):
    return fcurve(obj, name).evaluate(frame)


def test_import_bakes_the_stream(head, joy):
    stream, values = joy
    assert bpy.ops.mpeg4face.import_fap_stream(filepath=str(JOY), start_frame=5) == {"FINISHED"}
    scene = bpy.context.scene
    assert scene.render.fps / scene.render.fps_base == stream.frame_rate == 25
    assert (scene.frame_start, scene.frame_end) == (5, 5 + 107)
    curve = fcurve(head)
    assert len(curve.keyframe_points) == 108
    assert {p.interpolation for p in curve.keyframe_points} == {"LINEAR"}
    for index in (0, 10, 30, 60, 107):
        assert key_value(head, 5 + index) == pytest.approx(values[index] / 512, abs=1e-6)
    scene.frame_set(5 + 30)
    assert head.data.shape_keys.key_blocks[KEY].value == pytest.approx(values[30] / 512, abs=1e-6)
    block = head.data.shape_keys.key_blocks[KEY]
    assert values.min() < 0
    assert block.slider_min == pytest.approx(values.min() / 512, abs=1e-6)  # widened
    assert block.slider_max == 1.0
    state = head.mpeg4face_stream
    assert state.filepath == str(JOY) and state.frames == 108 and state.start_frame == 5


def test_slider_widened_above_one(head, joy):
    _, values = joy
    head.data.shape_keys.key_blocks[KEY].name = "fap3@128"
    bpy.ops.mpeg4face.import_fap_stream(filepath=str(JOY))
    assert key_value(head, 1 + 40, "fap3@128") == pytest.approx(values[40] / 128, abs=1e-6)
    assert head.data.shape_keys.key_blocks["fap3@128"].slider_max == pytest.approx(
        values.max() / 128, abs=1e-6)


def test_two_amplitudes_of_one_fap(head, joy):
    _, values = joy
    add_key(head, "fap3@128")
    bpy.ops.mpeg4face.import_fap_stream(filepath=str(JOY))
    index = int(np.argmax(values))  # above 128: in [128, 512]
    t = (values[index] - 128) / (512 - 128)
    assert key_value(head, 1 + index) == pytest.approx(t, abs=1e-6)
    assert key_value(head, 1 + index, "fap3@128") == pytest.approx(1 - t, abs=1e-6)


def test_import_resamples_to_the_scene_rate(head, joy):
    _, values = joy
    scene = bpy.context.scene
    scene.render.fps = 50
    assert bpy.ops.mpeg4face.import_fap_stream(
        filepath=str(JOY), frame_rate="SCENE", resample="LINEAR") == {"FINISHED"}
    assert scene.render.fps == 50
    assert (scene.frame_start, scene.frame_end) == (1, 216)
    for index in (10, 30):
        assert key_value(head, 1 + 2 * index) == pytest.approx(values[index] / 512, abs=1e-6)
        assert key_value(head, 2 + 2 * index) == pytest.approx(
            (values[index] + values[index + 1]) / 1024, abs=1e-6)


# stretch_r_cornerlip (FAP 7) from stretch_l_cornerlip (FAP 6) at 3/4: a smile lopsided to
# the left. Not the left-right preset: a decoder mirrors an unsent partner anyway (resolved()
# gives FAP 7 = FAP 6), so its f = F would pass with the FIT ignored.
LOPSIDED_FIT = {
    "format": "mpeg4face-fit", "version": 1, "nodes": [[6], [7]],
    "links": [{"parent": 0, "child": 1, "functions": [{
        "fap": 7, "numerator": [{"coefficient": 0.75, "exponents": [1]}],
        "denominator": [{"coefficient": 1.0, "exponents": [0]}]}]}],
}
RIGHT_KEY = "fap7_stretch_r_cornerlip@512"
CORNER = slice(30, 40)  # the vertices RIGHT_KEY moves, apart from the jaw's
STRETCH = np.array([-0.05, 0.0, 0.0])


def left_side_only(folder):
    """joy.fap without FAP 7, and LOPSIDED_FIT: (stream file, FIT file, FAP 7 per frame as
    FitTable.interpolate derives it)."""
    joy = mpeg4face.read_fap_stream(JOY)
    mask, values = np.array(joy.mask), np.array(joy.values)
    mask[:, 6], values[:, 6] = False, 0
    stream = folder / "joy_left.fap"
    mpeg4face.write_fap(mpeg4face.FapStream.from_arrays(
        joy.frame_numbers, mask, values, frame_rate=joy.frame_rate), str(stream))
    table = mpeg4face.fit_table_from_json(json.dumps(LOPSIDED_FIT))
    fit = folder / "lopsided.json"
    fit.write_text(table.to_json())
    derived = table.interpolate(mpeg4face.read_fap_stream(stream)).resolved()["values"][:, 6]
    return stream, fit, derived


def test_import_through_a_fit(head, tmp_path, joy):
    """The stream does not send FAP 7; the FIT derives it. Its key is baked, and shown by
    the live preview (started from the remembered stream and FIT), with the FIT's values."""
    _, jaw = joy
    add_key(head, RIGHT_KEY, moved=CORNER, by=STRETCH)
    stream, fit, derived = left_side_only(tmp_path)
    assert np.count_nonzero(derived) > 50  # the FIT has something to show
    assert bpy.ops.mpeg4face.import_fap_stream(
        filepath=str(stream), fit_path=str(fit)) == {"FINISHED"}
    assert head.mpeg4face_stream.fit_path == str(fit)
    for index in (0, 10, 30, 60, 107):
        assert key_value(head, 1 + index, RIGHT_KEY) == pytest.approx(derived[index] / 512,
                                                                     abs=1e-6)
    basis = coords(head.data.shape_keys.key_blocks["Basis"])
    assert bpy.ops.mpeg4face.live_preview(action="START") == {"FINISHED"}
    for index in (30, 60):
        bpy.context.scene.frame_set(1 + index)
        expected = basis.copy()
        expected[JAW] += jaw[index] / 512 * DROP
        expected[CORNER] += derived[index] / 512 * STRETCH
        np.testing.assert_allclose(evaluated(head), expected, atol=1e-5)


def evaluated(obj):
    depsgraph = bpy.context.evaluated_depsgraph_get()
    return coords(obj.evaluated_get(depsgraph).data)


def test_live_preview_is_the_fat_result_and_stops(head, joy):
    _, values = joy
    basis = coords(head.data.shape_keys.key_blocks["Basis"])
    assert bpy.ops.mpeg4face.import_fap_stream(filepath=str(JOY), preview="LIVE") == {"FINISHED"}
    assert live_preview.is_live(head)
    assert live_preview._on_frame_change in bpy.app.handlers.frame_change_pre
    assert not head.data.shape_keys.animation_data  # nothing baked
    for index in (30, 60):
        bpy.context.scene.frame_set(1 + index)
        expected = basis.copy()
        expected[JAW] += values[index] / 512 * DROP
        np.testing.assert_allclose(evaluated(head), expected, atol=1e-5)
    assert bpy.ops.mpeg4face.live_preview(action="STOP") == {"FINISHED"}
    assert not live_preview.is_live(head)
    assert live_preview.LIVE_KEY not in head.data.shape_keys.key_blocks
    assert live_preview._on_frame_change not in bpy.app.handlers.frame_change_pre
    np.testing.assert_allclose(evaluated(head), basis, atol=1e-6)
    # started again from the panel's button, from the remembered stream
    assert bpy.ops.mpeg4face.live_preview(action="START") == {"FINISHED"}
    assert live_preview.is_live(head)


def test_the_bake_is_the_live_preview_where_no_priority_applies(head, tmp_path):
    """FAP 3 keyed at 128, 512 and -256 (three intervals, not proportional), viseme 3 and
    FAP 5 on some of the viseme's vertices: baked, every frame shows what Live shows, but
    those where FAP 5 and the viseme are sent together (the low-level FAP overrides the
    viseme there, which shape keys cannot show); the bake names those frames."""
    add_key(head, "fap3@128", by=np.array([0.02, 0.0, -0.05]))
    add_key(head, "fap3@-256", by=np.array([0.0, 0.01, 0.03]))
    add_key(head, "viseme3", moved=slice(30, 50), by=np.array([0.0, 0.04, 0.0]))
    add_key(head, "fap5@300", moved=slice(40, 45), by=np.array([0.0, 0.0, 0.02]))
    frames = 30
    mask = np.zeros((frames, 68), dtype=bool)
    values = np.zeros((frames, 68), dtype=np.int32)
    visemes = np.zeros((frames, 4), dtype=np.int32)
    mask[:, 2], values[:, 2] = True, np.linspace(-500, 900, frames).round()
    mask[10:, 0], visemes[10:25] = True, (3, 0, 63, 0)  # then viseme 0 (a decoder holds)
    mask[20:25, 4], values[20:25, 4] = True, 150
    mask[25:, 4], values[25:, 4] = True, -100  # FAP 5 without the viseme
    path = tmp_path / "mix.fap"
    mpeg4face.write_fap(mpeg4face.FapStream.from_arrays(
        np.arange(frames), mask, values, visemes=visemes, frame_rate=30), str(path))
    stream = mpeg4face.read_fap_stream(path)
    reports = []
    op = SimpleNamespace(report=lambda kind, text: reports.append(text))
    bake.bake_stream(op, bpy.context, head, stream_data.grammar_keys(head), stream, 1, "HOLD")
    assert any("differs from a decoder at 5 frames (21-25)" in r for r in reports), reports
    baked = []
    for k in range(frames):
        bpy.context.scene.frame_set(1 + k)
        baked.append(evaluated(head))
    live_preview.start_live(head, bpy.context.scene, stream_data.grammar_keys(head), stream, 1,
                            draw=False)
    for k in range(frames):
        bpy.context.scene.frame_set(1 + k)
        live = live_coords(head)
        if 20 <= k < 25:
            assert np.abs(baked[k] - live).max() > 0.01, k  # the viseme added under FAP 5
        else:
            np.testing.assert_allclose(baked[k], live, atol=2e-5, err_msg=f"frame {k}")


def test_live_preview_builds_the_tables_of_the_streams_faps_only(head, monkeypatch):
    # A key of FAP 4, which the stream never animates: no table for it (the start does not
    # read it), and FAP 3 shows as the whole face's tables show it.
    add_key(head, "fap4_lower_t_midlip@200", moved=slice(30, 40), by=np.array([0, 0, 0.05]))
    sent = (0, 256, 512, 128)
    mask = np.zeros((len(sent), 68), dtype=bool)
    values = np.zeros((len(sent), 68), dtype=np.int32)
    mask[:, 2], values[:, 2] = True, sent
    stream = mpeg4face.FapStream.from_arrays(np.arange(len(sent), dtype=np.int32), mask,
                                             values, frame_rate=30.0)
    generate, built = mpeg4face.generate_face, []

    def spy(model, *args, **kwargs):
        result = generate(model, *args, **kwargs)
        built.append(sorted(t["fap"] for t in result["face"].tables))
        return result

    monkeypatch.setattr(mpeg4face, "generate_face", spy)
    basis = coords(head.data.shape_keys.key_blocks["Basis"])
    live_preview.start_live(head, bpy.context.scene, stream_data.grammar_keys(head),
                                stream, 1)
    assert built == [[3]]
    for index, value in enumerate(sent):
        bpy.context.scene.frame_set(1 + index)
        expected = basis.copy()
        expected[JAW] += value / 512 * DROP
        np.testing.assert_allclose(evaluated(head), expected, atol=1e-5)


def test_the_mesh_read_in_object_mode_is_the_bmesh_one(head):
    # The live preview reads the mesh with foreach_get; Edit Mode (and the panels) through
    # bmesh: the same vertices, faces (a triangle, a quad, a pentagon) and feature points.
    mesh = bpy.data.meshes.new("polygons")
    mesh.from_pydata([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (2, 0, 0), (2, 1, 0),
                      (3, 0.5, 0), (2.5, 2, 0)], [], [(0, 1, 2), (1, 4, 5, 2), (4, 6, 7, 5, 2)])
    polygons = bpy.data.objects.new("polygons", mesh)
    polygons.vertex_groups.new(name="FP_2.1").add([6], 1.0, "REPLACE")
    try:
        for obj in (head, polygons):
            coords_, faces, fp_vertices, _ = mesh_data.mesh_and_points(obj)
            with mesh_data.face_bmesh(obj) as bm:
                np.testing.assert_array_equal(coords_, mesh_data.standard_coords(bm))
                assert list(faces) == mesh_data.coord_index(bm)
                assert mesh_data.fp_groups(obj) == mesh_data.fp_groups(obj, bm)
            assert fp_vertices
        assert list(mesh_data.mesh_and_points(polygons)[1]) == [
            0, 1, 2, -1, 1, 4, 5, 2, -1, 4, 6, 7, 5, 2, -1]
    finally:
        bpy.data.objects.remove(polygons)
        bpy.data.meshes.remove(mesh)


def test_live_handler_forgets_a_deleted_object(head):
    bpy.ops.mpeg4face.import_fap_stream(filepath=str(JOY), preview="LIVE")
    head.shape_key_remove(head.data.shape_keys.key_blocks[live_preview.LIVE_KEY])
    bpy.context.scene.frame_set(3)  # must not raise
    assert not live_preview._live
    assert live_preview._on_frame_change not in bpy.app.handlers.frame_change_pre


EYE_POSE, EYE_TURN = "fap23_yaw_l_eyeball@30000", 0.4  # radians about Blender's Z
HEAD_POSE, HEAD_TURN = "fap49_head_yaw@20000", 0.2


@pytest.fixture
def eye(head):
    """A left eye below the head: a small tetrahedron off its own origin, without shape
    keys. Markers neutral (200), EYE_POSE (210) turning the eye and HEAD_POSE (220) turning
    the head, keyed there only, so every object is at its neutral place before frame 200."""
    mesh = bpy.data.meshes.new("eye_l")
    mesh.from_pydata([(0.01, 0.0, 0.0), (0.02, 0.0, 0.0), (0.01, -0.01, 0.0),
                      (0.01, 0.0, 0.01)], [], [(0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)])
    obj = bpy.data.objects.new("eye_l", mesh)
    scene = bpy.context.scene
    scene.collection.objects.link(obj)
    obj.parent = head
    obj.location = (0.1, -0.05, 0.2)
    for name, frame in (("neutral", 200), (EYE_POSE, 210), (HEAD_POSE, 220)):
        scene.timeline_markers.new(name, frame=frame)
        for posed, pose, turn in ((obj, EYE_POSE, EYE_TURN), (head, HEAD_POSE, HEAD_TURN)):
            posed.rotation_euler = (0, 0, turn if name == pose else 0)
            posed.keyframe_insert("rotation_euler", frame=frame)
    scene.frame_set(1)
    yield obj
    live_preview.stop_live(head)
    bpy.data.objects.remove(obj)
    bpy.data.meshes.remove(mesh)
    scene.timeline_markers.clear()
    head.animation_data_clear()


def write_stream(path, faps):
    """A 30 fps stream sending each FAP of `faps` (number -> value per frame)."""
    frames = len(next(iter(faps.values())))
    mask = np.zeros((frames, 68), dtype=bool)
    values = np.zeros((frames, 68), dtype=np.int32)
    for fap, sent in faps.items():
        mask[:, fap - 1], values[:, fap - 1] = True, sent
    mpeg4face.write_fap(mpeg4face.FapStream.from_arrays(
        np.arange(frames), mask, values, frame_rate=30), str(path))
    return path


def live_coords(obj):
    return coords(obj.data.shape_keys.key_blocks[live_preview.LIVE_KEY])


def moved(matrix, points):
    """Points (N, 3) through a 4x4 mathutils matrix."""
    m = np.array(matrix)
    return points @ m[:3, :3].T + m[:3, 3]


def test_live_preview_of_a_part_and_its_pose(head, eye, tmp_path):
    """The eye turns by FAP 23 about its origin and the jaw opens by FAP 3, each in its own
    live key: the objects stay where they are; Stop takes the keys and the eye's added
    Basis away."""
    faps = {3: [0, 256, 400], 23: [0, 20000, -12000]}
    path = write_stream(tmp_path / "eye.fap", faps)
    scene = bpy.context.scene
    model, _ = poses.read_posed_face_model(head, operators_faces.key_names, scene)
    evaluator = mpeg4face.FatEvaluator(mpeg4face.generate_face(model)["face"])
    stream = mpeg4face.read_fap_stream(path)
    eye_basis = coords(eye.data)
    matrices = [o.matrix_world.copy() for o in (head, eye)]
    head_display = (head.show_only_shape_key, head.active_shape_key_index)

    assert bpy.ops.mpeg4face.import_fap_stream(filepath=str(path), preview="LIVE") == {
        "FINISHED"}
    assert eye.data.shape_keys.key_blocks.keys() == [live_preview.LIVE_BASIS,
                                                     live_preview.LIVE_KEY]
    assert head.show_only_shape_key and eye.show_only_shape_key
    for index in (1, 2):
        scene.frame_set(1 + index)
        turn = Matrix.Rotation(EYE_TURN * faps[23][index] / 30000, 4, "Z")
        np.testing.assert_allclose(live_coords(eye), moved(turn, eye_basis), atol=1e-6)
        core = evaluator.evaluate(stream, index)["coord"][0]
        np.testing.assert_allclose(live_coords(head), feature_points.to_blender_axes(core),
                                   atol=1e-6)
        assert [o.matrix_world for o in (head, eye)] == matrices

    assert bpy.ops.mpeg4face.live_preview(action="STOP") == {"FINISHED"}
    assert eye.data.shape_keys is None and not eye.show_only_shape_key
    assert live_preview.LIVE_KEY not in head.data.shape_keys.key_blocks
    assert (head.show_only_shape_key, head.active_shape_key_index) == head_display
    assert not live_preview.is_live(head) and not live_preview.is_live(eye)


def test_live_preview_turns_the_head_with_its_parts(head, eye, tmp_path):
    """A head pose turns the head about its origin and carries the eye along, each shown in
    its own (neutral) frame."""
    path = write_stream(tmp_path / "yaw.fap", {49: [10000]})
    head_basis = coords(head.data.shape_keys.key_blocks["Basis"])
    eye_basis = coords(eye.data)
    eye_neutral = eye.matrix_local.copy()
    assert bpy.ops.mpeg4face.import_fap_stream(filepath=str(path), preview="LIVE") == {
        "FINISHED"}
    turn = Matrix.Rotation(HEAD_TURN * 10000 / 20000, 4, "Z")
    np.testing.assert_allclose(live_coords(head), moved(turn, head_basis), atol=1e-6)
    np.testing.assert_allclose(live_coords(eye), moved(
        eye_neutral.inverted() @ turn @ eye_neutral, eye_basis), atol=1e-6)


def test_live_preview_refuses_parts_sharing_a_mesh(head, eye, tmp_path):
    path = write_stream(tmp_path / "eye.fap", {23: [10000]})
    twin = bpy.data.objects.new("eye_r", eye.data)
    bpy.context.scene.collection.objects.link(twin)
    twin.parent = head
    try:
        with pytest.raises(RuntimeError, match="eye_l and eye_r share the mesh eye_l"):
            bpy.ops.mpeg4face.import_fap_stream(filepath=str(path), preview="LIVE")
        assert not live_preview.is_live(head) and eye.data.shape_keys is None
    finally:
        bpy.data.objects.remove(twin)


def test_encode(head, tmp_path, joy):
    stream, _ = joy
    with pytest.raises(RuntimeError, match="No stream on candide3"):
        bpy.ops.mpeg4face.encode_fap_stream(filepath=str(tmp_path / "none.fba"))
    bpy.ops.mpeg4face.import_fap_stream(filepath=str(JOY))
    out = tmp_path / "joy.fba"
    assert bpy.ops.mpeg4face.encode_fap_stream(
        filepath=str(out), mode="dct", fap_quant=2) == {"FINISHED"}
    expected = mpeg4face.encode_fba(stream, "dct", 2)
    assert out.read_bytes() == expected.data
    state = head.mpeg4face_stream
    assert (state.bits, state.encoded_mode) == (expected.bits, "dct")
    assert state.bits_per_second == pytest.approx(expected.bits_per_second)
    assert state.psnr == pytest.approx(expected.psnr)
    assert len(mpeg4face.read_fap_stream(out)) == len(stream)


@pytest.mark.skipif(shutil.which("flite") is None, reason="flite is not installed")
def test_speak(head, tmp_path):
    add_key(head, "viseme10", by=np.array([0.0, 0.0, -0.05]))
    add_key(head, "viseme1", by=np.array([0.0, 0.0, 0.01]))
    scene = bpy.context.scene
    assert bpy.ops.mpeg4face.speak_text(
        text="Hello papa", voice="slt", folder=str(tmp_path), start_frame=10) == {"FINISHED"}
    state = head.mpeg4face_stream
    assert state.filepath.endswith(".fap") and state.start_frame == 10
    stream = mpeg4face.read_fap_stream(state.filepath)
    assert stream.frame_rate == 30
    for name in ("viseme10", "viseme1"):
        assert max(p.co[1] for p in fcurve(head, name).keyframe_points) > 0.5
    strips = list(compat.strips(scene.sequence_editor))
    assert len(strips) == 1 and strips[0].type == "SOUND"
    wav = bpy.path.abspath(strips[0].sound.filepath)
    assert wav.endswith(".wav") and wav.startswith(str(tmp_path))
    assert strips[0].frame_start == 10
    assert scene.frame_start == 10
    assert scene.frame_end >= strips[0].frame_final_end - 1
    assert scene.frame_end >= 10 + len(stream) - 1
    assert scene.sync_mode == "AUDIO_SYNC"
    # speaking again replaces the strip
    bpy.ops.mpeg4face.speak_text(text="Hello", folder=str(tmp_path))
    assert len(compat.strips(scene.sequence_editor)) == 1


def test_speak_without_flite_is_reported(head, tmp_path, monkeypatch):
    monkeypatch.setenv("PATH", str(tmp_path))  # no flite on it
    message = r"Cannot speak: .*cannot run 'flite' \(No such file or directory\): install"
    with pytest.raises(RuntimeError, match=message):
        bpy.ops.mpeg4face.speak_text(text="Hello", folder=str(tmp_path))
    assert not head.mpeg4face_stream.filepath
    assert not list(tmp_path.glob("*.wav"))


def test_bad_input_is_reported(head, tmp_path):
    bad = tmp_path / "bad.fap"
    bad.write_text("not a stream\n")
    with pytest.raises(RuntimeError, match="Cannot read the stream"):
        bpy.ops.mpeg4face.import_fap_stream(filepath=str(bad))
    with pytest.raises(RuntimeError, match="Cannot read the stream"):
        bpy.ops.mpeg4face.import_fap_stream(filepath=str(tmp_path / "missing.fba"))
    with pytest.raises(RuntimeError, match="Cannot read the stream"):
        bpy.ops.mpeg4face.import_fap_stream(filepath=str(JOY), fit_path=str(bad))
    with pytest.raises(RuntimeError, match="No stream on candide3"):
        bpy.ops.mpeg4face.live_preview(action="START")
    calls = (
        lambda: bpy.ops.mpeg4face.import_fap_stream(filepath=str(JOY)),
        lambda: bpy.ops.mpeg4face.speak_text(text="Hello", folder=str(tmp_path)),
        lambda: bpy.ops.mpeg4face.live_preview(action="START"),
    )
    head.data.shape_keys.key_blocks[KEY].name = "jaw"
    for call in calls:
        with pytest.raises(RuntimeError, match="candide3 has no shape keys named fap<N>"):
            call()
    bpy.context.view_layer.objects.active = None
    for call in (*calls, lambda: bpy.ops.mpeg4face.encode_fap_stream(filepath=str(JOY))):
        with pytest.raises(RuntimeError, match="No active object"):
            call()
    bpy.context.view_layer.objects.active = head


def test_live_needs_measurable_fapu(head):
    for group in list(head.vertex_groups):
        head.vertex_groups.remove(group)
    with pytest.raises(RuntimeError, match="Cannot build the face's tables.*MNS0"):
        bpy.ops.mpeg4face.import_fap_stream(filepath=str(JOY), preview="LIVE")
    assert not live_preview.is_live(head)


class Layout:
    """Records the panel's labels and buttons (stands in for bpy.types.UILayout)."""

    def __init__(self, log):
        self.log = log

    def label(self, text="", icon="NONE"):
        if icon == "BLANK1" and self.log:  # a wrapped label's next line: one message
            self.log[-1] += " " + text
        else:
            self.log.append(text)

    def operator(self, idname, text="", icon="NONE"):
        self.log.append(f"[{text or idname}]")
        return SimpleNamespace()

    def __getattr__(self, name):  # row(), column(), box()
        return lambda *args, **kwargs: Layout(self.log)


def test_panel_shows_the_stream_and_the_encoding(head, tmp_path):
    def draw():
        log = []
        panels_stream.MPEG4FACE_PT_fap_stream.draw(SimpleNamespace(layout=Layout(log)), bpy.context)
        return log

    assert draw()[0] == "1 shape keys named for FAPs"
    bpy.ops.mpeg4face.import_fap_stream(filepath=str(JOY))
    bpy.ops.mpeg4face.encode_fap_stream(filepath=str(tmp_path / "joy.fba"), mode="pca")
    log = draw()
    assert "joy.fap" in log and "108 frames from frame 1" in log
    assert "[Start Live Preview]" in log and "pca: joy.fba" in log
    assert any(line.startswith("17312 bits") or "bit/s" in line for line in log)
    assert any(line.endswith("dB") for line in log)


def test_registered_with_a_menu_entry():
    from mpeg4face_blender.ui.operators import import_stream

    for name in ("MPEG4FACE_OT_import_fap_stream", "MPEG4FACE_OT_encode_fap_stream",
                 "MPEG4FACE_OT_speak_text", "MPEG4FACE_OT_live_preview",
                 "MPEG4FACE_PT_fap_stream"):
        assert hasattr(bpy.types, name), name
    assert import_stream.stream_import_menu in bpy.types.TOPBAR_MT_file_import._dyn_ui_initialize()


def test_disabling_the_addon_stops_the_live_preview(head, addon_disabled_after):
    bpy.ops.mpeg4face.import_fap_stream(filepath=str(JOY), preview="LIVE")
    addon_disabled_after()
    assert live_preview._on_frame_change not in bpy.app.handlers.frame_change_pre
    assert live_preview.LIVE_KEY not in head.data.shape_keys.key_blocks
    assert not head.show_only_shape_key


@pytest.fixture
def addon_disabled_after():
    """A function that disables the add-on; it is enabled again after the test."""
    import addon_utils

    from conftest import ADDON

    yield lambda: addon_utils.disable(ADDON, default_set=True)
    addon_utils.enable(ADDON, default_set=True)
