"""Every page's Reset of the Safety chart (docs/safety.md); drive 1's stop (thesis section 3.1.2)."""

from __future__ import annotations

from ..fields import flag
from .spec import Cockpit, Reply, command


@command("safety_reset")
def reset(session: Cockpit, cid: int) -> Reply:
    """Reset: the Safety chart's ``reset`` event, posted as ``post Safety reset`` is (an input the debugger
    records); refused while the chart has not tripped."""
    robot = session.debugger.robot
    if not robot.tripped:
        raise ValueError("the Safety chart has not tripped: there is nothing to reset")
    session.debugger.post(robot.safety.chart_name, "reset")
    return {"text": f"Reset: the Safety chart re-initialises the drives (it tripped on: {robot.safety.reason})"}


@command("drive1_stop", stop=flag)
def drive1_stop(session: Cockpit, cid: int, stop: bool) -> Reply:
    """Drive 1's ``stop`` input (thesis section 3.1.2, fig. 3.2: "a non-zero value stops the first drive"):
    set through the debugger as ``set DriveInit1.stop 1`` is (an input it records); ``stop`` false releases
    it, and the chart goes back into the state it left (its history state)."""
    dbg = session.debugger
    was = bool(dbg.robot.chart("DriveInit1").stop)
    if was == stop:
        raise ValueError("drive 1 is stopped already" if stop else "drive 1 is not stopped: nothing to release")
    dbg.set_input("DriveInit1", "stop", stop)
    if stop:
        return {"text": "Drive 1 stops where it is (DriveInit1.stop = 1): its setpoint is held at its encoder"}
    return {"text": "Drive 1 released (DriveInit1.stop = 0): it goes on from the state it was stopped in"}
