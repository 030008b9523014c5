"""The house: layers as folders, imports pointing inwards only, no cycle.

The import graph is read from the source: every ``import`` statement counts,
also those inside functions (which hide a cycle until the function runs) and
those under ``if TYPE_CHECKING:`` (a type-only import is still a dependency of
the design).  Package ``__init__`` files are left out of the graph: they hold
lazy tables of names (strings), which import nothing until a name is read
(:func:`test_package_inits_import_nothing_but_the_lazy_table` keeps them so).
A name imported from a package (``from drakegrasp.planning import
plan_grasps``) is an edge to the module its table names, so going through a
package hides no dependency.

The layers, inner to outer (``docs/architecture.md``)::

    foundation   errors, _lazy
    core, _solvers                    (numpy only; the solver gateway)
    certificates
    closure
    quality, plant                    (peers: neither imports the other)
    batch, visualization              (peers)
    systems, planning, distributed    (peers)
    cli
    __main__

This refines the order ``core → certificates → closure → {quality, plant} →
{batch, systems, visualization, distributed} → cli``: the outer ring is split
where one of its folders drives another (the Dask driver runs the batch
engine; the monitor and the planner use the batch engine and the pictures).
A module may import from its own folder and from any inner layer, never from a
peer or an outer one.
"""

from __future__ import annotations

import ast
import importlib
import subprocess
import sys
from pathlib import Path

import pytest

import drakegrasp

PACKAGE = Path(drakegrasp.__file__).resolve().parent

LAYERS: tuple[tuple[str, ...], ...] = (
    ("errors", "_lazy"),
    ("core", "_solvers"),
    ("certificates",),
    ("closure",),
    ("quality", "plant"),
    ("batch", "visualization"),
    ("systems", "planning", "distributed"),
    ("cli",),
    ("__main__",),
)
RANK = {room: rank for rank, rooms in enumerate(LAYERS) for room in rooms}

MAX_DEPTH = 11
"""The longest import chain, in edges (14 before the layers became folders).

Measured with names imported through packages resolved to their modules.
Before round 36 the graph stopped at a package (its lazy table, and the
eager imports of the ``batch``, ``quality`` and ``visualization`` packages
then) and read 11; followed through them, the chain was 14 long.  It was 12
while the ε stage imported the LP's chunk and the verdict-only run sat in a
module above the chunk.  One of the chains that set it now, each module
importing the next: ``__main__`` → cli → planner → ranking → batch API →
batch chunk → batch construction → friction cones → grasp → contact →
deprecation → errors.  A change that
lengthens it adds a level to every import of the package: it fails here so
that it is a decision.
"""

MAX_ROOT_MODULES = 6


def module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {
    module_name(p): p for p in sorted(PACKAGE.rglob("*.py")) if "models" not in p.parts
}
PACKAGES = {n for n, p in MODULES.items() if p.name == "__init__.py"}


def _import_targets(node: ast.AST) -> list[str]:
    if isinstance(node, ast.Import):
        return [a.name for a in node.names]
    if isinstance(node, ast.ImportFrom) and node.module:
        return [node.module] + [f"{node.module}.{a.name}" for a in node.names]
    return []


def package_exports(package: str) -> dict[str, str]:
    """A package's names → the modules they are read from, packages looked through.

    The package's lazy tables as the package itself holds them (importing a
    package runs only its ``__init__``, which imports nothing but ``_lazy``):
    ``_SOURCES`` (``{module: names}``) and ``_SUBMODULES`` (a tuple of child
    names, or ``{name: module}``).  A name whose table points at another
    package (the root's ``plan_grasps`` → ``drakegrasp.planning``) is looked
    up in that package's table in turn.
    """
    namespace = vars(importlib.import_module(package))
    children = namespace.get("_SUBMODULES", ())
    if not isinstance(children, dict):
        children = {name: f"{package}.{name}" for name in children}
    found: dict[str, str] = dict(children)
    for module, names in namespace.get("_SOURCES", {}).items():
        found.update(dict.fromkeys(names, module))  # a public name comes first
    for name, module in found.items():
        if module in PACKAGES and module != package:
            found[name] = package_exports(module).get(name, module)
    return found


DYNAMIC_IMPORTS: dict[str, set[str]] = {
    "drakegrasp.batch.aot_build": {
        "drakegrasp.batch." + rel.removesuffix(".py").replace("/", ".")
        for rel in importlib.import_module("drakegrasp.batch.aot").SOURCES
    },
}
"""Imports no statement shows: ``importlib.import_module`` of computed names.

The ahead-of-time build imports every kernel module by name.  The other
``import_module`` calls are ``_lazy`` (the tables, resolved above),
``batch.compiled._kernel`` (a kernel unpickled by reference, as ``pickle``
imports a function's module) and ``batch.aot`` (the compiled extension, not
a source module); :func:`test_every_import_by_name_is_accounted_for` keeps
this list complete.
"""


def _resolved(node: ast.AST) -> list[str]:
    """The modules an import statement reaches, through packages' name tables.

    ``from drakegrasp.planning import plan_grasps`` imports
    ``drakegrasp.planning.planner`` (the package's lazy table says where the
    name lives): the edge goes there, not to the package's ``__init__``.
    """
    names = _import_targets(node)
    if isinstance(node, ast.ImportFrom) and node.module in PACKAGES:
        table = package_exports(node.module)
        names += [table[a.name] for a in node.names if a.name in table]
    return names


def opaque_imports(path: Path) -> list[str]:
    """Imports whose target module the graph cannot tell.

    ``import drakegrasp.batch`` or ``from drakegrasp.batch import run`` (then
    ``run.stream...``), and a name that a package's tables do not hold, reach
    modules only through attribute reads; the root package for
    ``drakegrasp.__version__`` is the exception.
    """
    found = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            found += [
                a.name
                for a in node.names
                if a.name in PACKAGES
                and a.name != "drakegrasp"
                and not a.asname
                or a.name in PACKAGES
                and a.asname
            ]
        elif isinstance(node, ast.ImportFrom) and node.module in PACKAGES:
            table = package_exports(node.module)
            found += [
                f"{node.module}.{a.name}"
                for a in node.names
                if table.get(a.name, f"{node.module}.{a.name}") in PACKAGES
                or a.name not in table
                and f"{node.module}.{a.name}" not in MODULES
            ]
    return found


def imports_of(path: Path, *, module_level_only: bool = False) -> set[str]:
    """drakegrasp modules that ``path`` imports (``from pkg import mod`` too).

    A name imported from a package counts as an import of the module its
    tables name (:func:`package_exports`); :data:`DYNAMIC_IMPORTS` are added.
    """
    tree = ast.parse(path.read_text())
    me = module_name(path)
    stack = list(tree.body)
    found: set[str] = set(DYNAMIC_IMPORTS.get(me, ()))
    while stack:
        node = stack.pop()
        if module_level_only and isinstance(
            node, ast.FunctionDef | ast.AsyncFunctionDef
        ):
            continue
        for name in _resolved(node):
            if name in MODULES and name != me and not me.startswith(name + "."):
                found.add(name)
        stack.extend(ast.iter_child_nodes(node))
    return found


def graph(*, module_level_only: bool = False) -> dict[str, set[str]]:
    """Module → the modules it imports, package ``__init__`` files left out."""
    return {
        name: imports_of(path, module_level_only=module_level_only) - PACKAGES
        for name, path in MODULES.items()
        if name not in PACKAGES
    }


def room(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "__init__"


def find_cycle(edges: dict[str, set[str]]) -> list[str] | None:
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(n):
        state[n] = 1
        stack.append(n)
        for m in sorted(edges.get(n, ())):
            if state.get(m) == 1:
                return stack[stack.index(m) :] + [m]
            if m not in state:
                cycle = visit(m)
                if cycle:
                    return cycle
        state[n] = 2
        stack.pop()
        return None

    for n in sorted(edges):
        if n not in state:
            cycle = visit(n)
            if cycle:
                return cycle
    return None


def layering_violations(edges: dict[str, set[str]]) -> list[str]:
    """Imports that point outwards, or sideways into a peer folder."""
    bad = []
    for a, targets in edges.items():
        for b in targets:
            ra, rb = room(a), room(b)
            if ra == rb:
                continue
            if ra not in RANK or rb not in RANK:
                bad.append(f"{a} -> {b}: folder not in LAYERS")
            elif RANK[b.split(".")[1]] >= RANK[ra]:
                bad.append(f"{a} -> {b}")
    return sorted(bad)


def longest_chain(edges: dict[str, set[str]]) -> list[str]:
    memo: dict[str, list[str]] = {}

    def chain(m: str) -> list[str]:
        if m not in memo:
            best = [m]
            for t in sorted(edges.get(m, ())):
                c = [m, *chain(t)]
                if len(c) > len(best):
                    best = c
            memo[m] = best
        return memo[m]

    return max((chain(m) for m in edges), key=len)


def test_the_cycle_finder_finds_a_cycle():
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": set()}) is None


def test_no_import_cycle_type_only_and_function_level_imports_included():
    cycle = find_cycle(graph())
    assert cycle is None, f"import cycle: {' -> '.join(cycle)}"


def _as_a_module(source: str, monkeypatch) -> Path:
    """A library module's path whose text reads as ``source`` in this test."""
    path = PACKAGE / "core" / "contact.py"
    real = Path.read_text
    monkeypatch.setattr(
        Path,
        "read_text",
        lambda self, *a, **k: source if self == path else real(self, *a, **k),
    )
    return path


def test_type_only_and_lazy_imports_are_edges(monkeypatch):
    source = (
        "from typing import TYPE_CHECKING\n"
        "if TYPE_CHECKING:\n    from drakegrasp.core.grasp import Grasp\n"
        "def f():\n    from drakegrasp.plant.scene import load_scene\n"
    )
    found = imports_of(_as_a_module(source, monkeypatch))
    assert {"drakegrasp.core.grasp", "drakegrasp.plant.scene"} <= found


def test_every_folder_has_a_layer():
    rooms = {room(m) for m in MODULES} - {"__init__"}
    assert rooms <= set(RANK), rooms - set(RANK)


def test_imports_point_inwards_only():
    assert layering_violations(graph()) == []


def test_the_layering_test_sees_an_upward_and_a_sideways_import():
    edges = graph()
    upward = {**edges, "drakegrasp.core.contact": {"drakegrasp.plant.analysis"}}
    assert layering_violations(upward) == [
        "drakegrasp.core.contact -> drakegrasp.plant.analysis"
    ]
    sideways = {**edges, "drakegrasp.quality.epsilon": {"drakegrasp.plant.scene"}}
    assert layering_violations(sideways) == [
        "drakegrasp.quality.epsilon -> drakegrasp.plant.scene"
    ]


def test_package_inits_import_nothing_but_the_lazy_table():
    # The graph leaves __init__ files out; an eager import there would be a
    # dependency of every module of the package that nothing here sees.
    for name in sorted(PACKAGES):
        tree = ast.parse(MODULES[name].read_text())
        targets = {t for node in ast.walk(tree) for t in _import_targets(node)}
        inner = {t for t in targets if t.split(".")[0] == "drakegrasp"}
        lazy = {"drakegrasp._lazy", "drakegrasp._lazy.lazy_exports"}
        lazy.add("drakegrasp._lazy.forward_moved_modules")  # strings, not imports
        assert inner <= lazy, (
            name,
            sorted(inner),
        )


def _children(package: str) -> set[str]:
    folder = MODULES[package].parent
    return {
        p.stem if p.is_file() else p.name
        for p in folder.iterdir()
        if (p.suffix == ".py" and p.stem not in ("__init__", "__main__"))
        or (p.is_dir() and (p / "__init__.py").exists() and p.name != "models")
    }


def _public_names(package: str) -> set[str]:
    tables = vars(importlib.import_module(package)).get("_SOURCES", {}).values()
    return {name for names in tables for name in names}


@pytest.mark.parametrize("package", sorted(PACKAGES))
def test_no_module_is_named_like_a_public_name_of_its_package(package):
    # Importing a module sets it as its package's attribute, over the public
    # name: ``from drakegrasp.closure import grasp_forces`` gave the module,
    # not the function, once anything (``dg.grasp_forces`` itself) had
    # imported ``drakegrasp.closure.grasp_forces``.  That module is now
    # ``closure.load_forces``.
    assert not _children(package) & _public_names(package)


@pytest.mark.parametrize("package", sorted(PACKAGES))
def test_a_package_lists_every_module_in_it_as_an_attribute(package):
    # drakegrasp.batch.run.stream, drakegrasp.quality._common: each step of a
    # dotted path is an attribute, imported on first read.
    children = vars(importlib.import_module(package)).get("_SUBMODULES", ())
    missing = _children(package) - set(children)
    assert not missing, missing


def test_every_listed_module_is_its_packages_attribute_in_a_fresh_interpreter():
    # The tables must also reach the package's __getattr__ (lazy_exports).
    pairs = [
        (package, child)
        for package in sorted(PACKAGES)
        for child in sorted(_children(package))
    ]
    code = (
        "import importlib\n"
        f"for package, child in {pairs!r}:\n"
        "    value = getattr(importlib.import_module(package), child)\n"
        "    assert value.__name__ == package + '.' + child, (package, child)\n"
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr[-2000:]


def test_public_names_stay_themselves_after_every_module_is_imported():
    # Whatever the user imported first, a package's public name is what its
    # table says, never a module that import history put in its place.
    modules = sorted(m for m in MODULES if m != "drakegrasp.__main__")
    names = {package: sorted(_public_names(package)) for package in sorted(PACKAGES)}
    assert sum(map(len, names.values())) > 100  # the tables were read
    code = (
        "import importlib, types\n"
        f"for module in {modules!r}:\n"
        "    importlib.import_module(module)\n"
        f"for package, names in {names!r}.items():\n"
        "    found = importlib.import_module(package)\n"
        "    for name in names:\n"
        "        if isinstance(getattr(found, name), types.ModuleType):\n"
        "            print(package, name)\n"
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr[-2000:]
    assert run.stdout == ""


def test_dotted_paths_resolve_in_a_fresh_interpreter():
    paths = [
        "batch.run.stream",
        "batch.files.reader",
        "batch.lp.dstar",
        "batch.build.construction",
        "batch.epsilon.driver",
        "quality._common",
        "core.antipodal",
        "systems.holding",
        "plant.scale",
    ]
    code = (
        "import functools, drakegrasp\n"
        f"for path in {paths!r}:\n"
        "    functools.reduce(getattr, path.split('.'), drakegrasp)\n"
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr


def test_every_import_by_name_is_accounted_for():
    # A new importlib.import_module call is a dependency no statement shows:
    # add its edges to DYNAMIC_IMPORTS, or name why it is none.
    known = {
        # a public name's module, a child module, a moved one, a split one's part
        "drakegrasp._lazy": 4,
        "drakegrasp.batch.compiled": 1,  # a kernel unpickled by reference
        "drakegrasp.batch.aot": 1,  # the compiled extension
        "drakegrasp.batch.aot_build": 1,  # the kernel modules: DYNAMIC_IMPORTS
    }
    calls: dict[str, int] = {}
    for name, path in MODULES.items():
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Call) and (
                getattr(node.func, "attr", None) == "import_module"
                or getattr(node.func, "id", None) in ("import_module", "__import__")
            ):
                calls[name] = calls.get(name, 0) + 1
    assert calls == known


def test_no_import_hides_its_module_behind_a_package():
    hidden = {
        name: found
        for name, path in MODULES.items()
        if name not in PACKAGES and (found := opaque_imports(path))
    }
    assert hidden == {}


def test_a_package_import_the_graph_cannot_follow_is_seen(monkeypatch):
    source = (
        "import drakegrasp.batch as b\n"
        "from drakegrasp.batch import run\n"
        "from drakegrasp.planning import no_such_name\n"
        "from drakegrasp import plan_grasps, examples\n"
    )
    path = _as_a_module(source, monkeypatch)
    assert opaque_imports(path) == [
        "drakegrasp.batch",
        "drakegrasp.batch.run",
        "drakegrasp.planning.no_such_name",
    ]
    # The root's names are looked up through the package they point at.
    assert {"drakegrasp.planning.planner", "drakegrasp.core.examples"} <= (
        imports_of(path)
    )


def test_a_name_imported_through_a_package_is_an_edge_to_its_module():
    cli = graph()["drakegrasp.cli"]
    # cli reads plan_grasps and stream_file from the packages' tables.
    assert "drakegrasp.planning.planner" in cli
    assert "drakegrasp.batch.files.driver" in cli


def test_dependency_depth():
    chain = longest_chain(graph())
    assert len(chain) - 1 <= MAX_DEPTH, " -> ".join(chain)


def test_few_modules_loose_at_the_root():
    loose = sorted(p.name for p in PACKAGE.glob("*.py"))
    assert len(loose) <= MAX_ROOT_MODULES, loose


def test_the_core_imports_numpy_and_the_foundation_only():
    """The core needs numpy, the standard library and drakegrasp's foundation."""
    outside = []
    for name, path in MODULES.items():
        if room(name) != "core":
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            for target in _import_targets(node):
                top = target.split(".")[0]
                if top == "drakegrasp":
                    if room(target) not in ("core", "errors", "_lazy"):
                        outside.append((name, target))
                elif top != "numpy" and top not in sys.stdlib_module_names:
                    outside.append((name, target))
    assert not outside, outside


@pytest.mark.parametrize(
    "name", [n for n in MODULES if room(n) in ("plant", "core", "closure")]
)
def test_each_module_imports_first_in_a_fresh_interpreter(name):
    run = subprocess.run(
        [sys.executable, "-c", f"import {name}"], capture_output=True, text=True
    )
    assert run.returncode == 0, run.stderr
