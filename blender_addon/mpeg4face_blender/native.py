# SPDX-License-Identifier: GPL-3.0-or-later
"""Finding the native module mpeg4face (bpy-free).

The add-on looks for it first in its own lib/ folder (where scripts/install_blender_addon.sh
copies it), then on sys.path. Loading never raises: a failure becomes a NativeStatus whose
problem() text the preferences show, because a Blender add-on must register even when its
native part is missing or was built for another Python.
"""

from __future__ import annotations

import importlib
import importlib.machinery
import sys
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType

MODULE_NAME = "mpeg4face"
LIB_DIR = Path(__file__).resolve().parent / "lib"
INSTALL_HINT = "run scripts/install_blender_addon.sh from the mpeg4face source tree"


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


def expected_file_name() -> str:
    """The extension file this Python imports, e.g. _core.cpython-311-x86_64-linux-gnu.so."""
    return "_core" + importlib.machinery.EXTENSION_SUFFIXES[0]


def load(lib_dir: Path = LIB_DIR, name: str = MODULE_NAME) -> NativeStatus:
    """Imports the native module, preferring the copy in lib_dir."""
    if (lib_dir / name).is_dir() and str(lib_dir) not in sys.path:
        sys.path.insert(0, str(lib_dir))
    try:
        return NativeStatus(importlib.import_module(name))
    # Anything the import raises (ImportError, or an error inside the module's __init__)
    # must end up in the preferences, not in a traceback that stops registration.
    except Exception as error:  # noqa: BLE001
        return NativeStatus(None, f"{type(error).__name__}: {error}")


def problem(status: NativeStatus, lib_dir: Path = LIB_DIR) -> list[str]:
    """Lines telling why the native module is unusable and how to fix it; [] when it loaded."""
    if status.ok:
        return []
    return [
        "The native module mpeg4face could not be imported:",
        status.error,
        f"Blender runs Python {python_version()}; it needs "
        f"{lib_dir / MODULE_NAME / expected_file_name()} (or mpeg4face on sys.path) "
        f"built for that Python.",
        f"To fix: {INSTALL_HINT}, then restart Blender.",
    ]


def description(status: NativeStatus) -> str:
    """One line naming the loaded module, for the preferences."""
    module = status.module
    if module is None:
        return "mpeg4face: not loaded"
    return f"mpeg4face {getattr(module, '__version__', '?')} from {Path(module.__file__).parent}"
