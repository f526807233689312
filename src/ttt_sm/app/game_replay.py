"""A game played again from its record (``game.jsonl``): the same seed, the person's recorded moves, the same state.

:func:`replay_record` rebuilds the game from the record's first line, plays it
with the moves the person made (:class:`RecordedPerson`) up to the chart tick
of the record's last line, and compares the checkpoint it reaches with the one
recorded there (docs/reliability.md, "Records that survive").
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..params import ArmParams
from .game import GameSession
from .game_outcome import GameError, GameInterrupted
from .game_record import ENDINGS, params_digest, read_record


class RecordedPerson:
    """The person of a record: the moves it recorded, in order, then giving up if it gave up."""

    def __init__(self, events: list[dict[str, Any]]) -> None:
        self._moves: Iterator[tuple[int, int] | None] = iter(
            [(int(e["row"]), int(e["column"])) if e["event"] == "person_drew" else None
             for e in events if e["event"] in ("person_drew", "given_up")])

    def choose(self, board: str, symbol: str) -> tuple[int, int] | None:
        return next(self._moves, None)

    def tell(self, message: str) -> None:
        pass


@dataclass(frozen=True)
class ReplayCheck:
    """What :func:`replay_record` found: the recorded and the replayed checkpoint at the record's last tick."""

    ending: str
    tick: int
    recorded: dict[str, Any]
    replayed: dict[str, Any]

    @property
    def identical(self) -> bool:
        return self.recorded == self.replayed

    def describe(self) -> str:
        same = "the same state" if self.identical else "a DIFFERENT state: " + ", ".join(
            k for k in self.recorded if self.recorded.get(k) != self.replayed.get(k))
        return f"replayed to chart tick {self.tick} (the record's {self.ending} event): {same}"


def replay_record(path: Path, params: ArmParams, progress: Callable[[str], None] | None = None) -> ReplayCheck:
    """Play the recorded game again (its seed, its person's moves) to its last tick; compare the states.

    The record must begin with its ``game`` line and end with one of
    :data:`ENDINGS` carrying a checkpoint; the parameters must be those it
    was made with (their digest is compared first).
    """
    lines = read_record(path)
    if not lines or lines[0].get("event") != "game":
        raise ValueError(f"{path}: not a game record (its first line is not the game's)")
    head, last = lines[0], lines[-1]
    if last.get("event") not in ENDINGS or "state" not in last:
        raise ValueError(f"{path}: the record does not end with one of {', '.join(ENDINGS)} and a state")
    if head["params_sha256"] != params_digest(params):
        raise ValueError(f"{path}: made with other parameters (SHA-256 {head['params_sha256'][:12]}...)")
    recorded = last["state"]
    tick = int(recorded["tick"])
    session = GameSession(params, seed=int(head["seed"]), robot_symbol=head["robot_symbol"],
                          person=RecordedPerson(lines), engine=head["engine"], camera=head["camera"],
                          record_trace=False, progress=progress, time_limit_s=float(head["time_limit_s"]))
    try:
        session.stop_at_tick = tick
        try:
            session.play(int(head.get("max_moves", 25)))
        except (GameInterrupted, GameError):
            pass
        replayed = session.checkpoint()
    finally:
        session.close()
    return ReplayCheck(str(last["event"]), tick, recorded, replayed)
