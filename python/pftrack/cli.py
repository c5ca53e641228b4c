"""The ``pftrack`` command line: parses arguments and wires the library together.

Sub-commands: ``demo`` (the built-in job), ``track``, ``eval``, ``recover``, ``experiment``.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every sub-command."""
    parser = argparse.ArgumentParser(
        prog="pftrack",
        description=(
            "Track many people or objects in video with one colour particle filter each, "
            "and recover the parts of their paths that tracking lost."
        ),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    from pftrack.recovery.cli import add_experiment_parser, add_recover_parser

    add_recover_parser(sub)
    add_experiment_parser(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``pftrack`` script; returns the exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args))
    except (FileNotFoundError, ValueError, TypeError) as exc:
        print(f"pftrack {args.command}: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
