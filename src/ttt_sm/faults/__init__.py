"""Faults injected into the arm, and the Safety chart's fault matrix (``ttt-sm faults``, docs/safety.md).

``plant``: what each fault of the arm does to the twin's plant and to the
readings taken of it, one definition for both arms.  ``twin``:
:class:`~.twin.FaultyArm`, the simulated arm with a fault switched on or
off.  ``matrix``: every fault in every phase of the robot's work, each on a
new robot over the twin or the firmware emulator, measured against the
plant's ground truth.  ``link``: the faults of the serial link, on the
emulator's wire.  A tool over the application (it builds robots), like the
scenario runner: simulation only.
"""
