# SPDX-License-Identifier: GPL-3.0-or-later
"""The one place for what differs between Blender versions (3.4 up to 4.x).

- The user add-on folder: scripts/addons in 3.x and 4.x. Blender 4.2's extensions live in
  another folder and need a blender_manifest.toml; this add-on installs as a legacy add-on,
  which 4.2 and later still load from scripts/addons.

Nothing else the add-on uses differs between 3.4 and 4.x so far; new differences go here.
"""

from __future__ import annotations

import bpy


def user_addon_dir() -> str:
    """Blender's user add-on folder (BLENDER_USER_SCRIPTS moves it)."""
    return bpy.utils.user_resource("SCRIPTS", path="addons", create=True)

