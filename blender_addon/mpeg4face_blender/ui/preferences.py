# SPDX-License-Identifier: GPL-3.0-or-later
"""The add-on preferences: the Blender versions needed on another, the native module's
status (why it is missing and how to fix it) and settings of the panel."""

import textwrap

import bpy
from bpy.props import FloatProperty, StringProperty

from .. import native

# The add-on's package (mpeg4face_blender, or what Blender installed it as): the key of
# its preferences.
ADDON = __package__.rpartition(".")[0]
# Set by register() in the add-on's __init__.py before this module registers.
status = native.NativeStatus(None, "not loaded yet")
# Set by register() to what the add-on needs, on a Blender it does not support (the
# annotation a string: an old Blender's Python reads this module too).
unsupported: "str | None" = None


class MPEG4FACE_AP_preferences(bpy.types.AddonPreferences):
    bl_idname = ADDON

    constraint_tolerance: FloatProperty(
        name="Location tolerance",
        description="Table 6 location warnings for feature points off their constraint by "
        "more than this fraction of ES0",
        default=0.02,
        min=0.0,
        max=1.0,
        subtype="FACTOR",
    )

    template_head: StringProperty(
        name="Template head",
        description="A head with feature points and FAP, viseme and expression shape keys "
        "(.glb), such as the ICT sample samples/build/ict_head.glb: Find Feature Points fits "
        "it to your head, Make Animatable also clones its shape keys",
        subtype="FILE_PATH",
    )

    def draw(self, context: bpy.types.Context) -> None:
        layout = self.layout
        if unsupported is not None:
            layout.label(text=unsupported, icon="ERROR")
            return
        lines = native.problem(status)
        if not lines:
            layout.label(text=native.description(status), icon="CHECKMARK")
            layout.prop(self, "constraint_tolerance")
            layout.prop(self, "template_head")
            return
        box = layout.box()
        box.alert = True
        for i, line in enumerate(lines):
            for j, part in enumerate(textwrap.wrap(line, 90) or [""]):
                box.label(text=part, icon="ERROR" if i == 0 and j == 0 else "BLANK1")


def preferences(context: bpy.types.Context) -> MPEG4FACE_AP_preferences:
    return context.preferences.addons[ADDON].preferences


register, unregister = bpy.utils.register_classes_factory((MPEG4FACE_AP_preferences,))
