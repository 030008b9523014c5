"""Where drakegrasp's models live, and how to make a Drake parser find them.

The models ship inside the package as ``drakegrasp.models`` (the top-level
``models/`` directory of a source checkout).  Its ``package.xml`` names the
package ``drakegrasp``, so after :func:`register_models` a parser resolves
``package://drakegrasp/hands/parallel_jaw.sdf`` and the like.
"""

from __future__ import annotations

import functools
import importlib.util
import logging
import math
import os
import re
from pathlib import Path

from pydrake.multibody.parsing import PackageMap, Parser
from pydrake.multibody.plant import MultibodyPlant

from drakegrasp.core.calls import checked_call
from drakegrasp.core.validation import path_text
from drakegrasp.errors import GraspError, InvalidOptionError, ModelError

__all__ = [
    "DRAKE_MODELS_ENV",
    "DRAKE_MODELS_HINT",
    "PACKAGE_NAME",
    "check_obj_vertices",
    "drake_reading",
    "explain_drake_models",
    "load_models",
    "models_dir",
    "new_parser",
    "register_models",
    "use_local_drake_models",
]

PACKAGE_NAME = "drakegrasp"

DRAKE_MODELS_ENV = "DRAKEGRASP_DRAKE_MODELS"
"""Environment variable naming a local copy of Drake's ``drake_models`` package.

Drake's wheel downloads ``package://drake_models/...`` on demand; offline
machines (CI, a laptop on a plane) set this variable to a folder holding the
package and call :func:`use_local_drake_models` on their parser.
"""

DRAKE_MODELS_HINT = (
    "Drake downloads the drake_models package on first use, and that failed "
    "(offline, or the download is blocked); use a local copy of it instead: set "
    f"{DRAKE_MODELS_ENV}=DIR, or pass --package drake_models=DIR to 'drakegrasp "
    "analyze' (package_map={'drake_models': DIR} to load_scene), DIR being the "
    "folder that holds wsg_50_description/, allegro_hand_description/, ..."
)
"""What to do when ``package://drake_models/...`` cannot be fetched."""


def explain_drake_models(message: str) -> str:
    """``message``, with :data:`DRAKE_MODELS_HINT` when drake_models failed to load.

    Drake's own words for a failed download (``"when downloading
    'drake_models'"``, or networking disabled by ``DRAKE_ALLOW_NETWORK`` for
    ``'drake_models'``) name neither drakegrasp's variable nor its command-line
    flag; other messages are returned unchanged.
    """
    text = " ".join(str(message).split())
    if "drake_models" not in text:
        return text
    if "DRAKE_ALLOW_NETWORK" in text:  # Drake's Parser() itself refuses
        return (
            f"{text}. Drake's Parser registers drake_models when it is made, "
            "so it cannot be made while DRAKE_ALLOW_NETWORK forbids package "
            "downloads and the cache lacks drake_models: unset "
            "DRAKE_ALLOW_NETWORK (or let it include package_map). " + DRAKE_MODELS_HINT
        )
    if "download" in text:
        return f"{text}. {DRAKE_MODELS_HINT}"
    return text


def new_parser(plant: MultibodyPlant, what: str) -> Parser:
    """``Parser(plant)``, or a ``ModelError`` naming ``what`` and the way out.

    Drake's parser registers ``drake_models`` as a download when it is made,
    and refuses to be made while ``DRAKE_ALLOW_NETWORK`` forbids downloads
    and the cache lacks the package (:func:`explain_drake_models`).

    Parameters
    ----------
    plant : MultibodyPlant
        Not finalized: the parser adds models to it.
    what : str
        What the parser is for, to begin the error ("scene 'x.yaml'").
    """
    try:
        return Parser(plant)
    except RuntimeError as e:  # its default PackageMap could not add drake_models
        raise ModelError(
            f"{what}: cannot make Drake's parser: " + explain_drake_models(str(e))
        ) from None


class _Collected(logging.Handler):
    """The records logged while it is attached."""

    def __init__(self) -> None:
        super().__init__()
        self.records: list[logging.LogRecord] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.records.append(record)


def drake_reading(read, *args, **kwargs):
    """``read(*args, **kwargs)``, a Drake reader whose refusal is a RuntimeError.

    Drake checks some of what it reads with ``DRAKE_DEMAND`` (a directive
    that names no kind, ``file: ''``), which pydrake raises as ``SystemExit``:
    an ``except Exception`` does not catch it and the program ends.  Its
    reason goes to the ``drake`` logger first, as a second line on stderr.
    Here the reason (what was logged at WARNING and above) is kept instead and
    raised as ``RuntimeError(reason)``, for the caller to name its file; what
    the reader logs without refusing reaches the logger's handlers afterwards.
    A reader that refuses has its INFO records dropped: they say what it was
    doing ("PackageMap: Downloading https://..."), which the refusal says
    again with its outcome, and they were a line on stderr before the CLI's
    one-line error.  What it logged at WARNING and above still reaches the
    handlers after a ``RuntimeError``.

    Raises
    ------
    RuntimeError
        Drake refused (its own RuntimeError, or a ``SystemExit`` with the
        logged reason).
    """
    logger = logging.getLogger("drake")
    collected = _Collected()
    propagate = logger.propagate
    logger.addHandler(collected)
    logger.propagate = False
    refused = True
    try:
        result = read(*args, **kwargs)
        refused = False
        return result
    except SystemExit as e:
        said = [
            r.getMessage() for r in collected.records if r.levelno >= logging.WARNING
        ]
        collected.records.clear()
        raise RuntimeError("; ".join(said) or str(e)) from None
    finally:
        logger.removeHandler(collected)
        logger.propagate = propagate
        for record in collected.records:
            if not refused or record.levelno >= logging.WARNING:
                logger.handle(record)


def load_models(where: str, read, *args, **kwargs):
    """:func:`drake_reading` of models, its refusal a :class:`~drakegrasp.ModelError`.

    Parameters
    ----------
    where : str
        What is read, as the message names it (``"scene 'a.yaml'"``, ``"model
        file 'hand.urdf'"``); the message is ``"{where}: cannot load the
        models: {Drake's reason}"``, with :data:`DRAKE_MODELS_HINT` when
        drake_models could not be fetched.
    read : callable
        The Drake reader, called as ``read(*args, **kwargs)``.

    Raises
    ------
    ModelError
        Drake refused (a missing file, an unknown package, text that is not
        a model).  A :class:`~drakegrasp.GraspError` passes unchanged.
    """
    try:
        return drake_reading(read, *args, **kwargs)
    except GraspError:
        raise
    except Exception as e:  # Drake reports what it cannot read as RuntimeError
        msg = explain_drake_models(str(e))
        raise ModelError(f"{where}: cannot load the models: {msg}") from None


@checked_call
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


@checked_call
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
    package_map = _package_map_of(parser_or_package_map, "register_models")
    path = str(models_dir())
    if package_map.Contains(PACKAGE_NAME):
        if package_map.GetPath(PACKAGE_NAME) == path:
            return package_map
        package_map.Remove(PACKAGE_NAME)
    package_map.Add(PACKAGE_NAME, path)
    return package_map


@checked_call
def use_local_drake_models(
    parser_or_package_map: Parser | PackageMap, path: str | os.PathLike | None = None
) -> PackageMap:
    """Point ``package://drake_models/...`` at a local folder instead of a download.

    Parameters
    ----------
    parser_or_package_map : pydrake.multibody.parsing.Parser or PackageMap
        The parser (its ``package_map()`` is updated) or package map to change.
    path : str or os.PathLike, optional
        Folder that holds the ``drake_models`` package (``wsg_50_description/``,
        ``allegro_hand_description/``, ...).  Default: the folder named by the
        environment variable :data:`DRAKE_MODELS_ENV`; when that is unset too,
        nothing changes and Drake downloads the package as usual.

    Returns
    -------
    PackageMap
        The package map, now resolving ``drake_models`` to ``path``.

    Raises
    ------
    ModelError
        If ``path`` (or the variable's value) is not a directory.
    InvalidOptionError
        If ``parser_or_package_map`` is neither a Parser nor a PackageMap.
    """
    package_map = _package_map_of(parser_or_package_map, "use_local_drake_models")
    from_env = path is None
    must = "a folder name (a str or an os.PathLike)"
    if path is None:
        path = os.environ.get(DRAKE_MODELS_ENV)
        if not path:
            return package_map
        path = path_text(DRAKE_MODELS_ENV, path, error=ModelError, must=must)
    else:
        path = path_text("path", path, must=must)
    # os.path's expanduser: pathlib's raises RuntimeError for "~nobody"
    folder = Path(os.path.expanduser(path)).resolve()
    if not os.path.isdir(folder):
        if from_env:
            raise ModelError(
                f"{DRAKE_MODELS_ENV} is set to {str(path)!r}, which is not a "
                "directory, so it does not hold the drake_models package: point "
                "it at a local copy of drake_models (the folder that holds "
                "wsg_50_description/, ...), or unset it to let Drake download it"
            )
        raise ModelError(
            f"drake_models folder {str(path)!r} is not a directory (set "
            f"{DRAKE_MODELS_ENV} or pass path= to a local copy of drake_models)"
        )
    if package_map.Contains("drake_models"):
        package_map.Remove("drake_models")
    package_map.Add("drake_models", str(folder))
    return package_map


def _package_map_of(parser_or_package_map, caller: str) -> PackageMap:
    if isinstance(parser_or_package_map, Parser):
        return parser_or_package_map.package_map()
    if isinstance(parser_or_package_map, PackageMap):
        return parser_or_package_map
    raise InvalidOptionError(
        f"{caller} expects a pydrake Parser or PackageMap, got "
        f"{type(parser_or_package_map).__name__}"
    )


def check_obj_vertices(path) -> None:
    """Refuse a Wavefront OBJ file whose vertices or faces Drake would misread.

    Drake's parser reads ``v nan 0 0`` as a vertex at a finite place, and the
    planner or a scene then works on a mesh the file does not describe; a face
    that names a vertex the file does not have stops the interpreter inside
    Drake.  So :func:`~drakegrasp.planning.scenes.planning_scene` and a
    scene's ``add_model`` of an ``.obj`` read its ``v`` and ``f`` lines first
    (under a second for 100,000 vertices and 200,000 faces).  A line is read as
    Drake reads it: its first word, after any indent, is the keyword.

    Parameters
    ----------
    path : str or os.PathLike
        The ``.obj`` file.

    Raises
    ------
    ModelError
        Naming the first bad line: a vertex that is not three finite numbers,
        or a face index that is not an integer naming a vertex of the file
        (``1 … V``, or ``-1 … -V`` counted back from the vertices read so far).
    """

    def bad(number, line, what):
        return ModelError(
            f"mesh {os.fspath(path)!r}, line {number}: {what}, got "
            f"{line.strip()[:80]!r}"
        )

    try:
        with open(path, encoding="utf-8", errors="replace") as f:
            count, highest = 0, (0, 0, "")  # vertices read; largest face index
            for number, line in enumerate(f, 1):
                words = line.split("#", 1)[0].split()
                if not words or words[0] not in ("v", "f"):
                    continue
                if words[0] == "v":
                    try:
                        values = [float(x) for x in words[1:4]]
                    except ValueError:
                        values = []
                    if len(values) < 3 or not all(math.isfinite(v) for v in values):
                        raise bad(number, line, "a vertex must be three finite numbers")
                    count += 1
                    continue
                for word in words[1:]:
                    # as Drake's reader (C's atoi): the leading integer counts
                    digits = re.match(r"[+-]?\d+", word)
                    if digits is None:
                        raise bad(
                            number, line, "a face's vertex must be an integer index"
                        )
                    index = int(digits.group())
                    if index == 0 or index < -count:
                        raise bad(number, line, f"a face names vertex {index}")
                    if index > highest[0]:
                        highest = (index, number, line)
            index, number, line = highest  # a forward reference counts the file's V
            if index > count:
                raise bad(
                    number, line,
                    f"a face names vertex {index} of a file of {count} vertices",
                )  # fmt: skip
    except OSError:
        return  # Drake's parser says what is wrong with the file
