"""What a scene file may reference, and the packages it can name.

**Packages.**  A scene names model files by ``package://NAME/...`` URLs.  The
parser that loads it knows, in this order of precedence:

1. ``drakegrasp`` (the shipped models) and Drake's own ``drake`` and
   ``drake_models`` (the latter downloaded on demand, or the local copy named
   by ``DRAKEGRASP_DRAKE_MODELS``);
2. the user's packages: ``load_scene(..., packages=...)`` or
   ``drakegrasp analyze --package NAME=DIR`` (repeatable);
3. every package found under ``ROS_PACKAGE_PATH``, crawled as Drake does
   (``PackageMap.PopulateFromRosPackagePath``: subdirectories of a package
   and directories holding ``AMENT_IGNORE``, ``CATKIN_IGNORE`` or
   ``COLCON_IGNORE`` are skipped; a name already known keeps its first path).

**References.**  Every ``file:`` of the scene's ``add_model`` and
``add_directives`` entries (and of the directive files those include, up to
:data:`MAX_INCLUDED_FILES`) must be

- ``package://NAME/PATH`` with NAME a known package and PATH staying inside it
  (no ``..`` that climbs out: ``package://drakegrasp/../../etc/x.sdf`` is
  refused), or
- ``file:///ABS/PATH`` or a relative path inside the scene file's own directory
  (after resolving symbolic links).

Anything else (other schemes, other directories) is a
:class:`~drakegrasp.errors.SceneError` unless the caller passes
``allow_any_file=True``, which trusts the scene.  The check covers the scene's
own references; the files inside a package (an SDF's meshes and includes) are
the package's business, resolved by Drake.
"""

from __future__ import annotations

import os
import posixpath
from collections.abc import Iterable, Mapping
from pathlib import Path

from pydrake.multibody.parsing import PackageMap, Parser

from drakegrasp.errors import SceneError
from drakegrasp.plant.models import register_models, use_local_drake_models

__all__ = [
    "MAX_INCLUDED_FILES",
    "PackagesSpec",
    "add_packages",
    "check_references",
]

MAX_INCLUDED_FILES = 32
"""Most directive files (the scene and what it includes) checked per scene."""

ROS_PACKAGE_PATH = "ROS_PACKAGE_PATH"

PackagesSpec = (
    PackageMap
    | Mapping[str, "str | os.PathLike"]
    | Iterable["str | os.PathLike"]
    | None
)


def add_packages(
    parser: Parser, packages: PackagesSpec = None, *, ros_package_path: bool = True
) -> PackageMap:
    """Register drakegrasp's, the user's and ``ROS_PACKAGE_PATH``'s packages.

    Parameters
    ----------
    parser : pydrake.multibody.parsing.Parser
    packages : PackageMap, mapping or iterable, optional
        A Drake ``PackageMap`` (merged in), a mapping ``{name: directory}``, or
        an iterable of package directories (each holding a ``package.xml``
        that names it).  These take precedence over ``ROS_PACKAGE_PATH``.
    ros_package_path : bool, optional
        Also crawl ``$ROS_PACKAGE_PATH`` when it is set (default True).

    Returns
    -------
    PackageMap
        The parser's package map.

    Raises
    ------
    SceneError
        A directory that does not exist, a package.xml that cannot be read, or
        a package that conflicts with one already registered.
    """
    package_map = parser.package_map()
    register_models(package_map)
    use_local_drake_models(package_map)
    if isinstance(packages, PackageMap):
        try:
            package_map.AddMap(packages)
        except RuntimeError as e:
            raise SceneError(f"cannot merge the given PackageMap: {e}") from None
    elif isinstance(packages, Mapping):
        for name, folder in packages.items():
            _add_named(package_map, name, folder)
    elif packages is not None:
        if isinstance(packages, str | os.PathLike):
            packages = [packages]
        for folder in packages:
            _add_package_xml(package_map, folder)
    if ros_package_path and os.environ.get(ROS_PACKAGE_PATH):
        package_map.PopulateFromRosPackagePath()
    return package_map


def _add_named(package_map: PackageMap, name, folder) -> None:
    if not isinstance(name, str) or not name or "/" in name:
        raise SceneError(
            f"package name must be a non-empty string without '/', got {name!r}"
        )
    path = Path(folder).expanduser()
    if not path.is_dir():
        raise SceneError(f"package {name!r}: {str(folder)!r} is not a directory")
    path = str(path.resolve())
    if package_map.Contains(name):
        if name in ("drake", "drakegrasp"):
            raise SceneError(f"package {name!r} is built in and cannot be replaced")
        package_map.Remove(name)
    package_map.Add(name, path)


def _add_package_xml(package_map: PackageMap, folder) -> None:
    path = Path(folder).expanduser()
    xml = path if path.name == "package.xml" else path / "package.xml"
    if not xml.is_file():
        raise SceneError(
            f"{str(folder)!r} holds no package.xml; pass {{name: directory}} to "
            "name a package without one"
        )
    try:
        package_map.AddPackageXml(str(xml.resolve()))
    except RuntimeError as e:
        raise SceneError(f"cannot add the package of {str(xml)!r}: {e}") from None


def _files(data: dict) -> list[tuple[str, str]]:
    """(directive kind, file URL) of every add_model / add_directives entry."""
    directives = data.get("directives", [])
    if not isinstance(directives, list):
        raise SceneError(
            f"'directives' must be a list, got {type(directives).__name__}"
        )
    out = []
    for entry in directives:
        if not isinstance(entry, dict):
            continue  # Drake's own schema check reports it
        for kind in ("add_model", "add_directives"):
            body = entry.get(kind)
            if isinstance(body, dict) and "file" in body:
                if not isinstance(body["file"], str):
                    raise SceneError(
                        f"{kind}.file must be a string URL, got {body['file']!r}"
                    )
                out.append((kind, body["file"]))
    return out


def _within(path: str, root: Path) -> bool:
    real = Path(os.path.realpath(path))
    return real == root or root in real.parents


def _check_url(
    url: str, *, scene_dir: Path, package_map: PackageMap
) -> tuple[str, str | None]:
    """Refuse a URL the policy forbids; return (why-ok, local path or None)."""
    if url.startswith("package://"):
        name, _, rel = url[len("package://") :].partition("/")
        if not package_map.Contains(name):
            known = sorted(package_map.GetPackageNames())
            raise SceneError(
                f"unknown package {name!r} in {url!r} (known packages: {known}); "
                f"register it with load_scene(..., packages={{{name!r}: DIR}}), "
                f"`drakegrasp analyze --package {name}=DIR`, or ROS_PACKAGE_PATH"
            )
        normal = posixpath.normpath(rel) if rel else ""
        if (
            not rel
            or normal.startswith("../")
            or normal in ("..", ".")
            or (normal.startswith("/"))
        ):
            raise SceneError(
                f"{url!r} leaves the package {name!r} (its path {rel!r} climbs "
                "out with '..' or is empty); a scene may only reference files "
                "inside its packages and its own directory (allow_any_file=True "
                "trusts the scene)"
            )
        return "package", None
    if "://" in url and not url.startswith("file://"):
        raise SceneError(
            f"{url!r}: only package:// and file:// URLs (or paths relative to the "
            "scene file) may be referenced"
        )
    local = url[len("file://") :] if url.startswith("file://") else url
    path = local if os.path.isabs(local) else str(scene_dir / local)
    if not _within(path, scene_dir):
        raise SceneError(
            f"{url!r} is outside the scene's directory {str(scene_dir)!r}; a scene "
            "may only reference files inside its packages and its own directory "
            "(allow_any_file=True trusts the scene)"
        )
    return "file", path


def check_references(
    path: Path, data: dict, package_map: PackageMap, *, read_yaml
) -> None:
    """Enforce the reference policy on a scene and the directive files it adds.

    Parameters
    ----------
    path : pathlib.Path
        The scene file.
    data : dict
        Its YAML data.
    package_map : PackageMap
        The packages it may name.
    read_yaml : callable
        ``read_yaml(path) -> (text, data)`` for included directive files.

    Raises
    ------
    SceneError
        Naming the scene, the offending URL and the rule.
    """
    scene_dir = Path(os.path.realpath(path)).parent
    pending, seen = [(path, data)], set()
    while pending:
        current, current_data = pending.pop()
        seen.add(os.path.realpath(current))
        if len(seen) > MAX_INCLUDED_FILES:
            raise SceneError(
                f"scene {str(path)!r} includes more than {MAX_INCLUDED_FILES} "
                "directive files"
            )
        try:
            entries = _files(current_data)
        except SceneError as e:
            raise SceneError(f"scene {str(current)!r}: {e}") from None
        for kind, url in entries:
            try:
                how, local = _check_url(
                    url, scene_dir=scene_dir, package_map=package_map
                )
                if kind == "add_directives" and local is None and how == "package":
                    local = package_map.ResolveUrl(url)
            except SceneError as e:
                raise SceneError(f"scene {str(current)!r}: {e}") from None
            except RuntimeError as e:
                raise SceneError(
                    f"scene {str(current)!r}: cannot resolve {url!r}: {e}"
                ) from None
            if kind == "add_directives" and os.path.realpath(local) not in seen:
                pending.append((Path(local), read_yaml(Path(local))[1]))
