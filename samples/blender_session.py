# SPDX-License-Identifier: GPL-3.0-or-later
"""What the sample scripts run inside Blender share: the built module and the add-on on
sys.path (MPEG4FACE_PYTHONPATH is the build's python folder), the add-on enabled, and the
script's own arguments (those after Blender's `--`)."""

from __future__ import annotations

import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
ADDON = "mpeg4face_blender"


def start() -> list[str]:
    """Prepares the session; returns the script's arguments."""
    build = os.environ.get("MPEG4FACE_PYTHONPATH", str(ROOT / "build/release/python"))
    for path in (build, str(ROOT / "blender_addon")):
        if path not in sys.path:
            sys.path.insert(0, path)
    sys.dont_write_bytecode = True
    import addon_utils

    if addon_utils.enable(ADDON, default_set=True) is None:
        raise SystemExit(f"{ADDON}: the add-on did not enable (see the messages above)")
    argv = sys.argv
    return argv[argv.index("--") + 1:] if "--" in argv else []
