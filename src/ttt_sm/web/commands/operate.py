"""The Operational page's commands (``/operate``, :mod:`..operate`): Trigger and Stop_simulation."""

from __future__ import annotations

from ..fields import number, one_of, optional
from ..operate import MAGNITUDE_CM, SPEED_RANGE, STAIRCASE_AXES, STAIRCASE_STEPS, SYMBOLS
from .spec import Cockpit, Reply, command


@command("operate_trigger", symbol=one_of(*SYMBOLS), magnitude_cm=number(*MAGNITUDE_CM), speed=number(*SPEED_RANGE),
         axis=optional(one_of(*STAIRCASE_AXES), "z"), steps=optional(one_of(*STAIRCASE_STEPS), "big"))
def trigger(session: Cockpit, cid: int, symbol: str, magnitude_cm: float, speed: float, axis: str,
            steps: str) -> Reply:
    """Trigger: draw ``symbol`` (``"X"``, ``"O"`` or ``"sine"``) ``magnitude_cm`` (0 .. 10) big at ``speed``
    (0 .. 5) in the field's middle; or (``"staircase"``) play the staircase of section 3.5 along ``axis``
    (``"x"``, ``"y"``, ``"z"``) with ``steps`` (``"small"``, ``"big"``) stairs."""
    return session.operate.trigger(symbol, magnitude_cm, speed, axis, steps)


@command("operate_stop")
def stop(session: Cockpit, cid: int) -> Reply:
    """Stop_simulation: the arm returns to its start pose."""
    return session.operate.stop()
