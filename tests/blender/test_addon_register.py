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
from mpeg4face_blender.scene import compat  # noqa: E402
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


def test_an_unsupported_blender_gets_one_line(addon_disabled, monkeypatch, capsys):
    """Enabling the add-on in a Blender it does not support registers the preferences only,
    which show the line that is also printed, and no traceback."""
    line = "MPEG-4 Face needs Blender 3.4 (Debian 12) or 4.2 LTS and later; this is 3.6.5"
    monkeypatch.setattr(compat, "unsupported", lambda: line)
    mpeg4face_blender.register()
    try:
        assert preferences.MPEG4FACE_AP_preferences.is_registered
        assert not hasattr(bpy.types, "MPEG4FACE_OT_assign_feature_point")
        assert preferences.unsupported == line
        assert capsys.readouterr().err.strip() == line
    finally:
        mpeg4face_blender.unregister()


def test_streams_dropped_on_the_viewport_are_imported():
    """A FileHandler (Blender 4.1 and later) imports a dropped .fap or .fba."""
    fh = getattr(bpy.types, "MPEG4FACE_FH_fap_stream", None)
    assert (fh is not None) is compat.FILE_HANDLERS
    if fh is not None:
        assert fh.bl_import_operator == "mpeg4face.import_fap_stream"
        assert fh.bl_file_extensions == ".fap;.fba"
