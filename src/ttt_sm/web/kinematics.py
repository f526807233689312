"""The ``/kinematics`` page's JSON: the workspace, the DH table and its frames, the IK race.

docs/kinematics.md, "Lab", describes the views.

Each view is a plain function of the parameters and a query (``dict`` of
strings, as the URL gives it) returning JSON-ready data; ``ttt-sm
kinematics`` prints the same documents.  A bad query value raises
:class:`KinematicsQueryError`, a one-line message naming the key, which the
route answers with status 400.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from ..params import ArmParams
from ..twin.kinematics import arm_points, fk, jacobian
from ..twin.kinematics.dh import DH_COLUMNS, dh_frames, dh_table
from ..twin.kinematics.race import race
from ..twin.kinematics.solver import HOME_Q
from ..twin.kinematics.workspace import TOOLS, with_lengths, workspace
from ..vision.simulated import CameraPose


class KinematicsQueryError(ValueError):
    """A query value of a kinematics view is missing or out of its range."""


def _number(query: Mapping[str, str], key: str, default: float | None, lo: float, hi: float) -> float | None:
    raw = query.get(key)
    if raw is None or raw == "":
        return default
    try:
        value = float(raw)
    except ValueError:
        raise KinematicsQueryError(f"{key} must be a number, got {raw!r}") from None
    if not (math.isfinite(value) and lo <= value <= hi):
        raise KinematicsQueryError(f"{key} must be a number in [{lo:g}, {hi:g}], got {raw!r}")
    return value


def workspace_view(params: ArmParams, query: Mapping[str, str]) -> dict[str, Any]:
    """The workspace for ``tool``, lengths ``L2``/``L3`` (m), limits ``q2_max_deg``/``q3_max_deg``, a ``cells``
    field of ``cell_m`` cells (default the board's)."""
    tool = query.get("tool") or "pen_vertical"
    if tool not in TOOLS:
        raise KinematicsQueryError(f"tool must be one of {', '.join(TOOLS)}, got {tool!r}")
    g = params.geometry
    lengths = {k: v for k in ("L2", "L3") if (v := _number(query, k, None, 0.05, 0.6)) is not None}
    geometry = with_lengths(g, **lengths)
    hi = list(params.joint_max)
    for i, key in ((1, "q2_max_deg"), (2, "q3_max_deg")):
        v = _number(query, key, None, -180.0, 180.0)
        if v is not None:
            hi[i] = math.radians(v)
    lo = params.joint_min
    for i in range(4):
        if hi[i] <= lo[i]:
            raise KinematicsQueryError(f"q{i + 1}'s upper limit {math.degrees(hi[i]):g} deg is not above its"
                                       f" lower limit {math.degrees(lo[i]):g} deg")
    cells = int(_number(query, "cells", params.board.cells, 1, 12) or params.board.cells)
    cell_m = _number(query, "cell_m", params.board.cell_size, 0.005, 0.2) or params.board.cell_size
    resolution = int(_number(query, "resolution", 64, 8, 200) or 64)
    w = workspace(params, tool, geometry, lo, hi, resolution=resolution, cells=cells, field_size=cells * cell_m)
    # the game's camera (the simulated one, as mounted by default: beyond the far edge, thesis section 3.6.3)
    camera = CameraPose.beyond_far_edge(params).board_footprint(params.board.surface_z)
    return {**w.as_dict(), "camera_field_m": [[round(float(x), 5), round(float(y), 5)] for x, y in camera]}


def _q_deg(query: Mapping[str, str]) -> np.ndarray:
    raw = query.get("q_deg")
    if not raw:
        return np.asarray(HOME_Q, float)
    try:
        values = [float(v) for v in raw.split(",")]
    except ValueError:
        raise KinematicsQueryError(f"q_deg must be four numbers separated by commas (deg), got {raw!r}") from None
    if len(values) != 4 or not all(math.isfinite(v) and abs(v) <= 360 for v in values):
        raise KinematicsQueryError(f"q_deg must be four finite angles in [-360, 360] deg, got {raw!r}")
    return np.radians(values)


def dh_view(params: ArmParams, query: Mapping[str, str]) -> dict[str, Any]:
    """The DH table (thesis eqs. 3.17-3.21) and frames 0..4 at ``q_deg`` (default the home pose)."""
    q = _q_deg(query)
    g = params.geometry
    frames = dh_frames(q, g)
    return {"columns": list(DH_COLUMNS),
            "rows": [[round(float(v), 9) for v in row] for row in dh_table(g)],
            "q_rad": [float(v) for v in q],
            "frames": [{"origin_m": [float(v) for v in f[:3, 3]],
                        "axes": [[float(v) for v in f[:3, k]] for k in range(3)]} for f in frames],
            "fk": [float(v) for v in fk(q, g)],
            "arm_m": [[float(v) for v in p] for p in arm_points(q, g)]}


def race_view(params: ArmParams, query: Mapping[str, str]) -> dict[str, Any]:
    """The IK race to ``x, y, z`` (m), ``phi_deg`` from the home pose, up to ``max_iterations``.

    ``seconds`` of each method is its second run's (the first compiles the kernels); output only."""
    x = _number(query, "x", None, -2.0, 2.0)
    y = _number(query, "y", None, -2.0, 2.0)
    if x is None or y is None:
        raise KinematicsQueryError("x and y (m) are required: the target on the board")
    z = _number(query, "z", params.board.surface_z, -2.0, 2.0)
    phi = _number(query, "phi_deg", 0.0, -180.0, 180.0)
    n = int(_number(query, "max_iterations", 100, 1, 1000) or 100)
    target = np.array([x, y, z, math.radians(phi or 0.0)])
    race(target, params, max_iterations=n)  # the first call compiles and fills caches: time the second, warm
    results = race(target, params, max_iterations=n)
    g = params.geometry
    out = []
    for r in results:
        finite = [q for q in r.iterates if np.isfinite(q).all()]
        dets = [float(np.linalg.det(jacobian(q, g))) for q in finite]
        out.append({"method": r.method, "converged": r.converged, "reason": r.reason,
                    "iterations": len(r.iterates) - 1, "seconds": r.seconds,
                    "errors_m": [e if math.isfinite(e) else None for e in r.errors],
                    "tips_m": [[float(v) for v in fk(q, g)[:3]] for q in finite],
                    "arm_m": [[float(v) for v in p] for p in arm_points(finite[-1], g)] if finite else None,
                    "q_rad": [float(v) for v in r.q] if np.isfinite(r.q).all() else None,
                    "min_abs_det": min((abs(d) for d in dets), default=None)})
    return {"target": [float(v) for v in target], "max_iterations": n, "methods": out}


#: The views by name, as routes and the CLI call them.
VIEWS: dict[str, Callable[[ArmParams, Mapping[str, str]], dict[str, Any]]] = {
    "workspace": workspace_view, "dh": dh_view, "race": race_view}


def json_route(path: str, views: Mapping[str, Callable[[ArmParams, Mapping[str, str]], dict[str, Any]]],
               params: Callable[[], ArmParams]) -> Any:
    """The route ``path`` (with ``{view}``) answering ``views[view](params(), query)`` as JSON.

    An unknown view is a 404, a bad query value a 400 with the one-line message; the
    view runs in a worker thread (a twin run takes a while).
    """
    import asyncio

    from starlette.requests import Request
    from starlette.responses import JSONResponse, Response
    from starlette.routing import Route

    async def view(request: Request) -> Response:
        name = request.path_params["view"]
        fn = views.get(name)
        if fn is None:
            return JSONResponse({"error": f"no view {name!r}: one of {', '.join(views)}"}, status_code=404)
        try:
            data = await asyncio.to_thread(fn, params(), dict(request.query_params))
        except (KinematicsQueryError, ValueError) as exc:
            return JSONResponse({"error": str(exc)}, status_code=400)
        return JSONResponse(data, headers={"Cache-Control": "no-store"})

    return Route(path, view)


def routes(params: Callable[[], ArmParams]) -> list[Any]:
    """The page's JSON routes (``/api/kinematics/<view>``), for :func:`~.server.create_app`."""
    return [json_route("/api/kinematics/{view}", VIEWS, params)]
