# SPDX-License-Identifier: GPL-3.0-or-later
"""FAP Keys from ARKit Keys: the active head's ARKit blendshape keys (eyeBlinkLeft, jawOpen,
...) and FP_ feature points go to `mpeg4face.arkit_fap_keys`; the FAP, viseme and expression
keys it makes come back as shape keys in the grammar, with a report of the FAPs made and
missed (a popup, the Info editor, and a line in the FAP Shape Keys panel)."""

# No postponed annotations: bpy reads the property annotations.
import bpy
from bpy.app.handlers import persistent
from bpy.props import BoolProperty

import mpeg4face

from ...logic import arkit as arkit_logic
from ...scene import mesh_data
from . import faces as operators_faces

# The last report per object name, for the panel's line and the tests; forgotten when a
# file is loaded.
arkit_reports: dict[str, arkit_logic.ArkitKeysReport] = {}


@persistent
def _forget_arkit_reports(*_args: object) -> None:
    arkit_reports.clear()


def arkit_names(obj: bpy.types.Object) -> list[str]:
    """The object's shape keys that are ARKit blendshapes."""
    return arkit_logic.arkit_key_names(operators_faces.key_names(obj))


class MPEG4FACE_OT_arkit_fap_keys(bpy.types.Operator):
    """Make FAP shape keys (fap3_open_jaw@<amplitude>, ...), viseme and expression keys from
    the active head's ARKit blendshape keys, measured on the head through its FP_ feature
    points; keys of those names are replaced, the others kept"""

    bl_idname = "mpeg4face.arkit_fap_keys"
    bl_label = "FAP Keys from ARKit Keys"
    bl_options = {"REGISTER", "UNDO"}

    visemes: BoolProperty(name="Visemes", default=True,
                          description="Also make viseme1..14 from the FAP keys")
    expressions: BoolProperty(name="Expressions", default=True,
                              description="Also make expression1..6 from the FAP keys")

    def execute(self, context: bpy.types.Context) -> set[str]:
        obj = operators_faces.editable_mesh(self, context)
        if obj is None:
            return {"CANCELLED"}
        if not operators_faces.has_feature_points(self, obj):
            return {"CANCELLED"}
        model, group_warnings = mesh_data.read_face_model(obj, arkit_names(obj))
        try:  # without ARKit keys the core's error lists the names looked for
            result = mpeg4face.arkit_fap_keys(model, visemes=self.visemes,
                                              expressions=self.expressions)
        except mpeg4face.Error as error:
            self.report({"ERROR"}, f"{obj.name}: {error}")
            return {"CANCELLED"}
        keys = arkit_logic.made_keys(result["head"])
        replaced = operators_faces.write_keys(obj, keys)
        report = arkit_logic.keys_report(obj.name, result, list(keys), replaced)
        report.warnings[:0] = group_warnings
        arkit_reports[obj.name] = report
        if report.warnings:
            self.report({"WARNING"}, f"{len(report.warnings)} warnings (see the report)")
        # The whole report as one entry of the Info editor; the summary last, for the status bar.
        self.report({"INFO"}, "\n".join(report.lines()[1:]))
        self.report({"INFO"}, report.summary())
        if not bpy.app.background and context.window is not None:
            show_report(context, report)
        return {"FINISHED"}


def show_report(context: bpy.types.Context, report: arkit_logic.ArkitKeysReport) -> None:
    """The report as a popup: the summary, then the FAP keys made and the FAPs missed in
    columns."""
    def draw(menu: bpy.types.Menu, _context: bpy.types.Context) -> None:
        layout = menu.layout
        layout.label(text=report.summary())
        for title, rows in (("Made (residual: other feature points' motion / the FAP's)",
                             report.made), ("Missed", report.missed),
                            ("Warnings", report.warnings)):
            if not rows:
                continue
            layout.separator()
            layout.label(text=title)
            flow = layout.column_flow(columns=3 if len(rows) > 20 else 1)
            for row in rows:
                flow.label(text=row)

    context.window_manager.popup_menu(draw, title="FAP Keys from ARKit Keys", icon="INFO")


def register() -> None:
    bpy.utils.register_class(MPEG4FACE_OT_arkit_fap_keys)
    bpy.app.handlers.load_post.append(_forget_arkit_reports)


def unregister() -> None:
    if _forget_arkit_reports in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.remove(_forget_arkit_reports)
    arkit_reports.clear()
    bpy.utils.unregister_class(MPEG4FACE_OT_arkit_fap_keys)
