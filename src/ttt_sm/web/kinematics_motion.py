"""The ``/kinematics/motion`` page's JSON: trajectories compared on the twin, forces and velocities at the pen.

docs/kinematics.md, "Lab: trajectories and forces", describes the views.  As on
``/kinematics`` (:mod:`.kinematics`), each view is a plain function of the parameters
and a query (strings, as the URL gives them) returning JSON-ready data; ``ttt-sm
kinematics trajectory|forces --json`` prints the same documents, and a bad value
raises :class:`~.kinematics.KinematicsQueryError` (status 400).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from ..params import ArmParams
from ..twin.forces import ellipses_over_board, force_run, velocity_ellipse
from ..twin.kinematics import IKError, IKSolver, arm_points
from ..twin.trajectories import DRAW_SPEED_M_S, METHODS, PRESS_M, run_move
from .kinematics import KinematicsQueryError, _number, json_route

#: Series are sent every this many chart ticks (50 Hz at the thesis' 500 Hz chart rate).
DECIMATE = 10


def _r(a: Any, nd: int = 6) -> Any:
    """An array as nested lists of rounded floats."""
    return np.round(np.asarray(a, float), nd).tolist()


def _line(params: ArmParams, query: Mapping[str, str]) -> tuple[tuple[float, float], tuple[float, float]]:
    """The move's two points on the board (``x0, y0, x1, y1``, m), default one stroke of an X in the field's centre."""
    b = params.board
    cx, cy = b.field_center_x, b.field_center_y
    defaults = (cx - 0.025, cy - 0.025, cx + 0.025, cy + 0.025)
    x0, y0, x1, y1 = (_number(query, k, d, -1.0, 1.0) for k, d in zip(("x0", "y0", "x1", "y1"), defaults,
                                                                        strict=True))
    assert x0 is not None and y0 is not None and x1 is not None and y1 is not None
    if np.hypot(x1 - x0, y1 - y0) < 0.005:
        raise KinematicsQueryError("x0, y0 and x1, y1 must lie at least 5 mm apart")
    bx0, bx1, by0, by1 = b.board_bounds()
    for name, x, y in (("x0, y0", x0, y0), ("x1, y1", x1, y1)):
        if not (bx0 <= x <= bx1 and by0 <= y <= by1):
            raise KinematicsQueryError(f"{name} = {x:g}, {y:g} m lies off the whiteboard "
                                       f"(x {bx0:g}..{bx1:g}, y {by0:g}..{by1:g} m)")
    return (x0, y0), (x1, y1)


def trajectory_view(params: ArmParams, query: Mapping[str, str]) -> dict[str, Any]:
    """The four moves (``methods``, comma-separated; default all) from ``x0, y0`` to ``x1, y1`` at ``speed`` m/s,
    held ``hold_s`` after; each one's numbers and its series (every :data:`DECIMATE` chart ticks)."""
    pa, pb = _line(params, query)
    speed = _number(query, "speed", DRAW_SPEED_M_S, 0.002, 0.2) or DRAW_SPEED_M_S
    hold = _number(query, "hold_s", 2.0, 0.0, 10.0)
    methods = tuple(m for m in (query.get("methods") or ",".join(METHODS)).split(",") if m)
    bad = [m for m in methods if m not in METHODS]
    if bad or not methods:
        raise KinematicsQueryError(f"methods must be some of {', '.join(METHODS)}, got {query.get('methods')!r}")
    z = params.board.surface_z - PRESS_M
    a, b = (*pa, z), (*pb, z)
    out = []
    for m in methods:
        try:
            r = run_move(params, m, a, b, speed, hold or 0.0)
        except IKError as exc:
            raise KinematicsQueryError(f"the line cannot be drawn: {exc}") from None
        s = slice(DECIMATE - 1, None, DECIMATE)
        out.append({**r.summary(a, b), "t_s": _r(r.t[s], 4), "tip_m": _r(r.tip_m[s]),
                    "target_m": _r(r.target_m[s]), "following_rad": _r(r.following_rad[s], 7),
                    "current_a": _r(r.current_a[s], 4), "ink_m": [_r(p[::4]) for p in r.ink_m]})
    return {"a_m": list(a), "b_m": list(b), "speed_m_s": speed, "hold_s": hold, "press_m": PRESS_M,
            "board_m": list(params.board.board_bounds()), "field_m": list(params.board.field_bounds()),
            "methods": out}


def forces_view(params: ArmParams, query: Mapping[str, str]) -> dict[str, Any]:
    """The Jacobian and velocity ellipse at the pen on the board at ``x, y`` (default the field's centre), the
    ellipses on a ``grid`` x ``grid`` over the field, and a line drawn with the pen's force true and estimated."""
    b = params.board
    x = _number(query, "x", b.field_center_x, -1.0, 1.0)
    y = _number(query, "y", b.field_center_y, -1.0, 1.0)
    n = int(_number(query, "grid", 5, 2, 9) or 5)
    try:
        q = IKSolver(params).solve([x, y, b.surface_z, 0.0]).q
    except IKError as exc:
        raise KinematicsQueryError(f"x, y = {x:g}, {y:g} m: {exc}") from None
    pa, pb = _line(params, query)
    speed = _number(query, "speed", DRAW_SPEED_M_S, 0.002, 0.1) or DRAW_SPEED_M_S
    try:
        run = force_run(params, pa, pb, speed)
    except IKError as exc:
        raise KinematicsQueryError(f"the line cannot be drawn: {exc}") from None
    s = slice(DECIMATE - 1, None, DECIMATE)
    e = run.estimate
    return {"pose": {"x_m": x, "y_m": y, "q_rad": _r(q), "arm_m": _r(arm_points(q, params.geometry)),
                     **velocity_ellipse(q, params)},
            "ellipses": ellipses_over_board(params, n),
            "board_m": list(b.board_bounds()), "field_m": list(b.field_bounds()),
            "line": {"a_m": list(pa), "b_m": list(pb), "speed_m_s": speed, "t_s": _r(run.t[s], 4),
                     "true_n": _r(run.true_n[s], 4), "estimate_n": _r(e.normal_n[s], 4),
                     "estimate_vector_n": _r(e.vector_n[s], 4),
                     "observable": [bool(v) for v in e.observable[s]], "drawing": [bool(v) for v in run.drawing[s]],
                     "errors": run.errors()}}


#: The views by name, as the routes and the CLI call them.
VIEWS: dict[str, Callable[[ArmParams, Mapping[str, str]], dict[str, Any]]] = {
    "trajectory": trajectory_view, "forces": forces_view}


def routes(params: Callable[[], ArmParams], page: Callable[[str], Any]) -> list[Any]:
    """The page ``/kinematics/motion`` and its JSON routes ``/api/kinematics/motion/<view>``."""
    from starlette.requests import Request
    from starlette.responses import Response
    from starlette.routing import Route

    async def motion_page(request: Request) -> Response:
        return page("kinematics_motion.html")  # type: ignore[no-any-return]

    return [Route("/kinematics/motion", motion_page), json_route("/api/kinematics/motion/{view}", VIEWS, params)]
