"""What every subcommand of ``ttt-sm`` shares: the one-line error, the options, the output.

- :class:`CliError`: a user error; :func:`ttt_sm.cli.main` prints it as
  ``ttt-sm <command>: error: <message>`` on standard error, exit status 2.
- :func:`add_command`: a subcommand with the common ``--json`` and ``--seed``.
- :func:`emit` / :func:`print_json`: the result on standard output, as text or
  as one strict JSON document (:mod:`ttt_sm.runtime.jsonable`: NaN and
  infinity are ``null``, never the bare ``NaN`` that JSON readers refuse).
- :func:`progress`: progress lines on standard error, so ``--json`` output
  stays one document.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from typing import Any

from ..runtime.jsonable import dumps

Command = Callable[[argparse.Namespace], int]


class CliError(Exception):
    """A user error the CLI reports as one line."""


def add_command(sub: Any, name: str, func: Command, help_: str) -> argparse.ArgumentParser:
    """Add subcommand ``name`` running ``func``, with ``--json`` and ``--seed``."""
    sp: argparse.ArgumentParser = sub.add_parser(name, help=help_, description=help_)
    sp.set_defaults(func=func)
    sp.add_argument("--json", action="store_true", help="print one JSON document")
    sp.add_argument("--seed", type=int, default=0, help="seed of the simulated arm (default 0)")
    return sp


def progress(enabled: bool) -> Callable[[str], None]:
    """A ``say(msg)`` that writes progress lines to standard error (or nothing)."""
    def say(msg: str) -> None:
        if enabled:
            print(msg, file=sys.stderr, flush=True)
    return say


def print_json(data: Any) -> None:
    """Print ``data`` as one strict JSON document (indented by 2)."""
    print(dumps(data, indent=2))


def emit(data: Any, as_json: bool, text: str | None = None) -> None:
    """Print the result: JSON when ``as_json`` (or when there is no ``text``), else ``text``."""
    if as_json or text is None:
        print_json(data)
    else:
        print(text)
