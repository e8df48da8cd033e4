# SPDX-License-Identifier: GPL-3.0-or-later
"""MPEG-4 Face: feature points and FAPU of a head mesh, on top of the mpeg4face module.

Layout (like Blender's glTF add-on): native.py and fp_logic.py are bpy-free; properties,
operators, panels and preferences are the thin bpy layer; compat.py holds what differs
between Blender 3.x and 4.x. Nothing here imports bpy at import time, so the bpy-free
modules can be tested with plain pytest.
"""

from __future__ import annotations

from types import ModuleType

from . import native

bl_info = {
    "name": "MPEG-4 Face",
    "author": "mpeg4face contributors",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "3D Viewport > Sidebar > MPEG-4",
    "description": "MPEG-4 Face Animation feature points and FAPU",
    "doc_url": "https://github.com/mpeg4face/mpeg4face/blob/main/docs/blender.md",
    "category": "Animation",
}

_registered: list[ModuleType] = []


def register() -> None:
    """Registers the preferences always and the rest only when mpeg4face imports; never
    raises, so Blender keeps the add-on enabled and the preferences can say what is wrong."""
    from . import preferences

    status = native.load()
    try:
        preferences.register()
        if status.ok:
            from . import (
                export, import_stream, operators, operators_arkit, operators_check,
                operators_faces, operators_stream, panels, panels_faces, panels_stream,
                properties,
            )
            from . import import_mesh2d, operators_rig

            for module in (properties, operators, panels, operators_faces, operators_arkit,
                           panels_faces, export, operators_stream, import_stream,
                           panels_stream, operators_check, operators_rig, import_mesh2d):
                module.register()
                _registered.append(module)
    except Exception as error:  # noqa: BLE001 - e.g. a module too old for this add-on
        _unregister_features()
        status = native.NativeStatus(None, f"{type(error).__name__}: {error}")
    preferences.status = status


def _unregister_features() -> None:
    while _registered:
        _registered.pop().unregister()


def unregister() -> None:
    from . import preferences

    _unregister_features()
    if preferences.MPEG4FACE_AP_preferences.is_registered:
        preferences.unregister()
