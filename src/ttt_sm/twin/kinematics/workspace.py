"""The pen tip's reachable workspace from the joint limits (thesis section 3.4; docs/kinematics.md, "Lab").

The closed form of :func:`~.closed_form.ik_closed_form` (its one compiled
source, :func:`~.closed_form.closed_form_q`) solves every point of a grid for both elbow configurations;
a point is reachable in a configuration when its solution exists and lies
within the joint limits (``[drive.*]`` and ``[servo]`` of the parameter
file).  Three tools: the pen held vertical (``phi = 0``, how the arm draws),
the pen at any tilt (``phi`` sampled over [-90, 90] deg), and the sponge
(``phi = 90`` deg, the tool point ``sponge.offset`` above the board so the
sponge face touches it; section 3.6.1, Erase).

The result is a top view (the board plane, ``z = board.surface_z``), a side
view (the arm's plane: reach ``r`` from the base axis against height ``z``;
``q1`` does not enter it), and the configuration each cell of the playing
field needs.  Codes of a grid point: :data:`UNREACHABLE`, :data:`UP_ONLY`,
:data:`DOWN_ONLY`, :data:`BOTH`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numba
import numpy as np

from ttt_sm.params import ArmParams, Geometry

from .closed_form import closed_form_q, wrap_angle

UNREACHABLE, UP_ONLY, DOWN_ONLY, BOTH = 0, 1, 2, 3
#: Names of the codes, in code order.
CODE_NAMES = ("unreachable", "elbow up only", "elbow down only", "both")
#: The tools :func:`workspace` knows.
TOOLS = ("pen_vertical", "pen", "sponge")
#: Tilts tried for the free pen, rad.
FREE_PHI = np.radians(np.linspace(-90.0, 90.0, 13))


def solve_grid(x: Any, y: Any, z: Any, phi: float, geometry: Geometry, elbow_up: bool) -> np.ndarray:
    """The closed-form IK of many targets at once: q, shape (..., 4), NaN where no solution exists.

    Parameters
    ----------
    x, y, z : array_like
        Target points, m (broadcast together).
    phi : float
        Tool tilt, rad.
    geometry : Geometry
        Link lengths, m.
    elbow_up : bool
        True: q3 <= 0, as :func:`~.closed_form.ik_closed_form`.
    """
    g = geometry
    x, y, z = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float), np.asarray(z, float))
    q = _solve_all(x.ravel(), y.ravel(), z.ravel(), float(phi), g.L1, g.L2, g.L3, g.L4, g.l_f, bool(elbow_up))
    return q.reshape(*x.shape, 4)


@numba.njit(cache=True)
def _solve_all(x: np.ndarray, y: np.ndarray, z: np.ndarray, phi: float, L1: float, L2: float, L3: float,
               L4: float, l_f: float, elbow_up: bool) -> np.ndarray:
    q = np.empty((x.size, 4))
    for i in range(x.size):
        q1, q[i, 1], q[i, 2], q[i, 3], _, _ = closed_form_q(x[i], y[i], z[i], phi, L1, L2, L3, L4, l_f, elbow_up)
        q[i, 0] = wrap_angle(q1)
    return q


def _within(q: np.ndarray, q_min: Any, q_max: Any) -> np.ndarray:
    with np.errstate(invalid="ignore"):
        return np.all((q >= np.asarray(q_min)) & (q <= np.asarray(q_max)), axis=-1)


def classify(x: Any, y: Any, z: Any, params: ArmParams, tool: str = "pen_vertical",
             geometry: Geometry | None = None, q_min: Any = None, q_max: Any = None) -> np.ndarray:
    """The code (:data:`UNREACHABLE` .. :data:`BOTH`) of each target point for `tool`.

    ``z`` is the height of what touches the board: for the sponge its face, the tool point
    ``sponge.offset`` higher.  `geometry`, `q_min`, `q_max` override the parameter file's.
    """
    if tool not in TOOLS:
        raise ValueError(f"tool must be one of {', '.join(TOOLS)}, got {tool!r}")
    g = geometry or params.geometry
    lo = params.joint_min if q_min is None else q_min
    hi = params.joint_max if q_max is None else q_max
    zz = np.asarray(z, float) + (params.sponge.offset if tool == "sponge" else 0.0)
    phis = {"pen_vertical": [0.0], "pen": list(FREE_PHI), "sponge": [math.pi / 2]}[tool]
    up = down = np.zeros(np.broadcast_shapes(np.shape(x), np.shape(y), np.shape(zz)), bool)
    for phi in phis:
        up = up | _within(solve_grid(x, y, zz, phi, g, True), lo, hi)
        down = down | _within(solve_grid(x, y, zz, phi, g, False), lo, hi)
    return up.astype(np.int8) * UP_ONLY + down.astype(np.int8) * DOWN_ONLY


@dataclass
class Workspace:
    """One workspace picture's numbers (m, rad); :meth:`as_dict` is the JSON of the page and the CLI."""

    tool: str
    geometry: Geometry
    q_min: tuple[float, ...]
    q_max: tuple[float, ...]
    top_x: np.ndarray
    top_y: np.ndarray
    top: np.ndarray
    side_r: np.ndarray
    side_z: np.ndarray
    side: np.ndarray
    board: tuple[float, float, float, float]
    field: tuple[float, float, float, float]
    cells: list[list[str]]

    def needs(self, name: str) -> list[tuple[int, int]]:
        """The (row, column) of the field's cells whose configuration is `name`."""
        return [(i, j) for i, row in enumerate(self.cells) for j, c in enumerate(row) if c == name]

    def as_dict(self) -> dict[str, Any]:
        """Plain JSON: grids as lists of code rows (row = y for the top view, z for the side view)."""
        g = self.geometry
        return {"tool": self.tool, "geometry": {"L1": g.L1, "L2": g.L2, "L3": g.L3, "L4": g.L4, "l_f": g.l_f},
                "q_min_deg": [round(math.degrees(v), 6) for v in self.q_min],
                "q_max_deg": [round(math.degrees(v), 6) for v in self.q_max],
                "codes": list(CODE_NAMES),
                "top": {"x_m": _r(self.top_x), "y_m": _r(self.top_y), "code": self.top.tolist()},
                "side": {"r_m": _r(self.side_r), "z_m": _r(self.side_z), "code": self.side.tolist()},
                "board_m": list(self.board), "field_m": list(self.field), "cells": self.cells,
                "fits": all(c != "unreachable" for row in self.cells for c in row)}


def _r(a: np.ndarray) -> list[float]:
    return [round(float(v), 6) for v in a]


def field_cells(params: ArmParams, n: int, field_size: float | None = None, tool: str = "pen_vertical",
                geometry: Geometry | None = None, q_min: Any = None, q_max: Any = None) -> list[list[str]]:
    """Configuration each cell of an ``n x n`` field needs, row 0 at the field's low y.

    A cell counts as reachable in a configuration when its centre and four corners are:
    "elbow up" (the working one, whenever it reaches), "elbow down" (only it reaches), "unreachable".
    """
    b = params.board
    size = b.field_size if field_size is None else field_size
    cell = size / n
    x0, _, y0, _ = replace(b, field_size=size).field_bounds()
    out = []
    for i in range(n):
        row = []
        for j in range(n):
            cx, cy = x0 + (j + 0.5) * cell, y0 + (i + 0.5) * cell
            px = np.array([cx, cx - cell / 2, cx + cell / 2, cx - cell / 2, cx + cell / 2])
            py = np.array([cy, cy - cell / 2, cy - cell / 2, cy + cell / 2, cy + cell / 2])
            codes = classify(px, py, b.surface_z, params, tool, geometry, q_min, q_max)
            if np.all(codes & UP_ONLY):
                row.append("elbow up")
            elif np.all(codes & DOWN_ONLY):
                row.append("elbow down")
            else:
                row.append("unreachable")
        out.append(row)
    return out


def workspace(params: ArmParams, tool: str = "pen_vertical", geometry: Geometry | None = None,
              q_min: Any = None, q_max: Any = None, resolution: int = 64, cells: int | None = None,
              field_size: float | None = None) -> Workspace:
    """The reachable workspace for `tool`: top view around the board, side view in the arm's plane.

    Parameters
    ----------
    params : ArmParams
        Limits, board and sponge; `geometry`, `q_min`, `q_max` (rad) override its lengths and limits.
    resolution : int
        Grid points along each axis of each view.
    cells, field_size : int, float
        The playing field whose cells are classified (default the board's 5 x 0.15 m).
    """
    if not 8 <= resolution <= 400:
        raise ValueError(f"resolution must be 8..400 grid points, got {resolution}")
    g = geometry or params.geometry
    lo = tuple(params.joint_min if q_min is None else q_min)
    hi = tuple(params.joint_max if q_max is None else q_max)
    b = params.board
    reach = g.L2 + g.L3 + g.L4
    bx0, bx1, by0, by1 = b.board_bounds()
    x0, x1 = min(bx0, -g.l_f - reach), max(bx1, -g.l_f + reach)
    y0, y1 = min(by0, -reach), max(by1, reach)
    top_x = np.linspace(x0, x1, resolution)
    top_y = np.linspace(y0, y1, resolution)
    top = classify(top_x[None, :], top_y[:, None], b.surface_z, params, tool, g, lo, hi)
    side_r = np.linspace(0.0, reach * 1.05, resolution)
    side_z = np.linspace(g.L1 - reach * 1.05, g.L1 + reach * 1.05, resolution)
    # the arm's plane at q1 = 0: the target (0, r, z) lies at reach r in it (u = l_f, v = r in the closed form)
    off = params.sponge.offset if tool == "sponge" else 0.0
    side = classify(0.0, side_r[None, :], side_z[:, None] - off, params, tool, g, lo, hi)
    n = cells or b.cells
    size = b.field_size if field_size is None else field_size
    field = replace(b, field_size=size).field_bounds()
    return Workspace(tool, g, lo, hi, top_x, top_y, top.astype(np.int8), side_r, side_z, side.astype(np.int8),
                     b.board_bounds(), field, field_cells(params, n, size, tool, g, lo, hi))


def with_lengths(geometry: Geometry, **lengths: float) -> Geometry:
    """`geometry` with some link lengths (m) replaced: ``with_lengths(g, L2=0.25)``."""
    return replace(geometry, **lengths)
