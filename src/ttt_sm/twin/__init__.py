"""The arm's digital twin: kinematics, the simulated arm (cascade controller and plant) and its tuning.

``sim.ArmSim`` fuses the controller's step (``cascade.py``, ``_cascade.py``) and
the plant's (``plant.py``, ``_plant.py``) in one compiled loop (``_kernel.py``);
its ground truth sits behind ``truth.py``.  Nothing here imports charts, the
runtime, the scheduler or the application; the application wires them.  The
twin imports :mod:`ttt_sm.arm` (the interface it implements), never the reverse.
"""
