# SPDX-License-Identifier: GPL-3.0-or-later
"""Encoding the stream imported on the active head as an FBA bitstream (.fba), its bit
rate and PSNR kept for the panel."""

import math
from pathlib import Path

import bpy
from bpy.props import EnumProperty, IntProperty, StringProperty
from bpy_extras.io_utils import ExportHelper

import mpeg4face

from ...logic import stream as stream_logic
from . import stream as operators_stream
from .feature_points import active_mesh

ENCODING_MODES = (
    ("predictive", "Predictive", "The standard's predictive coding: arithmetic-coded "
     "differences from the previous frame"),
    ("dct", "DCT", "A DCT of 16 consecutive values of each FAP (docs/dct-mode.md)"),
    ("pca", "PCA", "A KLT per FAP group (docs/pca-mode.md)"),
)


class MPEG4FACE_OT_encode_fap_stream(bpy.types.Operator, ExportHelper):
    """Encode the stream imported on the active object as an FBA bitstream (.fba) and show
    its bit rate and PSNR"""

    bl_idname = "mpeg4face.encode_fap_stream"
    bl_label = "Encode FAP Stream"
    bl_options = {"REGISTER", "UNDO"}

    filename_ext = ".fba"
    filter_glob: StringProperty(default="*.fba", options={"HIDDEN"})
    mode: EnumProperty(name="Mode", items=ENCODING_MODES, default="predictive")
    fap_quant: IntProperty(
        name="Quantiser scale",
        description="fap_quant, the quantiser scale: larger is coarser (0: none)",
        default=1, min=0, max=31)

    def invoke(self, context: bpy.types.Context, event: bpy.types.Event) -> set[str]:
        obj = context.active_object
        if obj is not None and obj.type == "MESH" and obj.mpeg4face_stream.filepath:
            source = Path(bpy.path.abspath(obj.mpeg4face_stream.filepath))
            self.filepath = str(source.with_name(source.stem + "_coded.fba"))
        return ExportHelper.invoke(self, context, event)

    def execute(self, context: bpy.types.Context) -> set[str]:
        obj = active_mesh(self, context)
        if obj is None:
            return {"CANCELLED"}
        state = obj.mpeg4face_stream
        if not state.filepath:
            self.report({"ERROR"}, f"No stream on {obj.name}: import or speak one first")
            return {"CANCELLED"}
        # The stream as sent (no FIT: that is the decoder's side).
        stream = operators_stream.read_stream(self, state.filepath)
        if stream is None:
            return {"CANCELLED"}
        try:
            encoding = mpeg4face.encode_fba(stream, self.mode, self.fap_quant)
            mpeg4face.write_file_atomically(self.filepath, encoding.data)
        except operators_stream.INPUT_ERRORS as error:
            self.report({"ERROR"}, f"Cannot encode: {error}")
            return {"CANCELLED"}
        state.encoded_path, state.encoded_mode = self.filepath, self.mode
        state.bits, state.bits_per_second = encoding.bits, encoding.bits_per_second
        state.psnr = math.nan if encoding.psnr is None else encoding.psnr
        self.report({"INFO"}, f"Wrote {self.filepath}: "
                    + stream_logic.encoding_summary(encoding.bits, encoding.bits_per_second,
                                                    encoding.psnr))
        return {"FINISHED"}


register, unregister = bpy.utils.register_classes_factory((MPEG4FACE_OT_encode_fap_stream,))
