# SPDX-License-Identifier: GPL-3.0-or-later
"""scripts/install_blender_addon.sh into a temporary Blender user folder: the add-on and the
native module are copied, the add-on is enabled in the saved preferences, and a fresh Blender
starts with it loaded from there. Run through run_in_blender.py (MPEG4FACE_PYTHONPATH names
the build whose module is installed; nothing is built)."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

bpy = pytest.importorskip("bpy", reason="runs inside Blender only (see run_in_blender.py)")

from conftest import needs_blender_executable  # noqa: E402

pytestmark = needs_blender_executable(
    ": the install script runs it for its Python and add-on folder, the check starts it")

ROOT = Path(__file__).resolve().parent.parent.parent

CHECK = """
import addon_utils, bpy, json, sys
import mpeg4face, mpeg4face_blender
print('RESULT=' + json.dumps({
    'enabled': addon_utils.check('mpeg4face_blender'),
    'addon': mpeg4face_blender.__file__,
    'module': mpeg4face.__file__,
    'list': len(bpy.context.window_manager.mpeg4face_feature_points),
    'python': '%d.%d' % sys.version_info[:2],
}))
"""


@pytest.fixture
def user_dirs(tmp_path):
    env = dict(os.environ)
    env.update(
        BLENDER_USER_SCRIPTS=str(tmp_path / "scripts"),
        BLENDER_USER_CONFIG=str(tmp_path / "config"),
        BLENDER=bpy.app.binary_path,  # this Blender, not whichever is on PATH
        # The build run_in_blender.py was given: build/release/python -> build/release.
        MPEG4FACE_BUILD_DIR=str(Path(os.environ["MPEG4FACE_PYTHONPATH"]).resolve().parent),
        MPEG4FACE_SKIP_BUILD="1",
    )
    env.pop("PYTHONPATH", None)
    return tmp_path, env


def test_install_script(user_dirs):
    tmp, env = user_dirs
    run = subprocess.run([str(ROOT / "scripts" / "install_blender_addon.sh")], env=env,
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stdout + run.stderr
    addon = tmp / "scripts" / "addons" / "mpeg4face_blender"
    assert (addon / "__init__.py").is_file() and (addon / "logic" / "feature_points.py").is_file()
    assert list((addon / "lib" / "mpeg4face").glob("_core*.so"))
    assert (tmp / "config" / "userpref.blend").is_file()
    assert "install_blender_addon: done" in run.stdout

    # A new Blender with these preferences (not factory settings) has the add-on enabled,
    # with the native module from its lib/ folder and the list filled after start-up.
    check = subprocess.run([env["BLENDER"], "-b", "--python-exit-code", "1",
                            "--python-expr", CHECK], env=env, capture_output=True, text=True,
                           timeout=120)
    assert check.returncode == 0, check.stdout + check.stderr
    line = next(s for s in check.stdout.splitlines() if s.startswith("RESULT="))
    result = json.loads(line[len("RESULT="):])
    assert result["enabled"] == [True, True]
    assert result["addon"] == str(addon / "__init__.py")
    assert result["module"] == str(addon / "lib" / "mpeg4face" / "__init__.py")
    assert result["list"] == 85
    assert result["python"] == "%d.%d" % sys.version_info[:2]


def test_install_script_refuses_a_missing_module(user_dirs):
    tmp, env = user_dirs
    env["MPEG4FACE_BUILD_DIR"] = str(tmp / "no-build")
    run = subprocess.run([str(ROOT / "scripts" / "install_blender_addon.sh")], env=env,
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 1
    assert "no-build/python/mpeg4face/_core.cpython-3" in run.stderr
    assert "must be built for Blender's Python" in run.stderr
    assert not (tmp / "scripts" / "addons" / "mpeg4face_blender").exists()
