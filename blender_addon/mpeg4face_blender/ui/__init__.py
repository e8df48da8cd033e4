# SPDX-License-Identifier: GPL-3.0-or-later
"""The add-on's thin bpy UI layer: properties, preferences, operators (operators/),
panels (panels/) and the text helpers (text.py). The add-on's register() registers the
modules feature_modules() lists, in that order (the panels show in the order they register).

Importing this package imports neither bpy nor mpeg4face: preferences.py is imported
first, before mpeg4face is known to load; feature_modules() imports the rest."""

from __future__ import annotations

from types import ModuleType


def feature_modules() -> list[ModuleType]:
    """The modules to register once mpeg4face imports, in registration order."""
    from . import file_handlers, properties
    from ..scene import live_preview
    from .operators import (arkit, check, encode, export, faces, feature_points,
                            import_face, import_mesh2d, import_stream, live, rig, speech)
    from .panels import faces as faces_panel
    from .panels import feature_points as feature_points_panel
    from .panels import stream as stream_panel

    return [properties, feature_points, feature_points_panel, faces, arkit, faces_panel,
            export, live_preview, live, encode, speech, import_stream, stream_panel,
            check, rig, import_face, import_mesh2d, file_handlers]
