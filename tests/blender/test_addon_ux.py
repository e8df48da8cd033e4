# SPDX-License-Identifier: GPL-3.0-or-later
"""The add-on as a new user meets it (issue 22): every panel of the MPEG-4 tab reads at the
default sidebar width (229 px) with a face set up, a stream imported, tables generated and
the motion checked (layout_check.py: no text Blender would cut with "..."); the import
options labelled and with presets, the encoder's option named, the speech dialog's text
plain, the absolute threshold the core's message names offered, and the panels' reading
of the mesh kept across updates that do not change it. Run through run_in_blender.py."""

from types import SimpleNamespace

import numpy as np
import pytest

bpy = pytest.importorskip("bpy", reason="runs inside Blender only (see run_in_blender.py)")

import layout_check  # noqa: E402
from test_addon_stream import JOY, head  # noqa: E402,F401 - fixture

from mpeg4face_blender.ui import properties  # noqa: E402
from mpeg4face_blender.ui import text as ui_text  # noqa: E402
from mpeg4face_blender.ui.operators import faces as operators_faces  # noqa: E402
from mpeg4face_blender.ui.operators import import_stream  # noqa: E402
from mpeg4face_blender.ui.panels import feature_points as panels  # noqa: E402

WIDTH = 229  # px, the sidebar's default width at UI scale 1


def our_panels():
    def subclasses(cls):
        for sub in cls.__subclasses__():
            yield from subclasses(sub)
            yield sub

    return [p for p in subclasses(bpy.types.Panel)
            if getattr(p, "bl_category", "") == "MPEG-4" and p.is_registered]


@pytest.fixture
def set_up(head, tmp_path):
    """The head with a stream baked and encoded, tables generated, the motion checked."""
    properties.fill_all()
    assert bpy.ops.mpeg4face.import_fap_stream(filepath=str(JOY)) == {"FINISHED"}
    assert bpy.ops.mpeg4face.encode_fap_stream(filepath=str(tmp_path / "joy_coded.fba"),
                                               mode="dct") == {"FINISHED"}
    assert bpy.ops.mpeg4face.generate_tables() == {"FINISHED"}
    bpy.ops.mpeg4face.check_motion()
    return head


def test_every_panel_reads_at_the_default_width(set_up):
    context = bpy.context
    found = our_panels()
    assert {"MPEG4FACE_PT_feature_points", "MPEG4FACE_PT_fapu", "MPEG4FACE_PT_fap_stream",
            "MPEG4FACE_PT_face_tables"} <= {p.__name__ for p in found}
    width = WIDTH * ui_text.scale(context)
    cut = {p.__name__: layout_check.cut_labels(p, context, width) for p in found}
    wm = context.window_manager
    cut["feature point list"] = layout_check.cut_list_rows(
        panels.MPEG4FACE_UL_feature_points, context, width, wm, "mpeg4face_feature_points")
    assert not any(cut.values()), {k: v for k, v in cut.items() if v}


def test_the_check_finds_what_blender_cuts():
    """The check can fail: the messages of the old panels, as the issue saw them cut."""
    context = bpy.context

    class Old:
        def draw(self, context):
            self.layout.label(text="missing for FAPU: 3.5, 3.6, 8.3, 8.4, 9.15", icon="ERROR")
            row = self.layout.split(factor=0.55)
            row.label(text="2.1 Bottom of the chin", icon="CHECKMARK")

    layout = layout_check.Layout(context, layout_check.panel_width(context, WIDTH))
    Old.draw(SimpleNamespace(layout=layout), context)
    assert len(layout.cut()) == 2, layout.cut()
    # wrapped, the same message fits
    layout = layout_check.Layout(context, layout_check.panel_width(context, WIDTH))
    ui_text.label(layout, context, "missing for FAPU: 3.5, 3.6, 8.3, 8.4, 9.15", "ERROR")
    assert layout.cut() == [] and len(layout.items[0].items) == 2


def test_sub_panels_are_closed_by_default():
    sub = [p for p in our_panels() if getattr(p, "bl_parent_id", "")]
    assert sub and all("DEFAULT_CLOSED" in p.bl_options for p in sub), [
        p.__name__ for p in sub if "DEFAULT_CLOSED" not in p.bl_options]


class Recorder:
    """The labels and property labels an operator's draw() shows."""

    def __init__(self, log=None):
        self.log = [] if log is None else log

    def label(self, text="", **_):
        self.log.append(("label", text))

    def prop(self, data, name, text=None, **_):
        self.log.append(("prop", data.bl_rna.properties[name].name if text is None else text))

    def __getattr__(self, name):
        return lambda *args, **kwargs: Recorder(self.log)


def test_import_options_are_labelled_and_have_presets():
    for op in (import_stream.MPEG4FACE_OT_import_fap_stream,
               import_stream.MPEG4FACE_OT_import_livelink_capture):
        assert "PRESET" in op.bl_options
        rna = getattr(bpy.ops.mpeg4face, op.bl_idname.split(".")[1]).get_rna_type()
        fake = SimpleNamespace(layout=Recorder(), frame_rate="STREAM", preview="BAKE",
                               bl_rna=rna)
        fake.draw_frames = lambda lay, resampled=True: import_stream._StreamImport.draw_frames(
            fake, lay, resampled)
        fake.draw_preview = lambda lay: import_stream._StreamImport.draw_preview(fake, lay)
        op.draw(fake, bpy.context)
        layout = fake.layout
        labels = [text for kind, text in layout.log if kind == "label"]
        assert "Frame rate" in labels and "Preview" in labels, layout.log


def test_encoder_and_speech_read_plainly():
    encode = bpy.ops.mpeg4face.encode_fap_stream.get_rna_type().properties["fap_quant"]
    assert encode.name == "Quantiser scale"
    speak = bpy.ops.mpeg4face.speak_text.get_rna_type().properties["text"]
    assert "<" not in speak.default and "<FAP 2" in speak.description


def test_absolute_threshold_for_a_face_without_fapu(head):
    """The core's message for a face without FAPU asks for an absolute threshold: the
    operator offers it, and it makes the tables (of a viseme: no FAPU needed for its
    motion)."""
    head.data.shape_keys.key_blocks[1].name = "viseme1"
    for group in list(head.vertex_groups):
        if group.name != "FP_2.1":
            head.vertex_groups.remove(group)
    with pytest.raises(RuntimeError, match="absolute threshold"):
        bpy.ops.mpeg4face.generate_tables()
    assert bpy.ops.mpeg4face.generate_tables(absolute_threshold=1e-4) == {"FINISHED"}
    assert operators_faces.table_reports[head.name].lines()[0].startswith("1 FaceDefTables")


def test_panels_keep_their_reading_of_the_mesh(head):
    """One reading of the mesh per change of the face, not per scene update."""
    other = bpy.data.objects.new("empty", None)
    bpy.context.scene.collection.objects.link(other)
    bpy.context.view_layer.update()  # the fixture's changes of the head
    first = panels.cached_face_state(bpy.context)
    assert panels.cached_face_state(bpy.context) is first
    try:
        other.location.x = 3.0  # an update of another object
        bpy.context.view_layer.update()
        head.select_set(False)
        bpy.context.view_layer.update()
        assert panels.cached_face_state(bpy.context) is first
        co = np.empty(len(head.data.vertices) * 3, dtype=np.float32)
        head.data.vertices.foreach_get("co", co)
        co[0] += 0.01
        head.data.vertices.foreach_set("co", co)
        head.data.update()
        bpy.context.view_layer.update()
        assert panels.cached_face_state(bpy.context) is not first
    finally:
        bpy.data.objects.remove(other)
        head.select_set(True)


def test_the_bake_reports_everything_in_a_popup(head, monkeypatch):
    """Every line of the bake's report reaches the user (the status bar shows only the
    last one): the summary and what could not be baked, in one popup."""
    shown = []
    monkeypatch.setattr(ui_text, "popup",
                        lambda context, title, lines, **_: shown.append((title, lines)))
    assert bpy.ops.mpeg4face.import_fap_stream(filepath=str(JOY)) == {"FINISHED"}
    (title, lines), = shown
    assert title == "Bake" and lines[0].startswith("Baked 1 FAPs (3) onto candide3")
    assert any(line.startswith("In the stream without a shape key or pose marker") and
               "FAP 19 (close_t_l_eyelid)" in line for line in lines), lines
