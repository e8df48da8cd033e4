# SPDX-License-Identifier: GPL-3.0-or-later
"""Runs the pytest suite of tests/blender inside Blender.

    MPEG4FACE_PYTHONPATH=$PWD/build/python \\
        blender -b --factory-startup --python-exit-code 1 --python tests/blender/run_in_blender.py

MPEG4FACE_PYTHONPATH is the build's python folder (the one holding mpeg4face/). Blender's
Python must be the one the module was built for (Debian's Blender runs /usr/bin/python3's
3.11). Arguments after "--" go to pytest (-- -k rigged). Exits with pytest's status; "no
tests collected" counts as a failure.
"""

import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
TESTS = os.path.dirname(HERE)
ADDONS = os.path.join(os.path.dirname(TESTS), "blender_addon")  # mpeg4face_blender


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
    # add them if this one does not.
    dist = "/usr/lib/python3/dist-packages"
    if os.path.isdir(dist) and dist not in sys.path:
        sys.path.append(dist)
    sys.dont_write_bytecode = True

    import pytest

    extra = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    rc = int(pytest.main(["-q", "-p", "no:cacheprovider", HERE, *extra]))
    if rc == int(pytest.ExitCode.NO_TESTS_COLLECTED):
        print("run_in_blender.py: pytest collected no tests", file=sys.stderr)
        return 1
    return rc


raise SystemExit(main())
