# SPDX-License-Identifier: GPL-3.0-or-later
"""Enables the add-on (blender_addon/ is on sys.path, see run_in_blender.py) before any test
module imports it, so addon_utils owns the module, and builds the CANDIDE-3 head."""

from pathlib import Path

import pytest

try:
    import addon_utils
    import bpy
except ImportError:  # plain Python: the tests skip themselves
    bpy = None

ADDON = "mpeg4face_blender"
DATA = Path(__file__).resolve().parent.parent / "data"

if bpy is not None:
    addon_utils.enable(ADDON, default_set=True)


@pytest.fixture
def addon_disabled():
    """The add-on disabled for the test, enabled again afterwards."""
    addon_utils.disable(ADDON, default_set=True)
    yield
    addon_utils.enable(ADDON, default_set=True)
