# SPDX-License-Identifier: GPL-3.0-or-later
"""Drag and drop: a FAP stream (.fap, .fba) dropped on the 3D viewport (or the Outliner's
View Layer, as Blender's own importers take it) runs File > Import > FAP stream on it: its
options in a dialog, then the stream onto the active head. Blender has FileHandler from
4.1 (compat.FILE_HANDLERS); on 3.4 this module registers nothing. No .wrl handler: the
add-on exports MPEG-4 faces (.wrl) but has no import for them."""

import bpy

from ..scene import compat
from .operators.import_stream import MPEG4FACE_OT_import_fap_stream

_classes = []

if compat.FILE_HANDLERS:
    from bpy_extras.io_utils import poll_file_object_drop

    class MPEG4FACE_FH_fap_stream(bpy.types.FileHandler):
        bl_idname = "MPEG4FACE_FH_fap_stream"
        bl_label = "MPEG-4 FAP stream"
        bl_import_operator = MPEG4FACE_OT_import_fap_stream.bl_idname
        bl_file_extensions = ".fap;.fba"

        @classmethod
        def poll_drop(cls, context: bpy.types.Context) -> bool:
            return poll_file_object_drop(context)

    _classes.append(MPEG4FACE_FH_fap_stream)

register, unregister = bpy.utils.register_classes_factory(_classes)
