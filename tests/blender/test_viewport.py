# SPDX-License-Identifier: GPL-3.0-or-later
"""The real viewport under Xvfb (viewport/screenshots.py in a Blender of its own): a stream
previewed on CANDIDE-3 changes the mouth region of the screenshots between the neutral
frame and the open_jaw frame, and leaves the forehead as it was; two screenshots of the whole
window show every panel of the add-on's sidebar tab, and three the export's and the two
imports' (FAP stream, Live Link Face capture) file browsers with their options (the export's sub-panels must have drawn). The screenshots are kept
in $MPEG4FACE_SCREENSHOTS when it is set (scripts/test.sh: build/screenshots; the user
guide's pictures in docs/images come from there). Run through run_in_blender.py."""

import json
import os
import subprocess
from pathlib import Path

import pytest

bpy = pytest.importorskip("bpy", reason="runs inside Blender only (see run_in_blender.py)")

from conftest import needs_blender_executable  # noqa: E402

SCRIPT = Path(__file__).resolve().parent / "viewport" / "screenshots.py"


@needs_blender_executable(" in a window under Xvfb")
def test_previewed_stream_moves_the_mouth_in_the_viewport(tmp_path):
    out = Path(os.environ.get("MPEG4FACE_SCREENSHOTS") or tmp_path)
    out.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, MPEG4FACE_SCREENSHOT_DIR=str(out))
    command = ["xvfb-run", "-a", "-s", "-screen 0 1600x1000x24",
               bpy.app.binary_path, "--factory-startup",
               "--enable-event-simulate", "--python", str(SCRIPT)]
    run = subprocess.run(command, env=env, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    result = json.loads((out / "result.json").read_text())
    assert result["open_jaw_value"] == 315 and result["key_value"] == pytest.approx(1.0)
    # Mean change of a colour channel (0..1) over the box around the feature points.
    assert result["mouth_change"] > 0.01, result
    assert result["forehead_change"] < result["mouth_change"] / 20, result
    # The live preview drawn with the gpu module: the face is there (the head hidden), and
    # its mouth moves with the stream as the baked one does.
    assert result["live_hidden"] and result["live_face_drawn"] > 0.05, result
    assert result["live_mouth_change"] > 0.01, result
    assert result["live_forehead_change"] < result["live_mouth_change"] / 20, result
    # Every panel of the tab reads at the sidebar's default width (layout_check.py, in the
    # real sidebar with the sample head's panels filled).
    assert result["sidebar_width"] == 229 and result["cut"] == {}, result["cut"]
    # The export's file browser drew its options sub-panels.
    assert result["export_panels"] == ["FaceDefTables", "Head"], result
    for name in ("viewport_neutral.png", "viewport_open_jaw.png", "blender_sidebar.png", "viewport_live_open_jaw.png",
                 "blender_sidebar_229.png", "blender_sidebar_keys_229.png",
                 "blender_sidebar_keys.png", "blender_export.png", "blender_import.png",
                 "blender_import_capture.png"):
        assert (out / name).stat().st_size > 10_000, name
