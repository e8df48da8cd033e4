# SPDX-License-Identifier: GPL-3.0-or-later
"""The documentation stays true: the CLI reference is the program's own help, every
relative link in README.md and docs/ points at a file that exists, and the index
(docs/README.md) lists every page."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import mpeg4face

ROOT = Path(__file__).resolve().parents[2]
# The build's python/ folder holds the module; its bin/ holds the CLI.
CLI = Path(mpeg4face.__file__).resolve().parents[2] / "bin/mpeg4face"


def test_cli_reference_is_the_programs_help():
    result = subprocess.run([sys.executable, str(ROOT / "scripts/cli_reference.py"), "--cli",
                             str(CLI), "--check"], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr


def test_relative_links_resolve():
    broken = []
    for page in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]:
        for target in re.findall(r"\]\(([^)\s#]+)(?:#[^)]*)?\)", page.read_text()):
            if "://" in target or target.startswith("mailto:"):
                continue
            if not (page.parent / target).exists():
                broken.append(f"{page.relative_to(ROOT)}: {target}")
    assert not broken, "broken links:\n" + "\n".join(broken)


def test_the_index_lists_every_page():
    index = ROOT / "docs/README.md"
    listed = set(re.findall(r"\]\(([^)\s#]+\.md)", index.read_text()))
    pages = {p.name for p in (ROOT / "docs").glob("*.md")} - {"README.md"}
    assert pages - listed == set(), f"not in {index.relative_to(ROOT)}: {sorted(pages - listed)}"
