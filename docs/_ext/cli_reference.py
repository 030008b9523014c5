"""The argument parser of the ``drakegrasp`` command, for sphinx-argparse.

:func:`drakegrasp.cli.build_parser` returns the parser together with its
sub-command table; sphinx-argparse wants a function that returns the parser
alone, so the CLI reference page is generated from this one.
"""

from __future__ import annotations

import argparse

from drakegrasp.cli import build_parser


def parser() -> argparse.ArgumentParser:
    """The parser of ``drakegrasp`` (the same object ``drakegrasp.cli.main`` uses)."""
    return build_parser()[0]
