# SPDX-License-Identifier: GPL-3.0-or-later
"""ARKit heads and Live Link Face captures in the add-on, on CANDIDE-3 with three ARKit
shape keys (conftest.candide_arkit_shapes) and a key of the user's: FAP Keys from ARKit Keys
(the FAP 3 key drops the chin by its amplitude, keys replaced in place, the report, bad
input), and the real capture imported baked and live through the head's own ARKit keys or
an ARKit face file, and a broken capture refused with the scene unchanged. Run through
run_in_blender.py."""

import numpy as np
import pytest

bpy = pytest.importorskip("bpy", reason="runs inside Blender only (see run_in_blender.py)")

import mpeg4face  # noqa: E402
from conftest import DATA, candide_arkit_shapes  # noqa: E402

from mpeg4face_blender.logic import feature_points, shape_keys  # noqa: E402
from mpeg4face_blender.logic import stream as stream_logic  # noqa: E402
from mpeg4face_blender.scene import compat, live_preview, mesh_data, stream_data  # noqa: E402
from mpeg4face_blender.ui.operators import arkit as operators_arkit  # noqa: E402

CAPTURE = DATA / "livelink-face" / "MySlate_3_Jason_Millers_iPhone.csv"


def keys_of(obj):
    blocks = obj.data.shape_keys.key_blocks
    return {k.name: mesh_data.shape_key_coords(k) for k in blocks}


def add_shape(obj, name, displacement):
    """A key `name` = Basis + displacement (standard axes)."""
    if obj.data.shape_keys is None:
        obj.shape_key_add(name="Basis", from_mix=False)
    key = obj.shape_key_add(name=name, from_mix=False)
    basis = mesh_data.shape_key_coords(obj.data.shape_keys.reference_key)
    mesh_data.set_shape_key_coords(key, basis + feature_points.to_blender_axes(displacement))


@pytest.fixture
def arkit_head(candide_head):
    """CANDIDE-3, the only selected object, with the ARKit keys and "Smirk"; the scene at 30
    fps; afterwards the live preview stopped and the animation removed."""
    obj, model, fp_vertices = candide_head
    for other in bpy.context.view_layer.objects:
        other.select_set(other == obj)
    coords = model.meshes[0].coord
    for name, displacement in candide_arkit_shapes(coords, fp_vertices).items():
        add_shape(obj, name, displacement)
    add_shape(obj, "Smirk", np.zeros_like(coords))
    scene = bpy.context.scene
    scene.render.fps, scene.render.fps_base = 30, 1.0
    scene.frame_start, scene.frame_end = 1, 250
    yield obj, model, fp_vertices
    live_preview.stop_live(obj)
    for action in list(bpy.data.actions):
        bpy.data.actions.remove(action)


def test_fap_keys_from_arkit_keys(arkit_head):
    obj, model, fp_vertices = arkit_head
    before = keys_of(obj)
    assert bpy.ops.mpeg4face.arkit_fap_keys() == {"FINISHED"}
    after = keys_of(obj)
    for name, coords in before.items():  # the Basis, the ARKit keys and Smirk as they were
        assert np.array_equal(after[name], coords), name
    made = set(after) - set(before)
    report = operators_arkit.arkit_reports[obj.name]
    assert len(made) == report.written and report.replaced == 0
    assert report.visemes > 0 and report.missed
    [jaw] = [n for n in made if n.startswith("fap3_open_jaw@")]
    assert any(row.startswith(jaw + ": residual") for row in report.made)
    # At its amplitude the key drops the chin (2.1) by amplitude MNS units (Blender's -Z).
    amplitude = shape_keys.parse(jaw)["amplitude"]
    mns = mpeg4face.measure_fapu(model).unit("MNS")
    drop = after[jaw][fp_vertices["2.1"]] - after["Basis"][fp_vertices["2.1"]]
    assert drop[2] == pytest.approx(-amplitude * mns, rel=0.15)
    blocks = obj.data.shape_keys.key_blocks
    assert (blocks[jaw].slider_min, blocks[jaw].slider_max) == shape_keys.slider_range(jaw)

    # Again: the keys are replaced in place (same blocks), a widened slider stays widened.
    blocks[jaw].slider_max = 3.0
    order = list(blocks.keys())
    assert bpy.ops.mpeg4face.arkit_fap_keys() == {"FINISHED"}
    assert list(obj.data.shape_keys.key_blocks.keys()) == order
    assert operators_arkit.arkit_reports[obj.name].replaced == len(made)
    assert blocks[jaw].slider_max == 3.0
    np.testing.assert_allclose(mesh_data.shape_key_coords(blocks[jaw]), after[jaw], atol=1e-6)


def test_fap_keys_from_arkit_keys_bad_input(candide_head):
    obj, model, fp_vertices = candide_head
    add_shape(obj, "Smirk", np.zeros_like(model.meshes[0].coord))
    with pytest.raises(RuntimeError, match="candide3: .*looked for .*eyeBlinkLeft"):
        bpy.ops.mpeg4face.arkit_fap_keys()
    add_shape(obj, "jawOpen", candide_arkit_shapes(model.meshes[0].coord, fp_vertices)["jawOpen"])
    assert bpy.ops.mpeg4face.arkit_fap_keys() == {"FINISHED"}  # one ARKit key is enough
    obj.vertex_groups.clear()
    with pytest.raises(RuntimeError, match="candide3 has no feature points"):
        bpy.ops.mpeg4face.arkit_fap_keys()
    with pytest.raises(RuntimeError, match="Switch to Object Mode"):
        bpy.ops.object.mode_set(mode="EDIT")
        bpy.ops.mpeg4face.arkit_fap_keys()


def baked(obj, name, frames):
    curve = compat.action_fcurves(obj.data.shape_keys.animation_data).find(
        f'key_blocks["{name}"].value')
    return np.array([curve.evaluate(f) for f in frames])


def test_capture_import_baked_and_live(arkit_head, tmp_path):
    obj, _, fp_vertices = arkit_head
    with pytest.raises(RuntimeError, match="run FAP Keys from ARKit Keys first"):
        bpy.ops.mpeg4face.import_livelink_capture(filepath=str(CAPTURE), folder=str(tmp_path))
    assert bpy.ops.mpeg4face.arkit_fap_keys() == {"FINISHED"}
    [jaw] = [n for n in obj.data.shape_keys.key_blocks.keys() if n.startswith("fap3_")]
    assert bpy.ops.mpeg4face.import_livelink_capture(
        filepath=str(CAPTURE), folder=str(tmp_path), start_frame=3) == {"FINISHED"}
    scene = bpy.context.scene
    assert scene.render.fps / scene.render.fps_base == 25
    state = obj.mpeg4face_stream
    stream = mpeg4face.read_fap_stream(state.filepath)  # the converted stream, remembered
    assert state.filepath.startswith(str(tmp_path)) and stream.frame_rate == 25
    frames = stream_logic.scene_frame_count(stream.duration, 25)
    assert (scene.frame_start, scene.frame_end, state.frames) == (3, 3 + frames - 1, frames)
    # The baked keys are the stream's values / amplitude ...
    amplitude = shape_keys.parse(jaw)["amplitude"]
    np.testing.assert_allclose(baked(obj, jaw, 3 + np.arange(frames)) * amplitude,
                               stream.resolved()["values"][:, 2], atol=1e-3)
    # ... and drop the chin as the capture's JawOpen (resampled to 25 fps) does through the
    # jawOpen key: 0.1 at weight 1 (several FAP keys share that motion on this head).
    capture = mpeg4face.read_livelink_csv(CAPTURE)
    column = mpeg4face.livelink_channel_names().index("JawOpen")
    seconds = np.arange(frames) / 25
    jaw_open = np.interp(seconds, capture.times - capture.times[0], capture.values[:, column])
    blocks = obj.data.shape_keys.key_blocks
    basis = mesh_data.shape_key_coords(blocks["Basis"])[fp_vertices["2.1"]]
    chin = sum(baked(obj, name, 3 + np.arange(frames))
               * (mesh_data.shape_key_coords(blocks[name])[fp_vertices["2.1"], 2] - basis[2])
               for name in (k.name for k in stream_data.grammar_keys(obj).keys if k.fap >= 3))
    assert np.ptp(jaw_open) > 0.2 and np.corrcoef(-chin, jaw_open)[0, 1] >= 0.9
    assert np.abs(-chin - 0.1 * jaw_open).mean() <= 0.15 * 0.1 * jaw_open.max()

    # Live: the core's evaluation drops the chin where the jaw is most open.
    assert bpy.ops.mpeg4face.import_livelink_capture(
        filepath=str(CAPTURE), folder=str(tmp_path), preview="LIVE") == {"FINISHED"}
    assert live_preview.is_live(obj)
    chin = fp_vertices["2.1"]
    basis = mesh_data.shape_key_coords(obj.data.shape_keys.reference_key)[chin]
    scene.frame_set(1 + int(np.argmax(jaw_open)))
    live = mesh_data.shape_key_coords(obj.data.shape_keys.key_blocks[live_preview.LIVE_KEY])
    # jawOpen drops the chin by 0.1 at weight 1 (conftest.candide_arkit_shapes).
    assert basis[2] - live[chin][2] == pytest.approx(0.1 * np.max(jaw_open), rel=0.3)


def test_capture_through_an_arkit_face_file(candide_head, tmp_path):
    """A head without ARKit keys (only a FAP key) converts through an ARKit face (.glb)."""
    obj, model, fp_vertices = candide_head
    mesh = model.meshes[0]
    shapes = candide_arkit_shapes(mesh.coord, fp_vertices)
    face = tmp_path / "arkit.glb"
    mpeg4face.write_gltf(
        feature_points.face_model_from_arrays(mesh.coord, mesh.coord_index, fp_vertices, shapes),
        str(face))
    drop = np.zeros_like(mesh.coord)
    drop[fp_vertices["2.1"]] = (0, -0.1, 0)
    add_shape(obj, "fap3_open_jaw@512", drop)
    with pytest.raises(RuntimeError, match="has no ARKit shape keys .*give an ARKit face"):
        bpy.ops.mpeg4face.import_livelink_capture(filepath=str(CAPTURE), folder=str(tmp_path))
    assert bpy.ops.mpeg4face.import_livelink_capture(
        filepath=str(CAPTURE), folder=str(tmp_path), face_path=str(face)) == {"FINISHED"}
    values = baked(obj, "fap3_open_jaw@512", range(1, 50))
    assert np.ptp(values) > 0.1
    for action in list(bpy.data.actions):
        bpy.data.actions.remove(action)


def test_broken_capture_changes_nothing(arkit_head, tmp_path):
    obj, _, _ = arkit_head
    assert bpy.ops.mpeg4face.arkit_fap_keys() == {"FINISHED"}
    lines = CAPTURE.read_text().splitlines(keepends=True)
    cells = lines[4].split(",")
    cells[3] = "abc"  # line 5, column 4 (EyeLookDownLeft)
    lines[4] = ",".join(cells)
    broken = tmp_path / "broken.csv"
    broken.write_text("".join(lines))
    scene = bpy.context.scene
    before = (scene.render.fps, scene.render.fps_base, scene.frame_start, scene.frame_end,
              len(bpy.data.actions), obj.mpeg4face_stream.filepath)
    with pytest.raises(RuntimeError, match=r"broken\.csv:5: column 4 \(EyeLookDownLeft\)"):
        bpy.ops.mpeg4face.import_livelink_capture(filepath=str(broken),
                                                  folder=str(tmp_path / "out"))
    assert before == (scene.render.fps, scene.render.fps_base, scene.frame_start,
                      scene.frame_end, len(bpy.data.actions), obj.mpeg4face_stream.filepath)
    assert obj.data.shape_keys.animation_data is None and not (tmp_path / "out").exists()
