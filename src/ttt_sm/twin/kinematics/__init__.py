"""Forward and inverse kinematics of the RRRR arm (thesis section 3.4).

The pose of the tool is ``X = [x, y, z, phi]``: the pen tip in the global
frame (metres; the board surface is z = 0, the base axis is the vertical line
x = -l_f, y = 0) and its tilt phi about the global X axis (radians; 0 points
the pen straight down, pi/2 turns the tool horizontal so the sponge on its
side faces the board).  Joint angles are ``q = [q1, q2, q3, q4]`` (radians):
base yaw, shoulder pitch, elbow pitch, pen servo; q = 0 hangs the arm straight
down.  docs/kinematics.md derives the equations and lists the thesis' typos.

One module per idea, everything importable from here:

* :mod:`.chain`: the arm's chain of transforms written once, compiled on
  plain numbers (:func:`arm_chain`, and :data:`arm_chain_py` for plain
  Python); :func:`fk` and :func:`jacobian`, eqs. 3.22-3.25 and 3.30
  (corrected); :func:`arm_points` and :func:`link_points`.
* :mod:`.closed_form`: :func:`ik_closed_form` solves the inverse problem
  geometrically; it is the test oracle, not what the arm runs.
* :mod:`.dls`: :func:`damped_least_squares`, the thesis' iterative solver
  (eq. 3.35), with adaptive damping and a step limit that keep it converging
  from and near singular poses.
* :mod:`.solver`: :class:`IKSolver` wraps it for a control loop: warm start
  from the last solution, joint limits, and specific errors instead of wrong
  answers.
* :mod:`.errors`: :class:`IKError` and its kinds.
* :mod:`.bench`: how fast and how reliably the solver solves (``ttt-sm bench``).
"""

from .chain import arm_chain, arm_chain_py, arm_points, fk, jacobian, link_points
from .closed_form import ik_closed_form
from .dls import IKResult, damped_least_squares
from .errors import IKError, JointLimitError, NonFiniteTargetError, UnreachableTargetError
from .solver import HOME_Q, IKSolver

__all__ = ["HOME_Q", "IKError", "IKResult", "IKSolver", "JointLimitError", "NonFiniteTargetError",
           "UnreachableTargetError", "arm_chain", "arm_chain_py", "arm_points", "damped_least_squares", "fk",
           "ik_closed_form", "jacobian", "link_points"]
