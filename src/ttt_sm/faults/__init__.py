"""Faults injected into the twin, and the Safety chart's fault matrix (``ttt-sm faults``, docs/safety.md).

``twin``: :class:`~.twin.FaultyArm`, the simulated arm with a fault switched
on or off.  ``matrix``: every fault in every phase of the robot's work, each
on a new robot, measured against the twin's ground truth.  A tool over the
application (it builds robots), like the scenario runner: simulation only.
"""
