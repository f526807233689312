"""step / tick / next / run / pause: how far each goes, and where it stops."""

from __future__ import annotations

import pytest

from ttt_sm.debug import DebugError, Debugger


def test_step_runs_control_steps_and_tick_runs_to_just_after_chart_ticks(dbg: Debugger, params):
    divider = params.control.chart_divider
    stop = dbg.step()
    assert (stop.kind, stop.steps, stop.chart_ticks) == ("done", 1, 1)  # step 0 starts chart tick 1
    stop = dbg.step(3)
    assert (stop.steps, stop.chart_ticks) == (4, 2)
    stop = dbg.tick()
    assert (stop.steps, stop.chart_ticks) == (dbg.steps_of_tick(3), 3)
    stop = dbg.tick(10)
    assert stop.kind == "done" and stop.chart_ticks == 13
    assert stop.steps == 12 * divider + 1
    assert stop.t == pytest.approx(stop.steps * params.control.dt)
    assert dbg.robot.chart("DriveInit1").tick_count == 13


def test_next_stops_at_the_tick_of_the_next_transition_of_any_chart(dbg: Debugger):
    stop = dbg.next()
    assert stop.kind == "transition" and stop.chart_ticks == 1
    assert [(r.source, r.target) for r in stop.transitions] == [("power_on", "turn_fwd")]
    stop = dbg.next(10.0)
    assert stop.kind == "transition"
    taken = [(r.chart, r.source, r.target) for r in stop.transitions]
    assert taken == [("DriveInit1", "turn_fwd", "turn_back")]
    assert stop.transitions[0].tick == stop.chart_ticks == dbg.robot.chart_ticks
    t_turn = stop.t
    stop = dbg.next(0.01)  # nothing happens within 10 ms
    assert stop.kind == "timeout" and stop.transitions == ()
    assert stop.t == pytest.approx(t_turn + 0.01)


def test_run_times_out_after_the_simulated_seconds_asked(dbg: Debugger):
    stop = dbg.run(0.5)
    assert stop.kind == "timeout" and stop.steps == 500 and stop.t == pytest.approx(0.5)
    assert [r.target for r in stop.transitions] == ["turn_fwd"]


def test_pause_from_outside_stops_after_the_current_control_step(dbg: Debugger):
    class PauseOnTransition:  # stands in for a GUI's pause button
        def after_transition(self) -> None:
            dbg.pause()

    dbg.robot.chart("DriveInit1").add_listener(PauseOnTransition())
    stop = dbg.run(20.0)
    assert stop.kind == "paused" and stop.chart_ticks == 1
    stop = dbg.run(20.0)  # a new run forgets the old pause
    assert stop.kind == "paused" and dbg.trace.records[-1].target == "turn_back"


@pytest.mark.parametrize("call, message", [
    (lambda d: d.step(0), "step: the count must be a whole number >= 1"),
    (lambda d: d.tick(-2), "tick: the count must be"),
    (lambda d: d.run(-1.0), "run: the time must be a positive number of seconds"),
    (lambda d: d.next(float("nan")), "next: the time must be"),
])
def test_bad_counts_and_times(dbg: Debugger, call, message):
    with pytest.raises(DebugError, match=message):
        call(dbg)
    assert dbg.robot.steps == 0


def test_ctrl_c_during_a_run_pauses_it_between_two_control_steps(dbg: Debugger):
    import os
    import signal

    class CtrlC:  # the user presses Ctrl-C as drive 1 turns back
        def after_transition(self, target) -> None:
            if target.id == "turn_back":
                os.kill(os.getpid(), signal.SIGINT)

    before = signal.getsignal(signal.SIGINT)
    dbg.robot.chart("DriveInit1").add_listener(CtrlC())
    stop = dbg.run(20.0)
    assert stop.kind == "paused"
    assert dbg.trace.records[-1].target == "turn_back"
    assert stop.steps - dbg.steps_of_tick(dbg.trace.records[-1].tick) <= 2
    assert signal.getsignal(signal.SIGINT) is before  # Ctrl-C means KeyboardInterrupt again
