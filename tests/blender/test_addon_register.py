# SPDX-License-Identifier: GPL-3.0-or-later
"""Registering the add-on: twice in a row, and with the native module missing (only the
preferences, which say why). Run through run_in_blender.py."""

import functools

import pytest

bpy = pytest.importorskip("bpy", reason="runs inside Blender only (see run_in_blender.py)")

import addon_utils  # noqa: E402
from conftest import ADDON  # noqa: E402

import mpeg4face_blender  # noqa: E402
from mpeg4face_blender import native  # noqa: E402
from mpeg4face_blender.logic import feature_points  # noqa: E402
from mpeg4face_blender.ui import preferences, properties  # noqa: E402


def registered() -> dict[str, bool]:
    return {
        "preferences": preferences.MPEG4FACE_AP_preferences.is_registered,
        "assign": hasattr(bpy.types, "MPEG4FACE_OT_assign_feature_point"),
        "panel": hasattr(bpy.types, "MPEG4FACE_PT_feature_points"),
        "list": hasattr(bpy.types.WindowManager, "mpeg4face_feature_points"),
    }


def test_enable_registers_everything():
    assert addon_utils.check(ADDON) == (True, True)
    assert registered() == dict.fromkeys(("preferences", "assign", "panel", "list"), True)
    assert preferences.status.ok
    assert mpeg4face_blender.bl_info["category"] == "Animation"
    assert mpeg4face_blender.bl_info["blender"] == (3, 4, 0)
    # Filled by a timer (no event loop runs here) or after loading a file.
    assert bpy.app.timers.is_registered(properties.fill_all)
    bpy.ops.wm.read_homefile(use_factory_startup=True)
    items = bpy.context.window_manager.mpeg4face_feature_points
    assert len(items) == 85
    assert (items[0].fp_id, items[0].name) == ("2.1", "2.1 Bottom of the chin")
    assert {i.fp_id for i in items if i.needed_for_fapu} == feature_points.fapu_points()
    assert {i.fp_id for i in items if i.needed_for_cloning} == feature_points.cloning_points()


def test_register_unregister_twice(addon_disabled):
    for _ in range(2):
        mpeg4face_blender.register()
        assert all(registered().values())
        mpeg4face_blender.unregister()
        assert not any(registered().values())


def test_missing_native_module_registers_preferences_only(addon_disabled, monkeypatch):
    monkeypatch.setattr(native, "load", functools.partial(native.load, name="mpeg4face_not_built"))
    mpeg4face_blender.register()  # must not raise
    try:
        assert registered() == {"preferences": True, "assign": False, "panel": False,
                                "list": False}
        text = "\n".join(native.problem(preferences.status))
        assert "No module named 'mpeg4face_not_built'" in text
        assert f"Blender runs Python {native.python_version()}" in text
        assert native.expected_file_name() in text
        assert "run scripts/install_blender_addon.sh" in text
    finally:
        mpeg4face_blender.unregister()
    assert not any(registered().values())
