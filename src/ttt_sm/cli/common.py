"""What every subcommand of ``ttt-sm`` shares: the one-line error, the options, the output.

- :class:`CliError`: a user error; :func:`ttt_sm.cli.main` prints it as
  ``ttt-sm <command>: error: <message>`` on standard error, exit status 2.
- :func:`add_command`: a subcommand with the common ``--json`` and ``--seed``.
- :func:`emit` / :func:`print_json`: the result on standard output, as text or
  as one strict JSON document (:mod:`ttt_sm.runtime.jsonable`: NaN and
  infinity are ``null``, never the bare ``NaN`` that JSON readers refuse).
- :func:`progress`: progress lines on standard error, so ``--json`` output
  stays one document; :func:`status_line`: where a long run is, one line
  rewritten in place, on a terminal only.
- :func:`join_negative_values`: ``--start -120,0,0`` read as ``--start=-120,0,0``.
"""

from __future__ import annotations

import argparse
import os
import re
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from ..files import RecordBusyError, refuse_if_busy, save_figure
from ..runtime.jsonable import dumps

Command = Callable[[argparse.Namespace], int]


class CliError(Exception):
    """A user error the CLI reports as one line."""


class Interrupted(KeyboardInterrupt):
    """A signal that stops the command (SIGTERM; Ctrl-C is Python's own KeyboardInterrupt).

    Raised where the program is, as Ctrl-C is, so ``finally`` blocks and
    ``with`` blocks run and every record being written gets its last line
    (:class:`~ttt_sm.runtime.recordfile.RecordFile`); ``signal`` names it.
    """

    def __init__(self, signal_name: str = "SIGINT") -> None:
        super().__init__(signal_name)
        self.signal = signal_name


#: Packages whose code runs where an exception is printed and swallowed, so a signal waits until they
#: return: numba's compiler calls back into Python from C (llvmlite's ctypes callbacks), and the import
#: system frees its module locks in weakref callbacks (``_get_module_lock.<locals>.cb``).
_FOREIGN_PACKAGES = frozenset({"numba", "llvmlite", "ctypes", "importlib"})
#: How often a signal that waits looks again whether the foreign code has returned, s.
_RETRY_S = 0.05


def _in_foreign_code(frame: Any) -> bool:
    """Whether the Python stack at `frame` runs inside a package that calls back from C (see above)."""
    while frame is not None:
        if str(frame.f_globals.get("__name__", "")).partition(".")[0] in _FOREIGN_PACKAGES:
            return True
        frame = frame.f_back
    return False


def terminate_interrupts() -> Callable[[], None]:
    """Make SIGTERM and Ctrl-C stop the command at a safe point (in the main thread); returns what
    restores the handlers.

    Without it SIGTERM ends the process at once, in the middle of whatever it
    wrote, with no line saying so.  A signal is raised as :class:`Interrupted`
    (``KeyboardInterrupt`` for Ctrl-C) where Python is, unless that is inside
    numba's compiler or another package that calls back into Python from C:
    there the exception would be swallowed (``Exception ignored in ctypes
    callback``) and the command would go on.  Then the handler only notes the
    signal and looks again every 50 ms (``SIGALRM``) until the stack has left
    that code, and raises there.  Commands that stop in a gentler way
    (``ttt-sm play`` at the end of a chart step, ``ttt-sm gui`` through its
    server) put handlers of their own in place while they run.
    """
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        return lambda: None

    pending: list[int] = []

    def raise_now(signum: int) -> None:
        pending.clear()
        if signum == signal.SIGTERM:
            raise Interrupted("SIGTERM")
        raise KeyboardInterrupt

    def on_signal(signum: int, frame: object) -> None:
        if _in_foreign_code(frame):
            if not pending:
                pending.append(signum)
                signal.setitimer(signal.ITIMER_REAL, _RETRY_S)
            return
        raise_now(signum)

    def look_again(_signum: int, frame: object) -> None:
        if not pending:
            return
        if _in_foreign_code(frame):
            signal.setitimer(signal.ITIMER_REAL, _RETRY_S)
            return
        raise_now(pending[0])

    try:
        previous = {sig: signal.signal(sig, on_signal) for sig in (signal.SIGTERM, signal.SIGINT)}
        previous[signal.SIGALRM] = signal.signal(signal.SIGALRM, look_again)
    except ValueError:  # not the main interpreter
        return lambda: None

    def restore() -> None:
        signal.setitimer(signal.ITIMER_REAL, 0)
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    return restore


def add_command(sub: Any, name: str, func: Command, help_: str) -> argparse.ArgumentParser:
    """Add subcommand ``name`` running ``func``, with ``--json`` and ``--seed``."""
    sp: argparse.ArgumentParser = sub.add_parser(name, help=help_, description=help_)
    sp.set_defaults(func=func)
    sp.add_argument("--json", action="store_true", help="print one JSON document")
    sp.add_argument("--seed", type=seed, default=0, help="seed of the simulated arm (default 0)")
    return sp


def add_group(sub: Any, name: str, help_: str) -> tuple[argparse.ArgumentParser, Any]:
    """Add command group ``name`` (``ttt-sm NAME ACTION ...``): its parser and the subparsers of its actions.

    The action chosen is in ``args.NAME_command``.
    """
    sp: argparse.ArgumentParser = sub.add_parser(name, help=help_, description=help_)
    return sp, sp.add_subparsers(dest=f"{name}_command", required=True)


def save_png(fig: Any, path: str) -> None:
    """A matplotlib figure laid out, saved whole or not at all as a PNG (docs/reliability.md), then closed."""
    import matplotlib.pyplot as plt

    fig.tight_layout()
    try:
        save_figure(fig, path, dpi=90, format="png")
    finally:
        plt.close(fig)


#: A value that starts with a minus and a digit: a negative number, or a list of numbers.
_NEGATIVE_VALUE = re.compile(r"^-\.?\d")


def _value_options(parser: argparse.ArgumentParser) -> set[str]:
    """The option strings of `parser` that take one value (``--start Q1,Q2,Q3``)."""
    return {opt for action in parser._actions if action.option_strings and action.nargs is None
            for opt in action.option_strings}


def _subcommands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    return {}


def join_negative_values(parser: argparse.ArgumentParser, argv: Sequence[str]) -> list[str]:
    """``--opt -1,2`` written as ``--opt=-1,2``, for every option that takes a value.

    argparse reads a word that starts with ``-`` as an option unless it is a
    plain number, so ``--start -120,0,0`` failed with "expected one argument"
    while ``--start=-120,0,0`` worked; both mean the same to a person.
    """
    options = _value_options(parser)
    subcommands = _subcommands(parser)
    out: list[str] = []
    args = list(argv)
    i = 0
    while i < len(args):
        word = args[i]
        if word in subcommands:
            options = options | _value_options(subcommands[word])
            subcommands = _subcommands(subcommands[word])
        if word in options and i + 1 < len(args) and _NEGATIVE_VALUE.match(args[i + 1]):
            out.append(f"{word}={args[i + 1]}")
            i += 2
            continue
        out.append(word)
        i += 1
    return out


def arm_choice(text: str) -> str:
    """The ``type`` of every ``--arm``: ``sim`` or ``serial:PORT`` (the port is opened when the command runs)."""
    kind, sep, port = text.partition(":")
    if text == "sim" or (kind == "serial" and sep and port.strip()):
        return text
    raise argparse.ArgumentTypeError(f"expected sim or serial:PORT (a serial device or the link of ttt-sm arm"
                                     f" serve), got {text[:80]!r}")


def add_arm_option(sp: argparse.ArgumentParser) -> None:
    """The ``--arm`` option of the commands that drive the robot (docs/hardware.md, "Choosing the arm")."""
    sp.add_argument("--arm", type=arm_choice, default="sim", metavar="sim|serial:PORT",
                    help="sim (default): the twin in this process; serial:PORT: the arm behind a serial link"
                         " (a board, or ttt-sm arm serve's link)")


def whole_number(text: str) -> int:
    """A count or a size: a whole number 1 .. 10**6."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 1, got {text[:40]!r}") from None
    if not 1 <= value <= 10**6:
        raise argparse.ArgumentTypeError(f"expected a whole number 1 .. 1000000, got {text[:40]}")
    return value


def add_runner_options(sp: argparse.ArgumentParser, what: str) -> None:
    """``--workers`` and ``--dask`` of a sweep (``ttt-sm init``, ``ttt-sm faults``): where its `what` run."""
    sp.add_argument("--workers", type=whole_number, default=1, metavar="N",
                    help=f"{what} run at once on this machine, each in a process of its own (default 1: one after"
                         " another in this process); the report is the same whatever N")
    sp.add_argument("--dask", metavar="ADDRESS", default=None,
                    help=f"run the {what} on the Dask cluster whose scheduler is at ADDRESS (needs ttt_sm[cluster])")


def board_cells(text: str) -> str:
    """The ``type`` of a board given as text: rows may be split by '/', '|' or spaces, as ``ttt-sm camera serve``
    and ``ttt-sm ai move`` take them; the 25 cells are checked by the command that reads them."""
    return "".join(ch for ch in text if ch not in " \t\r\n/|")


def seed(text: str) -> int:
    """The ``type`` of every ``--seed``: a whole number 0 .. 2**63 - 1 (numpy's generators take no negative
    seed, and a run is reproducible from it)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 0, got {text[:40]!r}") from None
    if not 0 <= value < 2**63:
        raise argparse.ArgumentTypeError(f"expected a whole number 0 .. 2**63 - 1, got {text[:40]}")
    return value


def out_dir(path: str, what: str = "--out") -> Path:
    """The folder a command writes to, made now and known writable: refused before the run, not after it."""
    if not path.strip():  # Path('') is the current folder: a command would write its files among yours
        raise CliError(f"{what}: the folder name is empty; name one, e.g. {what} out/run")
    folder = Path(path)
    try:
        folder.mkdir(parents=True, exist_ok=True)
        probe = folder / f".ttt-sm-can-write-{os.getpid()}"
        probe.write_bytes(b"")
        probe.unlink()
    except (OSError, ValueError) as exc:  # ValueError: a NUL in the name
        reason = getattr(exc, "strerror", None) or str(exc)
        if isinstance(exc, FileExistsError):
            reason = "a file is there, not a folder"
        raise CliError(f"{what} {path[:200]}: cannot write there ({reason})") from None
    return folder


def trace_file(path: str, what: str = "--trace") -> Path:
    """A file a command streams a record to: not a folder, its folder made and known writable, before the run."""
    if not path.strip():
        raise CliError(f"{what}: the file name is empty; name one, e.g. {what} out/trace.jsonl")
    file = Path(path)
    if file.is_dir():
        raise CliError(f"{what}: {path[:200]} is a folder; name the file the record is written to")
    out_dir(str(file.parent), f"{what} {path[:200]}: its folder")
    try:
        refuse_if_busy(file)  # a second ttt-sm on the same record: refused now, not after building the robot
    except RecordBusyError as exc:
        raise CliError(f"{what} {exc}") from None
    return file


#: Whether a status line is on show (the next progress line first clears it).
_status_shown = False


def progress(enabled: bool, keep_status: bool = False) -> Callable[[str], None]:
    """A ``say(msg)`` that writes progress lines to standard error (or nothing).

    A status line on show is taken off first, or with ``keep_status`` ended
    where it stands (:func:`end_status`), so the line comes after it, never
    on it.
    """
    def say(msg: str) -> None:
        if enabled:
            if keep_status:
                end_status()
            else:
                clear_status()
            print(msg, file=sys.stderr, flush=True)
    return say


def status_line(every_s: float = 0.25) -> Callable[[str], None] | None:
    """A ``show(text)`` that rewrites one status line on standard error at most every ``every_s`` seconds
    of wall time, or None when standard error is not a terminal (a log or a pipe gets no status lines)."""
    stream = sys.stderr
    if stream is None or not stream.isatty():
        return None
    last = [0.0]

    def show(text: str) -> None:
        global _status_shown
        now = time.monotonic()
        if now - last[0] >= every_s:
            last[0] = now
            stream.write("\r\033[K  " + text[:150])
            stream.flush()
            _status_shown = True
    return show


def clear_status() -> None:
    """Take the status line off the terminal (before a line of its own, and at the end)."""
    global _status_shown
    if _status_shown and sys.stderr is not None:
        sys.stderr.write("\r\033[K")
        sys.stderr.flush()
        _status_shown = False


def end_status() -> None:
    """End the status line with a new line, so that what is written next starts a line of its own.

    The status line is rewritten in place with ``\\r``; erasing it before a
    message leaves the two on one line in a log of the terminal (``script``, a
    CI log: ``...drawing the fieldIf it is your turn``).  Ended, the last
    status stays on show above the message.
    """
    global _status_shown
    if _status_shown and sys.stderr is not None:
        sys.stderr.write("\n")
        sys.stderr.flush()
        _status_shown = False


def print_json(data: Any) -> None:
    """Print ``data`` as one strict JSON document (indented by 2)."""
    print(dumps(data, indent=2))


def emit(data: Any, as_json: bool, text: str | None = None) -> None:
    """Print the result: JSON when ``as_json`` (or when there is no ``text``), else ``text``."""
    if as_json or text is None:
        print_json(data)
    else:
        print(text)
