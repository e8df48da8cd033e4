# SPDX-License-Identifier: GPL-3.0-or-later
"""The add-on's layout (docs/blender.md, "Module layout"): every module of
mpeg4face_blender.logic, and native, imports with Blender absent and without importing
bpy or any other Blender module. Each import runs in a fresh interpreter whose meta path
refuses Blender's modules, so a logic module that imports bpy (directly or through a
module it imports) fails here; test_the_check_fails_on_a_module_that_imports_bpy shows
that it does."""

import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

ADDONS = Path(__file__).resolve().parents[2] / "blender_addon"
LOGIC = ADDONS / "mpeg4face_blender" / "logic"
BLENDER_MODULES = ("bpy", "bpy_extras", "bmesh", "mathutils", "blf", "gpu", "gpu_extras",
                   "aud", "addon_utils")

# Run in a child: a finder first on sys.meta_path refuses Blender's modules; then the
# module is imported and sys.modules checked for them.
CHILD = textwrap.dedent("""
    import importlib, sys

    BLENDER = set(sys.argv[3].split(","))

    class RefuseBlender:
        def find_spec(self, name, path=None, target=None):
            if name.partition(".")[0] in BLENDER:
                raise ImportError(f"{name} imported by a module that must be bpy-free")
            return None

    sys.meta_path.insert(0, RefuseBlender())
    sys.path.insert(0, sys.argv[1])
    importlib.import_module(sys.argv[2])
    loaded = sorted(m for m in sys.modules if m.partition(".")[0] in BLENDER)
    assert not loaded, loaded
    print("ok", sys.argv[2])
""")


def bpy_free_modules() -> list[str]:
    modules = ["mpeg4face_blender.native", "mpeg4face_blender.logic", "mpeg4face_blender.ui",
               "mpeg4face_blender"]
    return modules + sorted(f"mpeg4face_blender.logic.{p.stem}" for p in LOGIC.glob("*.py")
                            if p.stem != "__init__")


def import_alone(addons: Path, module: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", CHILD, str(addons), module,
                           ",".join(BLENDER_MODULES)],
                          capture_output=True, text=True, timeout=120)


def test_logic_holds_the_bpy_free_modules():
    names = {p.stem for p in LOGIC.glob("*.py")}
    assert {"feature_points", "shape_keys", "stream", "live", "rig", "arkit", "check"} <= names


@pytest.mark.parametrize("module", bpy_free_modules())
def test_module_imports_without_blender(module):
    run = import_alone(ADDONS, module)
    assert run.returncode == 0, run.stderr[-2000:]
    assert run.stdout.strip() == f"ok {module}"


def test_the_check_fails_on_a_module_that_imports_bpy(tmp_path):
    """A copy of the add-on with one logic module that imports bpy through another: the
    check refuses it (so it can fail), and the copy's other modules still pass."""
    import shutil

    copy = tmp_path / "mpeg4face_blender"
    shutil.copytree(ADDONS / "mpeg4face_blender", copy,
                    ignore=shutil.ignore_patterns("__pycache__"))
    (copy / "logic" / "leaky.py").write_text("from ..scene import compat  # imports bpy\n")
    run = import_alone(tmp_path, "mpeg4face_blender.logic.leaky")
    assert run.returncode != 0
    assert "bpy imported by a module that must be bpy-free" in run.stderr
    assert import_alone(tmp_path, "mpeg4face_blender.logic.stream").returncode == 0


VERSION_PATTERNS = ("bpy.app.version", "app.version_string", "app.version_file")


def version_checks(root: Path) -> list[str]:
    """Lines under root that read Blender's version, as 'path:line: text'."""
    found = []
    for path in sorted(root.rglob("*.py")):
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            if any(p in line for p in VERSION_PATTERNS):
                found.append(f"{path}:{number}: {line.strip()}")
    return found


def test_only_the_compat_module_reads_blenders_version(tmp_path):
    """Everything that differs between Blender versions goes through scene/compat.py
    (docs/blender.md): no other module of the add-on, nor a Blender test, reads the version.
    The test runner may name the Blender it runs in."""
    allowed = {ADDONS / "mpeg4face_blender" / "scene" / "compat.py",
               ADDONS.parent / "tests" / "blender" / "run_in_blender.py"}
    found = [line for root in (ADDONS, ADDONS.parent / "tests" / "blender")
             for line in version_checks(root) if Path(line.split(":")[0]) not in allowed]
    assert found == []
    # The search sees a version check where there is one.
    (tmp_path / "module.py").write_text("if bpy.app.version >= (4, 2, 0):\n    pass\n")
    assert version_checks(tmp_path) == [f"{tmp_path / 'module.py'}:1: if bpy.app.version >= (4, 2, 0):"]
