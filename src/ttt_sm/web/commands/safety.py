"""Every page's Reset of the Safety chart (docs/safety.md)."""

from __future__ import annotations

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
