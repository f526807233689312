"""The Operational page's commands (``/operate``, :mod:`..operate`): Trigger and Stop_simulation."""

from __future__ import annotations

from ..fields import number, one_of
from ..operate import MAGNITUDE_CM, SPEED_RANGE, SYMBOLS
from .spec import Cockpit, Reply, command


@command("operate_trigger", symbol=one_of(*SYMBOLS), magnitude_cm=number(*MAGNITUDE_CM), speed=number(*SPEED_RANGE))
def trigger(session: Cockpit, cid: int, symbol: str, magnitude_cm: float, speed: float) -> Reply:
    """Trigger: draw ``symbol`` (``"X"``, ``"O"`` or ``"sine"``) ``magnitude_cm`` (0 .. 10) big at ``speed``
    (0 .. 5) in the field's middle."""
    return session.operate.trigger(symbol, magnitude_cm, speed)


@command("operate_stop")
def stop(session: Cockpit, cid: int) -> Reply:
    """Stop_simulation: the arm returns to its start pose."""
    return session.operate.stop()
