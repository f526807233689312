"""What the scheduler, the charts' wiring and the debugger may use of an arm.

:class:`Arm` is the interface every backend offers: the simulated arm of
:mod:`ttt_sm.twin` today, a microcontroller behind a serial link later.  This
package imports nothing of the twin, the charts or the application, so each of
them can depend on it (docs/model.md, "The Arm interface").
"""

from .protocol import Arm, Sensors

__all__ = ["Arm", "Sensors"]
