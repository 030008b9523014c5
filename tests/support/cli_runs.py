"""Running the command line in-process, as the refusal tests do."""

from __future__ import annotations

from drakegrasp import cli


def run_cli(argv: list, capsys) -> tuple[int, str]:
    """``(exit status, stderr)`` of ``drakegrasp argv``, run through ``cli.main``.

    argparse's own refusals leave by ``SystemExit``; its code is the status.
    """
    try:
        status = cli.main(argv)
    except SystemExit as exit_:
        status = exit_.code
    return status, capsys.readouterr().err
