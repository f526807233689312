"""The record of a game (``game.jsonl``): written as it happens, ended however the game ends, replayable.

:class:`GameRecord` keeps the game's events and, once :meth:`~GameRecord.attach`\\ ed
to a file, appends each one as it happens, one JSON object per line, flushed:
first the chart transitions that happened since the last line, then the
event.  A game that is interrupted (Ctrl-C, SIGTERM) or fails still leaves
every line it wrote, and its last line says how it ended:

- the first line, ``event: "game"``: what a replay needs (seed, robot symbol,
  engine, person, camera, the parameters' SHA-256, the time limit);
- events of the game (``message``, ``field_drawn``, ``person_drew``, ...),
  each with ``t`` (simulated s) and ``tick`` (chart steps since power-on);
- the last line: ``finished``, ``interrupted`` (which signal, and what the
  game was waiting for) or ``error`` (why), each with a checkpoint of the
  state at that moment (:func:`checkpoint`).

:func:`~.game_replay.replay_record` plays the game again from the record's
seed and the person's recorded moves up to the last line's tick and compares
the state with the recorded checkpoint (docs/reliability.md, "Records that
survive").
"""

from __future__ import annotations

import hashlib
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np

from ..files import RecordWriteError
from ..params import ArmParams
from ..runtime.jsonable import dumps, jsonable
from ..runtime.listeners import Trace
from ..runtime.recordfile import ENDINGS, RecordFile
from ..runtime.recordfile import read_lines as read_record
from .robot import Robot


def params_digest(params: ArmParams) -> str:
    """SHA-256 of the parameters in force (their SI values as JSON): which arm a record was made on."""
    return hashlib.sha256(dumps(asdict(params), sort_keys=True).encode()).hexdigest()


def checkpoint(robot: Robot, session: dict[str, Any]) -> dict[str, Any]:
    """The state of a game at a chart-step boundary, as a record keeps it: readable parts and one digest.

    ``session``: the game session's own state (:meth:`.game.GameSession.state`).
    Readable: the chart tick, simulated time, both boards, the moves, every
    chart's active states.  ``digest``: SHA-256 over all of that plus every
    chart's data, the session's flags and the simulated arm's ground truth
    (joint and motor angles, currents, speeds, the encoders, the duties),
    float for float; a replay that reaches the same digest reached the same state.
    """
    charts = {name: sorted(str(s) for s in c.configuration_values) for name, c in robot.charts.items()}
    state: dict[str, Any] = {"tick": robot.chart_ticks, "steps": robot.steps, "t": robot.t,
                             "board": session["board"], "truth": session["truth"], "moves": len(session["moves"]),
                             "charts": charts}
    full = {**state, "data": {name: jsonable(c.snapshot()) for name, c in robot.charts.items()},
            "session": jsonable(session)}
    sim = robot.sim
    if sim is not None:
        arrays = [sim.q_encoder, sim.duty, sim.truth.q, sim.truth.q_motor, sim.truth.current_a,
                  sim.truth.speed_motor, sim.truth.speed_load]
        full["twin"] = hashlib.sha256(b"".join(np.ascontiguousarray(a, dtype=np.float64).tobytes()
                                               for a in arrays)).hexdigest()
    state["t"] = round(robot.t, 6)
    state["digest"] = hashlib.sha256(dumps(full, sort_keys=True).encode()).hexdigest()
    return state


class GameRecord:
    """The game's events in memory and, once attached to a file, appended to it as they happen.

    ``trace``: the chart transitions to interleave (a :class:`Trace` the
    session's charts report to); each line written is flushed, so what was
    written survives whatever ends the process next.
    """

    def __init__(self, trace: Trace | None = None) -> None:
        self.events: list[dict[str, Any]] = []
        self.trace = trace
        self.path: Path | None = None
        self._sink: RecordFile | None = None
        self._failure: RecordWriteError | None = None
        self._marks: list[int] = []  # len(trace.records) when each event was added
        self._traced = 0
        self.ended: str | None = None

    @classmethod
    def open(cls, path: Path) -> GameRecord:
        """A record written to ``path`` from the start (its folder made; OSError if it cannot be written)."""
        record = cls()
        record.attach(path)
        return record

    @property
    def attached(self) -> bool:
        return self._sink is not None

    def attach(self, path: Path) -> None:
        """Write to ``path`` from now on (what was recorded before first); raises OSError if it cannot."""
        if self._sink is not None:
            if path != self.path:
                raise ValueError(f"the record is written to {self.path} already, not {path}")
            return
        self._sink = RecordFile(path)  # whole lines or none; refused if another process writes it now
        self.path = path
        for event, mark in zip(self.events, self._marks, strict=True):
            self._write_transitions(mark)
            self._write(event)
        self._write_transitions(len(self.trace.records) if self.trace is not None else 0)

    def add(self, t: float, kind: str, tick: int | None = None, **data: Any) -> dict[str, Any]:
        """Record an event at simulated time ``t`` (and chart tick ``tick``); written and flushed if attached."""
        event = {"t": round(t, 4), **({} if tick is None else {"tick": tick}), "event": kind, **data}
        self.events.append(event)
        self._marks.append(len(self.trace.records) if self.trace is not None else 0)
        if self._sink is not None:
            self._write_transitions(self._marks[-1])
            self._write(event)
        if kind in ENDINGS:
            self.ended = kind
        return event

    def close(self) -> None:
        """Write what is left of the trace and close the file."""
        if self._sink is not None:
            self._write_transitions(len(self.trace.records) if self.trace is not None else 0)
            self._sink.close()
            self._failure = self._sink.failed
            self._sink = None

    @property
    def failed(self) -> RecordWriteError | None:
        """Why the file stopped before the game's end (the disk full: it holds whole lines only), or None."""
        return self._sink.failed if self._sink is not None else self._failure

    def _write(self, event: dict[str, Any]) -> None:
        assert self._sink is not None
        self._sink.write(dumps(event) + "\n")  # after a failed write: nothing (the file ended there)

    def _write_transitions(self, upto: int) -> None:
        if self.trace is None or self._sink is None:
            return
        records = self.trace.records
        lines = "".join(dumps({"event": "transition", **asdict(rec)}) + "\n" for rec in records[self._traced:upto])
        self._traced = max(self._traced, upto)
        self._sink.write(lines)


__all__ = ["ENDINGS", "GameRecord", "params_digest", "read_record"]
