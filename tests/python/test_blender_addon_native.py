# SPDX-License-Identifier: GPL-3.0-or-later
"""The add-on's one-line diagnosis of its native module (native.summary) for the packages of
scripts/package.sh: a module or wheel built for another Python, and a module missing from an
extension. bpy-free; the files are stand-ins, nothing is built."""

import re
import sys

import pytest

from mpeg4face_blender import native

THIS = "%d.%d" % sys.version_info[:2]
OTHER = "3.13" if THIS != "3.13" else "3.11"
OTHER_TAG = OTHER.replace(".", "")


@pytest.fixture
def as_extension(monkeypatch):
    """The add-on as Blender loads an extension: bl_ext.<repository>.<id>."""
    monkeypatch.setattr(native, "__package__", "bl_ext.user_default.mpeg4face")


def other_python_lib(tmp_path):
    """A lib/ holding a package whose extension module is for another CPython."""
    package = tmp_path / "mpeg4face_other"
    package.mkdir()
    (package / "__init__.py").write_text("from . import _core\n")
    (package / f"_core.cpython-{OTHER_TAG}-x86_64-linux-gnu.so").write_bytes(b"")
    return tmp_path


def test_module_for_another_python_is_one_line(tmp_path, capsys):
    lib = other_python_lib(tmp_path)
    status = native.load(lib_dir=lib, name="mpeg4face_other")
    sys.path.remove(str(lib))
    sys.modules.pop("mpeg4face_other", None)
    assert not status.ok
    line = native.summary(status, lib, "mpeg4face_other")
    assert line.startswith(f"mpeg4face: the native module is for CPython {OTHER}; this "
                           f"Blender runs {THIS} — install the add-on zip mpeg4face_blender-")
    assert f"(cp{sys.version_info[0]}{sys.version_info[1]})" in line
    assert "\n" not in line
    # load() printed it, and nothing else: no traceback.
    assert capsys.readouterr().err == line + "\n"


def test_wheel_for_another_python_in_an_extension(tmp_path, as_extension, monkeypatch):
    wheels = tmp_path / "wheels"
    wheels.mkdir()
    (wheels / f"mpeg4face-0.1.0-cp{OTHER_TAG}-cp{OTHER_TAG}-manylinux_2_35_x86_64.whl").touch()
    monkeypatch.setattr(native, "WHEELS_DIR", wheels)
    assert native.built_for(tmp_path / "lib") == [OTHER]
    status = native.NativeStatus(None, "ModuleNotFoundError: No module named 'mpeg4face'")
    line = native.summary(status, tmp_path / "lib")
    version = native.add_on_version()
    assert re.fullmatch(r"\d+\.\d+\.\d+", version)
    assert line == (f"mpeg4face: the native module is for CPython {OTHER}; this Blender runs "
                    f"{THIS} — install mpeg4face-{version}-"
                    f"{native.blender_platform().replace('-', '_')}.zip built for "
                    f"{native.BLENDER_OF_PYTHON.get(THIS, f'CPython {THIS}')} "
                    f"(cp{sys.version_info[0]}{sys.version_info[1]})")


def test_missing_in_an_extension_names_the_zip(tmp_path, as_extension):
    status = native.NativeStatus(None, "ModuleNotFoundError: No module named 'mpeg4face'")
    lines = native.problem(status, tmp_path)
    assert lines[0].startswith("mpeg4face: the native module could not be imported "
                               "(ModuleNotFoundError: No module named 'mpeg4face') — install "
                               f"mpeg4face-{native.add_on_version()}-")
    assert "installed with the extension" in lines[1]
    assert "install_blender_addon.sh" not in "\n".join(lines)  # no source tree here
