"""The ``drakegrasp`` command.

Usage::

    drakegrasp analyze [SCENE] [--mu M] [--contact-model MODEL]
                       [--torsional-friction NU] [--package NAME=DIR ...]
                       [--allow-any-file] [--json]
    drakegrasp scenes
    drakegrasp batch IN.npz OUT.npz [--kind force|form] [--mu M]
                     [--contact-model MODEL] [--torsional-friction NU]
                     [--num-generators NG] [--metrics NAME ...] [--progress]
                     [--overwrite]
    drakegrasp plan [OBJECT] [--hand HAND] [--num N] [--top K] [--seed S]
                    [--mu M] [--json | --out FILE.parquet]

``analyze`` loads a scene (a shipped scene's name or a YAML file; default: the
default scene), finds the contacts and prints the full report: contacts, ranks,
form closure, force closure with the hand check, exact-cone verdict, antipodal
test.  ``batch`` decides closure for every grasp of an ``.npz`` file (arrays
``positions`` and ``normals`` of shape (K, N, d), optionally ``mu``, ...) with
the vectorised batch engine and writes the verdicts to another file.
``plan`` finds grasps: a free-floating parallel-jaw gripper (``--hand``: a
model URL or file, ``wsg`` for Drake's WSG-50; default drakegrasp's flat-pad
jaw) sampled, filtered, closed and ranked on an object (a shipped object's
name, a model URL or a file; default ``box``), and prints the best ``--top``.

One interface: both commands name the contact model ``--contact-model``
(``batch --model`` is a deprecated alias that still works and says so), and
both follow one rule for soft fingers: ``--contact-model soft_finger`` needs a
torsional friction ν, from ``--torsional-friction`` or the scene / input file;
an explicit ``--torsional-friction 0`` is valid and makes soft fingers act as
hard ones.

Exit status: 0 on success, 1 on an error (one line on stderr, never a
traceback), 2 for a bad command line (argparse), 130 on Ctrl-C (SIGINT) with
one line ``drakegrasp: interrupted``.  ``batch`` refuses an output that is its
input or that exists, unless ``--overwrite``; it writes atomically (a
temporary file renamed into place), so an interrupted run loses nothing.
Set ``DRAKEGRASP_DEBUG=1`` to see the traceback of an unexpected error.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from collections.abc import Sequence

from drakegrasp.core.contact import ContactModel
from drakegrasp.core.tolerances import DEFAULT_TOL
from drakegrasp.errors import GraspError, InvalidOptionError

__all__ = ["build_parser", "main"]

EXIT_ERROR = 1
EXIT_INTERRUPTED = 130


def _cmd_analyze(args: argparse.Namespace) -> int:
    from drakegrasp.plant.analysis import analyze_grasp
    from drakegrasp.plant.scene import load_scene

    scene = load_scene(
        args.scene,
        package_map=dict(args.package) or None,
        allow_any_file=args.allow_any_file,
    )
    options = scene.analysis_options()
    if args.mu is not None:
        options["mu"] = args.mu
    if args.contact_model is not None:
        options["contact_model"] = ContactModel.parse(args.contact_model)
    if args.torsional_friction is not None:
        options["torsional_friction"] = args.torsional_friction  # 0 is valid
    elif (
        options["contact_model"] is ContactModel.SOFT_FINGER
        and not options["torsional_friction"]
    ):
        # The scene gives no ν (its default is 0): not given, as in the batch
        # command; analyze_grasp explains what is missing.
        options["torsional_friction"] = None
    report = analyze_grasp(scene.plant, scene.plant_context, **options)
    if args.json:
        out = {"scene": scene.name, "scene_file": str(scene.info.path)}
        out.update(report.to_dict())
        json.dump(out, sys.stdout, indent=2)
        sys.stdout.write("\n")
    else:
        print(f"scene {scene.name}: {scene.info.description}")
        print(report)
    return 0


def _cmd_scenes(args: argparse.Namespace) -> int:
    from drakegrasp.plant.scene import DEFAULT_SCENE, list_scenes

    infos = list_scenes()
    width = max(len(i.name) for i in infos)
    for info in infos:
        mark = "*" if info.name == DEFAULT_SCENE else " "
        print(f"{mark} {info.name:<{width}}  {info.description}")
    print("(* = default scene; run `drakegrasp analyze NAME`)")
    return 0


def _cmd_batch(args: argparse.Namespace) -> int:
    from drakegrasp.batch import stream_file

    if args.deprecated_model is not None:
        print(
            "drakegrasp: warning: --model is deprecated; use --contact-model",
            file=sys.stderr,
        )
        if args.contact_model is not None and args.contact_model != (
            args.deprecated_model
        ):
            raise InvalidOptionError(
                f"--model {args.deprecated_model} and --contact-model "
                f"{args.contact_model} disagree; give --contact-model only"
            )
    model = args.contact_model or args.deprecated_model or "hard_finger"
    options = {
        "kind": args.kind,
        "mu": args.mu,
        "model": model,
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

        summary = stream_file_on_cluster(
            args.input, args.output, scheduler=args.scheduler, **options
        )
    else:
        summary = stream_file(
            args.input, args.output, overwrite=args.overwrite, **options
        )
    print(summary)
    print(f"wrote {args.output}")
    return 0


def _workers(text: str) -> int:
    try:
        n = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: {text!r}") from None
    if n < 1:
        raise argparse.ArgumentTypeError(f"must be >= 1, got {text!r}")
    return n


def _positive_float(text: str) -> float:
    try:
        x = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not (x >= 0.0) or x == float("inf"):
        raise argparse.ArgumentTypeError(f"must be finite and >= 0, got {text!r}")
    return x


def _package(text: str) -> tuple[str, str]:
    name, sep, folder = text.partition("=")
    if not sep or not name or not folder or "/" in name:
        raise argparse.ArgumentTypeError(
            f"expected NAME=DIR (a package name, '=', its directory), got {text!r}"
        )
    return name, folder


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
    parser = argparse.ArgumentParser(
        prog="drakegrasp",
        description="Grasp analysis on top of Drake: contacts, grasp matrix, "
        "form and force closure.",
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
    analyze.add_argument(
        "--mu", type=_positive_float, help="friction coefficient (default: scene's)"
    )
    analyze.add_argument(
        "--contact-model",
        choices=[m.value for m in ContactModel],
        help="contact model (default: scene's)",
    )
    analyze.add_argument(
        "--torsional-friction",
        type=_positive_float,
        help="torsional friction coefficient of soft fingers (default: scene's)",
    )
    analyze.add_argument(
        "--package",
        action="append",
        type=_package,
        default=[],
        metavar="NAME=DIR",
        help="resolve package://NAME/... to DIR (repeatable; ROS_PACKAGE_PATH "
        "is honoured too)",
    )
    analyze.add_argument(
        "--allow-any-file",
        action="store_true",
        help="trust the scene: let it reference files outside its packages and "
        "its own directory",
    )
    analyze.add_argument("--json", action="store_true", help="print JSON")
    analyze.set_defaults(func=_cmd_analyze)

    scenes = sub.add_parser("scenes", help="list the shipped scenes")
    scenes.set_defaults(func=_cmd_scenes)
    _add_batch_parser(sub)
    _add_plan_parser(sub)
    return parser, sub


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
        help="decide closure for every grasp of an .npz file",
        description="Decide form or force closure for K grasps of N contacts "
        "stored as arrays positions (K, N, d) and normals (K, N, d) [, mu, "
        "torsional_friction, reference_points, characteristic_lengths] in an "
        ".npz file or a directory of .npy files (read chunk by chunk), and "
        "write is_closure, d_star, rank, margin, converged and "
        "the requested metrics to OUT (.npz, or .parquet with pyarrow).",
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
        "--num-generators", type=int, default=8, help="cone generators (default 8)"
    )
    batch.add_argument(
        "--torsional-friction",
        type=_positive_float,
        help="soft-finger torsional friction nu, overriding the file's array "
        "torsional_friction; required with --contact-model soft_finger unless "
        "the file has it (0 makes soft fingers act as hard ones)",
    )
    batch.add_argument(
        "--tol", type=_positive_float, default=DEFAULT_TOL, help="threshold on d*"
    )
    batch.add_argument(
        "--metrics",
        nargs="*",
        default=[],
        choices=_BatchMetrics(),
        metavar="NAME",
        help="metrics to add: %(choices)s",
    )
    batch.add_argument(
        "--chunk-size",
        type=int,
        default=None,
        help="grasps per chunk (default: sized to ~16 MiB of working memory)",
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
        "temporary file and renamed into place, and is never the input",
    )
    batch.set_defaults(func=_cmd_batch)


PLAN_HANDS = {
    "flat": "package://drakegrasp/hands/parallel_jaw_flat.sdf",
    "rounded": "package://drakegrasp/hands/parallel_jaw.sdf",
    "wsg": "package://drake_models/wsg_50_description/sdf/schunk_wsg_50_with_tip.sdf",
}
"""``plan --hand`` short names: drakegrasp's two jaws and Drake's WSG-50."""


def _plan_url(spec: str, folder: str) -> str:
    if "://" in spec or spec.endswith((".sdf", ".urdf", ".xml")):
        return spec
    return f"package://drakegrasp/{folder}/{spec}.sdf"


def _cmd_plan(args: argparse.Namespace) -> int:
    from drakegrasp.planning import plan_grasps, planning_scene

    if args.out is not None and not args.out.endswith(".parquet"):
        raise InvalidOptionError(f"--out must name a .parquet file, got {args.out!r}")
    hand = PLAN_HANDS.get(args.hand, args.hand)
    scene = planning_scene(_plan_url(args.object, "objects"), hand_url=hand)
    result = plan_grasps(
        scene.plant,
        scene.context,
        scene.object_body,
        hand=scene.hand,
        num_candidates=args.num,
        mu=args.mu,
        seed=args.seed,
        progress=args.progress,
    )
    if args.out is not None:
        _write_plan_parquet(result, args.out)
    if args.json:
        data = result.to_dict()
        data["candidates"] = data["candidates"][: args.top]
        json.dump(data, sys.stdout, indent=2)
        sys.stdout.write("\n")
    elif args.out is None:
        print(result.__str__().split("\n  #")[0])
        for k, c in enumerate(result[: args.top]):
            print(f"  #{k:<3} {c}")
    else:
        print(f"wrote {len(result)} candidates to {args.out}")
    return 0


def _write_plan_parquet(result, path: str) -> None:
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError as exc:
        raise InvalidOptionError(
            "--out FILE.parquet needs pyarrow (pip install pyarrow)"
        ) from exc
    columns = {}
    for name, values in result.table().items():
        if values.ndim == 1:
            columns[name] = values
        else:
            for j in range(values.shape[1]):
                columns[f"{name}_{j}"] = values[:, j]
    pq.write_table(pa.table(columns), path)


def _add_plan_parser(sub: argparse._SubParsersAction) -> None:
    plan = sub.add_parser(
        "plan",
        help="find ranked parallel-jaw grasps of an object",
        description="Sample antipodal grasps of a free parallel-jaw gripper on an "
        "object's collision geometry, reject colliding poses, close the fingers "
        "and rank the grasps (force closure, epsilon on one torque scale, "
        "robustness).",
    )
    plan.add_argument(
        "object",
        nargs="?",
        default="box",
        help="shipped object name (box, cylinder, sphere, hex_prism), a "
        "package:// URL or a model file (default: box)",
    )
    plan.add_argument(
        "--hand",
        default="flat",
        help=f"gripper: {', '.join(PLAN_HANDS)} or a model URL/file (default: flat)",
    )
    plan.add_argument("--num", type=int, default=500, help="poses to sample (500)")
    plan.add_argument("--top", type=int, default=10, help="candidates to print (10)")
    plan.add_argument("--seed", type=int, default=0, help="random seed (0)")
    plan.add_argument(
        "--mu", type=_positive_float, default=0.5, help="friction coefficient (0.5)"
    )
    plan.add_argument("--progress", action="store_true", help="show a progress bar")
    out = plan.add_mutually_exclusive_group()
    out.add_argument("--json", action="store_true", help="print JSON")
    out.add_argument("--out", default=None, help="write every candidate to a .parquet")
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
        return int(args.func(args))
    except KeyboardInterrupt:
        # Ctrl-C: one line and the conventional status 128 + SIGINT; batch
        # output is written atomically, so nothing half-written is left.
        print("drakegrasp: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:  # e.g. `drakegrasp analyze | head`
        return 0
    except GraspError as e:
        return _error(str(e))
    except (OSError, ValueError, RuntimeError, MemoryError) as e:
        # File or Drake errors that were not already wrapped.
        return _error(f"{type(e).__name__}: {e}" if not str(e) else str(e))
    except Exception as e:  # noqa: BLE001 - the CLI never shows a traceback
        if os.environ.get("DRAKEGRASP_DEBUG"):
            raise
        return _error(
            f"unexpected {type(e).__name__}: {e} (a bug in drakegrasp; rerun with "
            "DRAKEGRASP_DEBUG=1 for the traceback and report it)"
        )


def _error(message: str) -> int:
    """Print one line on stderr; return the error status."""
    text = " ".join(str(message).split())
    print(f"drakegrasp: error: {text}", file=sys.stderr)
    return EXIT_ERROR


if __name__ == "__main__":
    sys.exit(main())
