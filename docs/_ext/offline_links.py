"""Links to Drake's, Python's and NumPy's documentation, without intersphinx.

Drake publishes its Python API at https://drake.mit.edu/pydrake/, one page per
module, with an anchor per object (``pydrake.multibody.plant.html#
pydrake.multibody.plant.MultibodyPlant``).  The machine that builds these docs has
no network, so intersphinx cannot fetch Drake's ``objects.inv``; instead this
extension answers Sphinx's ``missing-reference`` event for any target that names
a pydrake object, after checking that the installed pydrake really has that
object (an unknown name stays unresolved, so the nitpicky build fails on it).

Short names used in our docstrings (``MultibodyPlant``, ``Context``, ...) are
mapped to their full names by :data:`SHORT_NAMES`.

numpydoc links the builtin types of a parameter list (``float``, ``None``,
``sequence``, ``array_like``, ...) as intersphinx targets ``python:...`` and
``numpy:...``; :data:`PYTHON_AND_NUMPY` gives each of them its page, and a
target outside that table stays unresolved.
"""

from __future__ import annotations

import importlib

from docutils import nodes
from sphinx.addnodes import pending_xref
from sphinx.application import Sphinx
from sphinx.environment import BuildEnvironment

DRAKE_PYDRAKE_URL = "https://drake.mit.edu/pydrake/"

#: The pydrake objects our docstrings name without their module.
SHORT_NAMES = {
    "MultibodyPlant": "pydrake.multibody.plant.MultibodyPlant",
    "Context": "pydrake.systems.framework.Context",
    "Diagram": "pydrake.systems.framework.Diagram",
    "Parser": "pydrake.multibody.parsing.Parser",
    "PackageMap": "pydrake.multibody.parsing.PackageMap",
    "RigidBody": "pydrake.multibody.tree.RigidBody",
    "Body": "pydrake.multibody.tree.RigidBody",
    "Frame": "pydrake.multibody.tree.Frame",
    "ModelInstanceIndex": "pydrake.multibody.tree.ModelInstanceIndex",
    "GeometryId": "pydrake.geometry.GeometryId",
    "SceneGraph": "pydrake.geometry.SceneGraph",
    "SceneGraphInspector": "pydrake.geometry.SceneGraphInspector",
    "QueryObject": "pydrake.geometry.QueryObject",
    "Meshcat": "pydrake.geometry.Meshcat",
    "Rgba": "pydrake.geometry.Rgba",
    "RigidTransform": "pydrake.math.RigidTransform",
    "RotationMatrix": "pydrake.math.RotationMatrix",
    "MathematicalProgram": "pydrake.solvers.MathematicalProgram",
    "MathematicalProgramResult": "pydrake.solvers.MathematicalProgramResult",
    "SolverId": "pydrake.solvers.SolverId",
    "SolutionResult": "pydrake.solvers.SolutionResult",
    "LeafSystem": "pydrake.systems.framework.LeafSystem",
}


PYTHON = "https://docs.python.org/3/"
NUMPY = "https://numpy.org/doc/stable/"

#: intersphinx-style targets numpydoc emits, and where they are documented.
PYTHON_AND_NUMPY = {
    **{
        f"python:{name}": f"{PYTHON}library/functions.html#{name}"
        for name in ("float", "int", "str", "tuple", "list", "dict", "bool", "set")
    },
    "python:None": f"{PYTHON}library/constants.html#None",
    "python:bltin-boolean-values": f"{PYTHON}library/stdtypes.html#boolean-type-bool",
    "python:sequence": f"{PYTHON}glossary.html#term-sequence",
    "python:iterable": f"{PYTHON}glossary.html#term-iterable",
    "python:mapping": f"{PYTHON}glossary.html#term-mapping",
    "python:callable": f"{PYTHON}glossary.html#term-callable",
    "python:file object": f"{PYTHON}glossary.html#term-file-object",
    "python:path-like object": f"{PYTHON}glossary.html#term-path-like-object",
    "numpy:array_like": f"{NUMPY}glossary.html#term-array_like",
    "numpy.ndarray": f"{NUMPY}reference/generated/numpy.ndarray.html",
    "numpy": f"{NUMPY}reference/index.html",
    "numpy:arrays.scalars": f"{NUMPY}reference/arrays.scalars.html",
    "os.replace": f"{PYTHON}library/os.html#os.replace",
}


def _locate(target: str) -> tuple[str, str] | None:
    """``(module, full name)`` of a pydrake object, or None when it does not exist.

    Drake documents an object on the page of the module it is exported from,
    which is the longest importable prefix of its dotted name.
    """
    full = SHORT_NAMES.get(target, target)
    if not full.startswith("pydrake."):
        return None
    parts = full.split(".")
    for split in range(len(parts), 0, -1):
        module_name = ".".join(parts[:split])
        try:
            obj = importlib.import_module(module_name)
        except ImportError:
            continue
        for attr in parts[split:]:
            obj = getattr(obj, attr, None)
            if obj is None:
                return None
        return module_name, full
    return None


def _resolve(
    _app: Sphinx, _env: BuildEnvironment, node: pending_xref, contnode: nodes.Node
) -> nodes.reference | None:
    target = node["reftarget"]
    if target in PYTHON_AND_NUMPY:
        uri, title = PYTHON_AND_NUMPY[target], target.split(":")[-1]
    elif node.get("refdomain") == "py" and (located := _locate(target)):
        module_name, full = located
        anchor = "" if full == module_name else f"#{full}"
        uri = f"{DRAKE_PYDRAKE_URL}{module_name}.html{anchor}"
        title = f"{full} (Drake documentation)"
    else:
        return None
    if contnode.astext() == target and target.startswith(("python:", "numpy:")):
        # numpydoc's xref shows the raw target ("python:float"): show "float".
        contnode = contnode.deepcopy()
        contnode.children = [nodes.Text(target.split(":", 1)[1])]
    reference = nodes.reference("", "", internal=False, refuri=uri, reftitle=title)
    reference.append(contnode)
    return reference


def setup(app: Sphinx) -> dict:
    """Register the resolver (a Sphinx extension's entry point)."""
    app.connect("missing-reference", _resolve)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
