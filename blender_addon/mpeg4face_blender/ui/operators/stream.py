# SPDX-License-Identifier: GPL-3.0-or-later
"""What the stream operators share: the active head with its grammar keys, the stream file
read (through a FIT), the errors reported instead of raised and the resampling choices.
The operators themselves: bake.py (import, speech), live.py, encode.py, speech.py,
import_stream.py; check.py reads streams through here too."""

import bpy

import mpeg4face

from ...logic import stream as stream_logic
from ...scene import poses
from ...scene.stream_data import grammar_keys
from .feature_points import active_mesh

# What the core may raise for a bad file or face, shown as a report instead of a traceback.
INPUT_ERRORS = (mpeg4face.Error, OSError, ValueError, RuntimeError)
RESAMPLE_ITEMS = (
    ("HOLD", "Sample and hold", "Each scene frame shows the last stream frame at or before "
     "its time, as a decoder holds a FAP until it is sent again"),
    ("LINEAR", "Linear", "FAP values interpolated linearly between the stream frames around "
     "each scene frame's time (viseme and expression weights cross-fade)"),
)


def stream_mesh(op: bpy.types.Operator, context: bpy.types.Context, poses_enough: bool = False
                ) -> tuple[bpy.types.Object, stream_logic.FaceKeys] | None:
    """The active mesh and its shape keys named by the grammar; None (reported) when there
    is no such mesh or it has no such key (with poses_enough, pose markers will do: a
    rigged head's poses play in the live preview)."""
    obj = active_mesh(op, context)
    if obj is None:
        return None
    if obj.mode != "OBJECT":
        op.report({"ERROR"}, "Switch to Object Mode (shape keys are read from the mesh)")
        return None
    keys = grammar_keys(obj)
    for problem in keys.malformed:
        op.report({"WARNING"}, f"Shape key {problem}")
    if not keys.keys and not (poses_enough and poses.pose_markers(context.scene, obj)):
        op.report({"ERROR"}, f"{obj.name} has no shape keys named fap<N>[_<label>]@<value>, "
                  "viseme<N> or expression<N>[@<intensity>] (see docs/fat.md)")
        return None
    return obj, keys


def read_stream(op: bpy.types.Operator, path: str, fit_path: str = ""
                ) -> mpeg4face.FapStream | None:
    """The stream of a .fap / .fba file, through the FIT when one is given; None (reported)
    when a file is unreadable."""
    try:
        stream = mpeg4face.read_fap_stream(bpy.path.abspath(path))
        if fit_path:
            stream = mpeg4face.read_fit_json(bpy.path.abspath(fit_path)).interpolate(stream)
    except INPUT_ERRORS as error:
        op.report({"ERROR"}, f"Cannot read the stream: {error}")
        return None
    if len(stream) == 0:
        op.report({"ERROR"}, f"{path} holds no frames")
        return None
    return stream
