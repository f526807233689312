"""The firmware's watchdog: setpoints missing for 50 ms bring the arm to a safe stop.

The C firmware runs the twin's plant here (its sensors read from the
plant, its commands applied to it), with gains downloaded and START sent
over the link as the PC does.  The PC streams setpoints that swing drive 1
and then falls silent: 50 control steps later the firmware holds every
drive where it is and lifts the pen, refuses setpoints until the next
START, and the arm stops.
"""

from __future__ import annotations

import numpy as np
import pytest

from ttt_sm.hardware import link as L
from ttt_sm.hardware.native import NativeFirmware, board_for
from ttt_sm.params import load_params
from ttt_sm.twin import layout
from ttt_sm.twin.cascade import CascadeController
from ttt_sm.twin.plant import REST_POSE, Plant
from ttt_sm.twin.tuning import design_gains

P = load_params()
PEN_UP = 0.9
STATE = {"idle": 0, "running": 1, "safe_stop": 2}


class Bench:
    """The C firmware on the twin's plant, and the PC's end of the link."""

    def __init__(self, lib) -> None:
        self.plant = Plant(P, np.array(REST_POSE), np.random.default_rng(0))
        self.fw = NativeFirmware(lib, board_for(P, PEN_UP))
        self.tx, self.rx = L.Sender(), L.Receiver()
        self.act = np.zeros(layout.N_ACT)
        self.statuses: list[L.Status] = []
        pc = CascadeController(P, design_gains(P), servo_angle=REST_POSE[3])
        self.send(L.Hello(), *[L.Gains(d, tuple(pc.cp[d, :layout.N_CP])) for d in range(3)],
                  L.Gains(3, tuple(pc.cg[:layout.N_CG])), L.Start())
        assert self.fw.state == STATE["running"]

    def send(self, *messages: L.Message) -> None:
        self.fw.rx(b"".join(self.tx.frame(m) for m in messages))

    def step(self) -> None:
        s = self.fw.sensors
        s.counts[:] = [int(c) for c in self.plant.counts]
        self.fw.step()
        self.act[:] = self.fw.act
        self.plant.step(self.act)
        self.statuses += [m for m in self.rx.feed(self.fw.tx()) if isinstance(m, L.Status)]  # the UART drains

    @property
    def speeds(self) -> np.ndarray:
        return self.plant.ps[:, layout.PS_WQ].copy()


def test_setpoints_missing_for_50_ms_stop_the_arm_and_lift_the_pen(firmware_libs):
    b = Bench(firmware_libs["float"])
    t = 0
    # the PC streams a swing of drive 1 at the chart rate (every 2 steps) for 0.4 s
    for t in range(400):
        if t % 2 == 0:
            b.send(L.Setpoints(b.fw.steps, (0.5 * t / 400, 0.0, 0.0, REST_POSE[3])))
        b.step()
    moving = abs(b.speeds[0])
    assert moving > 0.5  # rad/s: drive 1 is swinging when the PC falls silent
    last_setpoint = b.fw.steps - 2
    for _ in range(48):  # 49 steps without setpoints: still running
        b.step()
    assert b.fw.state == STATE["running"] and b.fw.steps - last_setpoint == 50
    b.step()
    assert b.fw.state == STATE["safe_stop"]  # the 50th silent step (50 ms) trips it
    cs, cgs = np.ctypeslib.as_array(b.fw.cascade.cs), np.ctypeslib.as_array(b.fw.cascade.cgs)
    assert cgs[layout.CGS_SV_SET] == pytest.approx(PEN_UP)  # the pen goes up
    stop_q = cs[:, layout.CS_R_RAW].copy()  # each drive holds where it was
    for _ in range(300):
        b.step()
    assert np.abs(b.speeds[:3]).max() < 0.01  # the arm has stopped
    assert np.all(np.ctypeslib.as_array(b.fw.cascade.cs)[:, layout.CS_R_RAW] == stop_q)
    assert b.plant.pgs[layout.PGS_SV_Q] == pytest.approx(PEN_UP, abs=0.01)
    # late setpoints after the stop are refused, not acted on, until the PC re-arms with START
    b.send(L.Setpoints(b.fw.steps, (0.0, 0.0, 0.0, REST_POSE[3])))
    assert b.fw.rejections()[L.Reason.REFUSED] == 1 and b.fw.state == STATE["safe_stop"]
    # the PC was told: every status from the trip on says so
    assert [m.state_name for m in b.statuses[-150:]] == ["safe_stop"] * 150
    assert b.rx.rejected == 0 and b.rx.seq.lost == 0
    b.send(L.Start())
    assert b.fw.state == STATE["running"]


def test_setpoints_every_chart_step_keep_it_running(firmware_libs):
    b = Bench(firmware_libs["float"])
    for t in range(2000):
        if t % 40 == 0:  # even 40 ms apart: under the limit
            b.send(L.Setpoints(b.fw.steps, (0.0, 0.0, 0.0, REST_POSE[3])))
        b.step()
    assert b.fw.state == STATE["running"]
    assert sum(b.fw.rejections().values()) == 0
