"""``ttt-sm kinematics workspace|dh|race``: the ``/kinematics`` page's views on the command line.

(``trajectory`` and ``forces``, the ``/kinematics/motion`` page's, come from :mod:`.kinematics_motion`.)

Each prints the same JSON document as the page's route ``/api/kinematics/<view>``
(``--json``), or a short text, and draws the view into a PNG (``--png PATH``).
docs/kinematics.md, "Lab", explains the views and the exercises.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from typing import Any

from .common import add_group, save_png
from .kinematics_view import view_command


def register(sub: Any) -> argparse.ArgumentParser:
    """Add the ``kinematics`` command group to the subcommands of ``ttt-sm``."""
    help_ = "the kinematics lab: reachable workspace, DH table, IK methods raced (the /kinematics page)"
    sp, acts = add_group(sub, "kinematics", help_)

    ws = acts.add_parser("workspace", help="where the pen tip reaches within the joint limits, top and side view",
                         description="The pen tip's reachable set within the joint limits, the board and the"
                                     " field over it, and the configuration each field cell needs.")
    ws.add_argument("--tool", choices=("pen_vertical", "pen", "sponge"), default="pen_vertical",
                    help="pen_vertical: phi = 0 (drawing); pen: any tilt; sponge: phi = 90 deg (default"
                         " pen_vertical)")
    ws.add_argument("--L2", type=float, default=None, help="upper arm length, m (default: the parameter file's)")
    ws.add_argument("--L3", type=float, default=None, help="forearm length, m (default: the parameter file's)")
    ws.add_argument("--q2-max-deg", type=float, default=None, help="shoulder's upper limit, deg")
    ws.add_argument("--q3-max-deg", type=float, default=None, help="elbow's upper limit, deg")
    ws.add_argument("--cells", type=int, default=None, help="cells per side of the field (default the board's)")
    ws.add_argument("--cell-m", type=float, default=None, help="cell side, m (default the board's)")
    _common(ws)
    ws.set_defaults(func=_run("workspace"))

    dh = acts.add_parser("dh", help="the Denavit-Hartenberg table (thesis eqs. 3.17-3.21) and its frames",
                         description="The DH table derived from the thesis' transforms and the frames at a pose.")
    dh.add_argument("--q-deg", nargs=4, type=float, metavar=("Q1", "Q2", "Q3", "Q4"), default=None,
                    help="joint angles, deg (default the home pose)")
    _common(dh)
    dh.set_defaults(func=_run("dh"))

    rc = acts.add_parser("race", help="five IK methods raced on one target",
                         description="The thesis' LM with fixed lambda, adaptive DLS, analytic elbow up and"
                                     " down, the twist step: iterations, error, why each stopped.")
    rc.add_argument("--target", nargs=2, type=float, metavar=("X", "Y"), required=True,
                    help="the target on the board, m")
    rc.add_argument("--z", type=float, default=None, help="target height, m (default the board's surface)")
    rc.add_argument("--phi-deg", type=float, default=0.0, help="tool tilt, deg (default 0: the pen vertical)")
    rc.add_argument("--max-iterations", type=int, default=100, help="iterations per method (default 100)")
    _common(rc)
    rc.set_defaults(func=_run("race"))
    from .kinematics_motion import add_motion_commands

    add_motion_commands(acts)  # trajectory, forces: the /kinematics/motion page's views
    return sp


def _common(p: argparse.ArgumentParser) -> None:
    p.add_argument("--json", action="store_true", help="print the view as one JSON document")
    p.add_argument("--png", metavar="PATH", default=None, help="draw the view into this PNG file")


def _query(view: str, args: argparse.Namespace) -> dict[str, str]:
    q: dict[str, str] = {}

    def put(key: str, value: Any) -> None:
        if value is not None:
            q[key] = repr(value) if isinstance(value, float) else str(value)

    if view == "workspace":
        put("tool", args.tool)
        put("L2", args.L2)
        put("L3", args.L3)
        put("q2_max_deg", args.q2_max_deg)
        put("q3_max_deg", args.q3_max_deg)
        put("cells", args.cells)
        put("cell_m", args.cell_m)
    elif view == "dh":
        if args.q_deg is not None:
            q["q_deg"] = ",".join(repr(v) for v in args.q_deg)
    else:
        put("x", args.target[0])
        put("y", args.target[1])
        put("z", args.z)
        put("phi_deg", args.phi_deg)
        put("max_iterations", args.max_iterations)
    return q


def _text(view: str, data: dict[str, Any]) -> str:
    if view == "workspace":
        marks = {"elbow up": "U", "elbow down": "D", "unreachable": "-"}
        rows = ["".join(marks[c] for c in row) for row in reversed(data["cells"])]
        return (f"workspace ({data['tool']}): field fits: {'yes' if data['fits'] else 'no'}; cells (far row first,"
                " U elbow up, D elbow down only, - unreachable):\n" + "\n".join("  " + r for r in rows))
    if view == "dh":
        lines = ["link  theta offset (rad)  d (m)    a (m)    alpha (rad)"]
        for i, (t, d, a, al) in enumerate(data["rows"], 1):
            lines.append(f"{i:<5} {t:<19.6f} {d:<8.4f} {a:<8.4f} {al:.6f}")
        return "\n".join(lines)
    lines = [f"IK race to x={data['target'][0]:.4f} m y={data['target'][1]:.4f} m z={data['target'][2]:.4f} m"]
    for m in data["methods"]:
        err = m["errors_m"][-1]
        lines.append(f"  {m['method']:<14} {m['reason']:<16} {m['iterations']:>4} iterations, final error "
                     + ("n/a" if err is None else f"{err:.2e} m") + f", {m['seconds'] * 1e6:.1f} us")
    return "\n".join(lines)


def _views() -> dict[str, Any]:
    from ..web.kinematics import VIEWS

    return VIEWS


def _run(view: str) -> Callable[[argparse.Namespace], int]:
    return view_command(view, _views, _query, _text, draw_png, _option_names)


def _option_names(message: str) -> str:
    """A query key in a message as the CLI's option (``q2_max_deg`` -> ``--q2-max-deg``)."""
    for key, opt in (("q2_max_deg", "--q2-max-deg"), ("q3_max_deg", "--q3-max-deg"), ("cell_m", "--cell-m"),
                     ("max_iterations", "--max-iterations"), ("phi_deg", "--phi-deg"), ("cells", "--cells"),
                     ("L2", "--L2"), ("L3", "--L3"), ("q_deg", "--q-deg"), ("x", "--target X"), ("y", "--target Y"),
                     ("z", "--z"), ("tool", "--tool")):
        if message.startswith(key + " "):
            return opt + message[len(key):]
    return message



#: Colours of the workspace codes: unreachable, elbow up only, elbow down only, both.
CODE_COLOURS = ("#ffffff", "#9ecae1", "#fdae6b", "#a1d99b")


def draw_png(view: str, data: dict[str, Any], path: str) -> None:
    """Draw one view's document (as :data:`~ttt_sm.web.kinematics.VIEWS` returns it) into a PNG at `path`."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch, Polygon, Rectangle


    if view == "workspace":
        fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 5.5))
        cmap = ListedColormap(CODE_COLOURS)
        t, s = data["top"], data["side"]
        ax1.pcolormesh(t["x_m"], t["y_m"], t["code"], cmap=cmap, vmin=0, vmax=3, shading="nearest")
        bx0, bx1, by0, by1 = data["board_m"]
        fx0, fx1, fy0, fy1 = data["field_m"]
        ax1.add_patch(Rectangle((bx0, by0), bx1 - bx0, by1 - by0, fill=False, ec="k", lw=1.5,
                                label="whiteboard"))
        ax1.add_patch(Polygon(data["camera_field_m"], closed=True, fill=False, ec="#1f77b4", lw=1.5, ls="--",
                              label="the camera's field"))
        ax1.add_patch(Rectangle((fx0, fy0), fx1 - fx0, fy1 - fy0, fill=False, ec="#d62728", lw=1.5,
                                label="playing field"))
        n = len(data["cells"])
        cell = (fx1 - fx0) / n
        for i, row in enumerate(data["cells"]):
            for j, c in enumerate(row):
                ax1.text(fx0 + (j + 0.5) * cell, fy0 + (i + 0.5) * cell, {"elbow up": "U", "elbow down": "D"}
                         .get(c, "x"), ha="center", va="center", fontsize=7)
        ax1.plot([-data["geometry"]["l_f"]], [0.0], "k^", label="base axis")
        ax1.set_aspect("equal")
        ax1.set_xlabel("x (m)")
        ax1.set_ylabel("y (m)")
        ax1.set_title(f"top view, board plane ({data['tool']})")
        ax2.pcolormesh(s["r_m"], s["z_m"], s["code"], cmap=cmap, vmin=0, vmax=3, shading="nearest")
        ax2.axhline(0.0, color="k", lw=1.5, label="board surface z = 0")
        ax2.plot([0.0], [data["geometry"]["L1"]], "ko", label="shoulder axis")
        ax2.set_aspect("equal")
        ax2.set_xlabel("reach r in the arm's plane (m)")
        ax2.set_ylabel("z (m)")
        ax2.set_title("side view, arm's plane")
        codes = [Patch(fc=c, ec="0.6", label=name) for c, name in zip(CODE_COLOURS, data["codes"], strict=True)]
        h1, _ = ax1.get_legend_handles_labels()
        ax1.legend(handles=h1 + codes, fontsize=7, loc="lower left")
        ax2.legend(fontsize=7, loc="lower left")
    elif view == "dh":
        fig = plt.figure(figsize=(11, 5))
        ax = fig.add_subplot(1, 2, 1, projection="3d")
        origins = [f["origin_m"] for f in data["frames"]]
        ax.plot(*zip(*origins, strict=True), "k-o", label="frame origins 0..4 (m)")
        for k, (colour, name) in enumerate((("#d62728", "x"), ("#2ca02c", "y"), ("#1f77b4", "z"))):
            for i, f in enumerate(data["frames"]):
                o, a = f["origin_m"], f["axes"][k]
                ax.quiver(*o, *(0.04 * v for v in a), color=colour, label=f"{name} axis" if i == 0 else None)
        for i, o in enumerate(origins):
            ax.text(*o, f" {i}", fontsize=9)
        lows = [min(o[k] for o in origins) - 0.05 for k in range(3)]
        highs = [max(o[k] for o in origins) + 0.05 for k in range(3)]
        ax.set_xlim(lows[0], highs[0])
        ax.set_ylim(lows[1], highs[1])
        ax.set_zlim(lows[2], highs[2])
        ax.set_box_aspect([h - lo for lo, h in zip(lows, highs, strict=True)])
        from matplotlib.ticker import MaxNLocator

        ax.xaxis.set_major_locator(MaxNLocator(3))
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        ax.set_zlabel("z (m)")
        ax.legend(fontsize=7, loc="upper left")
        ax.set_title("DH frames at q = " + ", ".join(f"{v * 57.29578:.0f}" for v in data["q_rad"]) + " deg")
        tab = fig.add_subplot(1, 2, 2)
        tab.axis("off")
        rows = [[str(i + 1)] + [f"{v:.4f}" for v in r] for i, r in enumerate(data["rows"])]
        tb = tab.table(cellText=rows, colLabels=["link", "theta offset (rad)", "d (m)", "a (m)", "alpha (rad)"],
                       colWidths=[0.1, 0.3, 0.2, 0.2, 0.2], loc="center")
        tb.auto_set_font_size(False)
        tb.set_fontsize(10)
        tb.scale(1, 1.6)
        tab.set_title("DH table (theta_i = q_i + offset)")
    else:
        fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 5))
        for m in data["methods"]:
            errs = [e for e in m["errors_m"] if e is not None]
            label = f"{m['method']}: {m['reason']} ({m['iterations']} it., {m['seconds'] * 1e6:.1f} us)"
            ax1.semilogy(range(len(errs)), [max(e, 1e-17) for e in errs], "-o", ms=3, label=label)
            tips = m["tips_m"]
            if tips:
                ax2.plot([p[0] for p in tips], [p[1] for p in tips], "-o", ms=3, label=m["method"])
        ax1.axhline(1e-5, color="0.5", ls="--", label="tolerance 1e-5 m")
        ax1.set_xlabel("iteration")
        ax1.set_ylabel("tip position error (m)")
        ax1.set_title("error vs iteration")
        ax1.legend(fontsize=7)
        ax2.plot([data["target"][0]], [data["target"][1]], "k*", ms=12, label="target")
        ax2.set_aspect("equal")
        ax2.set_xlabel("x (m)")
        ax2.set_ylabel("y (m)")
        ax2.set_title("pen tip per iteration, top view")
        ax2.legend(fontsize=7)
    save_png(fig, path)
