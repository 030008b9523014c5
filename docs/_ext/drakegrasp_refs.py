"""Resolve references to drakegrasp objects by the names users import them by.

The API reference documents every object once, in the module that defines it
(``drakegrasp.core.grasp.Grasp``), while docstrings and pages also name the public
re-exports (``drakegrasp.Grasp``, or ``ferrari_canny`` inside
``drakegrasp.quality``).  For a reference Sphinx could not resolve, this
extension imports the named object and, when its defining module's entry is
documented, links there.  Anything else stays unresolved, so the nitpicky build
still fails on a name that does not exist.
"""

from __future__ import annotations

import importlib
import inspect

from docutils import nodes
from sphinx.addnodes import pending_xref
from sphinx.application import Sphinx
from sphinx.environment import BuildEnvironment
from sphinx.util.nodes import make_refnode


def _import(dotted: str) -> object | None:
    """The object a dotted name denotes, or None."""
    parts = dotted.split(".")
    for split in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:split]))
        except ImportError:
            continue
        for attr in parts[split:]:
            try:
                obj = getattr(obj, attr)
            except AttributeError:
                return None
        return obj
    return None


def _canonical(obj: object) -> str | None:
    if inspect.ismodule(obj):
        return obj.__name__
    module = getattr(obj, "__module__", None)
    qualname = getattr(obj, "__qualname__", None)
    if module and qualname and module.startswith("drakegrasp"):
        return f"{module}.{qualname}"
    return None


def _resolve(
    app: Sphinx, env: BuildEnvironment, node: pending_xref, contnode: nodes.Node
) -> nodes.reference | None:
    if node.get("refdomain") != "py":
        return None
    target = node["reftarget"].lstrip("~.")
    candidates = [target]
    module, cls = node.get("py:module"), node.get("py:class")
    if module and cls:
        candidates.append(f"{module}.{cls}.{target}")
    if module:
        candidates.append(f"{module}.{target}")
        candidates.append(f"{module.rsplit('.', 1)[0]}.{target}")
    candidates.append(f"drakegrasp.{target}")
    objects = env.get_domain("py").objects
    for name in candidates:
        if not name.startswith("drakegrasp"):
            continue
        obj = _import(name)
        canonical = _canonical(obj) if obj is not None else None
        if canonical is None:
            continue
        entry = objects.get(canonical)
        if entry is None:
            continue
        return make_refnode(
            app.builder,
            node["refdoc"],
            entry.docname,
            entry.node_id,
            contnode,
            canonical,
        )
    return None


def setup(app: Sphinx) -> dict:
    """Register the resolver (a Sphinx extension's entry point)."""
    app.connect("missing-reference", _resolve)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
