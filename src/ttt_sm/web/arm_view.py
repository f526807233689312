"""The arm drawn live in the pages: its points from the true joint angles, the tool in use, the ink.

Every frame carries an ``arm`` part (:func:`arm_view`): the twin's TRUE joint
angles and the points along the arm that the project's one forward-kinematics
chain gives for them (:func:`~ttt_sm.twin.kinematics.arm_points`: the
column's foot, the shoulder, the elbow, the wrist, the pen tip; thesis
section 3.4, eqs. 3.17-3.25), the sponge's pad (thesis section 3.6.1), which
tool is in use, what touches the board, and a key that changes whenever the
ink may have changed.  The page draws them in two projections (a side view,
global y-z, and a top view, global x-y, over the whiteboard's ink) and
computes no kinematics of its own.

What stays the same for the whole session (the board, the field, the link
lengths) comes once in the session's ``info`` (:func:`arm_scene`).  The
board's ink is a picture (:func:`ink_picture`, ``/api/arm/ink.png``) that the
page asks for again when the frame's ``ink`` key changes.

Ground truth is simulation only: an arm that is no simulation has no
``arm`` part (None), and the page says so.
"""

from __future__ import annotations

from typing import Any

import cv2
import numpy as np

from ..app.robot import Robot
from ..params import ArmParams
from ..twin.kinematics import arm_chain_py, arm_points

#: Millimetres in a metre: points travel in mm, rounded to MM_DECIMALS.
MM = 1e3
MM_DECIMALS = 1
#: The ink picture's resolution, pixels per millimetre of board.
INK_PX_PER_MM = 2.0
#: The names of :func:`~ttt_sm.twin.kinematics.arm_points`' rows, in order.
POINT_NAMES = ("foot", "shoulder", "elbow", "wrist", "tip")


def _mm(*values: float) -> list[float]:
    return [round(v * MM, MM_DECIMALS) for v in values]


def arm_scene(params: ArmParams) -> dict[str, Any]:
    """What the arm's views need once: the board, the field and the link lengths, mm."""
    b, g, s = params.board, params.geometry, params.sponge
    bx0, bx1, by0, by1 = b.board_bounds()
    fx0, fx1, fy0, fy1 = b.field_bounds()
    reach = g.L2 + g.L3 + g.L4
    return {
        "board": _mm(bx0, bx1, by0, by1),
        "field": _mm(fx0, fx1, fy0, fy1),
        "cells": b.cells,
        "surface_z": round(b.surface_z * MM, MM_DECIMALS),
        "links": _mm(g.L1, g.L2, g.L3, g.L4, g.l_f),
        "reach": round(reach * MM, MM_DECIMALS),
        "sponge_width": round(s.width * MM, MM_DECIMALS),
        "ink_px_per_mm": INK_PX_PER_MM,
    }


def arm_view(robot: Robot) -> dict[str, Any] | None:
    """The ``arm`` part of a frame, plain data (None: the arm is no simulation, no true angles).

    ``q_deg``: the true joint angles q1..q4, degrees; ``points``: name -> [x, y, z]
    mm (:data:`POINT_NAMES`); ``sponge``: the pad's four corners [x, y, z] mm;
    ``tool``: ``"sponge"`` while the Control chart erases (its declared output
    ``erasing``), else ``"pen"``; ``touching``: ``"pen"``, ``"sponge"`` or None;
    ``ink``: changes whenever the board's ink may have.
    """
    truth = robot.truth
    if truth is None:
        return None
    g = robot.params.true_geometry  # the true arm, as built
    q1, q2, q3, q4 = truth.angles()
    points = arm_points((q1, q2, q3, q4), g)
    x, y, z, _, s1, c1, s_phi, c_phi = arm_chain_py(q1, q2, q3, q4, g.L1, g.L2, g.L3, g.L4, g.l_f)
    # The sponge's pad (the whiteboard's contact model): centre p + offset n, its face spanned by the
    # sideways direction (c1, s1, 0) and the tool axis u, each sponge.width wide.
    off, h = robot.params.sponge.offset, robot.params.sponge.width / 2
    n = (s1 * c_phi, -c1 * c_phi, -s_phi)
    u = (-s1 * s_phi, c1 * s_phi, -c_phi)
    side = (c1, s1, 0.0)
    centre = (x + off * n[0], y + off * n[1], z + off * n[2])
    corners = [_mm(*(centre[k] + a * h * side[k] + b * h * u[k] for k in range(3)))
               for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    board = robot.board
    contact = board.contact
    touching = "pen" if contact.pen_touching else "sponge" if contact.sponge_touching else None
    return {
        "q_deg": [round(float(v) * 180.0 / 3.141592653589793, 2) for v in (q1, q2, q3, q4)],
        "points": {name: _mm(*(float(v) for v in p)) for name, p in zip(POINT_NAMES, points, strict=True)},
        "sponge": corners,
        "tool": "sponge" if bool(getattr(robot.control, "erasing", False)) else "pen",
        "touching": touching,
        "ink": list(board.ink_version),
    }


def ink_picture(robot: Robot) -> np.ndarray:
    """The whiteboard's ink seen from above (x to the right, y up), :data:`INK_PX_PER_MM`, BGR."""
    return robot.board.render(px_per_mm=INK_PX_PER_MM, view="above")


def png(image: np.ndarray) -> bytes:
    """An image as PNG bytes."""
    ok, data = cv2.imencode(".png", image)
    if not ok:
        raise RuntimeError("OpenCV could not encode the whiteboard's picture as PNG")
    return bytes(data)
