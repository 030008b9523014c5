"""The ``drakegrasp`` command.

Usage::

    drakegrasp analyze [SCENE] [--mu M] [--contact-model MODEL]
                       [--torsional-friction NU] [--package NAME=DIR ...]
                       [--allow-any-file] [--json]
    drakegrasp scenes
    drakegrasp batch IN.npz OUT.npz [--kind force|form] [--mu M] [--model MODEL]
                     [--num-generators NG] [--metrics NAME ...] [--progress]

``analyze`` loads a scene (a shipped scene's name or a YAML file; default: the
default scene), finds the contacts and prints the full report: contacts, ranks,
form closure, force closure with the hand check, exact-cone verdict, antipodal
test.  ``batch`` decides closure for every grasp of an ``.npz`` file (arrays
``positions`` and ``normals`` of shape (K, N, d), optionally ``mu``, ...) with
the vectorised batch engine and writes the verdicts to another file.  Errors
print one line on stderr and exit with status 1 (2 for a bad
command line).
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence

from drakegrasp.contact import ContactModel
from drakegrasp.errors import GraspError

__all__ = ["build_parser", "main"]

EXIT_ERROR = 1


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
        options["torsional_friction"] = args.torsional_friction
    if (
        options["contact_model"] is ContactModel.SOFT_FINGER
        and not options["torsional_friction"]
    ):
        options["torsional_friction"] = None  # analyze_grasp explains what is missing
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

    options = {
        "kind": args.kind,
        "mu": args.mu,
        "model": args.model,
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
        from drakegrasp.distributed import stream_file_on_cluster

        summary = stream_file_on_cluster(
            args.input, args.output, scheduler=args.scheduler, **options
        )
    else:
        summary = stream_file(args.input, args.output, **options)
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
    return parser, sub


def _add_batch_parser(sub: argparse._SubParsersAction) -> None:
    from drakegrasp.batch import METRICS

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
        "--mu", type=_positive_float, help="friction for every contact (else file's)"
    )
    batch.add_argument(
        "--model",
        choices=[m.value for m in ContactModel],
        default="hard_finger",
        help="contact model (default: hard_finger)",
    )
    batch.add_argument(
        "--num-generators", type=int, default=8, help="cone generators (default 8)"
    )
    batch.add_argument(
        "--torsional-friction",
        type=_positive_float,
        help="soft-finger torsional friction (else the file's, or 0)",
    )
    batch.add_argument(
        "--tol", type=_positive_float, default=1e-6, help="threshold on d*"
    )
    batch.add_argument(
        "--metrics",
        nargs="*",
        default=[],
        choices=METRICS,
        metavar="NAME",
        help=f"metrics to add: {', '.join(METRICS)}",
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
        help="run on a Dask cluster (e.g. tcp://host:8786; needs the 'dask' extra)",
    )
    batch.add_argument("--progress", action="store_true", help="show a progress bar")
    batch.set_defaults(func=_cmd_batch)


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
    except BrokenPipeError:  # e.g. `drakegrasp analyze | head`
        return 0
    except (GraspError, OSError, ValueError, RuntimeError) as e:
        # GraspError covers bad scenes, bodies, contacts; the others are file or
        # Drake errors that were not already wrapped.  One line, no traceback.
        message = " ".join(str(e).split())
        print(f"drakegrasp: error: {message}", file=sys.stderr)
        return EXIT_ERROR


if __name__ == "__main__":
    sys.exit(main())
