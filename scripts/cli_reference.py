#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Writes docs/cli-reference.md: every command's --help, exactly as the CLI prints it.

    /usr/bin/python3 scripts/cli_reference.py [--cli build/release/bin/mpeg4face] [--check]

--check compares instead of writing (tests/python/test_docs.py runs it that way, so the
reference cannot drift from the program)."""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
REFERENCE = ROOT / "docs/cli-reference.md"


def help_text(cli: Path, *args: str) -> str:
    return subprocess.run([str(cli), *args, "--help"], check=True, capture_output=True,
                          text=True).stdout.rstrip() + "\n"


def reference(cli: Path) -> str:
    overview = help_text(cli)
    commands = re.findall(r"^  (\w+)\s{2,}", overview.split("commands:", 1)[1], re.MULTILINE)
    parts = ["# `mpeg4face` command reference\n\n"
             "Every command's `--help`, as the program prints it (written by "
             "`scripts/cli_reference.py`; a test checks that it is current). "
             "[cli.md](cli.md) explains the commands with examples.\n\n"
             f"```\n{overview}```\n"]
    for command in commands:
        parts.append(f"\n## {command}\n\n```\n{help_text(cli, command)}```\n")
    return "".join(parts)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cli", type=Path, default=ROOT / "build/release/bin/mpeg4face")
    parser.add_argument("--check", action="store_true")
    args = parser.parse_args()
    text = reference(args.cli)
    if args.check:
        if not REFERENCE.is_file() or REFERENCE.read_text() != text:
            print(f"{REFERENCE} is out of date: run scripts/cli_reference.py", file=sys.stderr)
            return 1
        return 0
    REFERENCE.write_text(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
