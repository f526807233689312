"""Where a debugging session has been: fingerprints to check a replay against, and how far it went.

A replay (:meth:`~.debugger.Debugger.replay`) goes back to any control step up
to the furthest one the session has run to, and says whether it arrived in
exactly the state the session saw there: :class:`History` keeps a
:func:`~.replay.fingerprint` after every command, in bounded memory.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

from ..app.robot import Robot
from .replay import differences, fingerprint

#: At most this many fingerprints are kept to check replays against (each a few kB): past
#: it every other old one is dropped, so a session that runs for hours (a GUI calls the
#: debugger 30 times a second) holds them spread over its whole run in bounded memory.
MAX_FINGERPRINTS = 512


class History:
    """The fingerprints of where the session has been, and the furthest control step it ran to.

    ``robot``: the robot now (a replay replaces it); ``forced``: the inputs
    forced now (a fingerprint includes them).
    """

    def __init__(self, robot: Callable[[], Robot], forced: Mapping[tuple[str, str], Any]) -> None:
        self._robot = robot
        self._forced = forced
        self._fingerprints: dict[int, dict[str, Any]] = {}
        #: The furthest control step the session has run to: a replay goes anywhere up to it.
        self.furthest_steps = 0

    def fingerprint(self) -> dict[str, Any]:
        """Everything a replay must reproduce, now (see :func:`.replay.fingerprint`)."""
        return fingerprint(self._robot(), self._forced)

    def restart(self) -> None:
        """A run from power-on (a new debugger, a start over): it has been where the robot stands only."""
        self._fingerprints = {}
        self.furthest_steps = self._robot().steps
        self.remember()

    def remember(self) -> None:
        """Keep the fingerprint of now (after a command ran or an input was applied)."""
        robot = self._robot()
        if robot.sim is None:  # no twin, nothing a replay could compare
            return
        kept = self._fingerprints
        kept[robot.steps] = self.fingerprint()
        if len(kept) > MAX_FINGERPRINTS:
            # Thin the older half (every other one), keep the recent half whole.
            steps = sorted(kept)
            old = steps[:len(steps) // 2]
            for s in old[1::2]:
                del kept[s]
        self.furthest_steps = max(self.furthest_steps, robot.steps)

    def forget_after(self, steps: int) -> None:
        """The future after control step ``steps`` is no longer what the session saw (an input changed it)."""
        self._fingerprints = {k: v for k, v in self._fingerprints.items() if k <= steps}

    def arrived(self, steps: int, dropped: bool) -> tuple[bool | None, tuple[str, ...]]:
        """A replay reached control step ``steps``: whether the state is the one seen there before (None: the
        session had not been there) and what differs.  ``dropped``: inputs after it were dropped, so the
        fingerprints after it are forgotten."""
        now = self.fingerprint()
        before = self._fingerprints.get(steps)
        diffs = tuple(differences(before, now)) if before is not None else ()
        if dropped:
            self.forget_after(steps)
        self._fingerprints[steps] = now if before is None else before
        return (None if before is None else not diffs), diffs

    @property
    def furthest_tick(self) -> int:
        """The furthest chart tick the session has run to: a replay takes any tick up to it."""
        divider = self._robot().params.control.chart_divider
        return (self.furthest_steps + divider - 1) // divider

    def steps_of_tick(self, tick: int) -> int:
        """The control step count right after chart tick ``tick`` (0: power-on)."""
        return 0 if tick == 0 else (tick - 1) * self._robot().params.control.chart_divider + 1
