"""Clocks behind one interface: virtual time, or wall-clock pacing.

The scheduler asks a clock to wait for the start of each control period.  A
:class:`VirtualClock` never waits (tests, scenarios, the default `play`: as
fast as the machine goes).  A :class:`WallClock` paces the loop to real time
(real hardware, a live GUI) and counts the periods it could not keep, never
hiding an overrun.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np


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
