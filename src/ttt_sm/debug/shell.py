"""The ``ttt-sm debug`` REPL: a :mod:`cmd` shell over :class:`~.debugger.Debugger`.

Interactive on a terminal (line editing, Enter repeats ``step``/``tick``/
``next``, Ctrl-C pauses a run), or scripted: commands read from a file or a
pipe are echoed after the prompt so the output reads as a transcript, and the
end of the input quits.  A bad command prints one ``error: ...`` line and the
session goes on.
"""

from __future__ import annotations

import cmd
import inspect
import os
import shlex
import sys
import traceback
from collections.abc import Iterable
from typing import IO

from ..app.robot import RobotError
from ..runtime import UnknownDataError, UnknownEventError
from ..runtime.jsonable import dumps
from . import views
from .debugger import Debugger
from .errors import DebugError
from .expr import Condition
from .shell_args import parse_count, parse_duration, parse_seconds
from .shell_complete import SHOW, Completion
from .shell_inputs import InputCommands
from .shell_stops import StopCommands

PROMPT = "(ttt-sm) "
#: What a command may raise for a request it cannot take: printed as one ``error:`` line.
USER_ERRORS = (DebugError, RobotError, UnknownEventError, UnknownDataError)
_REPEATABLE = ("step", "tick", "next")


class DebugShell(StopCommands, InputCommands, Completion, cmd.Cmd):
    """The debugger's commands; ``help COMMAND`` prints a command's docstring."""

    intro = ""
    prompt = PROMPT
    doc_header = "commands (help COMMAND for details):"

    def __init__(self, debugger: Debugger, stdout: IO[str] | None = None) -> None:
        super().__init__(stdout=stdout if stdout is not None else sys.stdout)
        self.dbg = debugger
        self.errors = 0
        self.scripted = False
        self._progress_shown = False
        #: The command running now (None between commands): where an interrupted session stood.
        self.command: str | None = None
        self._trace_failure_told = False
        #: ``display``: expressions shown after each stop, by number.
        self.displays: dict[int, Condition] = {}
        self._next_display = 1

    # -- plumbing -----------------------------------------------------------------

    def say(self, *lines: str) -> None:
        if self._progress_shown:  # a run's progress line is replaced by what comes next
            self.stdout.write("\r\033[K")
            self._progress_shown = False
        for line in lines:
            self.stdout.write(line + "\n")
        self.stdout.flush()

    def error(self, message: str) -> None:
        self.errors += 1
        self.say(f"error: {message}")

    def onecmd(self, line: str) -> bool:
        line = line.split("#", 1)[0].strip()
        if not line:
            return self.emptyline() if not self.scripted else False
        self.command = line  # still set if a signal ends the session in it
        done = False
        try:
            done = bool(super().onecmd(line))
        except USER_ERRORS as exc:
            self.error(str(exc))
        except Exception as exc:  # a bug in a chart action (or of ttt_sm): say it in words, keep the session
            said = " ".join(str(exc).split()) or "no message"
            self.error(f"{line.split()[0]}: it failed inside ({said}): a chart's action raised, or a bug of ttt_sm"
                       " (TTT_SM_TRACEBACK=1 shows where); the session goes on")
            if os.environ.get("TTT_SM_TRACEBACK"):
                traceback.print_exc()
        self.command = None
        failure = self.dbg.trace_failure
        if failure is not None and not self._trace_failure_told:  # once: the trace file stopped (a full disk)
            self._trace_failure_told = True
            self.error(f"the trace file {failure.filename} stopped: {failure.strerror}; the session goes on,"
                       " the newest transitions in memory (trace save FILE elsewhere keeps them)")
        return done

    def emptyline(self) -> bool:
        if self.lastcmd.split(" ", 1)[0] in _REPEATABLE:
            return bool(self.onecmd(self.lastcmd))
        return False

    def default(self, line: str) -> None:
        word = line.split()[0]
        self.error(f"unknown command {word!r}; commands: {', '.join(self.commands())}")

    def get_names(self) -> list[str]:
        return [n for n in super().get_names() if n != "do_EOF"]

    def commands(self) -> list[str]:
        return sorted(n[3:] for n in self.get_names() if n.startswith("do_"))

    def do_help(self, arg: str) -> None:
        """help [COMMAND]: the commands, one line each, or one command in full."""
        if arg.strip():
            func = getattr(self, "do_" + arg.strip(), None)
            if func is None or arg.strip() == "EOF":
                raise DebugError(f"no command {arg.strip()!r}; commands: {', '.join(self.commands())}")
            self.say(inspect.cleandoc(func.__doc__ or arg))
            return
        self.say("commands (help COMMAND for details):")
        seen: set[object] = set()
        for name in self.commands():
            func = getattr(self, "do_" + name)
            if func.__func__ in seen:
                continue
            seen.add(func.__func__)
            first = inspect.cleandoc(func.__doc__ or name).splitlines()[0]
            self.say(f"  {first}")

    def run_script(self, lines: Iterable[str]) -> None:
        """Run commands from a file or a pipe, echoed after the prompt; the end quits."""
        self.scripted = True
        for raw in lines:
            line = raw.rstrip("\r\n")
            self.say(PROMPT + line)
            if line.split("#", 1)[0].strip() == "EOF":  # cmd's word for the end of typed input: not a command here
                self.default(line)
                continue
            if self.onecmd(line):
                return
        self.say("(end of commands)")

    def show_progress(self, t: float, t_end: float) -> None:
        """A long run's progress, on one line that the next output replaces (on a terminal)."""
        self.stdout.write(f"\r  t = {t:.0f} s of at most {t_end:.0f} s simulated (Ctrl-C pauses)")
        self.stdout.flush()
        self._progress_shown = True

    def interact(self) -> None:
        """Read commands from the terminal until ``quit`` or Ctrl-D; Ctrl-C at the prompt is ignored.

        A long run shows its progress every few simulated seconds.
        """
        self.dbg.progress = self.show_progress
        while True:
            try:
                self.cmdloop()
                return
            except KeyboardInterrupt:
                self.say("", "(Ctrl-C: type quit to leave; Ctrl-C during run pauses it)")
                self.intro = ""

    # -- running ------------------------------------------------------------------

    def _tick_s(self) -> float:
        control = self.dbg.robot.params.control
        return float(control.chart_dt)

    def stopped(self, lines: Iterable[str]) -> None:
        """What a command that moved the robot says: its lines, then the ``display`` expressions."""
        self.say(*lines, *self.display_lines())

    def do_run(self, arg: str) -> None:
        """run [TIME]: run until a breakpoint hits or TIME passes (default 60 s); Ctrl-C pauses.
        TIME is simulated: 0.5 or 0.5s (seconds), 500ms, 250 ticks (chart ticks, 2 ms each);
        the run stops between two control steps."""
        self.stopped(views.stop_lines(self.dbg.run(parse_duration(arg, "run", 60.0, self._tick_s()))))

    def do_continue(self, arg: str) -> None:
        """continue [TIME]: the same as run: on from here until a breakpoint (default 60 s)."""
        self.do_run(arg)

    def do_step(self, arg: str) -> None:
        """step [N]: run N control steps (default 1; a chart tick starts every second one);
        step -N: go N control steps back (a replay, as back)."""
        n = parse_count(arg, "step")
        if n < 0:
            self.stopped([self.dbg.step_back(-n).describe()])
            return
        self.stopped(views.stop_lines(self.dbg.step(n)))

    def do_back(self, arg: str) -> None:
        """back [N]: go N chart ticks back (default 1): a replay to right after that tick.
        The inputs you gave later are kept and applied again when you run forward."""
        self.stopped([self.dbg.back(parse_count(arg, "back")).describe()])

    def do_tick(self, arg: str) -> None:
        """tick [N]: run up to and through the next N chart ticks (default 1)."""
        self.stopped(views.stop_lines(self.dbg.tick(parse_count(arg, "tick"))))

    def do_next(self, arg: str) -> None:
        """next [TIME]: run until any chart takes a transition (at most TIME, default 10 s; units as run)."""
        self.stopped(views.stop_lines(self.dbg.next(parse_duration(arg, "next", 10.0, self._tick_s()))))

    # -- looking ------------------------------------------------------------------

    def do_where(self, arg: str) -> None:
        """where: time and the active configuration of every chart (same as show charts)."""
        self.say(*views.where_lines(self.dbg))

    def do_show(self, arg: str) -> None:
        """show charts | data [CHART] [--diff] | timeline CHART [SECONDS] | signals | trace [N]
        | game | breakpoints | inputs | snapshot
        charts: active configurations; data: declared data with units (--diff: only what
        changed since just before the last chart tick, before -> now); timeline: when each
        state was entered and left, as bars and a table (the last SECONDS of chart time,
        default all kept); signals: time, setpoints, encoders, true angles, index switches,
        currents, tool pose; game: the board, the moves and where the game stands (--game);
        inputs: what you set, forced and posted (replay re-applies them);
        snapshot: everything as one JSON document."""
        what, _, rest = arg.strip().partition(" ")
        rest = rest.strip()
        if what == "charts":
            self.do_where("")
        elif what == "data":
            words = rest.split()
            diff = "--diff" in words
            words = [w for w in words if w != "--diff"]
            if len(words) > 1:
                raise DebugError(f"show data: expected [CHART] [--diff], got {rest!r}")
            if diff:
                chart = words[0] if words else None
                self.say(*views.diff_lines(self.dbg.data_diff(chart), chart))
                return
            for chart in (words or self.dbg.chart_names):
                self.say(*views.data_lines(self.dbg, chart))
        elif what == "timeline":
            words = rest.split()
            if not 1 <= len(words) <= 2:
                raise DebugError(f"show timeline: expected CHART [SECONDS]; charts: {', '.join(self.dbg.chart_names)}")
            seconds = parse_seconds(words[1], "show timeline", 0.0) if len(words) == 2 else None
            self.say(*views.timeline_lines(self.dbg, self.dbg.timeline(words[0], seconds)))
        elif what == "game":
            self.say(*views.game_lines(self.dbg))
        elif what == "signals":
            self.say(*views.signal_lines(self.dbg))
        elif what == "trace":
            self.say(*views.trace_lines(self.dbg.trace.records, parse_count(rest, "show trace", 10)))
        elif what == "breakpoints":
            self.say(*views.breakpoint_lines(self.dbg.breakpoints))
        elif what == "inputs":
            self.say(*views.action_lines(self.dbg.actions),
                     *(f"  {a.describe()} (ahead: applied when the run gets there)" for a in self.dbg.inputs.ahead))
        elif what == "snapshot":
            self.say(dumps(self.dbg.robot.snapshot(), sort_keys=True))
        else:
            raise DebugError(f"show what? {what!r} is not one of: {', '.join(SHOW)}" if what
                             else f"show what? one of: {', '.join(SHOW)}")

    def do_trace(self, arg: str) -> None:
        """trace [N]: the last N transitions (default 10); trace save FILE: all kept, as JSON Lines."""
        words = arg.split()
        if words and words[0] == "save":
            try:
                words = shlex.split(arg)  # a quoted name: '' is an empty name, not a file called ''
            except ValueError as exc:
                raise DebugError(f"trace save: {exc} in {arg!r}") from None
            if len(words) != 2:
                raise DebugError("trace save: expected one file name, e.g. trace save out/trace.jsonl")
            path = self.dbg.save_trace(words[1])
            trace = self.dbg.trace
            older = f" (the newest; {trace.dropped} older ones are not kept in memory" + (
                f", the trace file {self.dbg.trace_file.path} has them all)" if self.dbg.trace_file is not None
                else ": start the debugger with --trace FILE to keep them all)") if trace.dropped else ""
            self.say(f"{len(trace.records)} transitions written to {path}{older}")
            return
        self.say(*views.trace_lines(self.dbg.trace.records, parse_count(arg, "trace", 10)))

    def do_diagram(self, arg: str) -> None:
        """diagram CHART [FILE]: the chart's diagram, active states highlighted
        (.svg, .png, .dot, .md; default out/debug/CHART-tickN.svg)."""
        words = arg.split()
        if not 1 <= len(words) <= 2:
            raise DebugError(f"diagram: expected CHART [FILE]; charts: {', '.join(self.dbg.chart_names)}")
        path = self.dbg.diagram(words[0], words[1] if len(words) == 2 else None)
        self.say(f"{words[0]} diagram written to {path}")

    # -- leaving ----------------------------------------------------------------------

    def do_quit(self, arg: str) -> bool:
        """quit: leave the debugger (also exit, Ctrl-D)."""
        return True

    do_exit = do_quit

    def do_EOF(self, arg: str) -> bool:  # noqa: N802  (cmd's name for end of input)
        self.say("")
        return True
