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
from typing import IO, Any

from ..app.robot import RobotError
from ..runtime import UnknownDataError, UnknownEventError
from ..runtime.jsonable import dumps
from . import views
from .debugger import Debugger
from .errors import DebugError
from .expr import Condition, parse_condition

PROMPT = "(ttt-sm) "
#: What a command may raise for a request it cannot take: printed as one ``error:`` line.
USER_ERRORS = (DebugError, RobotError, UnknownEventError, UnknownDataError)
_REPEATABLE = ("step", "tick", "next")
_SHOW = ("charts", "data", "signals", "trace", "breakpoints", "inputs", "snapshot", "timeline", "game")


def _count(arg: str, what: str, default: int = 1) -> int:
    if not arg.strip():
        return default
    try:
        n = int(arg)
    except ValueError:
        raise DebugError(f"{what}: expected a whole number, got {arg.strip()!r}") from None
    return n


def _seconds(arg: str, what: str, default: float) -> float:
    if not arg.strip():
        return default
    try:
        return float(arg)
    except ValueError:
        raise DebugError(f"{what}: expected simulated seconds, got {arg.strip()!r}") from None


def _duration(arg: str, what: str, default: float, tick_s: float) -> float:
    """Simulated seconds from ``0.5``, ``0.5s``, ``500ms`` or ``250 ticks`` (chart ticks of ``tick_s``)."""
    text = arg.strip().lower()
    if not text:
        return default
    number, factor = text, 1.0
    for suffix, scale in (("ticks", tick_s), ("tick", tick_s), ("ms", 1e-3), ("s", 1.0)):
        if text.endswith(suffix):
            number, factor = text[:-len(suffix)].strip(), scale
            break
    try:
        return float(number) * factor
    except ValueError:
        raise DebugError(f"{what}: expected simulated time, e.g. {what} 0.5 (seconds), {what} 0.5s,"
                         f" {what} 500ms or {what} 250 ticks; got {arg.strip()!r}") from None


def _chart_dot(arg: str, what: str) -> tuple[str, str]:
    chart, dot, name = arg.partition(".")
    if not dot or not chart or not name or " " in name:
        raise DebugError(f"{what}: expected Chart.input, got {arg!r}")
    return chart, name


class DebugShell(cmd.Cmd):
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
        return float(control.chart_divider * control.dt)

    def stopped(self, lines: Iterable[str]) -> None:
        """What a command that moved the robot says: its lines, then the ``display`` expressions."""
        self.say(*lines, *self.display_lines())

    def do_run(self, arg: str) -> None:
        """run [TIME]: run until a breakpoint hits or TIME passes (default 60 s); Ctrl-C pauses.
        TIME is simulated: 0.5 or 0.5s (seconds), 500ms, 250 ticks (chart ticks, 2 ms each);
        the run stops between two control steps."""
        self.stopped(views.stop_lines(self.dbg.run(_duration(arg, "run", 60.0, self._tick_s()))))

    def do_continue(self, arg: str) -> None:
        """continue [TIME]: the same as run: on from here until a breakpoint (default 60 s)."""
        self.do_run(arg)

    def do_step(self, arg: str) -> None:
        """step [N]: run N control steps (default 1; a chart tick starts every second one);
        step -N: go N control steps back (a replay, as back)."""
        n = _count(arg, "step")
        if n < 0:
            self.stopped([self.dbg.step_back(-n).describe()])
            return
        self.stopped(views.stop_lines(self.dbg.step(n)))

    def do_back(self, arg: str) -> None:
        """back [N]: go N chart ticks back (default 1): a replay to right after that tick.
        The inputs you gave later are kept and applied again when you run forward."""
        self.stopped([self.dbg.back(_count(arg, "back")).describe()])

    def do_tick(self, arg: str) -> None:
        """tick [N]: run up to and through the next N chart ticks (default 1)."""
        self.stopped(views.stop_lines(self.dbg.tick(_count(arg, "tick"))))

    def do_next(self, arg: str) -> None:
        """next [TIME]: run until any chart takes a transition (at most TIME, default 10 s; units as run)."""
        self.stopped(views.stop_lines(self.dbg.next(_duration(arg, "next", 10.0, self._tick_s()))))

    # -- display ------------------------------------------------------------------

    def do_display(self, arg: str) -> None:
        """display EXPR: show EXPR after every stop (run, step, tick, next, back, replay);
        display alone shows them now.  EXPR as in break when: DriveInit1.pos_out, q_true[1],
        DriveInit1.pos_out - DriveInit1.pos_Encoder, DriveInit1.index and not DriveInit1.stop.
        watch is the same command; undisplay N removes one."""
        if not arg.strip():
            self.say(*(self.display_lines() or ["  (nothing displayed: display EXPR adds one)"]))
            return
        condition = parse_condition(arg, self.dbg.names)
        n = self._next_display
        self._next_display += 1
        self.displays[n] = condition
        self.say(*self._display_line(n, condition))

    do_watch = do_display

    def do_undisplay(self, arg: str) -> None:
        """undisplay N... | undisplay all: stop showing display expressions."""
        if arg.strip() == "all":
            self.displays.clear()
            self.say("nothing displayed now")
            return
        for n in self._ids(arg, "undisplay"):
            if self.displays.pop(n, None) is None:
                raise DebugError(f"undisplay: no display {n}; displays: "
                                 f"{', '.join(map(str, self.displays)) or 'none'}")
            self.say(f"display {n} removed")

    def display_lines(self) -> list[str]:
        return [line for n, c in self.displays.items() for line in self._display_line(n, c)]

    def _display_line(self, n: int, condition: Condition) -> list[str]:
        try:
            value = condition.value()
        except DebugError as exc:
            return [f"  {n}: {condition.text} = ? ({exc})"]
        chart, dot, name = condition.text.partition(".")
        unit = ""
        if dot and chart in self.dbg.robot.charts and name.isidentifier():
            unit = self.dbg.datum_decl(chart, name).unit
        return [f"  {n}: {condition.text} = {views.fmt_value(value, unit)}"]

    # -- breakpoints --------------------------------------------------------------

    def do_break(self, arg: str) -> None:
        """break KIND SPEC: add a breakpoint; break alone lists them.
        break enter Chart.state | break exit Chart.state
        break transition Chart source->target   (* for any state)
        break event Chart.event                 (tick: any tick transition)
        break when CONDITION   e.g. DriveInit1.pos_Encoder > 1.0 and not DriveInit1.index
                               (hits when it becomes true; signals: q_true[1], t, ...;
                                numbers may carry deg, mm, ms)"""
        if not arg.strip():
            self.say(*views.breakpoint_lines(self.dbg.breakpoints))
            return
        bp = self.dbg.add_breakpoint(arg)
        self.say(f"breakpoint {bp.id}: {bp.spec}")

    def _ids(self, arg: str, what: str) -> list[int]:
        try:
            ids = [int(a) for a in arg.split()]
        except ValueError:
            raise DebugError(f"{what}: expected breakpoint numbers, got {arg.strip()!r}") from None
        if not ids:
            raise DebugError(f"{what}: which breakpoint? (break lists them)")
        return ids

    def do_delete(self, arg: str) -> None:
        """delete ID... | delete all: remove breakpoints."""
        if arg.strip() == "all":
            self.dbg.delete(None)
            self.say("all breakpoints deleted")
            return
        for bp_id in self._ids(arg, "delete"):
            self.dbg.delete(bp_id)
            self.say(f"breakpoint {bp_id} deleted")

    def do_enable(self, arg: str) -> None:
        """enable ID...: enable breakpoints."""
        for bp_id in self._ids(arg, "enable"):
            self.dbg.enable(bp_id)
            self.say(f"breakpoint {bp_id} enabled")

    def do_disable(self, arg: str) -> None:
        """disable ID...: disable breakpoints (kept, not checked)."""
        for bp_id in self._ids(arg, "disable"):
            self.dbg.disable(bp_id)
            self.say(f"breakpoint {bp_id} disabled")

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
            seconds = _seconds(words[1], "show timeline", 0.0) if len(words) == 2 else None
            self.say(*views.timeline_lines(self.dbg, self.dbg.timeline(words[0], seconds)))
        elif what == "game":
            self.say(*views.game_lines(self.dbg))
        elif what == "signals":
            self.say(*views.signal_lines(self.dbg))
        elif what == "trace":
            self.say(*views.trace_lines(self.dbg.trace.records, _count(rest, "show trace", 10)))
        elif what == "breakpoints":
            self.say(*views.breakpoint_lines(self.dbg.breakpoints))
        elif what == "inputs":
            self.say(*views.action_lines(self.dbg.actions),
                     *(f"  {a.describe()} (ahead: applied when the run gets there)" for a in self.dbg.inputs.ahead))
        elif what == "snapshot":
            self.say(dumps(self.dbg.robot.snapshot(), sort_keys=True))
        else:
            raise DebugError(f"show what? {what!r} is not one of: {', '.join(_SHOW)}" if what
                             else f"show what? one of: {', '.join(_SHOW)}")

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
        self.say(*views.trace_lines(self.dbg.trace.records, _count(arg, "trace", 10)))

    def do_diagram(self, arg: str) -> None:
        """diagram CHART [FILE]: the chart's diagram, active states highlighted
        (.svg, .png, .dot, .md; default out/debug/CHART-tickN.svg)."""
        words = arg.split()
        if not 1 <= len(words) <= 2:
            raise DebugError(f"diagram: expected CHART [FILE]; charts: {', '.join(self.dbg.chart_names)}")
        path = self.dbg.diagram(words[0], words[1] if len(words) == 2 else None)
        self.say(f"{words[0]} diagram written to {path}")

    # -- changing things ------------------------------------------------------------

    def _set(self, arg: str, force: bool) -> None:
        what = "force" if force else "set"
        words = arg.split()
        if len(words) != 2:
            raise DebugError(f"{what}: expected Chart.input VALUE, e.g. {what} DriveInit1.stop 1")
        chart, name = _chart_dot(words[0], what)
        value = self.dbg.set_input(chart, name, words[1], force=force)
        decl = self.dbg.datum_decl(chart, name)
        note = " (forced until release)" if force else ""
        self.say(f"{chart}.{name} = {views.fmt_value(value, decl.unit)}{note}")

    def do_set(self, arg: str) -> None:
        """set Chart.input VALUE: set a chart input (1/0 for flags; numbers may carry deg, mm).
        Inputs the wiring feeds every chart step (index, pos_Encoder, ...) are overwritten
        at the next one: force them instead."""
        self._set(arg, False)

    def do_force(self, arg: str) -> None:
        """force Chart.input VALUE: set an input and keep it against the wiring until release."""
        self._set(arg, True)

    def do_release(self, arg: str) -> None:
        """release [Chart.input]: stop forcing one input, or all of them."""
        if arg.strip():
            chart, name = _chart_dot(arg.strip(), "release")
            released = self.dbg.release(chart, name)
        else:
            released = self.dbg.release()
        names = ", ".join(f"{c}.{n}" for c, n in released)
        self.say(f"released {names}" if released else "nothing was forced")

    def do_post(self, arg: str) -> None:
        """post CHART EVENT [NAME=VALUE ...]: post an event, handled at the chart's next tick."""
        try:
            words = shlex.split(arg)
        except ValueError as exc:  # an unclosed quote
            raise DebugError(f"post: {exc} in {arg!r}") from None
        if len(words) < 2:
            raise DebugError("post: expected CHART EVENT, e.g. post Homing stop")
        data: dict[str, Any] = {}
        for item in words[2:]:
            key, eq, text = item.partition("=")
            if not eq or not key.isidentifier():
                raise DebugError(f"post: event data must be NAME=VALUE, got {item!r}")
            try:
                data[key] = float(text)
            except ValueError:
                data[key] = text
        self.dbg.post(words[0], words[1], **data)
        self.say(f"posted {words[1]} to {words[0]}; handled at its next tick")

    def do_replay(self, arg: str) -> None:
        """replay TICK | replay step N [--drop]: rebuild the robot and run it again to chart tick TICK.
        The robot is rebuilt from its parameters, seed and start pose; the inputs you set,
        forced and posted up to there are re-applied at the same control steps, and the state
        reached is compared with the one the session saw there before: configurations, chart
        data and twin state, float for float.  The inputs you gave after it are kept: a run
        forward applies them again at their steps (show inputs lists them as ahead);
        --drop drops them instead."""
        words = arg.split()
        drop = "--drop" in words
        words = [w for w in words if w != "--drop"]
        if not words:
            raise DebugError("replay: to which chart tick? e.g. replay 1510 (or replay step 3021)")
        if words[0] == "step":
            if len(words) != 2:
                raise DebugError("replay step: which control step? e.g. replay step 3021")
            self.stopped([self.dbg.replay_to_step(_count(words[1], "replay step"), drop=drop).describe()])
            return
        if len(words) != 1:
            raise DebugError(f"replay: expected TICK [--drop], got {arg.strip()!r}")
        self.stopped([self.dbg.replay(_count(words[0], "replay"), drop=drop).describe()])

    # -- completion (Tab, on a terminal) ---------------------------------------------------

    def _states(self) -> list[str]:
        index = self.dbg.watch.index
        return [f"{c}.{s}" for c in self.dbg.chart_names for s in index.states(c)]

    def _data(self, inputs_only: bool = False) -> list[str]:
        out = []
        for name, chart in self.dbg.robot.charts.items():
            out += [f"{name}.{d.name}" for d in chart.declarations() if not inputs_only or d.kind == "input"]
        return out

    def _events(self) -> list[str]:
        index = self.dbg.watch.index
        return [f"{c}.{e}" for c in self.dbg.chart_names for e in index.events(c)]

    @staticmethod
    def _matching(text: str, names: Iterable[str]) -> list[str]:
        return [n for n in names if n.startswith(text)]

    def complete_break(self, text: str, line: str, begidx: int, endidx: int) -> list[str]:
        """Tab: the kind, then Chart.state (enter, exit), Chart.event, Chart.datum (when), a state (transition)."""
        words = line[:begidx].split()
        if len(words) <= 1:
            return self._matching(text, ("enter", "exit", "transition", "event", "when"))
        kind = words[1]
        if kind in ("enter", "exit"):
            return self._matching(text, self._states())
        if kind == "event":
            return self._matching(text, self._events())
        if kind == "when":
            return self._matching(text, self._data())
        if kind == "transition":
            if len(words) == 2:
                return self._matching(text, self.dbg.chart_names)
            return self._matching(text, [*self.dbg.watch.index.states(words[2]), "*"]) \
                if words[2] in self.dbg.chart_names else []
        return []

    def complete_display(self, text: str, line: str, begidx: int, endidx: int) -> list[str]:
        return self._matching(text, self._data())

    complete_watch = complete_display

    def complete_set(self, text: str, line: str, begidx: int, endidx: int) -> list[str]:
        return self._matching(text, self._data(inputs_only=True)) if len(line[:begidx].split()) <= 1 else []

    complete_force = complete_release = complete_set

    def complete_show(self, text: str, line: str, begidx: int, endidx: int) -> list[str]:
        words = line[:begidx].split()
        if len(words) <= 1:
            return self._matching(text, _SHOW)
        return self._matching(text, self.dbg.chart_names) if words[1] in ("data", "timeline") else []

    def complete_diagram(self, text: str, line: str, begidx: int, endidx: int) -> list[str]:
        return self._matching(text, self.dbg.chart_names) if len(line[:begidx].split()) <= 1 else []

    complete_post = complete_diagram

    # -- leaving ----------------------------------------------------------------------

    def do_quit(self, arg: str) -> bool:
        """quit: leave the debugger (also exit, Ctrl-D)."""
        return True

    do_exit = do_quit

    def do_EOF(self, arg: str) -> bool:  # noqa: N802  (cmd's name for end of input)
        self.say("")
        return True
