"""Clocks behind one interface (:class:`Clock`): virtual time, or wall-clock pacing.

The scheduler asks a clock to wait for the start of each control period.  A
:class:`VirtualClock` never waits (tests, scenarios, the default `play`: as
fast as the machine goes).  A :class:`WallClock` paces the loop to real time
(real hardware) and counts the periods it could not keep, never hiding an
overrun.  A :class:`PacedClock` paces a simulation at a speed that can change
while it runs (x0.1 to x10, or as fast as it goes), as a live GUI needs.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np


class Clock(Protocol):
    """What the scheduler asks of a clock."""

    @property
    def paced(self) -> bool:
        """Whether :meth:`wait_period` may wait (the scheduler then calls it every control step)."""

    def start(self) -> None:
        """Begin a run: period 0 is due now."""

    def wait_period(self, k: int) -> None:
        """Wait for the start of control period `k` of the run."""


@dataclass(frozen=True)
class PacingStats:
    """What a wall clock saw: how late each period started, and the misses."""

    periods: int
    deadline_misses: int
    lateness_p50_us: float
    lateness_p99_us: float
    lateness_max_us: float


class VirtualClock:
    """Simulated time only: `wait_period` returns at once."""

    paced = False

    def start(self) -> None:
        """Begin a run (nothing to do on virtual time)."""

    def wait_period(self, k: int) -> None:
        """Wait for the start of control period `k` (no wait on virtual time)."""


@dataclass
class WallClock:
    """Paces control periods of `period_s` to the wall clock.

    Sleeps until shortly before each period starts, then spins for the last
    `spin_s` (the OS sleep alone is too coarse at 1 kHz).  Period `k` is due at
    ``start + k * period_s``; its lateness is how long after that it began.  A
    deadline miss is a period that began a whole period late or more, so its
    step could not finish in its own slot.  Late periods are not skipped: the
    loop catches up, as a real-time loop with a bounded overrun would.
    """

    period_s: float
    spin_s: float = 0.0002
    paced = True
    _t0: float = 0.0
    _lateness_ns: list[int] = field(default_factory=list)

    def start(self) -> None:
        """Begin a run: period 0 is due now."""
        self._t0 = time.perf_counter()
        self._lateness_ns.clear()

    def wait_period(self, k: int) -> None:
        """Block until period `k` is due; record how late it actually starts."""
        due = self._t0 + k * self.period_s
        remaining = due - time.perf_counter()
        if remaining > self.spin_s:
            time.sleep(remaining - self.spin_s)
        while time.perf_counter() < due:
            pass
        self._lateness_ns.append(int((time.perf_counter() - due) * 1e9))

    def stats(self) -> PacingStats:
        """Lateness percentiles and deadline misses of the run so far."""
        if not self._lateness_ns:
            return PacingStats(0, 0, 0.0, 0.0, 0.0)
        late_us = np.asarray(self._lateness_ns, dtype=float) / 1e3
        misses = int(np.count_nonzero(late_us >= self.period_s * 1e6))
        return PacingStats(
            periods=len(late_us),
            deadline_misses=misses,
            lateness_p50_us=float(np.percentile(late_us, 50)),
            lateness_p99_us=float(np.percentile(late_us, 99)),
            lateness_max_us=float(late_us.max()),
        )


#: Speeds a :class:`PacedClock` takes: a tenth of real time to ten times it (None: unpaced).
MIN_SPEED, MAX_SPEED = 0.1, 10.0


@dataclass(frozen=True)
class PaceStats:
    """How a :class:`PacedClock` kept its pace since it was built.

    ``lag_s``: how far the last period began after its due time (wall
    seconds; negative: ahead).  ``overruns``: periods that began a whole
    period (of wall time, at the speed then) late or more.  ``slips``: times
    the loop fell more than ``max_lag_s`` behind and was re-anchored, giving
    up ``lost_s`` of wall time rather than racing to catch up.
    """

    speed: float | None
    periods: int
    lag_s: float
    lag_max_s: float
    overruns: int
    slips: int
    lost_s: float


class PacedClock:
    """Paces control periods to the wall clock at ``speed`` times real time, or not at all.

    Period `k` is due ``period_s * (k - k0) / speed`` after the anchor (the
    wall time of period `k0`): deadlines are absolute, so sleeping never
    accumulates drift, and simulated time stays within a period or so of
    the wall clock times the speed.  It sleeps only once it is ``slack_s``
    ahead (the OS sleep is too coarse for every 1 ms period; nothing spins),
    so steps run in short bursts between sleeps.

    ``speed`` None runs as fast as the machine goes.  :meth:`set_speed` and
    :meth:`restart` (after a pause) re-anchor at the next period.  A loop that
    falls more than ``max_lag_s`` behind (a busy machine, a slow step) is
    re-anchored and the slip counted (:class:`PaceStats`), instead of running
    flat out until it has caught up.
    """

    paced = True

    def __init__(self, period_s: float, speed: float | None = 1.0, *, max_lag_s: float = 0.25,
                 slack_s: float = 0.001) -> None:
        if not (math.isfinite(period_s) and period_s > 0):
            raise ValueError(f"period_s must be a positive number of seconds, got {period_s!r}")
        self.period_s = period_s
        self.max_lag_s = max_lag_s
        self.slack_s = slack_s
        self.speed: float | None = check_speed(speed)
        self._anchor: tuple[float, int] | None = None
        self._periods = 0
        self._lag = 0.0
        self._lag_max = 0.0
        self._overruns = 0
        self._slips = 0
        self._lost = 0.0

    def start(self) -> None:
        """Begin a run: the next period is due when it is asked for."""
        self.restart()

    def restart(self) -> None:
        """Re-anchor at the next period (after a pause: the time paused is not owed)."""
        self._anchor = None

    def set_speed(self, speed: float | None) -> None:
        """Change the speed (None: as fast as it goes); re-anchors at the next period."""
        self.speed = check_speed(speed)
        self._anchor = None

    def wait_period(self, k: int) -> None:
        """Sleep until period `k` is due, if the loop is ahead; count lateness if behind."""
        self._periods += 1
        speed = self.speed
        if speed is None:
            return
        now = time.perf_counter()
        anchor = self._anchor
        if anchor is None:
            self._anchor = (now, k)
            self._lag = 0.0
            return
        due = anchor[0] + (k - anchor[1]) * self.period_s / speed
        ahead = due - now
        if ahead > self.slack_s:
            time.sleep(ahead)
            self._lag = time.perf_counter() - due
            return
        late = -ahead
        self._lag = late
        if late > self._lag_max:
            self._lag_max = late
        if late >= self.period_s / speed:
            self._overruns += 1
            if late > self.max_lag_s:
                self._slips += 1
                self._lost += late
                self._anchor = (now, k)

    def stats(self) -> PaceStats:
        return PaceStats(self.speed, self._periods, self._lag, self._lag_max, self._overruns, self._slips,
                         self._lost)


def check_speed(speed: float | None) -> float | None:
    """A speed factor from :data:`MIN_SPEED` to :data:`MAX_SPEED`, or None (as fast as it goes)."""
    if speed is None:
        return None
    if isinstance(speed, bool) or not isinstance(speed, (int, float)) or not math.isfinite(speed) \
            or not MIN_SPEED <= speed <= MAX_SPEED:
        raise ValueError(f"speed must be a number from {MIN_SPEED:g} to {MAX_SPEED:g} (times real time),"
                         f" or None for as fast as it goes; got {speed!r}")
    return float(speed)
