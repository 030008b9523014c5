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

Modules that moved keep their old paths: :func:`forward_moved_modules` lets
``import drakegrasp.grasp`` give ``drakegrasp.core.grasp`` (the same module
object, with a ``DeprecationWarning`` naming the new path).
"""

from __future__ import annotations

import importlib
import importlib.machinery
import os
import sys
import warnings
from collections.abc import Callable, Iterable, Mapping
from types import ModuleType
from typing import Any

__all__ = ["forward_moved_modules", "lazy_exports"]


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


class _MovedModules:
    """Finds a moved module's old path and loads it as the module it became.

    A meta path finder and its loader (the import system's protocols).
    """

    def __init__(
        self,
        moved: Mapping[str, tuple[str, bool]],
        names: Mapping[str, Mapping[str, str]],
    ):
        self.moved = dict(moved)
        self.names = dict(names)
        self._specs: dict[str, importlib.machinery.ModuleSpec] = {}

    def find_spec(self, fullname, path=None, target=None):  # noqa: ARG002
        """A spec for an old path (None for any other name)."""
        if fullname not in self.moved:
            return None
        return importlib.machinery.ModuleSpec(fullname, self)

    def create_module(self, spec) -> ModuleType:
        new, deprecated = self.moved[spec.name]
        module = importlib.import_module(new)
        if deprecated:
            warnings.warn(
                f"the module {spec.name} moved to {new}; import it from there "
                "(the old path will be removed)",
                DeprecationWarning,
                stacklevel=_importer_level(),
            )
        extra = self.names.get(spec.name)
        if extra:  # the old module was split: its names from each part
            return _split_module(spec.name, module, extra)
        # the import system now sets module.__spec__ to the old path's spec;
        # exec_module puts the module's own back
        self._specs[spec.name] = module.__spec__
        return module

    def exec_module(self, module: ModuleType) -> None:
        """Nothing to run: the module is the one its new path imported.

        Its own ``__spec__`` is restored: with the old path's (this loader),
        ``importlib.reload`` of the module would run nothing and rename it
        to the old path.
        """
        spec = self._specs.pop(getattr(module.__spec__, "name", None), None)
        if spec is not None:
            module.__spec__ = spec

    def get_code(self, fullname):
        """``python -m old``: refused, naming the new path (no code here)."""
        new, _ = self.moved[fullname]
        raise ImportError(f"the module {fullname} moved to {new}; run that one")


def _split_module(name: str, first: ModuleType, extra: Mapping[str, str]):
    """The old module ``name``: ``first``'s names, and ``extra``'s from theirs.

    ``extra`` is ``{name: module path}`` for the names of the old module that
    went to other modules than ``first`` (each imported on first read).
    """
    module = ModuleType(name, first.__doc__)

    def __getattr__(attr: str):
        if attr in extra:
            return getattr(importlib.import_module(extra[attr]), attr)
        try:
            return getattr(first, attr)
        except AttributeError:
            raise AttributeError(f"module {name!r} has no attribute {attr!r}") from None

    def __dir__():
        return sorted(set(dir(first)) | set(extra))

    module.__getattr__ = __getattr__
    module.__dir__ = __dir__
    module.__all__ = [*getattr(first, "__all__", ()), *extra]
    return module


def _importer_level() -> int:
    """``stacklevel`` of :meth:`_MovedModules.create_module`'s warning.

    ``warnings`` steps over the import system's ``_bootstrap`` frames itself;
    ``importlib.import_module`` (and ``reload``), in ``importlib/__init__.py``,
    are stepped over here, so the warning names the line that asked for the
    old path (in ``__main__``, where the default filters show it).
    """
    level, frame = 2, sys._getframe(2)  # the frame that called create_module
    while frame is not None:
        name = frame.f_code.co_filename
        if "importlib" in name and "_bootstrap" in name:
            frame = frame.f_back  # not counted: warnings skips it too
            continue
        if not name.endswith(os.path.join("importlib", "__init__.py")):
            return level
        level += 1
        frame = frame.f_back
    return 2


def forward_moved_modules(
    moved: Mapping[str, str],
    aliases: Iterable[str] = (),
    names: Mapping[str, Mapping[str, str]] | None = None,
) -> None:
    """Let old module paths import the modules they became.

    ``import old`` (and ``from old import name``, and a pickle that names
    ``old``) gives the very module ``new`` is, whose attributes the old path's
    users read; ``old`` is kept in ``sys.modules``.  Each old path warns once
    per process (``DeprecationWarning``), unless it is one of ``aliases``:
    paths that stay public (``drakegrasp.examples``).

    Parameters
    ----------
    moved : mapping of str to str
        ``{old module path: new module path}``, full dotted names.  An old
        path's last part must not be a public name of its package, which the
        import would replace by the module.
    aliases : iterable of str, optional
        Old paths that import without a warning.
    names : mapping of str to mapping of str to str, optional
        ``{old module path: {name: module path}}`` for an old module that was
        split: the names it held that ``moved[old]`` does not, and where each
        went.  Its old path then imports a module of its own whose attributes
        are the new module's and these (not the very module ``new`` is).
    """
    aliases = set(aliases)
    table = {old: (new, old not in aliases) for old, new in moved.items()}
    names = dict(names or {})
    for finder in sys.meta_path:
        if isinstance(finder, _MovedModules):  # the package was imported again
            finder.moved.update(table)
            finder.names.update(names)
            return
    sys.meta_path.append(_MovedModules(table, names))
