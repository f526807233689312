"""The arm's digital twin: kinematics, the simulated plant and its control.

Nothing here imports charts or the runtime; the application wires them.
"""
