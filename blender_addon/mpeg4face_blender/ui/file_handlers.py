# SPDX-License-Identifier: GPL-3.0-or-later
"""Drag and drop: a file dropped on the 3D viewport (or the Outliner's View Layer, as
Blender's own importers take it) runs its File > Import: a FAP stream (.fap, .fba) with its
options in a dialog, then onto the active head; an MPEG-4 face (.wrl) at once, as a new
head. Blender has FileHandler from 4.1 (compat.FILE_HANDLERS); on 3.4 this module
registers nothing."""

import bpy

from ..scene import compat
from .operators.import_face import MPEG4FACE_OT_import_mpeg4_face
from .operators.import_stream import MPEG4FACE_OT_import_fap_stream

_classes = []

if compat.FILE_HANDLERS:
    from bpy_extras.io_utils import poll_file_object_drop

    class _ViewportDrop:
        @classmethod
        def poll_drop(cls, context: bpy.types.Context) -> bool:
            return poll_file_object_drop(context)

    class MPEG4FACE_FH_fap_stream(_ViewportDrop, bpy.types.FileHandler):
        bl_idname = "MPEG4FACE_FH_fap_stream"
        bl_label = "MPEG-4 FAP stream"
        bl_import_operator = MPEG4FACE_OT_import_fap_stream.bl_idname
        bl_file_extensions = ".fap;.fba"

    class MPEG4FACE_FH_mpeg4_face(_ViewportDrop, bpy.types.FileHandler):
        bl_idname = "MPEG4FACE_FH_mpeg4_face"
        bl_label = "MPEG-4 face"
        bl_import_operator = MPEG4FACE_OT_import_mpeg4_face.bl_idname
        bl_file_extensions = ".wrl"

    _classes += [MPEG4FACE_FH_fap_stream, MPEG4FACE_FH_mpeg4_face]

register, unregister = bpy.utils.register_classes_factory(_classes)
