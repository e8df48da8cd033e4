# SPDX-License-Identifier: GPL-3.0-or-later
"""Finding the native module mpeg4face (bpy-free).

Installed as an extension (Blender 4.2+, the zip of scripts/package.sh), Blender has put the
mpeg4face wheel into its extensions' site-packages and `import mpeg4face` finds it. Installed
as a plain add-on (the Blender 3.4 zip, or scripts/install_blender_addon.sh), the module is in
the add-on's own lib/ folder, which is looked at first. Loading never raises: a failure becomes
a NativeStatus whose summary() goes to the console as one line and whose problem() lines the
preferences show, because a Blender add-on must register even when its native part is missing
or was built for another Python.
"""

from __future__ import annotations

import importlib
import importlib.machinery
import platform
import re
import sys
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType

MODULE_NAME = "mpeg4face"
HERE = Path(__file__).resolve().parent
LIB_DIR = HERE / "lib"
WHEELS_DIR = HERE / "wheels"  # an extension's wheels, as its manifest lists them
INSTALL_HINT = "run scripts/install_blender_addon.sh from the mpeg4face source tree"
# The Blender releases that run each CPython, named in the advice for another Python.
BLENDER_OF_PYTHON = {"3.10": "Blender 3.1 to 4.0", "3.11": "Blender 4.1 to 5.0",
                     "3.13": "Blender 5.1+"}


@dataclass(frozen=True)
class NativeStatus:
    """The outcome of load(): the module, or why it could not be imported."""

    module: ModuleType | None
    error: str = ""

    @property
    def ok(self) -> bool:
        return self.module is not None


def python_version() -> str:
    return ".".join(map(str, sys.version_info[:3]))


def python_minor() -> str:
    """This Python as wheels and Blender's releases tell them apart: "3.11"."""
    return "%d.%d" % sys.version_info[:2]


def expected_file_name() -> str:
    """The extension file this Python imports, e.g. _core.cpython-311-x86_64-linux-gnu.so."""
    return "_core" + importlib.machinery.EXTENSION_SUFFIXES[0]


def load(lib_dir: Path = LIB_DIR, name: str = MODULE_NAME) -> NativeStatus:
    """Imports the native module, preferring the copy in lib_dir; on failure prints
    summary() (one line, no traceback) to the console."""
    if (lib_dir / name).is_dir() and str(lib_dir) not in sys.path:
        sys.path.insert(0, str(lib_dir))
    try:
        return NativeStatus(importlib.import_module(name))
    # Anything the import raises (ImportError, or an error inside the module's __init__)
    # must end up in the preferences, not in a traceback that stops registration.
    except Exception as error:  # noqa: BLE001
        status = NativeStatus(None, f"{type(error).__name__}: {error}")
    print(summary(status, lib_dir, name), file=sys.stderr)
    return status


def is_extension() -> bool:
    """Whether Blender loaded this add-on as an extension (bl_ext.<repository>.<id>)."""
    return (__package__ or "").startswith("bl_ext.")


def built_for(lib_dir: Path = LIB_DIR, name: str = MODULE_NAME) -> list[str]:
    """The CPython versions ("3.11") of the native modules shipped with the add-on: the
    extension files in lib_dir/name and the wheels in WHEELS_DIR."""
    # No walrus and the like here: __init__.py imports this module on any Blender, so that
    # an old one's Python can say what the add-on needs.
    tags = [re.match(r"_core\.cpython-(\d)(\d+)", f.name)
            for f in (lib_dir / name).glob("_core.cpython-*")]
    tags += [re.search(r"-cp(\d)(\d+)-", f.name) for f in WHEELS_DIR.glob(f"{name}-*.whl")]
    found = {f"{m[1]}.{m[2]}" for m in tags if m}
    return sorted(found, key=lambda v: tuple(map(int, v.split("."))))


def add_on_version() -> str:
    """The add-on's version from its blender_manifest.toml ("" when it cannot be read)."""
    try:
        import tomllib

        with open(HERE / "blender_manifest.toml", "rb") as file:
            return str(tomllib.load(file)["version"])
    except Exception:  # noqa: BLE001 - only names a file in advice
        return ""


def blender_platform() -> str:
    """This machine as Blender's extension platforms name it: linux-x64, macos-arm64..."""
    system = platform.system().lower().replace("darwin", "macos")
    machine = platform.machine().lower()
    machine = {"x86_64": "x64", "amd64": "x64", "aarch64": "arm64"}.get(machine, machine)
    return f"{system}-{machine}"


def needed_download() -> str:
    """What to install for this Blender, e.g. "mpeg4face-0.1.0-linux_x64.zip built for
    Blender 5.1+ (cp313)"."""
    major_minor = python_minor()
    version = add_on_version() or "<version>"
    blender = BLENDER_OF_PYTHON.get(major_minor, f"CPython {major_minor}")
    tag = "cp%d%d" % sys.version_info[:2]
    if is_extension():
        return f"{MODULE_NAME}-{version}-{blender_platform().replace('-', '_')}.zip " \
               f"built for {blender} ({tag})"
    return f"the add-on zip {MODULE_NAME}_blender-{version} built for {blender} ({tag}), " \
           f"or {INSTALL_HINT}"


def summary(status: NativeStatus, lib_dir: Path = LIB_DIR, name: str = MODULE_NAME) -> str:
    """One line: what is wrong with the native module and what to install; "" when it
    loaded."""
    if status.ok:
        return ""
    this = python_minor()
    shipped = built_for(lib_dir, name)
    if shipped and this not in shipped:
        return f"{MODULE_NAME}: the native module is for CPython {', '.join(shipped)}; this " \
               f"Blender runs {this} — install {needed_download()}"
    return f"{MODULE_NAME}: the native module could not be imported ({status.error}) — " \
           f"install {needed_download()}"


def problem(status: NativeStatus, lib_dir: Path = LIB_DIR) -> list[str]:
    """Lines telling why the native module is unusable and how to fix it; [] when it loaded.
    The first is summary(); the others give the import error and the file looked for."""
    if status.ok:
        return []
    if is_extension():
        needs = f"the wheel of {MODULE_NAME} for that Python, installed with the extension"
        fix = f"install {needed_download()}, then restart Blender"
    else:
        needs = f"{lib_dir / MODULE_NAME / expected_file_name()} (or mpeg4face on sys.path) " \
                f"built for that Python"
        fix = f"{INSTALL_HINT}, then restart Blender"
    first = summary(status, lib_dir)
    return [
        first,
        *([] if status.error in first else [f"The import failed: {status.error}"]),
        f"Blender runs Python {python_version()}; it needs {needs}.",
        f"To fix: {fix}.",
    ]


def description(status: NativeStatus) -> str:
    """One line naming the loaded module, for the preferences."""
    module = status.module
    if module is None:
        return "mpeg4face: not loaded"
    return f"mpeg4face {getattr(module, '__version__', '?')} from {Path(module.__file__).parent}"
