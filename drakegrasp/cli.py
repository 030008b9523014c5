"""The ``drakegrasp`` command.

Usage::

    drakegrasp --version
    drakegrasp analyze [SCENE] [--mu M|plant] [--contact-model MODEL]
                       [--torsional-friction NU] [--distance-tolerance D]
                       [--plane PLANE] [--characteristic-length B]
                       [--num-generators NG] [--tol TOL] [--patches MODE]
                       [--close | --no-close] [--allow-penetration]
                       [--check-pose | --no-check-pose]
                       [--coupling-tolerance C]
                       [--load gravity|FX,FY,FZ,MX,MY,MZ] [--object-mass KG]
                       [--torque-limits plant|T1,T2,...]
                       [--package NAME=DIR ...] [--allow-any-file] [--json]
    drakegrasp scenes
    drakegrasp batch IN.npz OUT.npz [--kind force|form] [--mu M]
                     [--contact-model MODEL] [--torsional-friction NU]
                     [--num-generators NG] [--tol TOL] [--metrics NAME ...]
                     [--chunk-size K] [--workers W] [--format npz|parquet]
                     [--scheduler ADDRESS] [--progress] [--overwrite]
    drakegrasp warmup [--json]
    drakegrasp plan [SCENE | OBJECT] [--hand HAND] [--num N] [--top K]
                    [--seed S] [--mu M|plant] [--mass KG] [--torque-limit NM]
                    [--squeeze-limit N] [--contact-model MODEL]
                    [--torsional-friction NU] [--preshape JOINT=VALUE|open ...]
                    [--shake K [--squeeze X] [--stiffness K] [--damping D]
                     [--hydroelastic PA|none]]
                    [--package NAME=DIR ...] [--allow-any-file] [--progress]
                    [--json | --out FILE.parquet] [--scene-out FILE.yaml]
                    [--overwrite]

Every option's default and meaning: ``drakegrasp COMMAND --help`` (read from
the library's own defaults), or the generated reference in the CLI guide.
``--model`` is a deprecated alias of ``batch --contact-model``.  ``--metrics``
takes every word up to the next option: put it after ``IN OUT`` or before
another option, or end it with ``--`` followed by ``IN OUT`` alone.

``analyze`` loads a scene (a shipped scene's name or a YAML file; default: the
default scene), finds the contacts and prints the full report: contacts, ranks,
form closure, force closure with the hand check, exact-cone verdict, antipodal
test, and Ferrari–Canny's ε with moments divided by the object's size (the
radius about its origin that bounds its collision geometry;
:mod:`drakegrasp.plant.scale`).  ``--close`` closes the hand onto the object
first (as a scene's ``close: true`` does); an impossible pose is refused with
a hint naming ``--allow-penetration`` and ``--no-check-pose``, which analyse
it anyway.  ``batch`` decides closure for every grasp of an ``.npz`` file (arrays
``positions`` and ``normals`` of shape (K, N, d), optionally ``mu``, ...) with
the vectorised batch engine and writes the verdicts to another file.
``warmup`` runs every route of the batch engine now and prints each step, its
time and what it compiled: where the install compiled the kernels ahead of time
(:mod:`drakegrasp.batch.aot`) it loads them and compiles nothing; elsewhere
numba's JIT compiles them into numba's on-disk cache (once per install; later
processes load them from there); without numba there is nothing to compile.

``plan`` finds grasps: a free-floating hand (a parallel jaw or a multi-finger
hand) sampled, filtered, closed and ranked on an object, and prints the best
``--top``.  Given a scene (a YAML file ending ``.yaml``/``.yml`` or a shipped
scene's name), it plans for the hand and object that the scene's
``drakegrasp:`` section names (``hand:``, ``object_body:``), with the scene's
μ, contact model and tolerance, against everything else the scene holds (a
table, other objects).  The scene's welds that attach the hand to the world or
to anything else (which place it for ``analyze``, as in every shipped scene;
a table, a mount) are left out, since plan places the hand itself; a ``hand:``
of finger bodies plans for their whole model instance, and a scene without
``hand:`` for the one model instance that moves besides the object.  An
object that is welded or jointed to the world cannot be lifted and is refused
before any work, as are the world, a body of the hand or the hand's own
instance as the object; a planar scene (``plane:``) is refused, as plan
samples spatial grasps.  Given an object (a shipped object's name, a model
URL or a file, or a mesh ``.obj`` file, which Drake's parser makes one body
with the mass of water filling it; default ``box``), it plans for ``--hand`` (a
model URL or file, ``wsg`` for Drake's WSG-50, ``franka`` for Drake's Franka
(Panda) hand, ``allegro`` for Drake's Allegro right hand with its thumb
opposed; default drakegrasp's flat-pad jaw) in a scene of the two alone;
``--contact-model`` and ``--torsional-friction`` set the contacts' model (over
a scene's), ``--mass`` gives the object's mass, ``--squeeze-limit`` the squeeze
a parallel jaw will apply (default its actuators' effort limits: candidates
held within it rank first, and the output says when none is),
``--torque-limit`` the torque a multi-finger hand will apply and
``--preshape JOINT=VALUE`` its open shape (``--preshape open`` opens it
from there), and ``--shake K`` shakes the
first K candidates in a Drake simulation and lists them again, those that
held first (:func:`~drakegrasp.planning.shake_ranking.shake_candidates`; the
gains ``--squeeze``, ``--stiffness`` and ``--damping``, light ones by default
for ``--hand allegro``; ``--hydroelastic`` compliant fingers, by default for
drakegrasp's flat-pad jaws and the Allegro hand).  ``--mu plant``
plans with the friction the plant gives the hand's and the object's geometries
(the smallest, where pairs differ, said on stderr) instead of a number.
``plan --progress`` and ``batch --progress`` need the optional tqdm
(``pip install "drakegrasp[progress]"``); without it they are refused before
any work.

One interface: every command names the contact model ``--contact-model``
(``batch --model`` is a deprecated alias that still works and says so), and
both follow one rule for soft fingers: ``--contact-model soft_finger`` needs a
torsional friction ν, from ``--torsional-friction`` or the scene / input file;
an explicit ``--torsional-friction 0`` is valid and makes soft fingers act as
hard ones.

Exit status: 0 on success, 1 on an error (one line on stderr, never a
traceback), 2 for a bad command line (argparse), 130 on Ctrl-C (SIGINT) with
one line ``drakegrasp: interrupted``, 143 on SIGTERM and 129 on SIGHUP with one
line ``drakegrasp: terminated by SIGTERM`` (the run unwinds as on Ctrl-C: no
partial file, scratch folder or worker process is left; a first signal that
arrives once the command has finished and written its output lets the exit
finish, with the command's status).  ``batch`` and
``plan --out`` / ``--scene-out`` refuse an output that exists unless
``--overwrite`` (``batch``
also one that is its input), checked before any work; both write atomically
(a temporary file renamed into place), so an interrupted run loses nothing.
Set ``DRAKEGRASP_DEBUG=1`` to see the traceback of an unexpected error.
Messages name the command's flags (``--num``, ``--overwrite``), not the Python
keywords of the library calls behind them.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import difflib
import json
import math
import os
import re
import signal
import sys
import threading
import unicodedata
import warnings
from collections.abc import Sequence
from pathlib import Path

from drakegrasp.core.contact import ContactModel
from drakegrasp.core.tolerances import DEFAULT_NUM_GENERATORS, DEFAULT_TOL
from drakegrasp.core.validation import describe, path_text
from drakegrasp.errors import (
    GraspError,
    InvalidOptionError,
    InvalidPoseError,
    ModelError,
    cut_message,
)

__all__ = ["Terminated", "build_parser", "main", "printable", "run"]

EXIT_ERROR = 1
EXIT_INTERRUPTED = 130


# The remedy of a refused pose in the command line's words.
PENETRATION_REMEDY = "add --allow-penetration or --no-check-pose to analyse it anyway"
JOINT_LIMIT_REMEDY = "add --no-check-pose to analyse it anyway"


def _cmd_analyze(args: argparse.Namespace) -> int:
    from drakegrasp.errors import PenetrationError

    try:
        return _analyze(args)
    except InvalidPoseError as e:
        if not e.remedy:  # not a refusal that an option lifts
            raise
        cli = (
            PENETRATION_REMEDY
            if isinstance(e, PenetrationError)
            else (JOINT_LIMIT_REMEDY)
        )
        raise e.with_remedy(cli) from None


def _analyze(args: argparse.Namespace) -> int:
    from drakegrasp.plant.analysis import analyze_grasp
    from drakegrasp.plant.scale import SCALE_NAME, object_radius
    from drakegrasp.plant.scene import load_scene

    scene = load_scene(
        args.scene,
        package_map=_package_map(args.package),
        allow_any_file=args.allow_any_file,
        close=args.close,
        torsional_friction=args.torsional_friction,
    )
    changes = {
        name: getattr(args, name)
        for name in _ANALYSIS_FLAGS
        if getattr(args, name, None) is not None
    }
    if changes.get("load", "gravity") != "gravity" and "object_mass" not in changes:
        changes["object_mass"] = None  # a wrench given: the scene's mass weighs nothing
    try:
        options = scene.options.replace(**changes)
    except GraspError as e:  # a flag's value the options refuse, in flag words
        raise _in_flag_words(e, {name: _flag(name) for name in changes}) from None
    if options.torque_limits is not None and options.load is None:
        raise InvalidOptionError(
            "--torque-limits are the motors of the load section: give --load "
            "gravity (or a wrench FX,FY,FZ,MX,MY,MZ), or the scene's load:"
        )
    try:
        report = analyze_grasp(
            scene.plant,
            scene.plant_context,
            scene.object_body,
            hand=scene.hand,
            options=options,
        )
    except InvalidOptionError as e:  # a flag's value the analysis refuses
        raise _in_flag_words(e, {name: _flag(name) for name in changes}) from None
    epsilon = {
        "epsilon": None,
        "norm": "L1",
        "torque_scale": object_radius(
            scene.plant, scene.plant_context, scene.object_body
        ),
        "scale": SCALE_NAME,
        "reason": None,
    }
    epsilon.update(_epsilon(report, epsilon["torque_scale"]))
    if args.json:
        out = {"scene": scene.name, "scene_file": str(scene.info.path)}
        out.update(report.to_dict())
        out["closure"] = None if scene.closure is None else scene.closure.to_dict()
        out["epsilon"] = epsilon
        json.dump(out, sys.stdout, indent=2)
        sys.stdout.write("\n")
    else:
        print(f"scene {printable(scene.name)}: {scene.info.description}")
        if scene.closure is not None:
            print(scene.closure)
        print(report)
        value = epsilon["epsilon"]
        shown = (
            f"not computed ({epsilon['reason']})" if value is None else f"{value:.4g}"
        )
        print(
            f"  epsilon (Ferrari-Canny, L1) = {shown}, moments / b_s with b_s = "
            f"{epsilon['torque_scale'] * 1e3:.4g} mm, {SCALE_NAME}"
        )
    return 0


def _epsilon(report, torque_scale: float) -> dict:
    """ε (L1) of the report's grasp with moments divided by ``torque_scale``."""
    from drakegrasp.quality.epsilon import ferrari_canny

    try:
        value = ferrari_canny(
            report.grasp,
            num_generators=report.options.num_generators,
            torque_scale=torque_scale,
        )
    except InvalidOptionError as e:  # too many primitive wrenches for a hull
        return {"reason": str(e)}
    return {"epsilon": float(value)}


def _cmd_scenes(_args: argparse.Namespace) -> int:
    from drakegrasp.plant.scene import DEFAULT_SCENE, list_scenes

    infos = list_scenes()
    width = max(len(i.name) for i in infos)
    for info in infos:
        mark = "*" if info.name == DEFAULT_SCENE else " "
        print(f"{mark} {info.name:<{width}}  {info.description}")
    print("(* = default scene; run `drakegrasp analyze NAME`)")
    return 0


_MODEL_NOTE = "--model is deprecated; use --contact-model"
"""What ``batch --model`` (the deprecated alias) says: after a run that
succeeds, or inside the one error line of a run that fails."""


def _cmd_batch(args: argparse.Namespace) -> int:
    if args.deprecated_model is None:
        summary = _batch(args)
    else:
        if args.contact_model is not None and args.contact_model != (
            args.deprecated_model
        ):
            raise InvalidOptionError(
                f"--model {args.deprecated_model} and --contact-model "
                f"{args.contact_model} disagree; give --contact-model only "
                "(--model is its deprecated alias)"
            )
        try:
            summary = _batch(args)
        except GraspError as e:  # one line: the error, then the note
            message = _cli_words(str(e), "batch")
            raise InvalidOptionError(f"{message} ({_MODEL_NOTE})") from None
        print(f"drakegrasp: warning: {_MODEL_NOTE}", file=sys.stderr)
    print(summary)
    print(f"wrote {printable(args.output)}")
    return 0


def _batch(args: argparse.Namespace):
    """``batch``'s run: the summary of what it wrote."""
    from drakegrasp.batch import stream_file

    model = args.contact_model or args.deprecated_model or "hard_finger"
    from drakegrasp.batch.options import BatchOptions

    # the engine's choices, checked here once (one line on stderr if bad)
    try:
        engine = BatchOptions(
            contact_model=model,
            num_generators=args.num_generators,
            tol=args.tol,
            chunk_size=args.chunk_size,
            progress=args.progress,
            metrics=tuple(args.metrics),
            workers=args.workers,
        )
    except GraspError as e:
        raise _in_flag_words(e, {name: _flag(name) for name in _BATCH_FLAGS}) from None
    options = {
        "kind": args.kind,
        "mu": args.mu,
        "contact_model": model,
        "num_generators": args.num_generators,
        "torsional_friction": args.torsional_friction,
        "tol": args.tol,
        "chunk_size": args.chunk_size,
        "progress": args.progress,
        "metrics": tuple(args.metrics),
        "workers": args.workers,
        "fmt": args.format,
    }
    if args.scheduler is not None:
        from drakegrasp.distributed.batch_side import stream_file_on_cluster

        ignored = [
            flag
            for flag, given in (
                ("--workers", args.workers is not None),
                ("--progress", args.progress),
                ("--format", args.format is not None),
            )
            if given
        ]
        if ignored:
            raise InvalidOptionError(
                f"{', '.join(ignored)} cannot be used with --scheduler: the "
                "cluster's workers run the chunks and write Parquet shards into "
                "OUT's dataset directory; drop them or run without --scheduler"
            )
        for key in ("workers", "progress", "fmt"):
            options.pop(key)
        summary = stream_file_on_cluster(
            args.input,
            args.output,
            scheduler=args.scheduler,
            overwrite=args.overwrite,
            **options,
        )
    else:
        if args.progress:
            _check_progress()
        summary = stream_file(
            args.input,
            args.output,
            kind=args.kind,
            mu=args.mu,
            torsional_friction=args.torsional_friction,
            fmt=args.format,
            overwrite=args.overwrite,
            options=engine,
        )
    return summary


_BATCH_FLAGS = ("contact_model", "num_generators", "tol", "chunk_size", "workers")
"""``BatchOptions`` fields that ``batch`` sets from the flag of the same name."""


def _flag(name: str) -> str:
    """The flag of the Python keyword ``name``: ``--num-generators``."""
    return "--" + name.replace("_", "-")


def _in_flag_words(error: GraspError, flags: dict[str, str]) -> GraspError:
    """``error`` in flags, if its message starts with a keyword of ``flags``.

    The library's validators start their message with the keyword they check
    (``num_candidates must be ...``); ``flags`` maps the keywords the command
    set from its flags to those flags (``{"num_candidates": "--num"}``).  Such
    a message names every keyword of ``flags`` as its flag ("call again with
    another --seed"); any other message is kept as it is.
    """
    text = str(error)
    if not any(text.startswith(f"{keyword} ") for keyword in flags):
        return error
    for keyword, flag in flags.items():
        text = re.sub(rf"(?<![\w.'=-]){keyword}(?![\w'=])", flag, text)
    return InvalidOptionError(text)


def _value_checks() -> dict:
    """The library's validator of each option that a command takes as a flag."""
    from drakegrasp.core.validation import (
        check_coefficient,
        check_distance_tolerance,
        check_length,
        check_num_generators,
        check_tol,
    )

    def coefficient(name: str):
        return lambda value: (
            value == "plant" or check_coefficient(name, value, error=InvalidOptionError)
        )

    return {
        "mu": coefficient("mu"),
        "torsional_friction": coefficient("torsional_friction"),
        "distance_tolerance": check_distance_tolerance,
        "characteristic_length": lambda value: check_length(
            "characteristic_length", value, error=InvalidOptionError
        ),
        "num_generators": check_num_generators,
        "tol": check_tol,
    }


def _check_values(args: argparse.Namespace) -> None:
    """Refuse a flag's value outside the library's range, naming the flag.

    The ranges are the library's own (:mod:`drakegrasp.core.validation`),
    checked before any work so that the one line says ``--tol must be ...``
    where the library, given the keyword, says ``tol must be ...``.
    """
    form = getattr(args, "kind", None) == "form"  # batch --kind form ignores them
    for name, check in _value_checks().items():
        value = getattr(args, name, None)
        if value is None or (form and name in ("mu", "torsional_friction")):
            continue
        try:
            check(value)
        except GraspError as e:
            raise _in_flag_words(e, {name: _flag(name)}) from None


_SOFT_FINGER_REMEDY = {
    "analyze": "soft fingers (--contact-model soft_finger, or the scene's "
    "contact_model:) need a torsional friction nu: give --torsional-friction NU "
    "or the scene's torsional_friction: (0 makes soft fingers act as hard ones)",
    "plan": "--contact-model soft_finger needs a torsional friction nu: give "
    "--torsional-friction NU (0 makes soft fingers act as hard ones)",
    "batch": "--contact-model soft_finger needs a torsional friction nu: give "
    "--torsional-friction NU or the input's array torsional_friction (0 makes "
    "soft fingers act as hard ones)",
}
"""The refusal of soft fingers without a ``ν``, in each command's words (a
scene file's soft finger without one is refused by the file's own check)."""


@contextlib.contextmanager
def _warnings_as_lines(command: str | None):
    """Show each warning once as one line ``drakegrasp: warning: ...``.

    Python's own form names a file and a line of the library and repeats the
    calling line under it; a command's user wants the advice, in flags.
    """
    shown: set[str] = set()

    def show(message, *_where, **_file):  # warnings.showwarning's signature
        text = " ".join(_cli_words(str(message), command).split())
        if text not in shown:
            shown.add(text)
            print(f"drakegrasp: warning: {text}", file=sys.stderr)

    with warnings.catch_warnings():
        warnings.showwarning = show
        yield


def _cli_words(message: str, command: str | None) -> str:
    """A library ``message`` with its Python remedies given as flags.

    ``overwrite=True`` is ``--overwrite`` (``batch`` and ``plan --out``);
    soft fingers without a ``ν`` name ``--torsional-friction`` or the scene's
    key; a ``DRAKEGRASP_DRAKE_MODELS`` folder that lacks a model is named.
    """
    # the library's remedy phrase only: a path may hold any words
    message = re.sub(
        r"pass overwrite=True(?: \(drakegrasp batch --overwrite\))? to replace",
        "pass --overwrite to replace",
        message,
    )
    message = message.replace(  # the soft-finger shake's advice
        "give hydroelastic_modulus= (1e6 Pa, rubber)",
        "give --hydroelastic 1e6 (Pa, rubber)",
    )
    message = message.replace(  # the shake's friction advice
        "plan with the models' friction,", "plan with --mu plant,"
    )
    if command == "batch":  # batch --kind form: the friction program's flag
        message = re.sub(
            r"(needs friction); use batch_force_closure\b", r"\1; use --kind force",
            message,
        )  # fmt: skip
    from drakegrasp.core.contact import missing_torsional_friction
    from drakegrasp.plant.scene_file import LOADER_NU_REMEDY

    # a scene file's soft fingers without a ν: analyze's flag gives one
    message = message.replace(
        f"{LOADER_NU_REMEDY}, ",
        "give --torsional-friction NU, " if command in ("analyze", "plan") else "",
    )
    # the library's one refusal of soft fingers without a ν, in flag words
    if message == str(missing_torsional_friction()) and command in _SOFT_FINGER_REMEDY:
        return _SOFT_FINGER_REMEDY[command]
    if "package://drake_models/" in message and "does not exist" in message:
        from drakegrasp.plant.models import DRAKE_MODELS_ENV

        folder = os.environ.get(DRAKE_MODELS_ENV)
        # the folder is blamed only when it lacks the model's whole directory
        # (wsg_50_description/), not for a file name misspelt in the URL
        first = re.search(r"package://drake_models/([^/\s'\"]+)/", message)
        # os.path's isdir: pathlib's raised for a name too long, inside this
        # handler of another error
        if folder and first and not os.path.isdir(os.path.join(folder, first[1])):
            message += (
                f" ({DRAKE_MODELS_ENV} is set to {folder!r}, which does not hold "
                "this model: point it at a local copy of the drake_models "
                "package, or unset it to let Drake download the package)"
            )
    return message


def _parsed(text: str, convert, noun: str, ok, must: str):
    """``convert(text)`` when ``ok`` of it, else an argparse error saying why."""
    try:
        x = convert(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not {noun}: {describe(text)}") from None
    if not ok(x):
        raise argparse.ArgumentTypeError(f"must be {must}, got {describe(text)}")
    return x


def _workers(text: str) -> int:
    return _parsed(text, int, "an integer", lambda n: n >= 1, ">= 1")


def _positive_float(text: str) -> float:
    return _parsed(
        text, float, "a number", lambda x: x >= 0.0 and x != float("inf"),
        "finite and >= 0",
    )  # fmt: skip


def _strictly_positive(text: str) -> float:
    return _parsed(
        text, float, "a number", lambda x: 0.0 < x < float("inf"), "finite and > 0"
    )


def _modulus(text: str) -> float | str:
    if text.strip().lower() == "none":
        return "none"
    try:
        return _strictly_positive(text)
    except argparse.ArgumentTypeError:
        raise argparse.ArgumentTypeError(
            f"expected a modulus in Pa (finite, > 0) or none, got {describe(text)}"
        ) from None


def _count(text: str) -> int:
    return _parsed(text, int, "a whole number", lambda k: k >= 0, ">= 0")


def _package(text: str) -> tuple[str, str]:
    name, sep, folder = text.partition("=")
    if not sep or not name or not folder or "/" in name:
        raise argparse.ArgumentTypeError(
            "expected NAME=DIR (a package name, '=', its directory), got "
            f"{describe(text)}"
        )
    return name, folder


def _package_map(packages: list[tuple[str, str]]) -> dict[str, str] | None:
    """``--package`` flags as a map; one name given two directories is refused.

    (The last one won, silently: a scene then read another package's files.)
    """
    found: dict[str, str] = {}
    for name, folder in packages:
        if found.setdefault(name, folder) != folder:
            raise InvalidOptionError(
                f"--package {name} is given twice, as {found[name]!r} and "
                f"{folder!r}: give each package one directory"
            )
    return found or None


def _add_scene_file_options(
    parser: argparse.ArgumentParser, *, package_help: str
) -> None:
    """``--package NAME=DIR`` and ``--allow-any-file``: where a scene's files may be."""
    parser.add_argument(
        "--package",
        action="append",
        type=_package,
        default=[],
        metavar="NAME=DIR",
        help=package_help,
    )
    parser.add_argument(
        "--allow-any-file",
        action="store_true",
        help="trust the scene: let it reference files outside its packages and "
        "its own directory",
    )


_JIT_TIME = "40 s to two minutes, depending on the machine and its load"
"""How long numba's JIT takes to compile every kernel (``warmup``).

Measured with an empty ``NUMBA_CACHE_DIR`` on a shared two-core machine: 86
functions in 42 s (one core busy) and in 59 s of CPU (74 s wall, load 1.5);
the first closure and ε calls of a process, 56-68 s at load 3 and up to two
minutes at load 8-10 (``benchmarks/README.md``, ``bench_first_call.py``).
The same words are in :mod:`drakegrasp.batch.compiled`'s stderr line.
"""


def _cmd_warmup(args: argparse.Namespace) -> int:
    from drakegrasp.batch.aot import status
    from drakegrasp.batch.warmup import warmup

    if not args.json:
        route = status()
        wait = "" if route.startswith("ahead-of-time") else f": {_JIT_TIME}"
        print(f"compiling the batch kernels where needed ({route}){wait} ...")

    def show(step) -> None:
        if not args.json:
            print(f"  {step.name}: {step.seconds:.2f} s, {step.compiled} compiled")

    report = warmup(progress=show)
    if args.json:
        print(json.dumps(report.to_dict(), indent=2))
    elif not report.available:
        print(str(report))
    else:
        where = report.cache_dir or "numba's default cache"
        print(
            f"done: {report.compiled} functions compiled in {report.seconds:.1f} s "
            f"(kernels: {report.route}; cache: {where})"
        )
    return 0


_METRICS_HINT = (
    "--metrics takes every word after it up to the next option: put it after "
    "the positional arguments or before another option, or end it with -- and "
    "give only the positional arguments after that"
)
"""Where ``batch --metrics NAME ...`` goes on the line (it would take IN OUT)."""


class _Parser(argparse.ArgumentParser):
    """argparse with one-line refusals, as every other error of the command.

    argparse prints the whole usage block before its error; a script reading
    stderr, or a user scanning it, gets one line naming the bad argument and
    where the help is.  Subcommands' parsers are of this class too.
    """

    def error(self, message: str):
        if message.startswith("argument --metrics: invalid choice"):
            message += f"; {_METRICS_HINT}"
        message = cut_message(message)  # argparse names a bad argument whole
        self.exit(2, f"{self.prog}: error: {message} (see: {self.prog} --help)\n")


def _version() -> str:
    """The version of the drakegrasp that is running (``drakegrasp.__version__``).

    Not the installed distribution's metadata: a source tree on ``PYTHONPATH``
    or a stale editable install would report another version than the code's.
    """
    import drakegrasp

    return drakegrasp.__version__


class _Version(argparse.Action):
    """``--version``: print ``drakegrasp VERSION`` and exit 0.

    argparse's own ``version`` action needs the text when the parser is built;
    this one looks the version up only when the flag is given.
    """

    def __init__(self, option_strings, dest=argparse.SUPPRESS, help=None):
        super().__init__(
            option_strings, dest=dest, default=argparse.SUPPRESS, nargs=0, help=help
        )

    def __call__(self, parser, _namespace, _values, _option_string=None):
        print(f"drakegrasp {_version()}")
        parser.exit()


def build_parser() -> tuple[argparse.ArgumentParser, argparse._SubParsersAction]:
    """The argument parser and its subparsers (other subcommands add themselves).

    Returns
    -------
    parser : argparse.ArgumentParser
    subparsers : argparse._SubParsersAction
        Add a subcommand with ``subparsers.add_parser(name)`` and
        ``set_defaults(func=handler)``; the handler takes the parsed namespace
        and returns the exit status.
    """
    parser = _Parser(
        prog="drakegrasp",
        description="Grasp analysis on top of Drake: contacts, grasp matrix, "
        "form and force closure.",
    )
    parser.add_argument(
        "--version", action=_Version, help="print drakegrasp's version and exit"
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True

    analyze = sub.add_parser(
        "analyze",
        help="analyse the grasp of a scene (default: the default scene)",
        description="Load a scene and print its grasp analysis.",
    )
    analyze.add_argument(
        "scene",
        nargs="?",
        default=None,
        help="shipped scene name (see `drakegrasp scenes`) or scene YAML file",
    )
    _add_analysis_options(analyze)
    analyze.add_argument(
        "--close",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="close the hand onto the object before analysing (from the "
        "scene's joint values; default: the scene's 'close:', else no)",
    )
    _add_scene_file_options(
        analyze,
        package_help="resolve package://NAME/... to DIR (repeatable; "
        "ROS_PACKAGE_PATH is honoured too)",
    )
    analyze.add_argument("--json", action="store_true", help="print JSON")
    analyze.set_defaults(func=_cmd_analyze)

    scenes = sub.add_parser("scenes", help="list the shipped scenes")
    scenes.set_defaults(func=_cmd_scenes)
    _add_batch_parser(sub)
    _add_plan_parser(sub)
    return parser, sub


# AnalysisOptions fields the analyze command sets (None: the scene's value).
_ANALYSIS_FLAGS = (
    "mu",
    "contact_model",
    "torsional_friction",
    "distance_tolerance",
    "plane",
    "characteristic_length",
    "num_generators",
    "tol",
    "allow_penetration",
    "patches",
    "check_pose",
    "coupling_tolerance",
    "load",
    "object_mass",
    "torque_limits",
)


def _add_analysis_options(parser: argparse.ArgumentParser) -> None:
    """``analyze``'s options, with the help and defaults of AnalysisOptions."""
    from drakegrasp.plant.options import OPTION_HELP, PATCH_MODES, PLANES

    defaults = _analysis_defaults()
    kinds = {
        "mu": {"type": _mu},
        "contact_model": {"choices": [m.value for m in ContactModel]},
        "torsional_friction": {"type": _positive_float},
        "distance_tolerance": {"type": _positive_float},
        "plane": {"choices": sorted(PLANES)},
        "characteristic_length": {"type": _positive_float},
        "num_generators": {"type": int},
        "tol": {"type": _positive_float},
        "patches": {"choices": list(PATCH_MODES)},
        "coupling_tolerance": {"type": _positive_float},
        "load": {
            "type": _named_or_numbers("gravity"),
            "metavar": "gravity|FX,FY,FZ,MX,MY,MZ",
        },
        "torque_limits": {
            "type": _named_or_numbers("plant"),
            "metavar": "plant|T1,T2,...",
        },
        "object_mass": {"type": _positive_float, "metavar": "KG"},
    }
    for name in _ANALYSIS_FLAGS:
        flag = "--" + name.replace("_", "-")
        default = defaults[name]
        shown = (
            "the scene's"
            if name in _SCENE_OPTIONS
            else "the farthest contact from the reference point, O's origin"
            if default is None
            else f"{default}"
        )
        help_text = f"{OPTION_HELP[name]} (default: {shown})"
        if isinstance(default, bool):
            parser.add_argument(
                flag,
                action=argparse.BooleanOptionalAction,
                default=None,
                help=help_text,
            )
        else:
            parser.add_argument(flag, default=None, help=help_text, **kinds[name])


# The options a scene file sets; the others default to AnalysisOptions'.
_SCENE_OPTIONS = (
    "mu",
    "contact_model",
    "torsional_friction",
    "plane",
    "distance_tolerance",
    "load",
    "object_mass",
    "torque_limits",
)


def _named_or_numbers(name: str):
    """``--load`` / ``--torque-limits``: ``name``, or comma-separated numbers."""

    def parse(text: str) -> str | tuple[float, ...]:
        if text == name:
            return text
        try:
            return tuple(float(v) for v in text.split(","))
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"expected {name!r} or comma-separated numbers, got {describe(text)}"
            ) from None

    return parse


def _analysis_defaults() -> dict:
    from dataclasses import fields

    from drakegrasp.plant.options import AnalysisOptions

    return {f.name: f.default for f in fields(AnalysisOptions)}


def _mu(text: str) -> float | str:
    """``--mu``: a friction coefficient, or ``plant``."""
    return text if text == "plant" else _positive_float(text)


class _BatchMetrics:
    """The batch engine's metric names, read from it when argparse needs them.

    ``choices`` of ``batch --metrics``: argparse reads it only to check a
    given name or to print help, so every other command (``analyze``) runs
    without importing the batch engine and its worker pools.
    """

    def _names(self) -> tuple[str, ...]:
        from drakegrasp.batch import METRICS

        return METRICS

    def __contains__(self, name: object) -> bool:
        return name in self._names()

    def __iter__(self):
        return iter(self._names())

    def __len__(self) -> int:
        return len(self._names())


def _add_batch_parser(sub: argparse._SubParsersAction) -> None:
    batch = sub.add_parser(
        "batch",
        help="decide closure for every grasp of an .npz file or a folder of .npy files",
        description="Decide form or force closure for K grasps of N contacts "
        "stored as arrays positions (K, N, d) and normals (K, N, d) [, mu, "
        "torsional_friction, reference_points, characteristic_lengths] in an "
        ".npz file or a directory of .npy files (read chunk by chunk), and "
        "write is_closure, d_star, margin, converged, rank, required_rank, "
        "kind, tol, normal_certificate (--kind force) and the requested "
        "metrics to OUT (.npz, or .parquet with pyarrow).",
    )
    batch.add_argument(
        "input", help="input .npz file, or a directory of .npy files (memory-mapped)"
    )
    batch.add_argument("output", help="output .npz (or .parquet) file")
    batch.add_argument(
        "--kind", choices=["force", "form"], default="force", help="default: force"
    )
    batch.add_argument(
        "--mu",
        type=_positive_float,
        help="friction coefficient of every contact, overriding the file's "
        "array mu; --kind force needs one or the other (--kind form ignores it)",
    )
    batch.add_argument(
        "--contact-model",
        choices=[m.value for m in ContactModel],
        default=None,
        help="contact model (default: hard_finger); soft_finger needs a "
        "torsional friction (--torsional-friction or the file's)",
    )
    batch.add_argument(
        "--model",
        dest="deprecated_model",
        choices=[m.value for m in ContactModel],
        default=None,
        help="deprecated alias of --contact-model",
    )
    batch.add_argument(
        "--num-generators",
        type=int,
        default=DEFAULT_NUM_GENERATORS,
        help="generators of each polyhedral friction cone (default %(default)s)",
    )
    batch.add_argument(
        "--torsional-friction",
        type=_positive_float,
        help="soft-finger torsional friction nu, overriding the file's array "
        "torsional_friction; required with --contact-model soft_finger unless "
        "the file has it (0 makes soft fingers act as hard ones)",
    )
    batch.add_argument(
        "--tol",
        type=_positive_float,
        default=DEFAULT_TOL,
        help="threshold on d* (default %(default)g)",
    )
    batch.add_argument(
        "--metrics",
        nargs="*",
        default=[],
        choices=_BatchMetrics(),
        metavar="NAME",
        help=f"metrics to add: %(choices)s; {_METRICS_HINT}",
    )
    batch.add_argument(
        "--chunk-size",
        type=int,
        default=None,
        help="grasps per chunk (default: sized by the engine's working-memory "
        "budget per chunk, drakegrasp.batch.run.stream.CHUNK_BYTES)",
    )
    batch.add_argument(
        "--workers",
        type=_workers,
        default=None,
        help="worker processes (default: every available core)",
    )
    batch.add_argument(
        "--format",
        choices=["npz", "parquet"],
        default=None,
        help="output format (default: from OUT's suffix; parquet needs pyarrow)",
    )
    batch.add_argument(
        "--scheduler",
        default=None,
        metavar="ADDRESS",
        help="run on the Dask scheduler at ADDRESS (host:port; needs the dask extra)",
    )
    batch.add_argument(
        "--progress",
        action="store_true",
        help='show a progress bar (needs: pip install "drakegrasp[progress]")',
    )
    batch.add_argument(
        "--overwrite",
        action="store_true",
        help="replace an existing OUT (default: refuse); OUT is written to a "
        "temporary file and renamed into place, and is never the input; with "
        "--scheduler, replace the shards of another job in OUT's dataset "
        "directory (a rerun of the same job resumes it)",
    )
    batch.set_defaults(func=_cmd_batch)

    warm = sub.add_parser(
        "warmup",
        help="get the batch engine's kernels ready now (once per install)",
        description="Run every route of the batch engine on a few seeded grasps "
        "and print each step, its time and what it compiled; the first line "
        "names the route the kernels take.  Where the install compiled the "
        "kernels ahead of time (for this CPU and these sources), they are "
        "loaded and nothing is compiled: the run only checks that they serve "
        "every route, in seconds.  Otherwise (no such kernels, another CPU, "
        "edited sources, or DRAKEGRASP_KERNELS=jit) numba's JIT compiles every "
        "kernel into its on-disk cache (NUMBA_CACHE_DIR, else numba's user-wide "
        f"cache), {_JIT_TIME}, so that the first batch call of later "
        "processes does not wait.  Without numba there is nothing to compile: "
        "the engine runs its numpy route.",
    )
    warm.add_argument("--json", action="store_true", help="print the report as JSON")
    warm.set_defaults(func=_cmd_warmup)


PLAN_HANDS = {
    "flat": "package://drakegrasp/hands/parallel_jaw_flat.sdf",
    "rounded": "package://drakegrasp/hands/parallel_jaw.sdf",
    "wsg": "package://drake_models/wsg_50_description/sdf/schunk_wsg_50_with_tip.sdf",
    "franka": "package://drake_models/franka_description/urdf/panda_hand.urdf",
    "allegro": "package://drake_models/allegro_hand_description/sdf/"
    "allegro_hand_description_right.sdf",
}
"""``plan --hand`` short names: drakegrasp's two jaws, Drake's WSG-50, Drake's
Franka (Panda) hand and Drake's Allegro right hand.

``franka`` is ``panda_hand.urdf``, whose fingers touch with a 9 mm sphere and
four 1 mm pad spheres each (Drake's model for grasping); ``hand.urdf`` touches
with one 12 mm sphere a finger, two point contacts that never resist a torque
about the line through them."""

PLAN_PRESHAPES = {"allegro": {"joint_12": 1.0}}
"""The open hand an alias starts from, joint name to value (rad or m), where
the model's zero is not one to grasp with; ``--preshape`` overrides it.

The Allegro's zero puts its thumb beside the index finger, and outside the
thumb joint's limits (``joint_12`` in [0.263, 1.396] rad); at 1.0 rad it
opposes the fingers.  Measured (100 poses, seed 0, mu 0.5): the YCB soup can
gets 69 candidates, 10 in force closure, against 15 and 1 from the zero
clipped to the limits; drakegrasp's box 58 and 2 against 15 and 0."""


PLAN_SHAKE_DEFAULTS = {
    "flat": {"hydroelastic_modulus": 1e6},
    "rounded": {"hydroelastic_modulus": 1e6},
    "allegro": {
        "squeeze": 0.7,
        "stiffness": 10.0,
        "damping": 0.1,
        "hydroelastic_modulus": 1e6,
    },
}
"""``plan --shake``'s options for a hand alias (``plan``'s default hand is
``flat``), where the shake test's defaults do not suit it; the flags override
them.

- Hydroelastic fingers (1e6 Pa, rubber): drakegrasp's jaws have flat pads,
  which Drake's point contact touches at one point each, so the object pivots
  between them: on the box, 1 of the top 6 held at 20 N with point contact, 6
  of 6 with hydroelastic pads (``benchmarks/bench_pad_contact.py``).  The
  Allegro hand's finger links are boxes too: its best sugar-box grasp held
  with them and turned 17° with point contact.  The WSG-50 touches with tip
  spheres and holds either way: the model's own contact.
- The Allegro hand's gains: each closing joint is aimed to press with its
  effort limit, 0.7 N·m, at 10 N·m/rad and 0.1 N·m·s/rad; at the fixed 4000
  N·m/rad and 50 that were once every joint's default Drake's SAP solver
  stopped on 2 of the top 10 sugar-box candidates
  (``benchmarks/bench_allegro_squeeze.py``).  Seated on the soup
  can, the joints press with 0.33-0.38 N·m on average (those whose links
  touch nothing with none, the rest up to 0.7) and the five best grasps hold;
  at 100 N·m/rad the 0.007 rad aim is taken up as the fingers close on, they
  press with 0.03-0.07 N·m and all five drop (review, round 27)."""

SHAKE_FLAGS = {
    "squeeze": "--squeeze",
    "stiffness": "--stiffness",
    "damping": "--damping",
    "hydroelastic_modulus": "--hydroelastic",
}
"""``shake_test`` keywords that ``plan --shake`` sets from a flag, and that flag."""


MODEL_SUFFIXES = (".sdf", ".urdf", ".xml")
"""File endings of the model files Drake's parser reads (``plan`` checks them)."""

OBJECT_SUFFIXES = (*MODEL_SUFFIXES, ".obj")
"""``plan``'s object may also be a mesh: Drake's parser makes an ``.obj`` file one
body, the mesh its collision geometry, with the mass of water filling it."""


def _model_file(spec: str, what: str) -> str:
    """``spec`` as it is: a URL, or a model file that exists."""
    spec = path_text(what, spec)
    if "://" not in spec and not os.path.isfile(spec):
        raise InvalidOptionError(f"{what} file {spec!r} not found")
    return spec


def _plan_url(spec: str) -> str:
    """``plan``'s object: a URL or model file as it is, or a shipped name's URL."""
    from drakegrasp.plant.models import models_dir

    if "://" in spec or spec.endswith(OBJECT_SUFFIXES):
        return _model_file(spec, "object")
    shipped = sorted(p.stem for p in (models_dir() / "objects").glob("*.sdf"))
    if spec not in shipped:
        raise InvalidOptionError(
            f"object {spec!r} is not a shipped object ({', '.join(shipped)}), a "
            f"scene, a package:// URL, a model file ({', '.join(MODEL_SUFFIXES)}) "
            "or a mesh (.obj)"
        )
    return f"package://drakegrasp/objects/{spec}.sdf"


def _plan_hand(spec: str | None) -> str:
    """``plan --hand``: a short name's URL, or a URL or model file as it is.

    ``None`` (no ``--hand``) is the flat jaw; an empty ``--hand ""`` is
    refused, as an empty object or scene is.
    """
    if spec is None:
        spec = "flat"
    elif not spec.strip():
        raise InvalidOptionError(
            f"--hand is empty; give one of the hand aliases {', '.join(PLAN_HANDS)}"
            f", a package:// URL or a model file ({', '.join(MODEL_SUFFIXES)}), "
            "or leave --hand out for the flat jaw"
        )
    if spec in PLAN_HANDS:
        return PLAN_HANDS[spec]
    if spec.lower() in PLAN_HANDS:  # "WSG", "Allegro"
        return PLAN_HANDS[spec.lower()]
    if "://" in spec or spec.endswith(MODEL_SUFFIXES):
        return _model_file(spec, "--hand")
    close = difflib.get_close_matches(spec.lower(), PLAN_HANDS, n=1)
    guess = f" (did you mean {close[0]!r}?)" if close else ""
    raise InvalidOptionError(
        f"--hand {spec!r} is not one of the hand aliases {', '.join(PLAN_HANDS)}"
        f"{guess}, a package:// URL or a model file ({', '.join(MODEL_SUFFIXES)})"
    )


def _is_scene(target: str) -> bool:
    """Whether ``plan``'s argument names a scene (a YAML file or a shipped one)."""
    from drakegrasp.plant.scene import list_scenes

    if target.endswith((".yaml", ".yml")):
        return True
    return target in {info.name for info in list_scenes()}


def _plan_setup(args: argparse.Namespace):
    """(plant, context, object body, hand, options, add_models) of ``plan``'s target.

    ``add_models`` is the recipe the shake test rebuilds an object's scene
    from; None for a scene file.
    """
    from drakegrasp.planning import planning_scene

    if _is_scene(args.object):
        from drakegrasp.plant.scene import load_scene, read_scene_info, scene_path

        if args.hand is not None:
            raise InvalidOptionError(
                "--hand is for an object; a scene names its own hand (its "
                "drakegrasp: section's 'hand:')"
            )
        info = read_scene_info(
            scene_path(args.object), torsional_friction=args.torsional_friction
        )
        if info.plane is not None:
            raise InvalidOptionError(
                f"scene {info.name!r} is planar (plane: {info.plane}); plan "
                "samples spatial grasps of a free hand: analyse it with "
                f"`drakegrasp analyze {info.name}`"
            )
        # plan places the hand itself: a weld of the hand to the world, which
        # places it for analyze, is left out
        scene = load_scene(
            args.object,
            package_map=_package_map(args.package),
            allow_any_file=args.allow_any_file,
            close=False,
            free_hand=True,
            # as analyze: a soft-finger file without nu takes the flag's
            torsional_friction=args.torsional_friction,
        )
        info = scene.info
        # scene.options, as analyze reads the file: a soft finger the file
        # gives no ν is refused, not planned as a soft finger with ν = 0
        options = {
            "contact_model": info.contact_model,
            "torsional_friction": scene.options.torsional_friction,
            "distance_tolerance": info.distance_tolerance,
        }
        plant, context, body, hand = (
            scene.plant, scene.plant_context, scene.object_body, scene.hand
        )  # fmt: skip
        default_mu = info.mu
        add_models = None
    else:
        scene = planning_scene(
            _plan_url(args.object),
            hand_url=_plan_hand(args.hand),
            package_map=_package_map(args.package),
        )
        plant, context, body, hand = (
            scene.plant, scene.context, scene.object_body, scene.hand
        )  # fmt: skip
        options = {}
        default_mu = PLAN_DEFAULT_MU
        add_models = scene.add_models
    from drakegrasp.planning.approach import OPEN

    alias = (args.hand or "").lower()
    given = dict(v for v in args.preshape if v != OPEN)
    preshape = {**PLAN_PRESHAPES.get(alias, {}), **given}
    if preshape:
        _apply_preshape(plant, context, body, hand, preshape, given=given)
    if OPEN in args.preshape:  # opened from the shape set above
        options["preshape"] = OPEN
    # the flags over the scene's values, as for analyze
    if args.contact_model is not None:
        options["contact_model"] = args.contact_model
    if args.torsional_friction is not None:
        options["torsional_friction"] = args.torsional_friction
    mu = default_mu if args.mu is None else args.mu
    # a scene's `mu: plant` is read from the plant, as --mu plant is
    options["mu"] = _plant_mu(plant, context, body, hand) if mu == "plant" else mu
    return plant, context, body, hand, options, add_models


def _apply_preshape(plant, context, body, hand, values: dict, *, given: dict):
    """Set the hand's open shape in ``context``: ``values`` maps joints to positions.

    A joint is named as in the model (``joint_12``) or scoped
    (``model::joint_12``); it must be a one-degree-of-freedom joint that moves
    a body of the hand, and the value a finite number within its limits.  A
    parallel jaw takes none: it opens fully.  ``given`` are the ones the user
    wrote (``--preshape``), named in a refusal.
    """
    from drakegrasp.planning import hand_is_parallel_jaw
    from drakegrasp.plant.validation import hand_bodies, plant_context_of

    ctx = plant_context_of(plant, context)
    if given and hand_is_parallel_jaw(plant, ctx, body, hand):
        raise InvalidOptionError(
            "--preshape is for multi-finger hands; a parallel jaw opens fully "
            "and closes along its chord"
        )
    moved = {b.index() for b in hand_bodies(plant, body, hand)}
    joints = [  # the joints that move a body of the hand
        j
        for j in (plant.get_joint(i) for i in plant.GetJointIndices())
        if j.child_body().index() in moved
    ]
    from drakegrasp.plant.couplings import plant_couplings
    from drakegrasp.plant.fingers import joint_name as scoped_joint

    followers = {c[0]: c[1] for c in plant_couplings(plant)}
    q = plant.GetPositions(ctx)
    for name, value in values.items():
        model, sep, joint_name = name.rpartition("::")
        matches = [
            j
            for j in joints
            if j.name() == joint_name
            and (not sep or plant.GetModelInstanceName(j.model_instance()) == model)
        ]
        if len(matches) != 1:
            how = "no joint of the hand" if not matches else "several joints"
            names = [j.name() for j in joints if j.num_positions() == 1]
            raise InvalidOptionError(
                f"--preshape {name}: {how} is named {name!r}; the hand's joints "
                f"are {names}"
            )
        joint = matches[0]
        if joint.num_positions() != 1:
            raise InvalidOptionError(
                f"--preshape {name}: the joint has {joint.num_positions()} "
                "positions; a pre-shape sets one-degree-of-freedom joints"
            )
        scoped = scoped_joint(plant, joint)
        if scoped in followers:  # set from its leader: the value would be lost
            raise InvalidOptionError(
                f"--preshape {name}: the joint follows {followers[scoped]} (a "
                "<mimic>), which sets it: give the leader's value"
            )
        low = float(joint.position_lower_limits()[0])
        high = float(joint.position_upper_limits()[0])
        if not low <= value <= high:  # finite: _joint_value or an alias's
            raise InvalidOptionError(
                f"--preshape {name}={value:g} is outside the joint's limits "
                f"[{low:g}, {high:g}]"
            )
        q[joint.position_start()] = value
    plant.SetPositions(ctx, q)


def _joint_value(text: str) -> tuple[str, float] | str:
    """``--preshape NAME=VALUE``: a joint's name and a finite position; or ``open``."""
    from drakegrasp.planning.approach import OPEN

    if text == OPEN:
        return OPEN
    name, sep, value = text.partition("=")
    try:
        number = float(value)
    except ValueError:
        number = float("nan")
    if not sep or not name or not math.isfinite(number):
        raise argparse.ArgumentTypeError(
            f"expected JOINT=VALUE (a joint's name, '=', a finite position in "
            f"rad or m) or {OPEN!r}, got {describe(text)}"
        )
    return name, number


PLAN_DEFAULT_MU = 0.5
"""``plan``'s friction coefficient for an object when ``--mu`` is not given."""


def _plant_mu(plant, context, object_body, hand) -> float:
    """``plan --mu plant``: one coefficient from the plant's geometries.

    The planner takes one μ for every contact; the plant gives one per pair of
    a hand and an object geometry.  Where they differ, the smallest is used (a
    grasp in force closure with the narrowest cones is one with wider cones
    too), and a note on stderr says so.  It is the dynamic coefficient, never
    above the static one (Drake requires it): what a discrete simulation of
    the grasp uses (the shake test's, any time-stepping plant's) and what a
    grip that starts to slip has.  The planning plant is continuous, whose
    rule is the static one: planning with it, the top grasps of a box of
    static 0.9 and dynamic 0.25 fell in the shake test at 1.2 times the
    squeeze they were said to need.
    """
    from drakegrasp.plant.friction import MU_RELATIVE_TOL, hand_object_friction

    values = hand_object_friction(plant, context, object_body, hand, rule="dynamic")
    if values.size == 0:
        raise InvalidOptionError(
            "--mu plant: the hand or the object has no collision geometry to "
            "read a friction from; give --mu as a number"
        )
    mu = float(values[0])
    if values[-1] - mu > MU_RELATIVE_TOL * max(mu, 1.0):
        _say(
            "drakegrasp: note: --mu plant: the plant's dynamic "
            f"friction of hand and object geometries ranges from {mu:g} to "
            f"{values[-1]:g}; planning with the smallest, {mu:g}"
        )
    return mu


def _check_progress() -> None:
    """``--progress`` needs tqdm: refuse it up front, before any work, if missing."""
    try:
        import tqdm.auto  # noqa: F401
    except ImportError:
        raise InvalidOptionError(
            "--progress needs the optional package tqdm, which is not installed: "
            'pip install "drakegrasp[progress]", or leave out --progress'
        ) from None


def _check_pyarrow() -> None:
    """``--out FILE.parquet`` needs pyarrow: refuse it up front, before planning."""
    try:
        import pyarrow.parquet  # noqa: F401
    except ImportError:
        raise InvalidOptionError(
            "--out FILE.parquet needs the optional package pyarrow, which is not "
            'installed: pip install "drakegrasp[parquet]", or leave out --out'
        ) from None


def _cmd_plan(args: argparse.Namespace) -> int:
    from drakegrasp.planning import plan_grasps

    if args.out is not None:
        from drakegrasp.batch.files.writer import check_output

        if not args.out.endswith(".parquet"):
            raise InvalidOptionError(
                f"--out must name a .parquet file, got {args.out!r}"
            )
        _check_pyarrow()  # (it was found missing after the whole plan)
        # before planning: refuse an existing file unless --overwrite, as batch
        check_output(
            Path(path_text("--out", args.out)),
            (),
            overwrite=args.overwrite,
            remedy="pass --overwrite",
        )
    if args.scene_out is not None:
        _check_scene_out(args)
    elif args.overwrite and args.out is None:
        raise InvalidOptionError(
            "--overwrite is for --out FILE.parquet or --scene-out FILE.yaml"
        )
    if args.progress:
        _check_progress()
    shake = _shake_options(args)
    plant, context, object_body, hand, options, add_models = _plan_setup(args)
    if shake is not None:
        _check_shake_motors(plant, object_body, hand)
    try:
        result = plan_grasps(
            plant,
            context,
            object_body,
            hand=hand,
            num_candidates=args.num,
            seed=args.seed,
            progress=args.progress,
            object_mass=args.mass,
            torque_limit=args.torque_limit,
            squeeze_limit=args.squeeze_limit,
            **options,
        )
    except GraspError as e:
        raise _in_flag_words(e, _PLAN_FLAGS) from None
    result = _in_plan_words(result)
    # The plan is written and printed before the shake, so that a shake that
    # fails or is interrupted leaves it (JSON is one document: shaken first).
    if args.scene_out is not None and not len(result):
        # before --out is written: a failed command leaves no file behind
        why = "; ".join(
            f"{count} {reason}" for reason, count in result.rejections.items()
        )
        raise InvalidOptionError(
            f"--scene-out: the plan has no candidate to write ({result.num_sampled}"
            f" sampled poses, rejected: {why or 'none'})"
        )
    if args.out is not None:
        _write_plan_parquet(result, args.out, overwrite=args.overwrite)
    if args.json:
        data = result.to_dict()
        data["candidates"] = data["candidates"][: args.top]
        shaken = None
        if shake is not None:
            shaken = _shaken(add_models, result, args, shake)
            data["shaken"] = shaken.to_dict()
        json.dump(data, sys.stdout, indent=2)
        sys.stdout.write("\n")
        return _write_scene_out(args, result, shaken, plant, context, object_body)
    if args.out is None:
        print(result.__str__().split("\n  #")[0])
        for k, c in enumerate(result[: args.top]):
            print(f"  #{k:<3} {c}")
    else:
        print(f"wrote {len(result)} candidates to {args.out}")
    shaken = None
    if shake is not None:
        sys.stdout.flush()
        shaken = _shaken(add_models, result, args, shake)
        print(shaken)
    return _write_scene_out(args, result, shaken, plant, context, object_body)


def _check_shake_motors(plant, object_body, hand) -> None:
    """``plan --shake``: refused before planning when the hand has no motor."""
    from drakegrasp.plant.validation import hand_bodies

    bodies = {int(b.index()) for b in hand_bodies(plant, object_body, hand)}
    if not any(
        int(plant.get_joint_actuator(a).joint().child_body().index()) in bodies
        for a in plant.GetJointActuatorIndices()
    ):
        raise InvalidOptionError(
            "--shake squeezes with the hand's motors, and the model gives the "
            "hand's joints no actuator (a URDF joint gets one from a "
            "<transmission>; Drake adds none for an effort limit of 0): plan "
            "without --shake, or give the model its motors"
        )


def _check_scene_out(args: argparse.Namespace) -> None:
    """``plan --scene-out``: refused up front where it cannot be written."""
    if not args.scene_out.endswith((".yaml", ".yml")):
        raise InvalidOptionError(
            f"--scene-out must name a .yaml file, got {args.scene_out!r}"
        )
    if _is_scene(args.object):
        raise InvalidOptionError(
            "--scene-out writes the grasp of an object and --hand; a scene's "
            "own file places its hand: apply a candidate to it in Python "
            "(candidate.apply, then analyze_grasp)"
        )
    path = Path(path_text("--scene-out", args.scene_out))
    if path.is_dir():
        raise InvalidOptionError(f"--scene-out {str(path)!r} is a directory")
    if path.exists() and not args.overwrite:
        raise InvalidOptionError(
            f"--scene-out {str(path)!r} exists; pass --overwrite to replace it"
        )
    if not path.resolve().parent.is_dir():
        raise InvalidOptionError(
            f"--scene-out {str(path)!r}: its folder does not exist"
        )
    from drakegrasp.batch.files.writer import unwritable

    why = unwritable(path.resolve().parent)
    if why:
        raise InvalidOptionError(f"--scene-out {str(path)!r}: {why}")


def _write_scene_out(args, result, shaken, plant, context, object_body) -> int:
    """``plan --scene-out``: the best candidate as a scene ``analyze`` loads.

    The planner's best, or with ``--shake`` the best of those that held.
    """
    if args.scene_out is None:
        return 0
    from drakegrasp.batch.files.writer import placed
    from drakegrasp.planning.grasp_scene import grasp_scene_text

    if not len(result):
        raise InvalidOptionError("--scene-out: the plan has no candidate to write")
    best = result[0] if shaken is None or shaken.best is None else shaken.best
    rank = next(k for k, c in enumerate(result) if c is best)
    held = "" if shaken is None else (" (held)" if shaken.best is not None else "")
    path = Path(args.scene_out)
    # mu as planned: --mu plant planned with the smallest dynamic coefficient,
    # where the scene's mu: plant would read the static one (a continuous plant)
    source = "; mu: --mu plant's, the models' dynamic" if args.mu == "plant" else ""
    text = grasp_scene_text(
        plant, context, best, object_body=object_body,
        hand_file=_plan_hand(args.hand), object_file=_plan_url(args.object),
        mu=result.mu, folder=path.resolve().parent,
        description=f"Candidate #{rank}{held} of drakegrasp plan "
        f"{args.object} --hand {args.hand or 'flat'} (sample {best.sample}"
        f"{source}).",
    )  # fmt: skip
    with placed(path, overwrite=args.overwrite) as tmp:
        Path(tmp).write_text(text)
    note = "" if shaken is None or shaken.best is not None else ", none held"
    line = f"wrote candidate #{rank}{note} to {path} (drakegrasp analyze {path})"
    if args.json:  # stdout holds the JSON document alone
        _say(f"drakegrasp: {line}")
    else:
        print(line)
    return 0


def _shaken(add_models, result, args: argparse.Namespace, options: dict):
    """``plan --shake``: the first ``args.shake`` candidates shaken in Drake."""
    from drakegrasp.planning.shake_ranking import shake_candidates

    try:
        return shake_candidates(add_models, result, top=args.shake, **options)
    except ModelError as e:  # a massless object: its object_mass= is --mass
        text = re.sub(r"give object_mass= \(kg\)", "give --mass KG", str(e))
        raise type(e)(text) from None


def _shake_options(args: argparse.Namespace) -> dict | None:
    """``plan --shake``'s options for ``shake_candidates``, checked before planning.

    None without ``--shake``.  The flags' values, over
    :data:`PLAN_SHAKE_DEFAULTS` for a hand alias, over the shake test's defaults.
    """
    given = {k: getattr(args, k) for k in SHAKE_FLAGS if getattr(args, k) is not None}
    if args.shake is None:
        if given:
            raise InvalidOptionError(
                f"{SHAKE_FLAGS[next(iter(given))]} is an option of the shake test: "
                "give it with --shake K"
            )
        return None
    if _is_scene(args.object):
        raise InvalidOptionError(
            "--shake is for an object and --hand: the shake test rebuilds the "
            "hand and the object alone, which a scene file does not give apart "
            "from its supports (in Python, shake_candidates takes an "
            "add_models of your own)"
        )
    from drakegrasp.planning.shake_ranking import check_settings

    options = {**PLAN_SHAKE_DEFAULTS.get((args.hand or "flat").lower(), {}), **given}
    if options.get("hydroelastic_modulus") == "none":
        options["hydroelastic_modulus"] = None  # the models' own contact
    flags = {"top": "--shake", "object_mass": "--mass", **SHAKE_FLAGS}
    # --mass too: the mass planned for is the mass shaken (refused here if
    # the shake cannot simulate it, before any planning)
    mass = {} if args.mass is None else {"object_mass": args.mass}
    try:
        check_settings(args.shake, "seat", {**options, **mass})
    except GraspError as e:
        words = _in_flag_words(e, flags)
        # the flag's spelling of the library's None
        raise type(words)(
            str(words).replace("must be None (", "must be none (")
        ) from None
    return options


_PLAN_FLAGS = {
    "num_candidates": "--num",
    "seed": "--seed",
    "object_mass": "--mass",
    "torque_limit": "--torque-limit",
    "squeeze_limit": "--squeeze-limit",
    "contact_model": "--contact-model",
    "torsional_friction": "--torsional-friction",
    "preshape": "--preshape",
}
"""``plan_grasps`` keywords that ``plan`` sets from a flag, and that flag."""

_PLAN_REASON_WORDS = {
    "contact_model='soft_finger' with torsional_friction models fingertips that do": (
        "soft fingers model fingertips that do (--contact-model soft_finger "
        "--torsional-friction NU)"
    ),
    "num_candidates is 0": "--num is 0",
    "open it (preshape='open', or joint values) or move the palm back (standoff=)": (
        "open it (--preshape open, or --preshape JOINT=VALUE)"
    ),
    "the jaw at squeeze_limit ": "the jaw at --squeeze-limit ",
    "the hand at torque_limit ": "the hand at --torque-limit ",
    "or pass squeeze_limit (": "or pass --squeeze-limit LIMIT (",
    "or pass torque_limit (": "or pass --torque-limit LIMIT (",
}
"""Phrases of a plan result's ``reason`` that name what ``plan`` cannot set."""


def _in_plan_words(result):
    """``result`` with its ``reason`` naming only what ``plan`` can set."""
    reason = result.reason
    for phrase, words in _PLAN_REASON_WORDS.items():
        reason = reason.replace(phrase, words)
    if reason == result.reason:
        return result
    return dataclasses.replace(result, reason=reason)


def _write_plan_parquet(result, path: str, *, overwrite: bool) -> None:
    """Write ``result.table()`` to ``path`` atomically, as ``batch`` does.

    A temporary file beside ``path`` is renamed into place
    (:func:`~drakegrasp.batch.files.writer.placed`): an interrupted run leaves
    no partial file and any earlier one intact.
    """
    from drakegrasp.batch.files.writer import placed

    _check_pyarrow()
    import pyarrow as pa
    import pyarrow.parquet as pq

    columns = {}
    for name, values in result.table().items():
        if values.dtype == object:  # str (torque_unit): a string column, rows or not
            columns[name] = pa.array(values.tolist(), type=pa.string())
        elif values.ndim == 1:
            columns[name] = values
        else:
            for j in range(values.shape[1]):
                columns[f"{name}_{j}"] = values[:, j]
    with placed(Path(path), overwrite=overwrite) as tmp:
        pq.write_table(pa.table(columns), tmp)


def _add_plan_parser(sub: argparse._SubParsersAction) -> None:
    plan = sub.add_parser(
        "plan",
        help="find ranked grasps of an object",
        description="Sample grasps of a free hand on an object's collision "
        "geometry (antipodal pinches for a parallel jaw, approaches and "
        "pre-shapes for a multi-finger hand), reject colliding poses, close the "
        "fingers and rank the grasps (force closure, epsilon on one torque "
        "scale, robustness, the weight they hold).",
    )
    plan.add_argument(
        "object",
        nargs="?",
        default="box",
        help="a scene: a YAML file or a shipped scene's name (`drakegrasp "
        "scenes`; not a planar one), planned for the hand and object its "
        "drakegrasp: section names, with its mu, against the rest of it (a weld "
        "of the hand to the world or a table, which places it for analyze, is "
        "left out: plan places the hand; an object welded to the world is "
        "refused); or an object: a shipped object name (box, "
        "cylinder, sphere, hex_prism), a package:// URL, a model file or a mesh "
        "(.obj: one body with the mass of water filling it), planned for --hand "
        "(default: box)",
    )
    plan.add_argument(
        "--hand",
        default=None,
        help=f"gripper for an object: {', '.join(PLAN_HANDS)} or a model "
        "URL/file (default: flat; a scene names its own)",
    )
    plan.add_argument("--num", type=int, default=500, help="poses to sample (500)")
    plan.add_argument("--top", type=_count, default=10, help="candidates to print (10)")
    plan.add_argument("--seed", type=int, default=0, help="random seed (0)")
    plan.add_argument(
        "--mu",
        type=_mu,
        default=None,
        help="friction coefficient of every contact, or 'plant': the plant's "
        "friction of the hand's and the object's geometries (Drake's combined "
        "dynamic coefficient, what a discrete simulation uses; the smallest "
        f"where pairs differ) (default: the scene's, else {PLAN_DEFAULT_MU})",
    )
    plan.add_argument(
        "--mass",
        type=_strictly_positive,
        default=None,
        metavar="KG",
        help="the object's mass in kg, for squeeze_needed and torque_needed "
        "(default: the model's; a mesh has the mass of water filling it)",
    )
    plan.add_argument(
        "--torque-limit",
        type=_strictly_positive,
        default=None,
        metavar="NM",
        help="multi-finger hands: the torque per motor (N·m) the hand "
        "will apply; candidates held within it rank first (default: the "
        "actuators' effort limits)",
    )
    plan.add_argument(
        "--squeeze-limit",
        type=_strictly_positive,
        default=None,
        metavar="N",
        help="parallel jaws: the squeeze per finger (N) the jaw will apply; "
        "candidates held within it rank first (default: the actuators' effort "
        "limits)",
    )
    plan.add_argument(
        "--contact-model",
        choices=[m.value for m in ContactModel],
        default=None,
        help="contact model of every contact: frictionless, hard_finger or "
        "soft_finger (default: the scene's, else hard_finger)",
    )
    plan.add_argument(
        "--torsional-friction",
        type=_positive_float,
        default=None,
        metavar="NU",
        help="soft-finger torsional friction nu (>= 0, dimensionless: a "
        "contact resists a torque about its normal up to b nu f_n, b the "
        "object's torque scale); required with --contact-model soft_finger "
        "(default: the scene's)",
    )
    plan.add_argument(
        "--preshape",
        type=_joint_value,
        action="append",
        default=[],
        metavar="JOINT=VALUE|open",
        help="multi-finger hands: the open hand's position of a joint (rad or "
        "m, within its limits; repeatable; 'model::joint' where names repeat); "
        "default the model's, and for --hand allegro the thumb opposed "
        "(joint_12=1.0); 'open': from there, each joint turned the way that "
        "parts the fingertips, to its limit or as far as that parts them (an "
        "angular gripper shut at zero)",
    )
    plan.add_argument(
        "--shake",
        type=_count,
        default=None,
        metavar="K",
        help="shake the first K candidates in a Drake simulation (squeezed, "
        "then gravity turned through six directions) and list them again, "
        "those that held (within 10 mm and 10 deg of where the fingers seated "
        "the object) first; for an object and --hand, not a scene (default: "
        "no shake)",
    )
    plan.add_argument(
        "--squeeze",
        type=_strictly_positive,
        default=None,
        metavar="X",
        help="with --shake: what each closing joint presses with, N for a "
        "prismatic joint, N·m for a revolute one (default 20 N, for a "
        "revolute joint at the contacts: the torque that presses each finger "
        "it closes with 20 N there; within the actuators' effort limits; 0.7 "
        "for --hand allegro)",
    )
    plan.add_argument(
        "--stiffness",
        type=_strictly_positive,
        default=None,
        metavar="K",
        help="with --shake: the fingers' position gain, N/m or N·m/rad "
        "(default per joint: 4000 N/m for a prismatic one, and for a revolute "
        "one what aims it 0.1 rad past its place, its squeeze / 0.1 rad, at the "
        "default squeeze what deflects it 0.1 rad under 20 N at its contacts; "
        "10 for --hand allegro)",
    )
    plan.add_argument(
        "--hydroelastic",
        type=_modulus,
        default=None,
        metavar="PA|none",
        dest="hydroelastic_modulus",
        help="with --shake: make the hand's geometries compliant hydroelastic "
        "with this modulus in Pa (the object's rigid, unless its model makes it "
        "compliant), so that a flat pad presses "
        "over a patch, not at Drake's one contact point; none: the models' own "
        "contact (default 1e6 for --hand flat, rounded and allegro, none "
        "otherwise)",
    )
    plan.add_argument(
        "--damping",
        type=_positive_float,
        default=None,
        metavar="D",
        help="with --shake: the fingers' damping, N·s/m or N·m·s/rad "
        "(default the stiffness times 0.0125 s: 50 at 4000 N/m; 0.1 for --hand "
        "allegro)",
    )
    _add_scene_file_options(
        plan,
        package_help="resolve package://NAME/... to DIR, in a scene's files or "
        "the object's and --hand's URLs (repeatable)",
    )
    plan.add_argument(
        "--progress",
        action="store_true",
        help='show a progress bar (needs: pip install "drakegrasp[progress]")',
    )
    out = plan.add_mutually_exclusive_group()
    out.add_argument("--json", action="store_true", help="print JSON")
    out.add_argument(
        "--out",
        default=None,
        help="write every candidate to a .parquet (an empty result: zero rows); "
        "an existing file is refused unless --overwrite",
    )
    plan.add_argument(
        "--scene-out",
        default=None,
        metavar="FILE.yaml",
        help="write the best candidate (with --shake: the best that held) as a "
        "scene file that `drakegrasp analyze FILE.yaml` loads: the hand welded "
        "where the plan put it, every joint set, the object at its pose; model "
        "files are referred to relative to FILE's folder (one outside it needs "
        "analyze --allow-any-file); for an object and --hand, not a scene",
    )
    plan.add_argument(
        "--overwrite",
        action="store_true",
        help="with --out or --scene-out: replace an existing file (default: "
        "refuse); it is written to a temporary file and renamed into place",
    )
    plan.set_defaults(func=_cmd_plan)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit status.

    Parameters
    ----------
    argv : sequence of str, optional
        Arguments without the program name (default: ``sys.argv[1:]``).
    """
    parser, _ = build_parser()
    args = parser.parse_args(argv)
    try:
        with _terminable(), _warnings_as_lines(getattr(args, "command", None)):
            _check_values(args)
            return int(args.func(args))
    except Terminated as t:
        # SIGTERM or SIGHUP: unwound like Ctrl-C, so partial files and scratch
        # folders are removed; the worker pool stops here, not at exit.
        _stop_workers(abandon=True)
        _say(f"drakegrasp: terminated by {t.name}")
        _SIGNALLED.append(t.signum)
        return 128 + t.signum
    except KeyboardInterrupt:
        # Ctrl-C: one line and the conventional status 128 + SIGINT; batch
        # output is written atomically, so nothing half-written is left.  The
        # workers ignore SIGINT (the parent decides): they are stopped here.
        _stop_workers(abandon=True)
        print("drakegrasp: interrupted", file=sys.stderr)
        _SIGNALLED.append(signal.SIGINT)
        return EXIT_INTERRUPTED
    except BrokenPipeError:  # e.g. `drakegrasp analyze | head`
        return 0
    except GraspError as e:
        return _error(_cli_words(str(e), getattr(args, "command", None)))
    except OSError as e:  # a file error not already wrapped: its names cut short
        names = [
            describe(os.fsdecode(f))
            for f in (e.filename, e.filename2)
            if isinstance(f, str | bytes | os.PathLike)
        ]
        if e.strerror and names:
            return _error(f"{e.strerror}: {' -> '.join(names)}")
        return _error(f"{type(e).__name__}: {e}" if not str(e) else str(e))
    except (ValueError, RuntimeError, MemoryError) as e:
        # File or Drake errors that were not already wrapped.
        return _error(f"{type(e).__name__}: {e}" if not str(e) else str(e))
    except SystemExit as e:
        # pydrake raises a failed DRAKE_DEMAND ("Failure at ...") as
        # SystemExit with its text: one line, like any other refusal
        if not isinstance(e.code, str):
            raise
        return _error(e.code)
    except Exception as e:  # noqa: BLE001 - the CLI never shows a traceback
        if os.environ.get("DRAKEGRASP_DEBUG"):
            raise
        return _error(
            f"unexpected {type(e).__name__}: {e} (a bug in drakegrasp; rerun with "
            "DRAKEGRASP_DEBUG=1 for the traceback and report it)"
        )


class Terminated(BaseException):  # noqa: N818 - like KeyboardInterrupt
    """SIGTERM or SIGHUP received: raised in the main thread to unwind the run.

    A ``BaseException``, like ``KeyboardInterrupt``, so that ``finally``
    blocks and writers' ``except BaseException`` cleanups run while no
    ``except Exception`` swallows it.
    """

    def __init__(self, signum: int):
        self.signum = signum
        self.name = signal.Signals(signum).name
        super().__init__(self.name)


_TERMINATING = tuple(
    getattr(signal, name) for name in ("SIGTERM", "SIGHUP") if hasattr(signal, name)
)


def _importing(frame) -> bool:
    """Whether the interrupted Python code runs inside an import or a fork.

    An exception raised there is caught before it can unwind the run: module
    initialisers catch it (pydrake's logs a many-line CRITICAL report and
    fails the import, exit 1), and the at-fork hooks that run while the
    worker pool starts (``logging``'s lock release) print "Exception ignored"
    and drop it, so the run carried on after Ctrl-C or SIGTERM.
    """
    while frame is not None:
        name = frame.f_code.co_filename
        if name.startswith("<frozen importlib") or (
            frame.f_code.co_name == "_launch" and name.endswith("popen_fork.py")
        ):
            return True
        frame = frame.f_back
    return False


def _later(signum: int) -> None:
    """Deliver ``signum`` to this process again in 50 ms (after the import)."""
    timer = threading.Timer(0.05, os.kill, (os.getpid(), signum))
    timer.daemon = True
    timer.start()


_HANDLERS_OWNER = {"pid": None}  # the process whose run the handlers unwind


def _in_forked_child(signum: int) -> bool:
    """Handle ``signum`` as a pool worker would, if this is a forked child.

    A fork copies the handlers, and a worker resets them only once it runs its
    initialiser.  A signal to the whole group can land before that, even in the
    fork's own hooks, where starting the deferral's timer thread raced
    ``threading``'s after-fork reset (a ``KeyError`` traceback on stderr).  So
    a child never defers: SIGTERM ends it at once, as its default does, and
    SIGHUP and Ctrl-C are left to the parent, as the worker's initialiser does.
    """
    if _HANDLERS_OWNER["pid"] in (None, os.getpid()):
        return False
    if signum == signal.SIGTERM:
        signal.signal(signum, signal.SIG_DFL)
        os.kill(os.getpid(), signum)
    else:
        signal.signal(signum, signal.SIG_IGN)
    return True


def _raise_terminated(signum: int, frame) -> None:
    if _in_forked_child(signum):
        return
    if _importing(frame):
        _later(signum)
        return
    for sig in _TERMINATING:  # a second signal must not interrupt the cleanup
        signal.signal(sig, signal.SIG_IGN)
    threading.excepthook = _quiet_pool_thread_race
    raise Terminated(signum)


def _raise_interrupt(signum: int, frame) -> None:
    """Ctrl-C as Python's own handler, deferred while an import runs."""
    if _in_forked_child(signum):
        return
    if _importing(frame):
        _later(signum)
        return
    threading.excepthook = _quiet_pool_thread_race
    raise KeyboardInterrupt


@contextlib.contextmanager
def _terminable():
    """Turn SIGTERM and SIGHUP into :class:`Terminated` while the command runs.

    These and Ctrl-C (when Python's default handler has it) wait while an
    import runs (see :func:`_importing`) and land right after it.

    Without this, either signal kills the interpreter at once: no ``finally``
    runs, ``.partial`` files and ``.batch-*`` scratch folders stay, and the
    kept worker pool is never told to stop.  Only the main thread can set
    handlers; elsewhere (``main`` called from a thread) nothing changes.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    _HANDLERS_OWNER["pid"] = os.getpid()
    previous = {sig: signal.signal(sig, _raise_terminated) for sig in _TERMINATING}
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        previous[signal.SIGINT] = signal.signal(signal.SIGINT, _raise_interrupt)
    try:
        yield
    finally:
        _FINISHED.append(True)  # a signal from here on finds the work done
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def _stop_workers(*, abandon: bool = False) -> None:
    """Stop the batch engine's kept worker pool, if this process started one.

    ``abandon=True`` after a signal: the workers are killed, not waited for.
    """
    workers = sys.modules.get("drakegrasp.batch.run.workers")
    if workers is None:
        return
    workers.shutdown_pool(abandon=abandon)


def _quiet_pool_thread_race(args) -> None:
    """``threading.excepthook`` that drops the pool thread's cancelled-future race.

    After a signal to the whole process group the workers die while this
    process cancels their chunks; CPython 3.11's pool thread can then fail on a
    cancelled future (``InvalidStateError`` in ``terminate_broken``) and print a
    traceback that says nothing the one-line message does not.  Installed when
    the signal arrives; every other thread exception is printed as before.
    """
    from concurrent.futures import InvalidStateError
    from concurrent.futures.process import _ExecutorManagerThread

    if isinstance(args.thread, _ExecutorManagerThread) and issubclass(
        args.exc_type, InvalidStateError
    ):
        return
    threading.__excepthook__(args)


def _say(line: str) -> None:
    """One line on stderr, unless stderr is gone (a hung-up terminal)."""
    try:
        print(line, file=sys.stderr)
    except OSError:
        pass


def printable(text: str) -> str:
    r"""``text`` safe to print on a terminal: control characters escaped.

    File names may hold anything but ``/`` and NUL: a terminal escape
    (``]0;...``), a bidirectional override (U+202E) or an undecodable
    byte (a lone surrogate, which ``print`` cannot even encode).  Those
    characters (Unicode categories Cc, Cf and Cs) are shown as Python escapes,
    ```` or ``‮``; every other character is kept.
    """
    return "".join(
        c.encode("unicode_escape", "backslashreplace").decode("ascii")
        if unicodedata.category(c) in ("Cc", "Cf", "Cs")
        else c
        for c in str(text)
    )


def _error(message: str) -> int:
    """Print one line on stderr; return the error status."""
    text = printable(" ".join(cut_message(str(message)).split()))
    print(f"drakegrasp: error: {text}", file=sys.stderr)
    return EXIT_ERROR


_SIGNALLED: list[int] = []  # the signals that ended a run of main(), for run()


def run() -> None:
    """The ``drakegrasp`` program: :func:`main`, then exit with its status.

    After SIGTERM, SIGHUP or Ctrl-C the run has already cleaned up (partial files,
    scratch folders, the worker pool and its shared memory) and said so in one
    line; the process then ends at once, without the interpreter's exit-time
    joins.  A signal to the whole process group can leave a pool worker that
    was being started as the others died, and waiting for it would hang the
    program (and a ``| tee`` reading its output).  Such a worker ends by itself
    once it sees its parent gone.

    Outside the command's body the program handles signals too: before it (the
    arguments being read) a SIGTERM or SIGHUP ends the program at once, with
    the same line and status; after it (the output written), the first such
    signal or Ctrl-C lets the exit finish with the command's own status, and a
    second one ends the process at once.
    """
    _FINISHED.clear()
    main_thread = threading.current_thread() is threading.main_thread()
    if main_thread:
        for sig in _TERMINATING:
            signal.signal(sig, _outside_the_command)
    code = main()
    if _SIGNALLED:
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code)
    if main_thread:
        signal.signal(signal.SIGINT, _noted_late)
    _stop_workers()  # here, not in the interpreter's exit
    sys.exit(code)


_FINISHED: list[bool] = []  # the command's body has ended (:func:`_terminable`)


def _noted_late(signum: int, _frame) -> None:
    """A signal once the command has finished: taken; a second one ends it."""
    signal.signal(signum, signal.SIG_DFL)


def _outside_the_command(signum: int, frame) -> None:
    """SIGTERM or SIGHUP while :func:`run` is not inside the command's body.

    Before the body (the arguments being read) nothing is under way: the
    process ends at once, with the line and status of a signalled run.  After
    it, the command has written its files, but the interpreter's exit still
    stops the kept worker pool and tears the modules down; with the default
    handler a signal then killed the process (status -15, the output
    complete, at times a fragment of a traceback on stderr).  Now the first
    such signal is taken and the exit goes on with the command's own status;
    a second ends the process at once, as the default does.
    """
    if _in_forked_child(signum):
        return
    if not _FINISHED:
        _say(f"drakegrasp: terminated by {signal.Signals(signum).name}")
        os._exit(128 + signum)
    _noted_late(signum, frame)


if __name__ == "__main__":
    run()
