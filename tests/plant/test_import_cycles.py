"""No import cycles inside drakegrasp, and every module imports on its own.

The graph is read from the source (every ``import`` statement, also those
inside functions, which hide a cycle until the function runs), so a cycle
fails here even when the import order happens to work today.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

import drakegrasp

PACKAGE = Path(drakegrasp.__file__).resolve().parent


def module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {
    module_name(p): p for p in sorted(PACKAGE.rglob("*.py")) if "models" not in p.parts
}


def imports_of(path: Path, modules: dict[str, Path]) -> set[str]:
    """drakegrasp modules that ``path`` imports (``from pkg import mod`` too)."""
    tree = ast.parse(path.read_text())
    me = module_name(path)
    found: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module:
            names = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
        else:
            continue
        for name in names:
            if name in modules and name != me:
                found.add(name)
    return found


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(n):
        state[n] = 1
        stack.append(n)
        for m in sorted(graph[n]):
            if state.get(m) == 1:
                return stack[stack.index(m) :] + [m]
            if m not in state:
                cycle = visit(m)
                if cycle:
                    return cycle
        state[n] = 2
        stack.pop()
        return None

    for n in sorted(graph):
        if n not in state:
            cycle = visit(n)
            if cycle:
                return cycle
    return None


def test_the_cycle_finder_finds_a_cycle():
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": set()}) is None


def test_no_import_cycle_between_drakegrasp_modules():
    graph = {name: imports_of(path, MODULES) for name, path in MODULES.items()}
    cycle = find_cycle(graph)
    assert cycle is None, f"import cycle: {' -> '.join(cycle)}"


@pytest.mark.parametrize(
    "name", [n for n in MODULES if n.startswith("drakegrasp.plant")]
)
def test_each_plant_module_imports_first_in_a_fresh_interpreter(name):
    run = subprocess.run(
        [sys.executable, "-c", f"import {name}"], capture_output=True, text=True
    )
    assert run.returncode == 0, run.stderr
