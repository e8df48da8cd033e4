# SPDX-License-Identifier: GPL-3.0-or-later
"""The add-on's properties. The feature point list the panel's UIList shows: one item per
point of the standard's table, kept on the window manager (a UIList needs a collection
property; nothing is saved in .blend files); the status of each point is read live from
the mesh, not stored. The stream on an object (Object.mpeg4face_stream): the stream last
imported or spoken onto it and its last encoding, saved with the .blend."""

import math

import bpy
from bpy.app.handlers import persistent
from bpy.props import BoolProperty, CollectionProperty, FloatProperty, IntProperty, \
    PointerProperty, StringProperty

import mpeg4face

from ..logic import feature_points


class MPEG4FACE_PG_feature_point(bpy.types.PropertyGroup):
    # name (from PropertyGroup) is "<id> <description>", so the list's filter finds both.
    fp_id: StringProperty(name="Feature point")
    description: StringProperty(name="Description")
    needed_for_fapu: BoolProperty(name="Needed for FAPU")
    needed_for_cloning: BoolProperty(name="Needed for cloning")


def fill_feature_point_list(wm: bpy.types.WindowManager) -> None:
    """Fills the window manager's list from the standard's table (once per window manager)."""
    items = wm.mpeg4face_feature_points
    rows = feature_points.feature_point_rows({})
    if len(items) == len(rows):
        return
    items.clear()
    for row in rows:
        item = items.add()
        item.name = f"{row.id} {row.description}"
        item.fp_id = row.id
        item.description = row.description
        item.needed_for_fapu = row.needed_for_fapu
        item.needed_for_cloning = row.needed_for_cloning


def fill_all() -> None:
    """Fills the list of every window manager (a bpy.app timer: returning None runs it once)."""
    for wm in bpy.data.window_managers:
        fill_feature_point_list(wm)


@persistent
def _fill_after_load(_dummy: object) -> None:
    fill_all()


def feature_point_enum_items() -> list[tuple[str, str, str]]:
    """EnumProperty items: ("2.1", "2.1 Bottom of the chin", description)."""
    return [(p.id, f"{p.id} {p.description}", p.description) for p in mpeg4face.feature_points()]


class MPEG4FACE_PG_stream(bpy.types.PropertyGroup):
    """The stream last imported or spoken onto an object (saved with the .blend) and the
    last encoding of it."""

    filepath: StringProperty(name="Stream", subtype="FILE_PATH")
    fit_path: StringProperty(name="FIT", subtype="FILE_PATH")
    start_frame: IntProperty(name="Start frame", default=1)
    frames: IntProperty(name="Frames")
    encoded_path: StringProperty(name="Encoded", subtype="FILE_PATH")
    encoded_mode: StringProperty(name="Mode")
    bits: IntProperty(name="Bits")
    bits_per_second: FloatProperty(name="Bit rate")
    psnr: FloatProperty(name="PSNR", default=math.nan)  # inf: lossless, nan: none


_classes = (MPEG4FACE_PG_feature_point, MPEG4FACE_PG_stream)


def register() -> None:
    for cls in _classes:
        bpy.utils.register_class(cls)
    wm = bpy.types.WindowManager
    wm.mpeg4face_feature_points = CollectionProperty(type=MPEG4FACE_PG_feature_point)
    wm.mpeg4face_feature_point_index = IntProperty(name="Active feature point", default=0)
    bpy.types.Object.mpeg4face_stream = PointerProperty(type=MPEG4FACE_PG_stream)
    # register() runs with bpy.data restricted (addon_utils), so the list is filled later:
    # after each file load, and by a timer when the add-on is enabled in a running Blender.
    bpy.app.handlers.load_post.append(_fill_after_load)
    bpy.app.timers.register(fill_all, first_interval=0.0)


def unregister() -> None:
    if bpy.app.timers.is_registered(fill_all):
        bpy.app.timers.unregister(fill_all)
    if _fill_after_load in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.remove(_fill_after_load)
    del bpy.types.Object.mpeg4face_stream
    del bpy.types.WindowManager.mpeg4face_feature_point_index
    del bpy.types.WindowManager.mpeg4face_feature_points
    for cls in reversed(_classes):
        bpy.utils.unregister_class(cls)
