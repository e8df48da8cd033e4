# SPDX-License-Identifier: GPL-3.0-or-later
"""The one place for what differs between Blender versions (3.4 up to 4.x).

- The user add-on folder: scripts/addons in 3.x and 4.x. Blender 4.2's extensions live in
  another folder and need a blender_manifest.toml; this add-on installs as a legacy add-on,
  which 4.2 and later still load from scripts/addons.
- Context overrides for operator calls: Blender 4.0 dropped the dict argument of bpy.ops
  calls; Context.temp_override (3.2 and later) works in both.
"""

from __future__ import annotations

from contextlib import AbstractContextManager
from typing import Any

import bpy


def user_addon_dir() -> str:
    """Blender's user add-on folder (BLENDER_USER_SCRIPTS moves it)."""
    return bpy.utils.user_resource("SCRIPTS", path="addons", create=True)


def context_override(context: bpy.types.Context, **members: Any) -> AbstractContextManager:
    """A context with the given members replaced, for calling operators from scripts."""
    return context.temp_override(**members)
