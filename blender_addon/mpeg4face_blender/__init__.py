# SPDX-License-Identifier: GPL-3.0-or-later
"""MPEG-4 Face: feature points and FAPU of a head mesh, on top of the mpeg4face module.

Layout (like Blender's glTF add-on, a bpy-free layer under a thin bpy one):
- native.py: finds and loads mpeg4face (bpy-free; the preferences show why it failed)
- logic/: bpy-free (numpy and mpeg4face), tested with plain pytest
- scene/: the bpy data layer: reads and writes meshes, shape keys, rigs, keyframes;
  scene/compat.py holds what differs between Blender versions (3.4, 4.2 LTS and later, 5.0)
  and which ones the add-on supports
- ui/: properties, preferences, operators/ (a module per concern), panels/, text helpers,
  file_handlers (drag and drop);
  ui.feature_modules() is the registration list
Nothing here imports bpy at import time, so the bpy-free modules can be tested with plain
pytest.
"""

from __future__ import annotations

import sys
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
    """Registers the preferences always and the rest only on a Blender the add-on supports
    (scene/compat.py) and when mpeg4face imports; never raises, so Blender keeps the add-on
    enabled and the preferences can say what is wrong."""
    from .scene import compat
    from .ui import preferences

    preferences.unsupported = compat.unsupported()
    if preferences.unsupported is not None:
        print(preferences.unsupported, file=sys.stderr)
        preferences.register()
        return
    status = native.load()
    try:
        preferences.register()
        if status.ok:
            from . import ui

            for module in ui.feature_modules():
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
    from .ui import preferences

    _unregister_features()
    if preferences.MPEG4FACE_AP_preferences.is_registered:
        preferences.unregister()
