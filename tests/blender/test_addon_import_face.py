# SPDX-License-Identifier: GPL-3.0-or-later
"""File > Import > MPEG-4 face (.wrl) and its drop on the viewport: CANDIDE-3 with its FAP
units, a viseme, an expression at two intensities and an eye below the head (a key of its
own, the pupil 3.5 on it and a head_yaw pose turning it), written by the core and imported:
the objects, FP_ groups and grammar keys, each key equal to the tables evaluated at its
amplitude, the tables the add-on exports from them giving the same motion, what is not
imported, a bad file leaving nothing behind. Run through run_in_blender.py."""

import math
from types import SimpleNamespace

import numpy as np
import pytest

bpy = pytest.importorskip("bpy", reason="runs inside Blender only (see run_in_blender.py)")

import mpeg4face  # noqa: E402
from conftest import DATA  # noqa: E402

from mpeg4face_blender.logic import face_import, feature_points  # noqa: E402
from mpeg4face_blender.scene import compat, mesh_data  # noqa: E402
from mpeg4face_blender.ui.operators import faces as operators_faces  # noqa: E402
from mpeg4face_blender.ui.operators import import_face  # noqa: E402

EYE_AT = (0.1, 0.3, 0.2)  # the eye's Transform, standard axes


def candide_face() -> mpeg4face.MpegFace:
    """CANDIDE-3's FAP units, viseme1, expression1 at 40 and 63, an eye (FAP 43 key, 3.5)
    under the head's Transform, a FAP 49 pose turning the eye: the generated face."""
    wfm = DATA / "candide3" / "candide3.wfm"
    model = mpeg4face.read_model(wfm)
    points, _ = mpeg4face.read_feature_point_csv(DATA / "candide3" / "feature_points.csv",
                                                 model)
    model.feature_points = points
    model = mpeg4face.name_candide_fap_units(model, mpeg4face.read_wfm(wfm))
    head = model.meshes[0]
    jaw = next(t for t in head.morph_targets if t.name.startswith("fap3_")).displacements
    head.morph_targets = [*head.morph_targets, mpeg4face.MorphTarget("viseme1", 0.5 * jaw),
                          mpeg4face.MorphTarget("expression1@40", 0.3 * jaw),
                          mpeg4face.MorphTarget("expression1", 0.6 * jaw)]
    eye = mpeg4face.IndexedFaceSet("eye_l", [(0, 0, 0), (0.02, 0, 0), (0, 0.02, 0),
                                             (0, 0, 0.02)],
                                   [0, 1, 2, -1, 0, 1, 3, -1, 0, 2, 3, -1, 1, 2, 3, -1])
    forward = np.zeros((4, 3))
    forward[1] = (0, 0, 0.01)
    eye.morph_targets = [mpeg4face.MorphTarget("fap43@300", forward)]
    root = model.transforms[0]
    root.children = [1]
    fps = dict(model.feature_points)
    fps["3.5"] = mpeg4face.FeaturePointBinding(1, 0)
    turn = mpeg4face.TransformChannel(1, mpeg4face.TransformChannel.Path.ROTATION, times=[0.0],
                                      values=[0, math.sin(0.1), 0, math.cos(0.1)])
    model = mpeg4face.FaceModel(
        meshes=[head, eye], roots=[0], feature_points=fps,
        transforms=[root, mpeg4face.Transform("eye_l", translation=EYE_AT, meshes=[1])],
        animations=[mpeg4face.MorphWeightAnimation("fap49@20000", transform_channels=[turn])])
    return mpeg4face.generate_face(model)["face"]


@pytest.fixture
def face_file(tmp_path):
    path = tmp_path / "candide_face.wrl"
    mpeg4face.write_vrml(candide_face(), path)
    return path


@pytest.fixture
def imported(face_file):
    """The face imported with no object active; the new objects removed afterwards."""
    before = set(bpy.data.objects)
    bpy.context.view_layer.objects.active = None
    assert bpy.ops.mpeg4face.import_mpeg4_face(filepath=str(face_file)) == {"FINISHED"}
    made = [o for o in bpy.data.objects if o not in before]
    yield bpy.context.view_layer.objects.active, made
    for obj in made:
        data = obj.data
        bpy.data.objects.remove(obj)
        bpy.data.meshes.remove(data)


def frame_of(name: str) -> mpeg4face.FapStream:
    """A one-frame stream of the key's FAP (viseme, expression) alone at its amplitude."""
    parsed = mpeg4face.parse_shape_key_name(name)
    return stream_at(parsed["fap"], parsed["select"], parsed["amplitude"])


def stream_at(fap: int, select: int, value: int) -> mpeg4face.FapStream:
    mask, values = np.zeros((1, 68), dtype=bool), np.zeros((1, 68), dtype=np.int32)
    visemes, expressions = np.zeros((1, 4), dtype=np.int32), np.zeros((1, 6), dtype=np.int32)
    mask[0, fap - 1] = True
    if fap == 1:
        visemes[0] = (select, 0, value, 0)
    elif fap == 2:
        expressions[0, :2] = (select, value)
    else:
        mask[0, 2:] = True  # the others at 0: a FAP not sent takes its partner's value
        values[0, fap - 1] = value
    return mpeg4face.FapStream.from_arrays([0], mask, values, visemes, expressions)


def motion(face: mpeg4face.MpegFace, stream: mpeg4face.FapStream) -> list[np.ndarray]:
    """Each mesh's motion from the neutral (standard axes) in the stream's first frame."""
    evaluator = mpeg4face.FatEvaluator(face)
    neutral = evaluator.neutral()["coord"]
    return [c - n for c, n in zip(evaluator.evaluate(stream, 0)["coord"], neutral)]


def key_motion(obj, name):
    keys = obj.data.shape_keys
    return feature_points.to_standard_axes(
        mesh_data.shape_key_coords(keys.key_blocks[name])
        - mesh_data.shape_key_coords(keys.reference_key))


def test_import_makes_the_head_its_parts_feature_points_and_keys(imported, face_file):
    head, made = imported
    face = mpeg4face.read_vrml(face_file)
    model = face.scene_graph
    assert head.name.startswith("candide3") and len(made) == 2
    [eye] = [o for o in made if o is not head]
    assert eye.parent is head and eye.name.startswith("eye_l")
    assert len(head.data.vertices) == model.meshes[0].vertex_count == 113
    assert len(head.data.polygons) == 184 and len(eye.data.vertices) == 4
    assert {o.name for o in bpy.context.selected_objects} == {head.name, eye.name}
    # The eye where its Transform puts it, in Blender's axes.
    assert np.allclose(np.array(eye.matrix_world)[:3, 3],
                       feature_points.to_blender_axes([EYE_AT])[0], atol=1e-6)
    # Feature points: FP_ groups of one vertex each, on the mesh holding them.
    for obj, mesh in ((head, 0), (eye, 1)):
        groups = {g.name: [v for v, _ in members]
                  for g, members in ((g, mesh_data.fp_groups(obj)[g.name])
                                     for g in obj.vertex_groups)}
        assert groups == {f"FP_{fp}": [b.vertex] for fp, b in model.feature_points.items()
                          if b.mesh == mesh}
    # A key per table and non-zero border, moving the face as the tables do there.
    expected = set()
    for table in face.tables:
        if table["fap"] == 1:
            expected.add(f"viseme{table['select']}")
        elif table["fap"] == 2:
            expected |= {f"expression{table['select']}@40", f"expression{table['select']}"}
        else:
            expected |= {(table["fap"], b) for m in table["meshes"]
                         for b in m["interval_borders"] if b}
    names = operators_faces.key_names(head) + operators_faces.key_names(eye)
    parsed = {n: mpeg4face.parse_shape_key_name(n) for n in names}
    assert {(p["fap"], p["amplitude"]) if p["fap"] > 2 else n.split("_")[0] + (
        f"@{p['amplitude']}" if p["amplitude"] != 63 else "") for n, p in parsed.items()} \
        == expected
    assert operators_faces.key_names(eye) == ["fap43_shift_tongue_tip@300"]
    size = float(np.linalg.norm(np.ptp(model.meshes[0].coord, axis=0)))
    for obj, mesh in ((head, 0), (eye, 1)):
        for name in operators_faces.key_names(obj):
            assert np.allclose(key_motion(obj, name), motion(face, frame_of(name))[mesh],
                               atol=1e-6 * size), name
    assert head.data.shape_keys.key_blocks["fap3_open_jaw@1000"].value == 0.0


def test_the_exported_tables_move_the_face_as_the_imported_ones(imported, face_file, tmp_path):
    """Import, then export: the FaceDefTables generated from the keys give the imported
    tables' motion at the borders, between them and beyond them."""
    head, _ = imported
    original = mpeg4face.read_vrml(face_file)
    wrl = tmp_path / "again.wrl"
    assert bpy.ops.mpeg4face.export_vrml(filepath=str(wrl), object_name=head.name) \
        == {"FINISHED"}
    again = mpeg4face.read_vrml(wrl)
    meshed = {(t["fap"], t["select"]) for t in original.tables if t["meshes"]}
    assert {(t["fap"], t["select"]) for t in again.tables} == meshed
    size = float(np.linalg.norm(np.ptp(original.scene_graph.meshes[0].coord, axis=0)))
    for table in original.tables:
        if not table["meshes"]:
            continue
        fap, select = table["fap"], table["select"]
        values = [20, 40, 63] if fap <= 2 else [-1500, -1000, -400, 300, 1000, 1700]
        for value in values:
            stream = stream_at(fap, select, value)
            for a, b in zip(motion(original, stream), motion(again, stream)):
                assert np.allclose(a, b, atol=1e-5 * size), (fap, select, value)


def test_what_is_not_imported_is_named(face_file):
    face = face_import.imported_face(mpeg4face.read_vrml(face_file), "candide_face")
    assert face.not_imported == [
        "the FaceDefTransforms (Transforms eye_l turned, moved or scaled) of FAP 49 head_yaw: "
        "shape keys move vertices only"]


def test_a_bad_file_leaves_nothing(monkeypatch, face_file):
    objects, meshes = set(bpy.data.objects), set(bpy.data.meshes)
    bad = DATA / "malformed" / "vrml_truncated.wrl"
    with pytest.raises(RuntimeError, match="Nothing imported: .*vrml_truncated.wrl:7: "):
        bpy.ops.mpeg4face.import_mpeg4_face(filepath=str(bad))
    assert set(bpy.data.objects) == objects and set(bpy.data.meshes) == meshes
    # A failure while the objects are made (the eye's key here) removes those made.
    add_key = operators_faces.add_key

    def fail_on_the_eye(obj, name, coords=None):
        if name.startswith("fap43"):
            raise RuntimeError("out of memory")
        return add_key(obj, name, coords)

    monkeypatch.setattr(operators_faces, "add_key", fail_on_the_eye)
    with pytest.raises(RuntimeError, match="out of memory"):
        bpy.ops.mpeg4face.import_mpeg4_face(filepath=str(face_file))
    assert set(bpy.data.objects) == objects and set(bpy.data.meshes) == meshes


def test_a_dropped_face_is_imported_without_the_file_browser():
    """The FileHandler (Blender 4.1 and later) hands a dropped .wrl to the import, whose
    invoke then imports it at once (a path set by the caller)."""
    fh = getattr(bpy.types, "MPEG4FACE_FH_mpeg4_face", None)
    assert (fh is not None) is compat.FILE_HANDLERS
    if fh is not None:
        assert fh.bl_import_operator == "mpeg4face.import_mpeg4_face"
        assert fh.bl_file_extensions == ".wrl"
    calls = []
    dropped = SimpleNamespace(properties=SimpleNamespace(is_property_set=lambda *a, **k: True),
                              execute=lambda context: calls.append(context) or {"FINISHED"})
    op = import_face.MPEG4FACE_OT_import_mpeg4_face
    assert op.invoke(dropped, bpy.context, None) == {"FINISHED"} and len(calls) == 1


def test_import_menu_entry():
    from test_addon_feature_points import draw

    assert import_face.face_import_menu in bpy.types.TOPBAR_MT_file_import._dyn_ui_initialize()
    assert draw(SimpleNamespace(draw=import_face.face_import_menu)) == [
        "operator mpeg4face.import_mpeg4_face: MPEG-4 face (.wrl)"]
