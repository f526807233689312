"""Text views of the debugger's state: configurations, chart data, signals, trace, stops.

Pure functions from the debugger's data to lines of text; the REPL prints
them, a GUI can show the same strings or read the data underneath.  Values
are SI inside; angles are shown in degrees too, lengths of the tool pose in mm.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from ..app.game import GameSession
from ..runtime.listeners import TraceRecord
from .breakpoints import Breakpoint
from .debugger import Debugger
from .records import Action, DataDiff, StopReason
from .timeline import TimelineWindow

#: Columns of the timeline's bars.
GANTT_WIDTH = 60
#: Rows of the timeline's table; earlier intervals are counted, not listed.
TIMELINE_ROWS = 30

#: Unit of each robot signal, per element where they differ (see Robot.signal_values).
SIGNAL_UNITS: dict[str, str | tuple[str, ...]] = {
    "t": "s", "q_set": "rad", "q_encoder": "rad", "q_true": "rad", "offset_estimate": "rad",
    "index": "bool", "counts": "1", "current_a": "A", "tool_true": ("m", "m", "m", "rad"),
    "fr_sw": "bool", "ik_error": "",
}
#: What a signal is, for `show signals`.
SIGNAL_DOCS: dict[str, str] = {
    "t": "simulated time since power-on",
    "q_set": "joint setpoints to the controllers, q1..q4 (drives 1-3 in encoder coordinates)",
    "q_encoder": "drive angles from the encoders (relative until initialised)",
    "q_true": "simulation only: true joint angles q1..q4 (the twin's truth, not seen by the charts)",
    "offset_estimate": "encoder offsets the Encoder blocks apply",
    "index": "index switch levels, drives 1-3",
    "counts": "encoder counts since power-on, drives 1-3",
    "current_a": "measured motor currents, drives 1-3",
    "tool_true": "simulation only: true tool pose x, y, z, phi (forward kinematics of q_true)",
    "fr_sw": "slow setpoint filters selected",
    "ik_error": "why inverse kinematics failed this step, if it did",
}


def fmt_value(value: Any, unit: str) -> str:
    """A value with its unit; radians also in degrees, metres of a pose also in mm."""
    if isinstance(value, bool) or value is None or isinstance(value, str):
        return str(value)
    if isinstance(value, (int, float)):
        v = float(value)
        if unit == "rad" and math.isfinite(v):
            return f"{v:.6g} rad ({math.degrees(v):.2f} deg)"
        if unit == "m" and math.isfinite(v):
            return f"{v * 1000:.2f} mm"
        if isinstance(value, int):
            return f"{value} {unit}".rstrip() if unit not in ("1", "") else str(value)
        return f"{v:.6g} {unit}".rstrip() if unit not in ("1", "") else f"{v:.6g}"
    return repr(value)


def _vector(values: Sequence[Any], unit: str | tuple[str, ...]) -> str:
    units = unit if isinstance(unit, tuple) else (unit,) * len(values)
    if all(u == "rad" for u in units):
        rad = " ".join(f"{float(v):.4f}" for v in values)
        deg = " ".join(f"{math.degrees(float(v)):.2f}" for v in values)
        return f"[{rad}] rad  ([{deg}] deg)"
    if units == ("m", "m", "m", "rad"):
        x, y, z, phi = (float(v) for v in values)
        return (f"x {x * 1000:.2f} mm, y {y * 1000:.2f} mm, z {z * 1000:.2f} mm,"
                f" phi {math.degrees(phi):.2f} deg")
    if all(u == "bool" for u in units):
        return "[" + " ".join("1" if v else "0" for v in values) + "]"
    text = " ".join(f"{v:.4g}" if isinstance(v, float) else str(v) for v in values)
    u = units[0] if units and units[0] not in ("1", "") else ""
    return f"[{text}] {u}".rstrip()


def where_lines(dbg: Debugger) -> list[str]:
    """Time and each chart's active configuration (outermost state first)."""
    robot = dbg.robot
    lines = [f"t = {robot.t:.3f} s, step {robot.steps}, chart tick {robot.chart_ticks}"
             + (", initialised" if robot.initialised else "")]
    width = max(len(n) for n in robot.charts)
    for name, states in dbg.where().items():
        chart = robot.charts[name]
        structure = type(chart).structure()
        parents = {s.id: s.parent for s in structure.states}
        leaves = [s for s in states if not any(parents.get(o) == s for o in states)]
        paths = []
        for leaf in leaves:
            chain = [leaf]
            while parents.get(chain[0]) is not None:
                chain.insert(0, parents[chain[0]])  # type: ignore[arg-type]
            paths.append(" > ".join(chain) + f"  ({chart.ticks_in(leaf)} ticks)")
        lines.append(f"  {name:<{width}}  " + " | ".join(paths))
    if dbg.game is not None:
        lines.append(f"  {'game':<{width}}  {game_phase(dbg.game)}")
    return lines


def game_phase(game: GameSession) -> str:
    """Where the game around the charts stands, in one line."""
    moves = len(game.moves)
    head = f"robot {game.robot_symbol} vs person {game.person_symbol}, {moves} move{'s' if moves != 1 else ''}"
    driver = game.driver
    if driver is not None and driver.error is not None:
        return f"{head}; stopped: {driver.error}"
    if driver is not None and driver.done:
        return f"{head}; over ({game.outcome}), the arm is off"
    if driver is not None and driver.wait is not None:
        return f"{head}; waiting for {driver.wait.what}"
    return head


def _board_rows(board: str) -> list[str]:
    return ["    1 2 3 4 5"] + [f"  {r + 1} " + " ".join(board[5 * r:5 * r + 5]) for r in range(5)]


def game_lines(dbg: Debugger, last_events: int = 8) -> list[str]:
    """The game: who plays what, the board the robot believes and the one drawn, moves, recent events."""
    game = dbg.game
    if game is None:
        return ["  no game in this session (start the debugger with --game)"]
    person = type(game.person).__name__
    camera = "in-process (direct)" if game.camera.mode == "direct" else f"through the {game.camera.mode} link"
    lines = [f"game: robot {game.robot_symbol} ({game.engine_name} engine) vs person {game.person_symbol}"
             f" ({person}); camera read {camera}",
             f"  now: {game_phase(game)}",
             "  the robot's board (what it drew and saw)   the board as drawn"]
    for mine, drawn in zip(_board_rows(game.board), _board_rows(game.truth), strict=True):
        lines.append(f"  {mine:<41}  {drawn}")
    for m in game.moves:
        lines.append(f"  move: {m['by']} {m['symbol']} in ({m['row']}, {m['column']}) at t = {m['t']:.3f} s"
                     + (f", seen at {tuple(m['detected'])}" if m.get("detected") else ""))
    # the record's first line (seed, engine, person, camera) is what the first line above says
    events = [e for e in game.record.events if e["event"] not in ("detected", "game")][-last_events:]
    for e in events:
        rest = str(e["text"]) if "text" in e else \
            ", ".join(f"{k} {v}" for k, v in e.items() if k not in ("t", "tick", "event", "think_ms"))
        lines.append(f"  t = {e['t']:.3f} s  {e['event']}" + (f": {rest}" if rest else ""))
    return lines


def data_lines(dbg: Debugger, chart: str) -> list[str]:
    """The chart's declared data: kind, name, value with unit, meaning."""
    c = dbg.chart(chart)
    decls = c.declarations()
    width = max(len(d.name) for d in decls) if decls else 0
    values = c.snapshot()
    forced = {n for (ch, n) in dbg.forced if ch == chart}
    lines = [f"{chart} data at chart tick {c.tick_count}:"]
    for d in decls:
        mark = " (forced)" if d.name in forced else ""
        lines.append(f"  {d.kind:<6} {d.name:<{width}}  {fmt_value(values[d.name], d.unit)}{mark}"
                     f"  -- {d.doc}")
    return lines


def diff_lines(diff: DataDiff | None, chart: str | None = None) -> list[str]:
    """The chart data changed by the last chart tick (and by what you set since), old -> new."""
    where = chart or "chart"
    if diff is None:
        return [f"  no chart tick has run yet: no {where} data changed"]
    head = f"{chart or 'Chart'} data changed since just before chart tick {diff.tick} (before -> now):"
    if not diff.changes:
        return [head, "  (nothing changed)"]
    names = [c.name if chart else f"{c.chart}.{c.name}" for c in diff.changes]
    width = max(len(n) for n in names)
    lines = [head]
    for c, name in zip(diff.changes, names, strict=True):
        lines.append(f"  {c.kind:<6} {name:<{width}}  {fmt_value(c.before, c.unit)} -> {fmt_value(c.after, c.unit)}")
    return lines


def timeline_lines(dbg: Debugger, window: TimelineWindow, width: int = GANTT_WIDTH,
                   rows: int = TIMELINE_ROWS) -> list[str]:
    """A chart's timeline as a text Gantt chart (a bar per state) and a table of intervals."""
    w = window
    span = max(1, w.last - w.first)
    col_s = span * w.period_s / width
    lines = [f"{w.chart}: chart ticks {w.first}..{w.last} (chart time {w.seconds(w.first):.3f}.."
             f"{w.seconds(w.last):.3f} s), one column = {col_s:.3g} s"]
    if w.dropped:
        lines.append(f"  ({w.dropped} older intervals are no longer kept)")
    structure = type(dbg.chart(w.chart)).structure()
    parents = {s.id: s.parent for s in structure.states}

    def depth(state: str) -> int:
        d, p = 0, parents.get(state)
        while p is not None:
            d, p = d + 1, parents.get(p)
        return d

    shown = [s.id for s in structure.states if any(iv.state == s.id for iv in w.intervals)]
    labels = {s: "  " * depth(s) + s for s in shown}
    lw = max((len(x) for x in labels.values()), default=5)
    for state in shown:
        bar = [" "] * width
        for iv in w.intervals:
            if iv.state != state:
                continue
            end = iv.left if iv.left is not None else w.last
            c0 = min(width - 1, int((max(iv.entered, w.first) - w.first) * width / span))
            c1 = max(c0, math.ceil((end - w.first) * width / span) - 1)
            for c in range(max(0, c0), min(width, c1 + 1)):
                bar[c] = "#"
        lines.append(f"  {labels[state]:<{lw}} |{''.join(bar)}|")
    left_t, right_t = f"{w.seconds(w.first):.3f} s", f"{w.seconds(w.last):.3f} s"
    lines.append(f"  {'':<{lw}}  {left_t}{right_t:>{width - len(left_t)}}")
    intervals = list(w.intervals)
    if len(intervals) > rows:
        lines.append(f"  ... {len(intervals) - rows} earlier intervals in this window"
                     f" (show timeline {w.chart} SECONDS shows fewer seconds)")
        intervals = intervals[-rows:]
    sw = max((len(iv.state) for iv in intervals), default=5)
    lines.append(f"  {'state':<{sw}}  {'entered':<24}  {'left':<24}  duration")
    for iv in intervals:
        entered = f"tick {iv.entered} ({w.seconds(iv.entered):.3f} s)"
        ticks = iv.ticks(w.last)
        count = f"({ticks} tick{'s' if ticks != 1 else ''})"
        if iv.left is None:
            left, dur = "(active)", f"{ticks * w.period_s:.3f} s so far {count}"
        else:
            left, dur = f"tick {iv.left} ({w.seconds(iv.left):.3f} s)", f"{ticks * w.period_s:.3f} s {count}"
        lines.append(f"  {iv.state:<{sw}}  {entered:<24}  {left:<24}  {dur}")
    return lines


def signal_lines(dbg: Debugger) -> list[str]:
    """The robot's signals now, with units (angles also in degrees)."""
    values = dbg.signals()
    width = max(len(n) for n in values)
    lines = []
    for name, value in values.items():
        doc = SIGNAL_DOCS.get(name)
        lines.append(f"  {name:<{width}}  {signal_text(name, value)}" + (f"  -- {doc}" if doc else ""))
    return lines


def signal_text(name: str, value: Any) -> str:
    """One signal's value with its unit, as `show signals` prints it (angles also in degrees)."""
    unit = SIGNAL_UNITS.get(name, "")
    if isinstance(value, (list, tuple)):
        return _vector(value, unit)
    return fmt_value(value, unit if isinstance(unit, str) else "")


def record_line(r: TraceRecord) -> str:
    """One transition: the chart tick it was taken in, and what.

    No second clock beside the ``t`` a stop prints (the simulated time): the
    chart's own clock (the trace's ``time_s``) is in the trace file."""
    return f"  tick {r.tick}  {r.chart}: {r.source} -> {r.target}  [{r.trigger}]"


def trace_lines(records: Sequence[TraceRecord], last: int = 10) -> list[str]:
    """The last transitions of the trace, oldest first."""
    shown = list(records)[-last:] if last > 0 else []
    head = [f"  ... {len(records) - len(shown)} earlier (trace save FILE writes them all)"] \
        if len(records) > len(shown) else []
    return head + [record_line(r) for r in shown] if records else ["  (no transitions yet)"]


def stop_lines(stop: StopReason, last: int = 10) -> list[str]:
    """What a run/step/tick/next command did: the transitions it saw and why it stopped."""
    lines = []
    if stop.transitions:
        lines += trace_lines(stop.transitions, last)
    return lines + [stop.describe()]


def breakpoint_lines(bps: Sequence[Breakpoint]) -> list[str]:
    return [f"  {bp.describe()}" for bp in bps] or ["  (no breakpoints)"]


def action_lines(actions: Sequence[Action]) -> list[str]:
    return [f"  {a.describe()}" for a in actions] or ["  (no inputs set or events posted)"]
