# SPDX-License-Identifier: GPL-3.0-or-later
"""Runs the pytest suite of tests/blender inside Blender, or with Blender as a Python module.

    MPEG4FACE_PYTHONPATH=$PWD/build/python \\
        blender -b --factory-startup --python-exit-code 1 --python tests/blender/run_in_blender.py
    MPEG4FACE_PYTHONPATH=$PWD/build/python build/venv-bpy-4.5/bin/python tests/blender/run_in_blender.py

The second form runs in a virtual environment holding PyPI's bpy (scripts/setup.sh makes one
per Blender version); bpy is imported first, then pytest runs as it does inside Blender.

MPEG4FACE_PYTHONPATH is the build's python folder (the one holding mpeg4face/). Blender's
Python must be the one the module was built for (Debian's Blender runs /usr/bin/python3's
3.11). Arguments after "--" go to pytest (-- -k rigged). Exits with pytest's status; "no
tests collected" counts as a failure.
"""

import os
import sys

# With PyPI's bpy, Blender starts at this import; inside Blender it is already there.
import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
TESTS = os.path.dirname(HERE)
ADDONS = os.path.join(os.path.dirname(TESTS), "blender_addon")  # mpeg4face_blender
AS_MODULE = not bpy.app.binary_path  # Blender as a Python module has no executable


def main() -> int:
    build = os.environ.get("MPEG4FACE_PYTHONPATH")
    if not build:
        print("run_in_blender.py: set MPEG4FACE_PYTHONPATH to the build's python folder",
              file=sys.stderr)
        return 2
    for path in (os.path.abspath(build), TESTS, ADDONS):
        if path not in sys.path:
            sys.path.insert(0, path)
    # Debian's Blender normally has the system site-packages (numpy, pytest) on sys.path;
    # add them if this one does not. A virtual environment with bpy has its own.
    dist = "/usr/lib/python3/dist-packages"
    in_venv = sys.prefix != sys.base_prefix
    if not in_venv and os.path.isdir(dist) and dist not in sys.path:
        sys.path.append(dist)
    sys.dont_write_bytecode = True

    # Inside Blender, pytest's arguments follow "--"; with bpy, they are the script's own.
    if "--" in sys.argv:
        extra = sys.argv[sys.argv.index("--") + 1:]
    else:
        extra = sys.argv[1:] if AS_MODULE else []
    if extra == ["--version"]:  # scripts/test.sh names the Blender it runs the suite in
        print("VERSION=" + bpy.app.version_string.split()[0])
        return 0

    import pytest

    rc = int(pytest.main(["-q", "-p", "no:cacheprovider", HERE, *extra]))
    if rc == int(pytest.ExitCode.NO_TESTS_COLLECTED):
        print("run_in_blender.py: pytest collected no tests", file=sys.stderr)
        return 1
    return rc


status = main()
if AS_MODULE:
    # Its exit handlers can wait for good once the suite has run (4.5: a static destructor
    # waits on a thread that has gone), so leave without them.
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(status)
raise SystemExit(status)
