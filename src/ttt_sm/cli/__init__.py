"""`ttt-sm`: the command line.  A thin layer: parse, call the app, print.

Every result-producing subcommand has `--json` (one JSON document on
standard output, progress on standard error).  Errors are one readable line
on standard error and exit status 2, never a traceback (:func:`main`): a
project error is its message, an operating-system error on a path names the
path and what to do, a closed pipe (``ttt-sm params | head``) ends quietly,
Ctrl-C says "interrupted" (status 130), SIGTERM likewise (status 143): both
raise :class:`~.common.Interrupted` where the program is, so every record
being written ends with its ``interrupted`` line (docs/reliability.md).  Anything else is a bug, reported in
one line that says so (status 70; ``TTT_SM_TRACEBACK=1`` shows the traceback).

The package: :mod:`.common` holds what every subcommand shares (the
one-line :class:`~.common.CliError`, the ``--json``/``--seed`` options, the
strict JSON output); each other module adds its subcommands with a
``register(subparsers)`` function, listed in :data:`SUBCOMMANDS` in the order
``ttt-sm --help`` shows them:

- :mod:`.commands`: play, demo, draw, tune, bench, ik, charts, params;
- :mod:`.sweeps`: init and faults (many runs on a pool or a cluster);
- :mod:`.precision`: precision (the thesis' staircase of section 3.5);
- :mod:`.scenario`, :mod:`.debug`, :mod:`.gui`, :mod:`.camera`, :mod:`.arm`, :mod:`.vision`, :mod:`.ai`,
  :mod:`.lab`, :mod:`.kinematics`: the command of that name (:mod:`.lab` also the global ``--chart``).

(Regenerating the repository's generated files is a development tool, ``make docs``
(``python -m tools.docs``), not a command of the installed package.)

The subcommand modules import only :mod:`.common` from this package, never
this module, and nothing below the CLI imports the CLI.
"""

from __future__ import annotations

import argparse
import errno
import os
import signal
import sys
from collections.abc import Sequence

from ..files import ADVICE as WRITE_ADVICE
from ..params import shown_path
from ..runtime.recordfile import interruption
from . import ai, arm, camera, commands, debug, gui, kinematics, lab, precision, scenario, sweeps, vision
from .common import join_negative_values, terminate_interrupts

#: The subcommand modules, in the order of ``ttt-sm --help``.
SUBCOMMANDS = (commands, sweeps, precision, scenario, debug, gui, camera, arm, vision, ai, lab, kinematics)


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of `ttt-sm` and its subcommands."""
    p = argparse.ArgumentParser(prog="ttt-sm", description=__doc__.splitlines()[0])
    p.add_argument("--params", metavar="FILE", default=None,
                   help="parameter file (default: the packaged arm.toml)")
    lab.add_global_options(p)
    sub = p.add_subparsers(dest="command", required=True)
    for module in SUBCOMMANDS:
        module.register(sub)
    return p


#: Exit status of an error that is a bug of ttt_sm, not of its input (EX_SOFTWARE of sysexits.h).
BUG_STATUS = 70

#: What to do about an operating-system error on a path, by errno.
_OS_ADVICE = {
    errno.ENOENT: "check the path: it does not exist",
    errno.EACCES: "check its permissions, or choose another path",
    errno.EPERM: "check its permissions, or choose another path",
    errno.EROFS: "it is on a read-only file system: choose another path",
    errno.EISDIR: "it is a folder where a file belongs: name a file",
    errno.ENOTDIR: "a part of it is a file where a folder belongs: choose another path",
    errno.EEXIST: "something of that name is already there: choose another path",
    errno.ENAMETOOLONG: "the name is too long: choose a shorter path",
    **WRITE_ADVICE,  # a full disk, a quota, a file-size limit
}


def error_line(command: str, exc: BaseException) -> tuple[str, int]:
    """The one line (without the newline) and the exit status the CLI gives for ``exc``."""
    where = f"ttt-sm {command}"
    if isinstance(exc, OSError) and (exc.filename is not None or exc.errno in _OS_ADVICE):
        path = shown_path(exc.filename) if exc.filename is not None else "a path"
        other = f" -> {shown_path(exc.filename2)}" if exc.filename2 is not None else ""
        reason = exc.strerror or str(exc)
        advice = _OS_ADVICE.get(exc.errno or 0, "check the path and try again")
        return f"{where}: error: {path}{other}: {reason}; {advice}", 2
    if type(exc).__module__.startswith("ttt_sm.") or isinstance(exc, (ValueError, OSError)):
        text = " ".join(str(exc).splitlines()) or type(exc).__name__  # \r too: one line, whatever the message
        return f"{where}: error: {text}", 2
    text = " ".join(str(exc).splitlines())[:300]
    return (f"{where}: internal error (a bug of ttt_sm, please report it): {type(exc).__name__}: {text}"
            f" (TTT_SM_TRACEBACK=1 shows where)"), BUG_STATUS


def _quiet_stdout() -> None:
    """After a closed pipe: send what is still buffered to /dev/null, so exiting does not complain."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError, AttributeError):  # no stdout at all
        pass


def _ignore_late_signals() -> None:
    """The ttt-sm process has done its work: a Ctrl-C or SIGTERM while it exits changes nothing.

    Without this, a signal in the last moments (after a command put back the handlers it had, while
    Python shuts down) killed the process with status -2 or -15 although its work and records were whole.
    """
    try:
        for sig in (signal.SIGINT, signal.SIGTERM):
            signal.signal(sig, signal.SIG_IGN)
    except ValueError:  # not the main thread: signals are not ours to handle
        pass


def _interrupted(command: str, exc: KeyboardInterrupt) -> int:
    """Ctrl-C or SIGTERM stopped `command`: one line, and the status a shell expects (130, 143)."""
    name = str(getattr(exc, "signal", "SIGINT"))
    print(f"ttt-sm {command}: interrupted" + (f" ({name})" if name != "SIGINT" else ""), file=sys.stderr)
    return 128 + (signal.SIGTERM if name == "SIGTERM" else signal.SIGINT)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the `ttt-sm` console script: run the subcommand, turn every error into one line."""
    command = "?"
    restore = terminate_interrupts()
    try:
        parser = build_parser()
        args = parser.parse_args(join_negative_values(parser, sys.argv[1:] if argv is None else argv))
        command = args.command
        args.ttt_sm_process = argv is None  # the process exits when the command returns
        with lab.chosen_charts(args):
            status = int(args.func(args))
        if argv is None:
            _ignore_late_signals()
        if sys.stdout is not None:
            sys.stdout.flush()  # a closed pipe shows here, not at exit
        return status
    except BrokenPipeError:
        _quiet_stdout()
        return 141  # as if killed by SIGPIPE (128 + 13), what `head` expects of a writer
    except KeyboardInterrupt as exc:
        return _interrupted(command, exc)
    except Exception as exc:
        interrupt = interruption(exc)  # e.g. the signal landed in a C extension's import
        if interrupt is not None:
            return _interrupted(command, interrupt)
        if os.environ.get("TTT_SM_TRACEBACK"):
            raise
        line, status = error_line(command, exc)
        print(line, file=sys.stderr)
        return status
    finally:
        if argv is None:  # the ttt-sm process: it exits now
            _ignore_late_signals()
        else:  # called in a program: give it back its handler
            restore()
