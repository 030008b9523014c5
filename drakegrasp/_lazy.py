"""A package's public names, imported from their modules on first access.

``import drakegrasp`` (and so every ``drakegrasp`` command, whose module lives
in the package) would otherwise import every layer at once: the batch engine
with its worker pools, Meshcat drawing, Drake Systems, quality metrics.  The
``analyze`` command needs none of them.  A package lists where each public
name lives; :func:`lazy_exports` gives it a module-level ``__getattr__`` (PEP
562) that imports the name's module when the name is first read and keeps the
value in the package, so later reads are plain attribute reads.
``from drakegrasp import X``, ``drakegrasp.X`` and ``from drakegrasp import *``
all resolve exactly as with eager imports.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Iterable, Mapping
from typing import Any

__all__ = ["lazy_exports"]


def lazy_exports(
    package: str,
    namespace: dict[str, Any],
    sources: Mapping[str, Iterable[str]],
    *,
    submodules: Iterable[str] | Mapping[str, str] = (),
) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """``__getattr__`` and ``__dir__`` for a package with lazy public names.

    Parameters
    ----------
    package : str
        The package's ``__name__``.
    namespace : dict
        The package's ``globals()``: a resolved name is stored there.
    sources : mapping of str to iterable of str
        ``{module: names}``: each public name and the module that defines it.
    submodules : iterable of str, or mapping of str to str, optional
        Submodules reachable as attributes (``drakegrasp.batch``), imported on
        first access; a mapping gives the full module path of each attribute
        (``{"examples": "drakegrasp.core.examples"}``).

    Returns
    -------
    (__getattr__, __dir__)
        To be assigned to the package's ``__getattr__`` and ``__dir__``.
    """
    where = {name: module for module, names in sources.items() for name in names}
    children = (
        dict(submodules)
        if isinstance(submodules, Mapping)
        else {name: f"{package}.{name}" for name in submodules}
    )

    def __getattr__(name: str) -> Any:
        module = where.get(name)
        if module is not None:
            value = getattr(importlib.import_module(module), name)
        elif name in children:
            value = importlib.import_module(children[name])
        else:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        namespace[name] = value
        return value

    def __dir__() -> list[str]:
        return sorted(set(namespace) | set(where) | set(children))

    return __getattr__, __dir__
