# SPDX-License-Identifier: GPL-3.0-or-later
"""The add-on's operators and panel on CANDIDE-3: assigning feature points, the list's
statuses, the FAPU read-out, Table 6 warnings, the mirror helper and error reports.
Run through run_in_blender.py."""

from types import SimpleNamespace

import pytest

bpy = pytest.importorskip("bpy", reason="runs inside Blender only (see run_in_blender.py)")

import bmesh  # noqa: E402
import mpeg4face  # noqa: E402
from conftest import group_members  # noqa: E402

from mpeg4face_blender.logic import feature_points  # noqa: E402
from mpeg4face_blender.scene import mesh_data  # noqa: E402
from mpeg4face_blender.ui import properties  # noqa: E402
from mpeg4face_blender.ui.panels import feature_points as panels  # noqa: E402


def edit_and_select(obj, vertices):
    """Edit Mode with exactly `vertices` selected."""
    if obj.mode != "EDIT":
        bpy.ops.object.mode_set(mode="EDIT")
    bm = bmesh.from_edit_mesh(obj.data)
    bm.verts.ensure_lookup_table()
    for v in bm.verts:
        v.select_set(False)
    for i in vertices:
        bm.verts[i].select_set(True)
    bm.select_flush_mode()
    bmesh.update_edit_mesh(obj.data)


class Layout:
    """Stands in for bpy.types.UILayout: records the labels and operator buttons drawn."""

    def __init__(self, log=None):
        self.log = [] if log is None else log

    def label(self, text="", icon="NONE"):
        self.log.append((text, icon))

    def operator(self, idname, text="", icon="NONE"):
        self.log.append((f"operator {idname}: {text}", icon))
        return SimpleNamespace()

    def template_list(self, *args, **kwargs):
        self.log.append(("template_list", args[0]))

    def prop(self, *args, **kwargs):
        pass

    def __getattr__(self, name):  # row(), column(), box(), split(): sub-layouts
        return lambda *args, **kwargs: Layout(self.log)


def draw(panel, context=None):
    """The panel's labels and buttons; a label wrapped to the panel's width (its lines after
    the first are marked BLANK1, or follow an icon-less one) read as one."""
    layout = Layout()
    panel.draw(SimpleNamespace(layout=layout), context or bpy.context)
    return [text for text, _ in layout.log]


def draw_joined(panel, context=None):
    layout = Layout()
    panel.draw(SimpleNamespace(layout=layout), context or bpy.context)
    out = []
    for text, icon in layout.log:
        if icon == "BLANK1" and out:
            out[-1] += " " + text
        else:
            out.append(text)
    return out


def test_assign_and_reassign(candide_head):
    obj, _, fp_vertices = candide_head
    edit_and_select(obj, [5])
    assert bpy.ops.mpeg4face.assign_feature_point(feature_point="3.5") == {"FINISHED"}
    assert group_members(obj, "FP_3.5") == [(5, 1.0)]
    edit_and_select(obj, [7])
    assert bpy.ops.mpeg4face.assign_feature_point(feature_point="3.5") == {"FINISHED"}
    assert group_members(obj, "FP_3.5") == [(7, 1.0)]  # moved, not added
    # Reassigning an existing point (from the CSV) replaces its vertex too.
    edit_and_select(obj, [fp_vertices["2.1"] + 1])
    bpy.ops.mpeg4face.assign_feature_point(feature_point="2.1")
    assert group_members(obj, "FP_2.1") == [(fp_vertices["2.1"] + 1, 1.0)]
    # Other groups are untouched.
    assert group_members(obj, "FP_9.15") == [(fp_vertices["9.15"], 1.0)]


@pytest.mark.parametrize("selected, message", [
    ([], r"Select exactly one vertex \(0 are selected\)"),
    ([1, 2], r"Select exactly one vertex \(2 are selected\)"),
])
def test_assign_needs_one_selected_vertex(candide_head, selected, message):
    obj, _, _ = candide_head
    edit_and_select(obj, selected)
    # bpy.ops turns an operator's ERROR report into RuntimeError for Python callers; in the
    # UI it is a report, and the operator returns CANCELLED.
    with pytest.raises(RuntimeError, match=message):
        bpy.ops.mpeg4face.assign_feature_point(feature_point="3.5")
    assert group_members(obj, "FP_3.5") is None


def test_bad_input_is_reported(candide_head):
    obj, _, _ = candide_head
    with pytest.raises(RuntimeError, match="Switch to Edit Mode and select one vertex"):
        bpy.ops.mpeg4face.assign_feature_point(feature_point="3.5")
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    bpy.context.scene.collection.objects.link(camera)
    try:
        bpy.context.view_layer.objects.active = camera
        for op in (bpy.ops.mpeg4face.assign_feature_point, bpy.ops.mpeg4face.mirror_feature_points):
            with pytest.raises(RuntimeError, match="camera is a camera object, not a mesh"):
                op()
        bpy.context.view_layer.objects.active = None
        for op in (bpy.ops.mpeg4face.assign_feature_point, bpy.ops.mpeg4face.mirror_feature_points):
            with pytest.raises(RuntimeError, match="No active object"):
                op()
    finally:
        bpy.data.objects.remove(camera)
        bpy.context.view_layer.objects.active = obj
    for group in [g for g in obj.vertex_groups]:
        obj.vertex_groups.remove(group)
    with pytest.raises(RuntimeError, match="candide3 has no feature points"):
        bpy.ops.mpeg4face.mirror_feature_points()


def test_state_statuses_fapu_and_warnings(candide_head):
    obj, model, fp_vertices = candide_head
    expected = mpeg4face.measure_fapu(model)
    for mode in ("OBJECT", "EDIT"):  # Edit Mode reads the edit bmesh
        bpy.ops.object.mode_set(mode=mode)
        state = mesh_data.read_face_state(obj, 0.02)
        assert {r.id: r.vertex for r in state.rows if r.is_set} == fp_vertices
        for reading in state.fapu:
            distance = getattr(expected, reading.name.lower())
            assert reading.measured
            assert reading.value == pytest.approx(distance.value, rel=1e-6)
            assert reading.unit == pytest.approx(distance.value / 1024, rel=1e-6)
            assert reading.points_used == distance.points_used
        assert [w.message for w in state.location_warnings] == [
            w.message for w in mpeg4face.check_location_constraints(model, expected, 0.02)]
    assert state.group_warnings == []


def test_panels_draw_the_state(candide_head):
    obj, model, fp_vertices = candide_head
    properties.fill_all()  # as after a file load (no event loop runs the timer here)
    bpy.context.view_layer.objects.active = obj
    es0 = mpeg4face.measure_fapu(model).es0.value
    main = draw_joined(panels.MPEG4FACE_PT_feature_points)
    assert "missing for FAPU: 3.5, 3.6" in main
    assert "complete for cloning" in main
    assert "operator mpeg4face.assign_feature_point: Assign 2.1 to Selected Vertex" in main
    fapu = draw(panels.MPEG4FACE_PT_fapu)
    assert fapu[:2] == [f"ES0 = {es0:.5g}", f"    FAPU = {es0 / 1024:.5g}"]
    # the points and the formula, wrapped to the panel's width (indented lines)
    assert [line.strip() for line in fapu[2:4]] == ["from 3.7, 3.11, 3.8, 3.12:",
                                                    "|(3.7+3.11)/2 - (3.8+3.12)/2|"]
    warnings = draw_joined(panels.MPEG4FACE_PT_location_warnings)
    assert len(warnings) == 5 and warnings[0].startswith("4.3.x differs from")

    # The list's rows: set with the vertex, or missing; the F / C flags.
    wm = bpy.context.window_manager
    items = {item.fp_id: (i, item) for i, item in enumerate(wm.mpeg4face_feature_points)}

    def row(fp):
        layout = Layout()
        index, item = items[fp]
        panels.MPEG4FACE_UL_feature_points.draw_item(
            None, bpy.context, layout, wm, item, 0, wm, "mpeg4face_feature_point_index", index)
        return layout.log

    assert row("9.15") == [("9.15", "CHECKMARK"), (f"v {fp_vertices['9.15']}", "NONE"),
                           ("FC", "NONE")]
    assert row("3.5") == [("3.5", "X"), ("missing", "NONE"), ("F", "NONE")]

    # Removing 9.15: the FAPU that need it say so, after the next depsgraph update.
    obj.vertex_groups.remove(obj.vertex_groups["FP_9.15"])
    bpy.context.view_layer.update()
    panels._forget()
    fapu = draw_joined(panels.MPEG4FACE_PT_fapu)
    assert "MNS0 unmeasured: needs 9.15 and 2.2" in fapu
    assert "missing for FAPU: 3.5, 3.6, 9.15" in draw_joined(panels.MPEG4FACE_PT_feature_points)


def test_panel_without_a_mesh(candide_head):
    bpy.context.view_layer.objects.active = None
    assert draw_joined(panels.MPEG4FACE_PT_feature_points) == [
        "Make the head mesh the active object"]
    assert draw(panels.MPEG4FACE_PT_fapu) == []


def test_mirror_places_missing_partners(candide_head):
    obj, _, fp_vertices = candide_head
    coords = {v.index: v.co.copy() for v in obj.data.vertices}
    removed = [fp for fp, v in fp_vertices.items()
               if coords[v].x < 0 and fp in feature_points.mirror_partners()]
    assert len(removed) > 20
    for fp in removed:
        obj.vertex_groups.remove(obj.vertex_groups[f"FP_{fp}"])
    assert bpy.ops.mpeg4face.mirror_feature_points(source="MISSING") == {"FINISHED"}
    for fp in removed:
        members = group_members(obj, f"FP_{fp}")
        assert members is not None and len(members) == 1 and members[0][1] == 1.0, fp
        # CANDIDE-3 is symmetric: the partner sits where the CSV puts it (on a closed
        # mouth two vertices share that place).
        assert (coords[members[0][0]] - coords[fp_vertices[fp]]).length < 1e-6, fp


def test_mirror_refuses_beyond_tolerance(candide_head, capfd):
    obj, _, fp_vertices = candide_head
    obj.vertex_groups.remove(obj.vertex_groups["FP_3.12"])
    obj.data.vertices[fp_vertices["3.12"]].co.z += 0.1  # the partner's place has no vertex
    # 1% of the bounding-box diagonal: the nearest vertex is farther.
    assert bpy.ops.mpeg4face.mirror_feature_points(source="MISSING", tolerance=0.01) == {
        "FINISHED"}
    assert group_members(obj, "FP_3.12") is None
    # Background Blender prints the reports.
    out = capfd.readouterr().out
    assert "Warning: 3.12 skipped: the vertex nearest to the mirror image of 3.7 is 0.09" in out
    assert "Warning: Mirrored 0 feature points, skipped 1" in out
    bpy.ops.mpeg4face.mirror_feature_points(source="MISSING", tolerance=0.2)
    nearest = group_members(obj, "FP_3.12")
    assert len(nearest) == 1 and nearest[0][0] != fp_vertices["3.12"]
    assert "Info: 3.12 = vertex" in capfd.readouterr().out


def test_mirror_from_one_side_replaces(candide_head):
    obj, _, fp_vertices = candide_head
    edit_and_select(obj, [0])
    bpy.ops.mpeg4face.assign_feature_point(feature_point="3.8")  # wrong on purpose
    bpy.ops.object.mode_set(mode="OBJECT")
    bpy.ops.mpeg4face.mirror_feature_points(source="LEFT")  # 3.11 is on the face's left
    assert group_members(obj, "FP_3.8") == [(fp_vertices["3.8"], 1.0)]
