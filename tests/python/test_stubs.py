# SPDX-License-Identifier: GPL-3.0-or-later
"""The hand-written stubs (bindings/mpeg4face/_core.pyi) against the built module: mypy's
stubtest (Debian's python3-mypy, installed by scripts/setup.sh) checks that every name in
the stub exists at runtime and the other way round, and that functions and methods take
the parameters the stub says. What pybind11 does differently by construction is listed in
stubtest_allowlist.txt, with the reason."""

import ast
import importlib.util
import os
import subprocess
import sys
from pathlib import Path

import mpeg4face

ALLOWLIST = Path(__file__).with_name("stubtest_allowlist.txt")


def test_the_stubs_match_the_module(tmp_path):
    assert importlib.util.find_spec("mypy") is not None, (
        "mypy is missing: scripts/setup.sh installs Debian's python3-mypy")
    stub = Path(mpeg4face.__file__).with_name("_core.pyi")
    assert stub.is_file(), f"{stub} is not installed beside the module"
    package_root = str(Path(mpeg4face.__file__).parent.parent)
    env = {**os.environ, "PYTHONPATH": package_root, "MYPYPATH": package_root}
    run = subprocess.run(
        [sys.executable, "-m", "mypy.stubtest", "mpeg4face._core", "--allowlist", str(ALLOWLIST)],
        capture_output=True, text=True, env=env, cwd=tmp_path, timeout=600)
    assert run.returncode == 0, run.stdout[-6000:] + run.stderr[-2000:]


def runtime_signatures(doc: str | None, name: str) -> list[list[str]]:
    """The parameter names of each signature pybind11 writes at the top of a docstring
    ("name(a: int, b: str = 'x') -> None", or "1. name(...)" per overload), self left out."""
    found = []
    for line in (doc or "").splitlines():
        line = line.strip()
        head = line.split(". ", 1)[1] if line[:1].isdigit() and ". " in line else line
        if not head.startswith(f"{name}("):
            continue
        depth, current, params = 0, "", []
        for char in head[len(name) + 1:]:
            if depth == 0 and char in ",)":
                params.append(current)
                current = ""
                if char == ")":
                    break
                continue
            depth += (char in "([") - (char in ")]")
            current += char
        found.append([p.split(":")[0].split("=")[0].strip() for p in params
                      if p.strip() and p.split(":")[0].strip() not in ("self", "*args", "**kwargs")])
    return found


def test_the_stubs_name_the_parameters_pybind11_has():
    # stubtest cannot see a pybind11 function's parameters (its runtime signature is
    # (*args, **kwargs)); pybind11 writes them in the docstring, so compare those names.
    stub = ast.parse(Path(mpeg4face.__file__).with_name("_core.pyi").read_text())
    checked, wrong = 0, []

    def check(node: ast.FunctionDef, owner: object, where: str) -> None:
        nonlocal checked
        runtime = getattr(owner, node.name, None)
        if runtime is None or any(isinstance(d, ast.Name) and d.id in ("property", "staticmethod")
                                  for d in node.decorator_list):
            return
        names = [a.arg for a in [*node.args.posonlyargs, *node.args.args] if a.arg != "self"]
        if node.args.kwonlyargs:  # pybind11 marks keyword-only parameters with "*" too
            names += ["*", *(a.arg for a in node.args.kwonlyargs)]
        signatures = runtime_signatures(runtime.__doc__, node.name)
        if not signatures:
            return
        checked += 1
        if names not in signatures:
            wrong.append(f"{where}{node.name}: stub {names}, module {signatures}")

    for node in stub.body:
        if isinstance(node, ast.FunctionDef):
            check(node, mpeg4face._core, "")
        elif isinstance(node, ast.ClassDef) and hasattr(mpeg4face._core, node.name):
            for item in node.body:
                if isinstance(item, ast.FunctionDef):
                    check(item, getattr(mpeg4face._core, node.name), f"{node.name}.")
    assert checked > 90
    assert not wrong, "\n".join(wrong)
