# SPDX-License-Identifier: GPL-3.0-or-later
"""FAP shape keys, FaceDefTables, MPEG-4 export and cloning on the CANDIDE-3 head: keys
added, mapped and mirrored by the operators, the generate report, .wrl / .glb read back,
a clone onto two heads twice and three times the size (with its progress), and the reports
of bad input. The Basis and every other key are compared before and after each operator.
Run through run_in_blender.py."""

from types import SimpleNamespace

import numpy as np
import pytest

bpy = pytest.importorskip("bpy", reason="runs inside Blender only (see run_in_blender.py)")

import mpeg4face  # noqa: E402

from mpeg4face_blender.logic import feature_points  # noqa: E402
from mpeg4face_blender.scene import mesh_data  # noqa: E402
from mpeg4face_blender.ui.operators import faces as operators_faces  # noqa: E402

JAW = 0.05  # how far the test's open_jaw key moves the chin, in Blender's -Z


def keys_of(obj):
    """Every key's name and positions."""
    keys = obj.data.shape_keys
    if keys is None:
        return {}
    return {k.name: mesh_data.shape_key_coords(k) for k in keys.key_blocks}


def assert_kept(before, after):
    """Every key of `before` is in `after` with the same positions."""
    for name, coords in before.items():
        assert name in after, f"{name} was removed"
        assert np.array_equal(coords, after[name]), f"{name} changed"


def displacement(obj, name):
    keys = obj.data.shape_keys
    return mesh_data.shape_key_coords(keys.key_blocks[name]) - mesh_data.shape_key_coords(
        keys.reference_key)


def only_selected(obj):
    for other in bpy.context.view_layer.objects:
        other.select_set(other == obj)


def sculpt(obj, name, vertices, offset):
    """Moves `vertices` of key `name` by `offset` (Blender's axes)."""
    key = obj.data.shape_keys.key_blocks[name]
    coords = mesh_data.shape_key_coords(key)
    coords[vertices] += offset
    mesh_data.set_shape_key_coords(key, coords)


@pytest.fixture
def head(candide_head):
    """CANDIDE-3, the only selected object, with a user's key "Smirk" and an open_jaw key moving the chin (2.1) down."""
    obj, _, fp_vertices = candide_head
    only_selected(obj)
    obj.shape_key_add(name="Basis", from_mix=False)
    smirk = obj.shape_key_add(name="Smirk", from_mix=False)
    smirk.value = 0.7  # a mix that must not leak into new keys
    sculpt(obj, "Smirk", [fp_vertices["2.4"]], (0.01, 0.0, 0.02))
    before = keys_of(obj)
    assert bpy.ops.mpeg4face.add_fap_shape_key(fap="3", amplitude=512) == {"FINISHED"}
    assert_kept(before, keys_of(obj))
    assert np.array_equal(displacement(obj, "fap3_open_jaw@512"), 0 * displacement(obj, "Smirk"))
    sculpt(obj, "fap3_open_jaw@512", [fp_vertices["2.1"]], (0.0, 0.0, -JAW))
    return obj, fp_vertices


def test_add_keys(head):
    obj, _ = head
    key = obj.data.shape_keys.key_blocks["fap3_open_jaw@512"]
    assert key.relative_key == obj.data.shape_keys.reference_key
    assert (key.slider_min, key.slider_max) == (0.0, 1.0)
    before = keys_of(obj)
    assert bpy.ops.mpeg4face.add_fap_shape_key(fap="6", amplitude=-300) == {"FINISHED"}
    assert bpy.ops.mpeg4face.add_fap_shape_key(fap="3", amplitude=1024) == {"FINISHED"}
    assert bpy.ops.mpeg4face.add_fap_shape_key(kind="VISEME", viseme="1") == {"FINISHED"}
    assert bpy.ops.mpeg4face.add_fap_shape_key(kind="EXPRESSION", expression="1",
                                               intensity=40) == {"FINISHED"}
    blocks = obj.data.shape_keys.key_blocks
    stretch = blocks["fap6_stretch_l_cornerlip@-300"]
    assert (stretch.slider_min, stretch.slider_max) == (-1.0, 1.0)  # bidirectional
    assert {"fap3_open_jaw@1024", "viseme1_p_b_m", "expression1_joy@40"} <= set(blocks.keys())
    assert_kept(before, keys_of(obj))
    # Every added key starts at 0, the face at rest (Blender 5.0 adds keys at 1).
    added = ("fap3_open_jaw@512", "fap6_stretch_l_cornerlip@-300", "fap3_open_jaw@1024",
             "viseme1_p_b_m", "expression1_joy@40")
    assert {k.name: k.value for k in blocks if k.name not in ("Basis", "Smirk")} == dict.fromkeys(
        added, 0.0)
    # A duplicate name is refused, and nothing changes.
    before = keys_of(obj)
    with pytest.raises(RuntimeError, match="already has a shape key fap3_open_jaw@512"):
        bpy.ops.mpeg4face.add_fap_shape_key(fap="3", amplitude=512)
    assert keys_of(obj).keys() == before.keys()


def mapping(key, use, **choice):
    """A row of Map Shape Keys' table; bpy.ops wants every property of a collection item."""
    row = {"name": key, "key": key, "use": use, "kind": "FAP", "fap": "3", "viseme": "1",
           "expression": "1", "amplitude": 1024, "intensity": 63}
    return row | choice


def test_map_shape_keys(head):
    obj, fp_vertices = head
    jaw = obj.shape_key_add(name="jawOpen", from_mix=False)
    sculpt(obj, "jawOpen", [fp_vertices["2.1"]], (0.0, 0.0, -0.03))
    before = keys_of(obj)
    assert bpy.ops.mpeg4face.map_shape_keys(mappings=[
        mapping("jawOpen", True, fap="3", amplitude=300), mapping("Smirk", False)
    ]) == {"FINISHED"}
    after = keys_of(obj)
    assert_kept(before, after)
    assert np.array_equal(after["fap3_open_jaw@300"], after["jawOpen"])
    assert jaw.name == "jawOpen"
    assert set(after) - set(before) == {"fap3_open_jaw@300"}
    # Without rows the suggestions apply: jawOpen -> FAP 3 at the default amplitude;
    # Smirk has none.
    assert bpy.ops.mpeg4face.map_shape_keys() == {"FINISHED"}
    assert set(keys_of(obj)) - set(after) == {"fap3_open_jaw@1024"}


def test_mirror_shape_key(head):
    obj, fp_vertices = head
    assert bpy.ops.mpeg4face.add_fap_shape_key(fap="6", amplitude=200) == {"FINISHED"}
    left, right = fp_vertices["2.4"], fp_vertices["2.5"]  # left / right lip corners
    sculpt(obj, "fap6_stretch_l_cornerlip@200", [left], (0.02, -0.01, 0.005))
    before = keys_of(obj)
    assert bpy.ops.mpeg4face.mirror_shape_key() == {"FINISHED"}
    assert_kept(before, keys_of(obj))
    d = displacement(obj, "fap7_stretch_r_cornerlip@200")
    assert np.allclose(d[right], (-0.02, -0.01, 0.005), atol=1e-6)
    moved = np.flatnonzero(np.abs(d).max(axis=1) > 0)
    assert moved.tolist() == [right]
    key = obj.data.shape_keys.key_blocks["fap7_stretch_r_cornerlip@200"]
    assert key.slider_min == -1.0
    # A FAP without a partner, and a second mirror onto the same name, are refused.
    with pytest.raises(RuntimeError, match="already has a shape key"):
        bpy.ops.mpeg4face.mirror_shape_key()
    obj.active_shape_key_index = list(obj.data.shape_keys.key_blocks.keys()).index(
        "fap3_open_jaw@512")
    with pytest.raises(RuntimeError, match="has no left/right partner"):
        bpy.ops.mpeg4face.mirror_shape_key()


def test_mirror_shape_key_of_a_head_off_the_middle(head):
    """A head modelled away from X = 0 (and turned) mirrors across the plane of its
    left/right feature points."""
    from mathutils import Matrix

    obj, fp_vertices = head
    obj.data.transform(Matrix.Translation((0.25, 0.1, 0)) @ Matrix.Rotation(0.2, 4, "Z"),
                       shape_keys=True)
    assert bpy.ops.mpeg4face.add_fap_shape_key(fap="6", amplitude=200) == {"FINISHED"}
    left, right = fp_vertices["2.4"], fp_vertices["2.5"]
    turn = np.array(Matrix.Rotation(0.2, 3, "Z"))
    sculpt(obj, "fap6_stretch_l_cornerlip@200", [left], tuple(turn @ (0.02, -0.01, 0.005)))
    assert bpy.ops.mpeg4face.mirror_shape_key() == {"FINISHED"}
    d = displacement(obj, "fap7_stretch_r_cornerlip@200")
    assert np.allclose(d[right], turn @ (-0.02, -0.01, 0.005), atol=1e-5)
    assert np.flatnonzero(np.abs(d).max(axis=1) > 0).tolist() == [right]


def test_generate_tables(head):
    obj, _ = head
    before = keys_of(obj)
    assert bpy.ops.mpeg4face.generate_tables() == {"FINISHED"}
    assert_kept(before, keys_of(obj))
    report = operators_faces.table_reports[obj.name]
    assert report.covered == ["fap3 open_jaw"] and report.moved == [1]
    assert report.copies == 1 and report.ignored == ["Smirk"]


def test_export_vrml_and_gltf(head, tmp_path, progress):
    obj, fp_vertices = head
    wrl, glb = tmp_path / "head.wrl", tmp_path / "head.glb"
    assert bpy.ops.mpeg4face.export_vrml(filepath=str(wrl)) == {"FINISHED"}
    assert bpy.ops.mpeg4face.export_gltf(filepath=str(glb)) == {"FINISHED"}
    assert progress == ([2, 2], [1, 2, 1, 2])  # the tables generated, then the file written
    face = mpeg4face.read_vrml(wrl)
    [table] = face.tables
    assert table["fap"] == 3 and table["meshes"][0]["vertices"] == 1
    # Evaluated at its amplitude the table reproduces the key (standard axes: Y up).
    mask, values = np.zeros((1, 68), dtype=bool), np.zeros((1, 68), dtype=np.int32)
    mask[0, 2], values[0, 2] = True, 512
    stream = mpeg4face.FapStream.from_arrays([0], mask, values)
    coord = mpeg4face.FatEvaluator(face).evaluate(stream, 0)["coord"][0]
    neutral = mpeg4face.FatEvaluator(face).neutral()["coord"][0]
    assert np.allclose(coord[fp_vertices["2.1"]] - neutral[fp_vertices["2.1"]], (0, -JAW, 0),
                       atol=1e-5)
    model = mpeg4face.read_gltf(glb)
    names = [t.name for m in model.meshes for t in m.morph_targets]
    assert any("fap3" in n for n in names), names
    # The FDP: every feature point of the head, on its vertex.
    assert {fp: b.vertex for fp, b in model.feature_points.items()} == fp_vertices


def test_exported_gltf_opens_in_blenders_gltf_importer(head, tmp_path, progress):
    """A third-party reader of our glTF: Blender's own importer (io_scene_gltf2) opens the
    exported face with its meshes and one shape key per morph target, named as we wrote."""
    glb = tmp_path / "head.glb"
    assert bpy.ops.mpeg4face.export_gltf(filepath=str(glb)) == {"FINISHED"}
    written = mpeg4face.read_gltf(glb)
    np.bool = bool  # Debian's importer still uses the alias numpy 1.24 removed
    before = set(bpy.data.objects)
    assert bpy.ops.import_scene.gltf(filepath=str(glb)) == {"FINISHED"}
    imported = [o for o in bpy.data.objects if o not in before and o.type == "MESH"]
    # The importer keeps the vertices that faces use (CANDIDE-3 has a few loose ones).
    assert sorted(len(o.data.vertices) for o in imported) == sorted(
        len(np.unique(m.triangles())) for m in written.meshes)
    keys = {k.name for o in imported if o.data.shape_keys for k in o.data.shape_keys.key_blocks}
    assert {t.name for m in written.meshes for t in m.morph_targets} <= keys


def scaled_copy(source, fp_vertices, scale):
    """A selected copy of the head's Basis `scale` times as large, with its feature points
    and a key of its own, "Mine"."""
    data = source.data.copy()
    target = bpy.data.objects.new(f"target x{scale}", data)
    bpy.context.scene.collection.objects.link(target)
    target.shape_key_clear()
    data.vertices.foreach_set("co", (operators_faces.basis_coords(target) * scale).ravel())
    target.shape_key_add(name="Basis", from_mix=False)
    target.shape_key_add(name="Mine", from_mix=False)
    for group in source.vertex_groups:
        fp = feature_points.feature_point_of_group(group.name)
        if fp:
            target.vertex_groups.new(name=group.name).add([fp_vertices[fp]], 1.0, "REPLACE")
    target.select_set(True)
    return target


@pytest.fixture
def progress(monkeypatch):
    """(steps, updates): what the operators give window_manager.progress_begin and
    progress_update. The RNA functions cannot be replaced, so with_progress is wrapped and
    its update recorded on the way to the window manager's."""
    steps, updates = [], []
    with_progress = operators_faces.with_progress

    def recording(context, count, work):
        steps.append(count)

        def recorded_work(update):
            def recorded_update(value):
                updates.append(value)
                update(value)

            return work(recorded_update)

        return with_progress(context, count, recorded_work)

    monkeypatch.setattr(operators_faces, "with_progress", recording)
    return steps, updates


def test_clone_onto_scaled_heads(head, progress):
    source, fp_vertices = head
    targets = {scale: scaled_copy(source, fp_vertices, scale) for scale in (2, 3)}
    steps, updates = progress
    try:
        bpy.context.view_layer.objects.active = source
        before = {obj.name: keys_of(obj) for obj in (source, *targets.values())}
        assert bpy.ops.mpeg4face.clone_motion() == {"FINISHED"}
        for obj in (source, *targets.values()):
            assert_kept(before[obj.name], keys_of(obj))
        chin = fp_vertices["2.1"]
        for scale, target in targets.items():
            cloned = displacement(target, "fap3_open_jaw@512")
            assert target.data.shape_keys.key_blocks["fap3_open_jaw@512"].value == 0.0
            assert np.allclose(cloned[chin],
                               scale * displacement(source, "fap3_open_jaw@512")[chin],
                               atol=1e-3), target.name
        # One progress step per target, each target's updates within its step.
        assert steps == [2]
        assert updates == sorted(updates)
        assert any(0 <= u < 1 for u in updates) and any(1 <= u < 2 for u in updates)
        assert updates[-1] == pytest.approx(2)
        # Cloning again replaces the grammar key in place.
        assert bpy.ops.mpeg4face.clone_motion() == {"FINISHED"}
        for target in targets.values():
            names = target.data.shape_keys.key_blocks.keys()
            assert names.count("fap3_open_jaw@512") == 1, target.name
    finally:
        for target in targets.values():
            data = target.data
            bpy.data.objects.remove(target)
            bpy.data.meshes.remove(data)


def test_bad_input_reports(candide_head, tmp_path):
    obj, _, _ = candide_head
    only_selected(obj)
    for op in (bpy.ops.mpeg4face.generate_tables, bpy.ops.mpeg4face.map_shape_keys,
               bpy.ops.mpeg4face.mirror_shape_key, bpy.ops.mpeg4face.clone_motion):
        with pytest.raises(RuntimeError, match="no shape keys"):
            op()
    with pytest.raises(RuntimeError, match="no shape keys"):
        bpy.ops.mpeg4face.export_vrml(filepath=str(tmp_path / "x.wrl"))
    with pytest.raises(RuntimeError, match="camera object, not a mesh"):
        bpy.ops.mpeg4face.export_gltf(filepath=str(tmp_path / "x.glb"), object_name="Camera")
    with pytest.raises(RuntimeError, match="No object Nobody"):
        bpy.ops.mpeg4face.export_gltf(filepath=str(tmp_path / "x.glb"), object_name="Nobody")
    with pytest.raises(RuntimeError, match="Amplitude 0"):
        bpy.ops.mpeg4face.add_fap_shape_key(fap="3", amplitude=0)
    bpy.ops.mpeg4face.add_fap_shape_key(fap="3", amplitude=512)
    with pytest.raises(RuntimeError, match="Select the target meshes"):
        bpy.ops.mpeg4face.clone_motion()
    cube = bpy.data.objects["Cube"]  # the factory scene's: no feature points
    cube.select_set(True)
    with pytest.raises(RuntimeError, match="Cube has no feature points"):
        bpy.ops.mpeg4face.clone_motion()
    cube.select_set(False)
    # Missing FAPU feature points: the core names them, nothing is written.
    obj.vertex_groups.remove(obj.vertex_groups["FP_9.15"])
    with pytest.raises(RuntimeError, match="needs 9.15 and 2.2"):
        bpy.ops.mpeg4face.export_vrml(filepath=str(tmp_path / "x.wrl"))
    assert not (tmp_path / "x.wrl").exists()
    for group in list(obj.vertex_groups):
        obj.vertex_groups.remove(group)
    with pytest.raises(RuntimeError, match="no feature points"):
        bpy.ops.mpeg4face.generate_tables()
    bpy.ops.object.mode_set(mode="EDIT")
    with pytest.raises(RuntimeError, match="Object Mode"):
        bpy.ops.mpeg4face.add_fap_shape_key(fap="3", amplitude=100)
    bpy.ops.object.mode_set(mode="OBJECT")
    bpy.context.view_layer.objects.active = None
    with pytest.raises(RuntimeError, match="No active object"):
        bpy.ops.mpeg4face.generate_tables()


def test_export_menu_entries():
    from test_addon_feature_points import draw

    from mpeg4face_blender.ui.operators import export

    assert export._menu in bpy.types.TOPBAR_MT_file_export._dyn_ui_initialize()
    lines = draw(SimpleNamespace(draw=export._menu))
    assert lines == ["operator mpeg4face.export_vrml: MPEG-4 Face (.wrl)",
                     "operator mpeg4face.export_gltf: MPEG-4 Face glTF (.glb)"]


def test_export_options_sub_panels():
    """The file browser's operator panel shows the options in sub-panels for our two
    exporters only; each draws its property of the running operator."""
    from mpeg4face_blender.ui.operators import export

    class Recording:
        def __init__(self):
            self.props = []

        def prop(self, data, name, *args):
            self.props.append(name)

        def prop_search(self, data, name, *args):
            self.props.append(name)

    panels = {"Head": "object_name", "FaceDefTables": "threshold"}
    for cls in (export.MPEG4FACE_PT_export_head, export.MPEG4FACE_PT_export_tables):
        assert getattr(bpy.types, cls.__name__).bl_parent_id == "FILE_PT_operator"
        for idname in ("MPEG4FACE_OT_export_vrml", "MPEG4FACE_OT_export_gltf"):
            operator = SimpleNamespace(bl_idname=idname)
            context = SimpleNamespace(space_data=SimpleNamespace(active_operator=operator))
            assert cls.poll(context)
            layout = Recording()
            cls.draw(SimpleNamespace(layout=layout), context)
            assert layout.props == [panels[cls.bl_label]]
        other = SimpleNamespace(bl_idname="EXPORT_SCENE_OT_gltf")
        assert not cls.poll(SimpleNamespace(space_data=SimpleNamespace(active_operator=other)))
        assert not cls.poll(SimpleNamespace(space_data=SimpleNamespace()))


def test_panels(head):
    from test_addon_feature_points import draw, draw_joined

    from mpeg4face_blender.ui.panels import faces as panels_faces

    obj, _ = head
    operators_faces.table_reports.clear()  # earlier tests' heads had the same name
    lines = draw(panels_faces.MPEG4FACE_PT_shape_keys)
    assert lines[0] == "1 shape keys named for MPEG-4"
    assert "operator mpeg4face.mirror_shape_key: " in lines
    assert "Not generated yet" in draw(panels_faces.MPEG4FACE_PT_face_tables)
    bpy.ops.mpeg4face.generate_tables()
    lines = draw_joined(panels_faces.MPEG4FACE_PT_face_tables)
    # the summary in the panel, the whole report (a line per table) in a popup
    assert "1 FaceDefTables from 1 shape keys" in lines
    assert "operator mpeg4face.show_report: " in lines
    assert "fap3 open_jaw: 1 vertices" in operators_faces.table_reports[obj.name].lines()
    assert bpy.ops.mpeg4face.show_report(kind="TABLES") == {"FINISHED"}
    lines = draw_joined(panels_faces.MPEG4FACE_PT_cloning)
    assert "Targets: select other meshes" in lines
