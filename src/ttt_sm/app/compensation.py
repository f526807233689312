"""Gear play compensation for the pitch joints: a model-based feedforward.

The encoders sit on the motor shafts (thesis section 3.2, note), so the
controllers hold the *motor* where inverse kinematics asks, and the links
hang behind it by half the gear clearance plus the gear's elastic
deflection under gravity.  On drives 2 and 3 gravity always loads the gear
the same way in the working area, so that offset is predictable: this joint
stage adds it to the setpoints,

    q_set += gain * sign(-tau_g) * (clearance / 2 + |tau_g| / stiffness),

with `tau_g` the gravity torque on the joint at the commanded pose.  With
`[control] gear_play_compensation = 0` it is off, and the "forward
kinematics of the encoders vs the true pen" comparison of thesis section 3.5
shows the full effect of the clearance.  Drive 1 turns about the vertical:
no gravity preloads its gear, so its play cannot be compensated this way.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..params import ArmParams
from ..sched.scheduler import Signals
from ..twin.plant import gear_play, gravity_coefficients, gravity_torques, gravity_torques_py


def play_offsets(params: ArmParams, q: np.ndarray) -> np.ndarray:
    """How far each link hangs behind its motor at pose `q` (rad, drives 1-3; 0 for drive 1)."""
    tau = gravity_torques(params, q)
    out = np.zeros(3)
    for d in (1, 2):
        out[d] = gear_play(tau[d], params.drives[d].gear_clearance, params.drives[d].gear_stiffness)
    return out


class GearPlayCompensation:
    """Joint stage: shift drives 2 and 3's setpoints by the play gravity takes up."""

    def __init__(self, params: ArmParams, active: Callable[[], bool]) -> None:
        self.params = params
        self.gain = params.control.gear_play_compensation
        self.active = active
        d2, d3 = params.drives[1], params.drives[2]
        self._play = (d2.gear_clearance, d2.gear_stiffness, d3.gear_clearance, d3.gear_stiffness)
        self._gravity = gravity_coefficients(params)

    def tick(self, signals: Signals) -> None:
        """Add the offset to the setpoints once the drives are initialised."""
        if self.gain == 0.0 or not self.active():
            return
        q1, q2, q3, q4 = signals.q_set
        g2, g23 = self._gravity
        tau2, tau3 = gravity_torques_py(g2, g23, q2, q3)  # on plain floats: it runs every chart step
        c2, k2, c3, k3 = self._play
        gain = self.gain
        # the play taken up towards the gravity torque
        q2 -= gain * gear_play(tau2, c2, k2)
        q3 -= gain * gear_play(tau3, c3, k3)
        signals.q_set = [float(q1), float(q2), float(q3), float(q4)]

