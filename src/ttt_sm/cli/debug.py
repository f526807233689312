"""``ttt-sm debug``: the subcommand that starts the debugger's REPL.

:func:`register` adds it to the ``ttt-sm`` parser; the robot and the
debugger are imported only when the command runs, so the CLI starts fast.
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Iterator
from typing import TYPE_CHECKING, Any

from ..params import shown_path
from .commands import open_arm
from .common import CliError, add_arm_option, seed, trace_file

if TYPE_CHECKING:
    from ..debug.debugger import Debugger
    from ..debug.shell import DebugShell


def register(sub: Any) -> argparse.ArgumentParser:
    """Add the ``debug`` subcommand to the subparsers of ``ttt-sm``."""
    help_ = "step through the robot's charts: breakpoints, data, signals, trace, replay"
    sp: argparse.ArgumentParser = sub.add_parser("debug", help=help_, description=help_)
    sp.set_defaults(func=cmd_debug)
    sp.add_argument("--seed", type=seed, default=0, help="seed of the simulated arm (default 0)")
    add_arm_option(sp)
    sp.add_argument("--start", metavar="Q1,Q2,Q3[,Q4]", default=None,
                    help="joint angles before power-on, degrees (default: the twin's rest pose)")
    sp.add_argument("--settle", metavar="SECONDS", type=float, default=0.0,
                    help="let the unpowered arm settle under gravity first (default 0)")
    sp.add_argument("--max-run", metavar="SECONDS", type=float, default=None,
                    help="the longest one command (run, next, step, tick) may run, simulated seconds (default 600)")
    sp.add_argument("--game", action="store_true",
                    help="a whole game: the Game and AlgorithmActivator charts, a simulated person"
                         " (X) and the camera (read in-process) play on as you step;"
                         " break enter Game.drawing stops at the robot's turn")
    sp.add_argument("--commands", metavar="FILE", default=None,
                    help="run the commands in FILE ('-': standard input) and quit;"
                         " standard input is read the same way when it is not a terminal")
    sp.add_argument("--trace", metavar="FILE", default=None,
                    help="stream every transition to FILE as it happens (JSON Lines, flushed line by line;"
                         " its last line says how the session ended); in memory the newest 5000 are kept")
    return sp


def parse_start(text: str) -> tuple[float, ...]:
    """``"0,10,-20"`` (degrees, 3 or 4 joints) -> radians, servo 0 if not given."""
    try:
        values = [float(v) for v in text.replace(" ", "").split(",") if v]
    except ValueError:
        raise ValueError(f"--start: expected 3 or 4 angles in degrees like 0,10,-20,0,"
                         f" got {text!r}") from None
    if len(values) not in (3, 4) or not all(math.isfinite(v) for v in values):
        raise ValueError(f"--start: expected 3 or 4 finite angles in degrees, got {text!r}")
    if len(values) == 3:
        values.append(0.0)
    return tuple(math.radians(v) for v in values)


#: Longest line read from a commands file: a command is a line; /dev/zero is one endless line.
MAX_COMMAND_CHARS = 10_000


def command_lines(stream: Any, what: str) -> Iterator[str]:
    """The lines of a commands file, each read no further than :data:`MAX_COMMAND_CHARS`."""
    number = 0
    while True:
        try:
            line = stream.readline(MAX_COMMAND_CHARS + 1)
        except UnicodeDecodeError as exc:
            raise CliError(f"--commands {what}: not UTF-8 text ({exc.reason})") from None
        if not line:
            return
        number += 1
        if len(line) > MAX_COMMAND_CHARS:
            raise CliError(f"--commands {what}:{number}: a line longer than {MAX_COMMAND_CHARS} characters:"
                           " not a commands file")
        yield line


def cmd_debug(args: argparse.Namespace) -> int:
    """Build the robot, then run the REPL: scripted (file or pipe) or interactive."""
    from ..debug.debugger import DEFAULT_MAX_RUN_S, Debugger
    from ..debug.shell import DebugShell
    from ..runtime.recordfile import ending_of
    from ..twin.workspace import load_arm

    max_run = DEFAULT_MAX_RUN_S if args.max_run is None else args.max_run
    if not (math.isfinite(max_run) and max_run > 0):
        raise CliError(f"--max-run must be a positive number of seconds, got {args.max_run}")
    trace_path = trace_file(args.trace) if args.trace is not None else None  # refused now if it cannot be written
    params = load_arm(getattr(args, "params", None))
    try:
        q_start = parse_start(args.start) if args.start else None
        if not args.settle >= 0 or not math.isfinite(args.settle):
            raise ValueError(f"--settle must be >= 0 seconds, got {args.settle}")
        if args.settle > max_run:
            raise ValueError(f"--settle: {args.settle:g} s is beyond {max_run:g} s of simulated time, the longest"
                             " one command runs (raise it with --max-run)")
        if args.arm != "sim" and (q_start is not None or args.settle):
            raise ValueError("--start and --settle pose the twin; an arm behind a serial link starts where it stands")
        conn = open_arm(args, params)
        dbg = Debugger.build(params, seed=args.seed, q_start=q_start, settle_s=args.settle, max_run_s=max_run,
                             game=args.game, trace_path=trace_path, arm=conn.arm if conn else None,
                             truth=conn.truth if conn else None)
    except ValueError as exc:  # a bad pose (SimError), a bad option
        raise CliError(str(exc)) from exc
    shell = DebugShell(dbg)
    try:
        status = _run_shell(args, dbg, shell, q_start)
    except BaseException as exc:  # the trace file says how the session ended, and in which command
        how, data = ending_of(exc)
        dbg.end_trace(how, **data, command=shell.command)
        raise
    finally:
        if conn is not None:
            conn.close()
    dbg.end_trace("finished", errors=shell.errors)
    if dbg.trace_failure is not None:  # the one line at the end: which file, why, what to do
        raise dbg.trace_failure
    return status


def _run_shell(args: argparse.Namespace, dbg: Debugger, shell: DebugShell, q_start: tuple[float, ...] | None) -> int:
    start = "rest pose" if q_start is None else \
        "(" + ", ".join(f"{math.degrees(v):.1f}" for v in q_start) + ") deg"
    shell.say(f"ttt-sm debugger: seed {args.seed}, "
              + (f"start {start}" if args.arm == "sim" else f"the arm behind {args.arm}")
              + (f", settled {args.settle:g} s" if args.settle else "")
              + (", a game: robot O against a simulated person X, camera read in-process" if args.game else "")
              + f"; charts {', '.join(dbg.chart_names)}. Type help.")
    if args.commands and args.commands != "-":
        try:
            with open(args.commands, encoding="utf-8") as f:
                shell.run_script(command_lines(f, args.commands))
        except (OSError, ValueError) as exc:  # ValueError: a NUL character in the name
            reason = getattr(exc, "strerror", None) or exc
            raise CliError(f"--commands: cannot read {shown_path(args.commands)}: {reason}") from exc
    elif args.commands == "-" or not sys.stdin.isatty():
        shell.run_script(command_lines(sys.stdin, "standard input"))
    else:
        shell.interact()
        return 0
    return 1 if shell.errors else 0
