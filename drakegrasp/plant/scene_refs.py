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
:data:`MAX_INCLUDED_FILES` loads), *as Drake reads them*, must be

- ``package://NAME/PATH`` with NAME a known package and PATH staying inside it
  (no ``..`` that climbs out: ``package://drakegrasp/../../etc/x.sdf`` is
  refused), or
- ``file:///ABS/PATH`` or a relative path (in the scene file itself; Drake
  refuses them in included files) inside the scene file's own directory (after
  resolving symbolic links, and with the host of ``file://HOST/ABS`` dropped, as
  Drake drops it).

The scene's YAML is read twice, by the safe reader
(:mod:`drakegrasp.plant.scene_file`) and by Drake; a file the two read apart (a
tag on a directive, a key given twice) is refused, and the check runs on Drake's
reading, which is what gets loaded.

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

from pydrake.multibody.parsing import LoadModelDirectives, PackageMap, Parser

from drakegrasp.core.validation import describe, path_text
from drakegrasp.errors import ModelError, SceneError
from drakegrasp.plant.models import (
    check_obj_vertices,
    drake_reading,
    explain_drake_models,
    register_models,
    use_local_drake_models,
)
from drakegrasp.plant.scene_file import check_poses

__all__ = [
    "MAX_INCLUDED_FILES",
    "MAX_URL_LENGTH",
    "PackagesSpec",
    "add_named_package",
    "add_packages",
    "anchor_relative_files",
    "check_references",
    "package_folder",
    "package_name",
]

MAX_INCLUDED_FILES = 32
"""Most directive files (the scene and what it includes) checked per scene."""

MAX_URL_LENGTH = 4096
"""Most characters of a ``file:`` of a directive: ``PATH_MAX``, the longest path
the system opens.  Drake's ``PackageMap.ResolveUrl`` crashed the process
(a segmentation fault) on a URL of 100,000 characters."""

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
            add_named_package(package_map, name, folder)
    elif packages is not None:
        if isinstance(packages, str | os.PathLike):
            packages = [packages]
        if not isinstance(packages, Iterable) or isinstance(packages, bytes):
            raise SceneError(
                "packages must be a PackageMap, a mapping {name: directory} or "
                f"directories, got {type(packages).__name__} {describe(packages)}"
            )
        for folder in packages:
            _add_package_xml(package_map, folder)
    if ros_package_path and os.environ.get(ROS_PACKAGE_PATH):
        _populate_from_ros_package_path(package_map)
    return package_map


def _populate_from_ros_package_path(package_map: PackageMap) -> None:
    """Drake's crawl of ``$ROS_PACKAGE_PATH``, its folders read as paths first.

    Drake raised a bare ``RuntimeError`` ("filesystem error: ... File name
    too long") for a folder whose name is too long.
    """
    for folder in os.environ[ROS_PACKAGE_PATH].split(os.pathsep):
        if folder:
            path_text(
                f"{ROS_PACKAGE_PATH} folder", folder, error=SceneError,
                must="a folder name",
            )  # fmt: skip
    try:
        package_map.PopulateFromRosPackagePath()
    except RuntimeError as e:
        raise SceneError(
            f"cannot read the packages of {ROS_PACKAGE_PATH}: "
            + " ".join(str(e).split())
        ) from None


def add_named_package(package_map: PackageMap, name, folder) -> None:
    """Add package ``name`` at ``folder``; it replaces one of that name.

    A name Drake or drakegrasp registers (``drake_models``, a download) is
    replaced by the user's folder, but ``drake`` and ``drakegrasp`` are
    built in and refused.

    Raises
    ------
    SceneError
        A name that is not a word, a folder that is not a directory, or a
        built-in package.
    """
    name = package_name(name)
    path = package_folder(f"package {describe(name)}", folder)
    if not os.path.isdir(path):  # (pathlib's raises for a path too long)
        raise SceneError(f"package {describe(name)}: {str(path)!r} is not a directory")
    path = str(path.resolve())
    if package_map.Contains(name):
        if name in ("drake", "drakegrasp"):
            raise SceneError(
                f"package {describe(name)} is built in and cannot be replaced"
            )
        package_map.Remove(name)
    package_map.Add(name, path)


def package_name(name, *, error: type = SceneError) -> str:
    """A package's ``name`` as a plain str: one folder of a ``package://`` URL.

    Read as a path is (a str subclass's own methods, a character Drake cannot
    encode), and refused with ``error`` when empty or holding ``/``; for
    scene files and for ``planning_scene(package_map=)`` alike.
    """
    must = "a non-empty string without '/'"
    name = path_text("package name", name, error=error, must=must)
    if "/" in name:
        raise error(f"package name must be {must}, got {describe(name)}")
    return name


def package_folder(what: str, folder, *, error: type = SceneError) -> Path:
    """A package's ``folder`` as a path, ``~`` expanded; not yet checked to exist.

    The one reading of a package folder, for scene files and for
    ``planning_scene(package_map=)``: ``""`` is the current folder (as
    pathlib reads it, and ``os.path.dirname`` returns it), and anything but a
    str or an os.PathLike is refused with ``error`` naming ``what``.
    """
    text = path_text(
        f"{what}: the directory",
        folder,
        error=error,
        must="a str or an os.PathLike",
        empty=True,  # the current folder, as pathlib reads "" (os.path.dirname's)
    )
    # os.path's: pathlib's raises RuntimeError for "~nobody" (no such user)
    return Path(os.path.expanduser(text))


def _add_package_xml(package_map: PackageMap, folder) -> None:
    path = package_folder("package", folder)
    xml = path if path.name == "package.xml" else path / "package.xml"
    if not os.path.isfile(xml):
        raise SceneError(
            f"{str(path)!r} holds no package.xml; pass {{name: directory}} to "
            "name a package without one"
        )
    try:
        package_map.AddPackageXml(str(xml.resolve()))
    except RuntimeError as e:
        raise SceneError(f"cannot add the package of {str(xml)!r}: {e}") from None


def _entries(directives) -> list[tuple[str, str]]:
    """(directive kind, file URL) of every add_model / add_directives (Drake's)."""
    out = []
    for directive in directives.directives:
        for kind in ("add_model", "add_directives"):
            body = getattr(directive, kind)
            if body is not None:
                out.append((kind, body.file))
    return out


def _kinds(directive) -> list[str]:
    return [k for k in _DIRECTIVE_KINDS if getattr(directive, k) is not None]


_DIRECTIVE_KINDS = (
    "add_model",
    "add_model_instance",
    "add_frame",
    "add_weld",
    "add_collision_filter_group",
    "add_directives",
)


def _check_agreement(data: dict, directives) -> None:
    """Refuse a file that this module's YAML reading and Drake's read apart.

    Both must see the same list of directives, each of the same kind, and the
    same ``file`` in every ``add_model`` and ``add_directives``.  (A YAML tag on
    a directive, ``add_model: !!set {...}``, is a set to one reader and a
    mapping to the other.)
    """
    listed = data.get("directives", [])
    if not isinstance(listed, list):
        raise SceneError(f"'directives' must be a list, got {type(listed).__name__}")
    if len(listed) != len(directives.directives):
        raise SceneError(
            f"Drake reads {len(directives.directives)} directives where the YAML "
            f"has {len(listed)}; the file is ambiguous"
        )
    for i, (entry, directive) in enumerate(
        zip(listed, directives.directives, strict=True)
    ):
        kinds = _kinds(directive)
        if not isinstance(entry, dict) or sorted(entry) != sorted(kinds):
            got = sorted(map(str, entry)) if isinstance(entry, dict) else entry
            raise SceneError(
                f"directive {i} reads as {got!r} in YAML but as {kinds} to Drake "
                "(a YAML tag or an unusual form); write it as a plain mapping"
            )
        for kind in ("add_model", "add_directives"):
            if kind not in kinds:
                continue
            body, url = entry[kind], getattr(directive, kind).file
            if type(body) is not dict or body.get("file") != url:
                shown = body.get("file") if type(body) is dict else body
                raise SceneError(
                    f"directive {i}: {kind}.file reads as {shown!r} in YAML but as "
                    f"{url!r} to Drake (a YAML tag or an unusual form); write it "
                    "as a plain string in a plain mapping"
                )


def anchor_relative_files(directives, path: Path) -> None:
    """Turn the scene's ``file:`` paths without a URL scheme into ``file://`` URLs.

    A relative path is relative to the scene file's directory (Drake, reading
    the directives from a string, would refuse it).  ``directives`` is changed
    in place.
    """
    for directive in directives.directives:
        for kind in (directive.add_model, directive.add_directives):
            if kind is None or "://" in kind.file:
                continue
            local = Path(kind.file)
            if not local.is_absolute():
                local = path.resolve().parent / local
            kind.file = f"file://{local}"


def _within(path: str, root: Path) -> bool:
    real = Path(os.path.realpath(path))
    return real == root or root in real.parents


def _check_url(
    url: str, *, scene_dir: Path, package_map: PackageMap
) -> tuple[str, str | None]:
    """Refuse a URL the policy forbids; return (why-ok, local path or None).

    ``url`` is Drake's reading of a ``file:``; a ``file://`` URL is resolved by
    Drake's own :meth:`PackageMap.ResolveUrl` (which drops a host:
    ``file://localhost/ABS`` is ``/ABS``), so the check reads what Drake loads.
    """
    if url.startswith("package://"):
        name, _, rel = url[len("package://") :].partition("/")
        if not package_map.Contains(name):
            known = sorted(package_map.GetPackageNames())
            raise SceneError(
                f"unknown package {name!r} in {url!r} (known packages: {known}); "
                f"register it with load_scene(..., package_map={{{name!r}: DIR}}), "
                f"`--package {name}=DIR` on the command line, or ROS_PACKAGE_PATH"
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
                "inside its packages and its own directory (allow_any_file=True, "
                "or --allow-any-file, trusts the scene)"
            )
        return "package", None
    if not url.startswith("file://"):
        raise SceneError(
            f"{url!r}: only package:// and file:// URLs (or paths relative to the "
            "scene file, in the scene file itself) may be referenced"
        )
    # Drake's reading of file://HOST/PATH is /PATH (the host is dropped).
    rest = url[len("file://") :]
    path = rest[rest.find("/") :] if "/" in rest else ""
    try:
        drake_path = package_map.ResolveUrl(url)
    except RuntimeError:
        drake_path = None  # does not exist: Drake will say so when loading
    if drake_path is not None and os.path.realpath(drake_path) != os.path.realpath(
        path
    ):
        raise SceneError(
            f"{url!r} resolves to {drake_path!r} to Drake, not to {path!r}; the "
            "URL is ambiguous"
        )
    if not path or not _within(path, scene_dir):
        raise SceneError(
            f"{url!r} is {path!r} to Drake, outside the scene's directory "
            f"{str(scene_dir)!r}; a scene may only reference files inside its "
            "packages and its own directory (allow_any_file=True, or "
            "--allow-any-file, trusts the scene)"
        )
    return "file", path


def _resolve(url: str, package_map: PackageMap) -> str:
    try:
        return package_map.ResolveUrl(url)
    except RuntimeError as e:
        msg = explain_drake_models(str(e))
        raise SceneError(f"cannot resolve {url!r}: {msg}") from None


def check_references(
    path: Path,
    data: dict,
    directives,
    package_map: PackageMap,
    *,
    read_yaml,
    allow_any_file: bool = False,
) -> None:
    """Check what Drake will load for a scene, its includes first.

    Drake's reading is what counts: ``directives`` is the scene's
    ``ModelDirectives`` as Drake parsed them (its relative paths are anchored to
    the scene's directory here, in place: see :func:`anchor_relative_files`),
    and every included directive file is read by Drake
    (``LoadModelDirectives``) as well as by the safe reader, and the two readings
    must agree.  Whatever ``allow_any_file`` says, includes are followed here
    before Drake follows them: a loop (a file that includes itself, directly or
    through others) is refused, where Drake would recurse until the process
    dies, and so is a scene that loads more than :data:`MAX_INCLUDED_FILES`
    directive files in all, counting a file each time it is loaded.  Every
    included file passes the safe reader's limits (size, no aliases, depth).

    Parameters
    ----------
    path : pathlib.Path
        The scene file.
    data : dict
        Its YAML data (the safe reader's).
    directives : pydrake.multibody.parsing.ModelDirectives
        Drake's reading of the scene's directives.
    package_map : PackageMap
        The packages it may name.
    read_yaml : callable
        ``read_yaml(path) -> (text, data)``, the safe reader.
    allow_any_file : bool, optional
        Trust the scene: skip the reference policy (the loop, count and reader
        checks still apply).

    Raises
    ------
    SceneError
        Naming the file, the offending URL and the rule.
    """
    scene_dir = Path(os.path.realpath(path)).parent
    loads = [0]

    def visit(current: Path, current_data: dict, parsed, chain: tuple[str, ...]):
        try:
            _check_agreement(current_data, parsed)
        except SceneError as e:
            raise SceneError(f"scene {str(current)!r}: {e}") from None
        if current is path:
            anchor_relative_files(parsed, path)
        for kind, url in _entries(parsed):
            if len(url) > MAX_URL_LENGTH:
                raise SceneError(
                    f"scene {str(current)!r}: {kind}.file {url[:60]!r}... has "
                    f"{len(url)} characters, more than any path can have "
                    f"({MAX_URL_LENGTH}, drakegrasp.plant.scene_refs.MAX_URL_LENGTH)"
                )
            try:
                if not allow_any_file:
                    _check_url(url, scene_dir=scene_dir, package_map=package_map)
                if kind == "add_model" and url.lower().endswith(".obj"):
                    check_obj_vertices(_resolve(url, package_map))
                if kind != "add_directives":
                    continue
                local = os.path.realpath(_resolve(url, package_map))
            except ModelError as e:  # SceneError, or a mesh with a bad vertex
                raise SceneError(f"scene {str(current)!r}: {e}") from None
            if local in chain:
                names = " -> ".join(Path(p).name for p in (*chain, local))
                raise SceneError(
                    f"scene {str(path)!r}: directive files include each other in a "
                    f"loop ({names}); Drake would recurse without end"
                )
            loads[0] += 1
            if loads[0] > MAX_INCLUDED_FILES:
                raise SceneError(
                    f"scene {str(path)!r} loads more than {MAX_INCLUDED_FILES} "
                    "directive files (counting each time a file is included)"
                )
            included_text, included_data = read_yaml(Path(local))
            try:
                included = drake_reading(LoadModelDirectives, local)
            except Exception as e:  # Drake's schema errors: RuntimeError et al.
                msg = " ".join(str(e).split())
                raise SceneError(
                    f"scene {str(current)!r}: bad model directives in {local!r}: {msg}"
                ) from None
            check_poses(Path(local), included_text)
            visit(Path(local), included_data, included, (*chain, local))

    visit(path, data, directives, (os.path.realpath(path),))
