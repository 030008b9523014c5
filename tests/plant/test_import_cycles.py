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


def imports_of(path: Path, modules: dict[str, Path], *, lazy: bool = True) -> set[str]:
    """drakegrasp modules that ``path`` imports (``from pkg import mod`` too).

    ``lazy=False`` keeps only the imports at module level (outside functions).
    """
    tree = ast.parse(path.read_text())
    me = module_name(path)
    nodes = _runtime(tree, functions=lazy)
    found: set[str] = set()
    for node in nodes:
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


def _is_type_checking(node) -> bool:
    test = getattr(node, "test", None)
    return isinstance(node, ast.If) and (
        (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING")
        or (isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")
    )


def _runtime(tree: ast.Module, *, functions: bool):
    """The nodes of ``tree`` that run (not under ``if TYPE_CHECKING:``).

    ``functions=False`` also leaves out function bodies.
    """
    stack = list(tree.body)
    while stack:
        node = stack.pop()
        if _is_type_checking(node):
            stack.extend(node.orelse)
            continue
        if not functions and isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            continue
        yield node
        stack.extend(ast.iter_child_nodes(node))


def _module_level(tree: ast.Module):
    """The nodes of ``tree`` that run at import time."""
    return _runtime(tree, functions=False)


# Lazy imports allowed to close a cycle (none: the certificate check, its text
# and the Meshcat arrows moved to modules of their own).
KNOWN_LAZY_EDGES: set[tuple[str, str]] = set()


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
    for a, b in KNOWN_LAZY_EDGES:
        if b in graph.get(a, ()) and b not in imports_of(
            MODULES[a], MODULES, lazy=False
        ):
            graph[a] = graph[a] - {b}
    cycle = find_cycle(graph)
    assert cycle is None, f"import cycle: {' -> '.join(cycle)}"


def test_no_import_cycle_at_module_level():
    graph = {n: imports_of(p, MODULES, lazy=False) for n, p in MODULES.items()}
    cycle = find_cycle(graph)
    assert cycle is None, f"import cycle: {' -> '.join(cycle)}"


def test_a_lazy_import_counts():
    # The cycle issue 8 removed hid in a function: contacts -> scene.
    source = "def f():\n    from drakegrasp.plant.scene import x\n"
    tree = ast.parse(source)
    assert not list(n for n in _module_level(tree) if isinstance(n, ast.ImportFrom))
    assert [n for n in _runtime(tree, functions=True) if isinstance(n, ast.ImportFrom)]
    # A type-only import is no edge.
    typed = ast.parse("if TYPE_CHECKING:\n    from drakegrasp.grasp import Grasp\n")
    assert not list(
        n for n in _runtime(typed, functions=True) if isinstance(n, ast.ImportFrom)
    )


@pytest.mark.parametrize(
    "name", [n for n in MODULES if n.startswith("drakegrasp.plant")]
)
def test_each_plant_module_imports_first_in_a_fresh_interpreter(name):
    run = subprocess.run(
        [sys.executable, "-c", f"import {name}"], capture_output=True, text=True
    )
    assert run.returncode == 0, run.stderr
