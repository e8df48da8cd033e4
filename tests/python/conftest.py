# SPDX-License-Identifier: GPL-3.0-or-later
"""Shared fixtures of the Python tests.

Run with: PYTHONPATH=build/python /usr/bin/python3 -m pytest tests/python
"""

import sys
from pathlib import Path

import pytest

TESTS_DIR = Path(__file__).resolve().parent.parent
# The Blender add-on's bpy-free modules (mpeg4face_blender.logic, .native).
sys.path.insert(0, str(TESTS_DIR.parent / "blender_addon"))


@pytest.fixture(scope="session")
def data_dir() -> Path:
    """tests/data."""
    return TESTS_DIR / "data"


@pytest.fixture(scope="session")
def malformed_dir(data_dir: Path) -> Path:
    """tests/data/malformed (small broken files)."""
    return data_dir / "malformed"
