# SPDX-License-Identifier: GPL-3.0-or-later
"""The core's layout as docs/architecture.md describes it: one folder of public headers per
module under core/include/mpeg4face/, each module summed up by a header of its own name
that a newcomer reads on two screens, internals under core/src/, sources under 800 lines,
and the C++ tests of a module in tests/cpp/<module>/."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
INCLUDE = ROOT / "core/include/mpeg4face"
SRC = ROOT / "core/src"
MODULES = ("model", "io", "fat", "stream", "codec", "clone", "fit", "speech", "mesh2d", "arkit")
SHARED = {"spec.hpp", "error.hpp"}  # the standard's tables and the error type: every module's
SCREEN_LINES = 50
INCLUDE_RE = re.compile(r'^#include "([^"]+)"', re.M)


def test_every_public_header_is_a_modules_or_shared() -> None:
    top = {p.name for p in INCLUDE.glob("*.hpp")}
    assert top == SHARED | {f"{m}.hpp" for m in MODULES}
    assert {p.name for p in INCLUDE.iterdir() if p.is_dir()} == set(MODULES)


@pytest.mark.parametrize("module", MODULES)
def test_a_modules_header_says_what_it_owns_on_two_screens(module: str) -> None:
    text = (INCLUDE / f"{module}.hpp").read_text()
    lines = text.splitlines()
    assert len(lines) <= 2 * SCREEN_LINES
    comment = [line for line in lines[1:] if line.startswith("//")]
    assert len(comment) >= 3, "the header must say what the module owns"
    headers = sorted(p.name for p in (INCLUDE / module).glob("*.hpp"))
    assert INCLUDE_RE.findall(text) == [f"mpeg4face/{module}/{h}" for h in headers]
    for h in headers:  # each header named in the summary, with what it holds
        assert re.search(rf"^//\s+{module}/{re.escape(h)}\s+\S", text, re.M), h


def test_public_headers_include_only_public_headers() -> None:
    for header in INCLUDE.rglob("*.hpp"):
        for included in INCLUDE_RE.findall(header.read_text()):
            assert (INCLUDE.parent / included).is_file(), f"{header}: {included}"


def test_no_source_over_800_lines() -> None:
    long = {str(p.relative_to(ROOT)): n for p in SRC.rglob("*.[ch]pp")
            if (n := len(p.read_text().splitlines())) > 800}
    assert not long


def test_each_module_has_its_tests_folder() -> None:
    tests = ROOT / "tests/cpp"
    for module in MODULES:
        assert list((tests / module).glob("test_*.cpp")), module
