"""Where drakegrasp's models live, and how to make a Drake parser find them.

The models ship inside the package as ``drakegrasp.models`` (the top-level
``models/`` directory of a source checkout).  Its ``package.xml`` names the
package ``drakegrasp``, so after :func:`register_models` a parser resolves
``package://drakegrasp/hands/parallel_jaw.sdf`` and the like.
"""

from __future__ import annotations

import functools
import importlib.util
from pathlib import Path

from pydrake.multibody.parsing import PackageMap, Parser

from drakegrasp.errors import ModelError

__all__ = ["PACKAGE_NAME", "models_dir", "register_models"]

PACKAGE_NAME = "drakegrasp"


@functools.cache
def models_dir() -> Path:
    """Absolute path of the directory that holds ``package.xml`` and the models.

    Returns
    -------
    pathlib.Path
        ``<site-packages>/drakegrasp/models`` in an installed wheel, or the
        top-level ``models/`` directory of a source checkout.

    Raises
    ------
    ModelError
        If neither location holds a ``package.xml``.
    """
    candidates = []
    spec = importlib.util.find_spec("drakegrasp.models")
    if spec is not None and spec.submodule_search_locations:
        candidates += [Path(p) for p in spec.submodule_search_locations]
    # Source checkout (editable installs made before models were packaged).
    candidates.append(Path(__file__).resolve().parents[2] / "models")
    for path in candidates:
        if (path / "package.xml").is_file():
            return path.resolve()
    raise ModelError(
        "drakegrasp's models were not found (looked for package.xml in "
        f"{[str(p) for p in candidates]}); reinstall drakegrasp"
    )


def register_models(parser_or_package_map: Parser | PackageMap) -> PackageMap:
    """Make ``package://drakegrasp/...`` resolve in a Drake parser or package map.

    Parameters
    ----------
    parser_or_package_map : pydrake.multibody.parsing.Parser or PackageMap
        The user's parser (its ``package_map()`` is updated) or a package map.
        Registering twice is harmless.

    Returns
    -------
    PackageMap
        The package map that now knows the ``drakegrasp`` package.

    Examples
    --------
    >>> parser = Parser(plant)  # doctest: +SKIP
    >>> register_models(parser)  # doctest: +SKIP
    >>> parser.AddModelsFromUrl(
    ...     "package://drakegrasp/objects/box.sdf")  # doctest: +SKIP
    """
    if isinstance(parser_or_package_map, Parser):
        package_map = parser_or_package_map.package_map()
    elif isinstance(parser_or_package_map, PackageMap):
        package_map = parser_or_package_map
    else:
        raise TypeError(
            "register_models expects a pydrake Parser or PackageMap, got "
            f"{type(parser_or_package_map).__name__}"
        )
    path = str(models_dir())
    if package_map.Contains(PACKAGE_NAME):
        if package_map.GetPath(PACKAGE_NAME) == path:
            return package_map
        package_map.Remove(PACKAGE_NAME)
    package_map.Add(PACKAGE_NAME, path)
    return package_map
