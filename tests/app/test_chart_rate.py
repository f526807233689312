"""One chart clock: the same X drawn with the charts at 1000, 500 and 250 Hz (docs/runtime.md, "One clock").

The charts take their tick period from the scheduler (`chart_divider / rate_hz`)
and turn every per-second datum (drawing speed, search speed) into a step per
tick with it, so a drawing takes the same time and lands as precisely at any
chart rate; the drives initialise at each.

Tolerances:

- time: a state ends on the first chart tick at or after the moment its
  condition holds, and the tick that takes a transition runs no during
  action (Stateflow's semantics), so each transition of a sequence may cost
  up to two chart periods more at the slower rate.  The bound is twice the
  transitions taken (all charts, counted by a trace) times the slowest chart
  period.
- precision: the desired path is one point per chart tick, so where the ink
  lies between two commanded points can differ by half a step at the slowest
  rate (speed x 4 ms / 2 = 0.04 mm at 20 mm/s): the rms and maximum error of
  the ink against the desired path agree within that.
"""

from __future__ import annotations

import dataclasses
import itertools

import pytest

from ttt_sm.app.drawing import DrawResult, DrawSession
from ttt_sm.params import ArmParams, load_params
from ttt_sm.runtime.listeners import Trace

P = load_params()
DIVIDERS = (1, 2, 4)


def at_divider(divider: int) -> ArmParams:
    return dataclasses.replace(P, control=dataclasses.replace(P.control, chart_divider=divider))


@dataclasses.dataclass(frozen=True)
class Run:
    chart_dt: float
    ready_s: float
    init_transitions: int
    x: DrawResult
    x_transitions: int


@pytest.fixture(scope="module")
def runs() -> dict[int, Run]:
    """The drives initialised, then an X in cell (2, 2), at each chart divider."""
    out = {}
    for divider in DIVIDERS:
        params = at_divider(divider)
        session = DrawSession(params, seed=0)
        trace = Trace().observe(*session.robot.charts.values())
        ready = session.start()
        init_transitions = len(trace.records)
        x = session.draw("X", 2, 2)
        out[divider] = Run(params.control.chart_dt, ready, init_transitions, x,
                           len(trace.records) - init_transitions)
    return out


def test_the_drives_initialise_and_reach_the_waiting_pose_at_every_chart_rate(runs):
    for a, b in itertools.combinations(DIVIDERS, 2):
        slack = 2 * max(runs[a].init_transitions, runs[b].init_transitions) * max(runs[a].chart_dt, runs[b].chart_dt)
        assert abs(runs[a].ready_s - runs[b].ready_s) <= slack, (a, b, runs[a].ready_s, runs[b].ready_s, slack)


def test_the_same_x_takes_the_same_time_at_every_chart_rate(runs):
    assert runs[2].x.duration_s == pytest.approx(11.0, abs=0.5)  # 4 moves, 2 strokes, back to the waiting pose
    for a, b in itertools.combinations(DIVIDERS, 2):
        slack = 2 * max(runs[a].x_transitions, runs[b].x_transitions) * max(runs[a].chart_dt, runs[b].chart_dt)
        assert abs(runs[a].x.duration_s - runs[b].x.duration_s) <= slack, (a, b, runs[a].x, runs[b].x, slack)


def test_the_same_x_is_drawn_as_precisely_at_every_chart_rate(runs):
    half_step_mm = 0.5 * runs[2].x.speed_mm_s * max(r.chart_dt for r in runs.values())
    for run in runs.values():
        assert run.x.ink_points > 100 and run.x.rms_error_mm <= 0.3 and run.x.max_error_mm <= 1.0, run.x
    for a, b in itertools.combinations(DIVIDERS, 2):
        x_a, x_b = runs[a].x, runs[b].x
        assert abs(x_a.rms_error_mm - x_b.rms_error_mm) <= half_step_mm, (a, b, x_a, x_b)
        assert abs(x_a.max_error_mm - x_b.max_error_mm) <= half_step_mm, (a, b, x_a, x_b)
