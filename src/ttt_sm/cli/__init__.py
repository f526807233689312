"""`ttt-sm`: the command line.  A thin layer: parse, call the app, print.

Every result-producing subcommand has `--json` (one JSON document on
standard output, progress on standard error).  Errors are one readable line
on standard error and exit status 2.

The package: :mod:`.common` holds what every subcommand shares (the
one-line :class:`~.common.CliError`, the ``--json``/``--seed`` options, the
strict JSON output); each other module adds its subcommands with a
``register(subparsers)`` function, listed in :data:`SUBCOMMANDS` in the order
``ttt-sm --help`` shows them:

- :mod:`.commands`: play, demo, draw, tune, bench, ik, init, charts, params;
- :mod:`.scenario`, :mod:`.debug`, :mod:`.gui`, :mod:`.camera`, :mod:`.vision`, :mod:`.ai`,
  :mod:`.docs`: the command of that name.

The subcommand modules import only :mod:`.common` from this package, never
this module, and nothing below the CLI imports the CLI.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from ..params import ParameterError
from . import ai, camera, commands, debug, docs, gui, scenario, vision
from .common import CliError, join_negative_values

#: The subcommand modules, in the order of ``ttt-sm --help``.
SUBCOMMANDS = (commands, scenario, debug, gui, camera, vision, ai, docs)


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of `ttt-sm` and its subcommands."""
    p = argparse.ArgumentParser(prog="ttt-sm", description=__doc__.splitlines()[0])
    p.add_argument("--params", metavar="FILE", default=None,
                   help="parameter file (default: the packaged arm.toml)")
    sub = p.add_subparsers(dest="command", required=True)
    for module in SUBCOMMANDS:
        module.register(sub)
    return p


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the `ttt-sm` console script."""
    from ..twin.kinematics import IKError

    parser = build_parser()
    args = parser.parse_args(join_negative_values(parser, sys.argv[1:] if argv is None else argv))
    try:
        return int(args.func(args))
    except (ParameterError, IKError, CliError) as exc:
        print(f"ttt-sm {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"ttt-sm {args.command}: interrupted", file=sys.stderr)
        return 130
