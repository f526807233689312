"""The paced clock on a fake wall clock: absolute deadlines, speed changes, overruns and slips.

No test here reads the real time: ``time.perf_counter`` and ``time.sleep`` are
replaced by a clock that advances only when the code sleeps or a "step" costs
time, so every number below is exact.
"""

from __future__ import annotations

import pytest

from ttt_sm.sched import clock as clock_module
from ttt_sm.sched.clock import PacedClock


class FakeTime:
    def __init__(self) -> None:
        self.now = 1000.0
        self.slept: list[float] = []

    def perf_counter(self) -> float:
        return self.now

    def sleep(self, seconds: float) -> None:
        self.slept.append(seconds)
        self.now += seconds + 0.00005  # the OS wakes a little late


@pytest.fixture
def fake(monkeypatch: pytest.MonkeyPatch) -> FakeTime:
    t = FakeTime()
    monkeypatch.setattr(clock_module.time, "perf_counter", t.perf_counter)
    monkeypatch.setattr(clock_module.time, "sleep", t.sleep)
    return t


def run(c: PacedClock, t: FakeTime, periods: int, step_cost_s: float, k0: int = 0) -> None:
    for k in range(k0, k0 + periods):
        c.wait_period(k)
        t.now += step_cost_s


def test_real_time_keeps_absolute_deadlines_without_drift(fake: FakeTime) -> None:
    c = PacedClock(0.001, 1.0)
    start = fake.now
    run(c, fake, 60_001, step_cost_s=30e-6)  # a minute of 1 ms periods, 30 us of work each
    # Period 60000 began within a period of 60 s after period 0: late wakes do not add up.
    assert fake.now - 30e-6 - start == pytest.approx(60.0, abs=0.001)
    assert c.stats().overruns == 0 and c.stats().slips == 0
    # It slept in bursts (every millisecond or two), never once for every period.
    assert 10_000 < len(fake.slept) < 60_000


def test_speed_scales_the_deadlines_and_a_change_reanchors(fake: FakeTime) -> None:
    c = PacedClock(0.001, 10.0)
    start = fake.now
    run(c, fake, 10_001, step_cost_s=10e-6)
    assert fake.now - 10e-6 - start == pytest.approx(1.0, abs=0.001)  # 10 s simulated in 1 s
    c.set_speed(0.5)
    mark = fake.now
    run(c, fake, 1001, step_cost_s=10e-6, k0=10_001)
    assert fake.now - 10e-6 - mark == pytest.approx(2.0, abs=0.002)  # 1 s simulated in 2 s
    c.set_speed(None)
    mark = fake.now
    run(c, fake, 1000, step_cost_s=10e-6, k0=11_002)
    assert fake.now - mark == pytest.approx(0.01)  # as fast as it goes: no sleep at all


def test_a_loop_too_slow_for_its_speed_counts_overruns_and_slips_instead_of_racing(fake: FakeTime) -> None:
    c = PacedClock(0.001, 10.0, max_lag_s=0.25)
    run(c, fake, 5001, step_cost_s=200e-6)  # needs 100 us a period at x10, takes 200 us
    s = c.stats()
    assert s.overruns > 4000
    assert s.slips >= 1 and s.lost_s > 0.25
    assert s.lag_max_s <= 0.25 + 0.001  # re-anchored, never further behind than max_lag_s


def test_restart_after_a_pause_owes_nothing(fake: FakeTime) -> None:
    c = PacedClock(0.001, 1.0)
    run(c, fake, 100, step_cost_s=10e-6)
    fake.now += 30.0  # paused for half a minute
    c.restart()
    run(c, fake, 100, step_cost_s=10e-6, k0=100)
    assert c.stats().overruns == 0 and c.stats().lag_max_s < 0.001


@pytest.mark.parametrize("speed", [0.0, 0.05, 11, float("nan"), True, "2"])
def test_a_speed_out_of_range_is_refused(speed: object) -> None:
    with pytest.raises(ValueError, match="speed must be a number from 0.1 to 10"):
        PacedClock(0.001, speed)  # type: ignore[arg-type]
