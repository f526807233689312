"""``ttt-sm kinematics trajectory|forces``: the ``/kinematics/motion`` page's views on the command line.

Each prints the same JSON document as the page's route ``/api/kinematics/motion/<view>``
(``--json``), or a short text, and draws the view into a PNG (``--png PATH``).
docs/kinematics.md, "Lab: trajectories and forces", explains the views.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from typing import Any

from .common import save_png
from .kinematics_view import view_command

#: One colour per trajectory method, as the page draws them.
METHOD_COLOURS = {"increment": "#1f77b4", "step_fr_sw": "#d62728", "cubic": "#2ca02c", "quintic": "#9467bd"}


def add_motion_commands(acts: Any) -> None:
    """Add ``trajectory`` and ``forces`` to the subcommands of ``ttt-sm kinematics`` (`acts`)."""
    tr = acts.add_parser("trajectory", help="constant increments (eq. 3.36), the fr_sw step, cubic and quintic"
                                            " moves compared on the twin",
                         description="One line drawn on the twin four ways: following error, motor current,"
                                     " time to arrive, the ink.")
    _line_args(tr)
    tr.add_argument("--hold", type=float, default=2.0, metavar="S", help="time held at the end, s (default 2)")
    tr.add_argument("--methods", default=None, help="comma-separated subset of increment,step_fr_sw,cubic,quintic")
    _common(tr)
    tr.set_defaults(func=_run("trajectory"))

    fo = acts.add_parser("forces", help="the Jacobian, the velocity ellipse over the board, the pen's contact force"
                                        " from the motor currents",
                         description="The Jacobian and manipulability at a pen position, the velocity ellipses"
                                     " over the field, and a line drawn with the pen's force true and estimated.")
    fo.add_argument("--at", nargs=2, type=float, metavar=("X", "Y"), default=None,
                    help="the pen on the board for the Jacobian, m (default the field's centre)")
    _line_args(fo)
    _common(fo)
    fo.set_defaults(func=_run("forces"))


def _line_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--from", dest="a", nargs=2, type=float, metavar=("X", "Y"), default=None,
                   help="the line's start on the board, m (default one stroke of an X in the field's centre)")
    p.add_argument("--to", dest="b", nargs=2, type=float, metavar=("X", "Y"), default=None,
                   help="the line's end on the board, m")
    p.add_argument("--speed", type=float, default=None, help="drawing speed, m/s (default 0.02)")


def _common(p: argparse.ArgumentParser) -> None:
    p.add_argument("--json", action="store_true", help="print the view as one JSON document")
    p.add_argument("--png", metavar="PATH", default=None, help="draw the view into this PNG file")


def _query(view: str, args: argparse.Namespace) -> dict[str, str]:
    q: dict[str, str] = {}
    for (kx, ky), v in ((("x0", "y0"), args.a), (("x1", "y1"), args.b)):
        if v is not None:
            q[kx], q[ky] = repr(v[0]), repr(v[1])
    if args.speed is not None:
        q["speed"] = repr(args.speed)
    if view == "trajectory":
        q["hold_s"] = repr(args.hold)
        if args.methods:
            q["methods"] = args.methods
    elif args.at is not None:
        q["x"], q["y"] = repr(args.at[0]), repr(args.at[1])
    return q


_OPTIONS = (("x0, y0", "--from"), ("x1, y1", "--to"), ("hold_s", "--hold"), ("methods", "--methods"),
            ("speed", "--speed"), ("x0", "--from X"), ("y0", "--from Y"), ("x1", "--to X"), ("y1", "--to Y"),
            ("x, y", "--at"), ("x", "--at X"), ("y", "--at Y"))


def _option_names(message: str) -> str:
    """A query key at the start of a message as the CLI's option (``hold_s`` -> ``--hold``)."""
    for key, opt in _OPTIONS:
        if message.startswith(key + " "):
            return opt + message[len(key):]
    return message


def _text(view: str, d: dict[str, Any]) -> str:
    if view == "trajectory":
        lines = [f"line ({d['a_m'][0]:.4f}, {d['a_m'][1]:.4f}) -> ({d['b_m'][0]:.4f}, {d['b_m'][1]:.4f}) m"
                 f" at {d['speed_m_s']:g} m/s"]
        lines.append("  method       move (s) arrive (s) max follow (mrad) max tip lag (mm) max I (A)"
                     " ink off line (mm)")
        for m in d["methods"]:
            arrive = "never" if m["arrive_s"] is None else f"{m['arrive_s']:.3f}"
            ink = "-" if m["ink_max_off_line_m"] is None else f"{m['ink_max_off_line_m'] * 1e3:.2f}"
            lines.append(f"  {m['method']:<12} {m['move_s']:>8.3f} {arrive:>10} {m['max_following_rad'] * 1e3:>17.3f}"
                         f" {m['max_tip_lag_m'] * 1e3:>16.2f} {m['max_current_a']:>9.3f} {ink:>17}")
        return "\n".join(lines)
    p, e = d["pose"], d["line"]["errors"]

    def pct(v: float | None) -> str:
        return "n/a" if v is None else f"{v * 100:.1f} %"

    return "\n".join([
        f"pen at ({p['x_m']:.4f}, {p['y_m']:.4f}) m: manipulability |det J| = {p['manipulability']:.3e} m^3,"
        f" velocity ellipse {p['axes_m_per_rad'][0]:.4f} x {p['axes_m_per_rad'][1]:.4f} m/s per rad/s",
        f"contact force while drawing: true {e['mean_true_n'] or 0:.3f} N, estimated {e['mean_estimate_n'] or 0:.3f} N"
        f" (where observable, {e['observable_share'] * 100:.0f} % of the line)",
        f"  relative error: mean {pct(e['mean_rel'])}, 95th percentile {pct(e['p95_rel'])}, max {pct(e['max_rel'])};"
        f" over the whole line: mean {pct(e['all_mean_rel'])}, 95th percentile {pct(e['all_p95_rel'])}"])


def _views() -> dict[str, Any]:
    from ..web.kinematics_motion import VIEWS

    return VIEWS


def _run(view: str) -> Callable[[argparse.Namespace], int]:
    return view_command(view, _views, _query, _text, draw_png, _option_names)


def draw_png(view: str, d: dict[str, Any], path: str) -> None:
    """Draw one view's document (as :data:`~ttt_sm.web.kinematics_motion.VIEWS` returns it) into a PNG at `path`."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    from matplotlib.patches import Ellipse, Rectangle


    if view == "trajectory":
        fig, axes = plt.subplots(2, 2, figsize=(12, 8))
        (ax_ink, ax_lag), (ax_fe, ax_i) = axes
        a, b = d["a_m"], d["b_m"]
        ax_ink.plot([a[0] * 1e3, b[0] * 1e3], [a[1] * 1e3, b[1] * 1e3], "k--", lw=1, label="the line asked for")
        for m in d["methods"]:
            c, name = METHOD_COLOURS[m["method"]], m["method"]
            for k, s in enumerate(m["ink_m"]):
                s = np.asarray(s)
                ax_ink.plot(s[:, 0] * 1e3, s[:, 1] * 1e3, color=c, lw=1.5, label=f"ink: {name}" if k == 0 else None)
            t = np.asarray(m["t_s"])
            lag = np.linalg.norm(np.asarray(m["tip_m"]) - np.asarray(m["target_m"]), axis=1)
            ax_lag.plot(t, lag * 1e3, color=c, label=name)
            ax_fe.plot(t, np.max(np.abs(np.asarray(m["following_rad"])), axis=1) * 1e3, color=c, label=name)
            cur = np.asarray(m["current_a"])
            ax_i.plot(t, cur[:, 1], color=c, label=f"{name}, drive 2")
            ax_i.plot(t, cur[:, 2], color=c, ls=":", label=f"{name}, drive 3")
        ax_ink.set_aspect("equal")
        ax_ink.set_xlabel("x (mm)")
        ax_ink.set_ylabel("y (mm)")
        ax_ink.set_title("ink on the board")
        ax_lag.set_xlabel("time (s)")
        ax_lag.set_ylabel("|tip - target| (mm)")
        ax_lag.set_title("how far the pen is from its target")
        ax_fe.set_xlabel("time (s)")
        ax_fe.set_ylabel("max |setpoint - encoder| (mrad)")
        ax_fe.set_title("following error of the cascades (drives 1-3)")
        ax_i.set_xlabel("time (s)")
        ax_i.set_ylabel("motor current (A)")
        ax_i.set_title("motor currents, drives 2 and 3")
        for ax in axes.flat:
            ax.legend(fontsize=7)
            ax.grid(alpha=0.3)
    else:
        fig, (ax_b, ax_f) = plt.subplots(1, 2, figsize=(12, 5.5), gridspec_kw={"width_ratios": [1, 1.3]})
        bx0, bx1, by0, by1 = d["board_m"]
        fx0, fx1, fy0, fy1 = d["field_m"]
        ax_b.add_patch(Rectangle((bx0, by0), bx1 - bx0, by1 - by0, fill=False, ec="k", label="whiteboard"))
        ax_b.add_patch(Rectangle((fx0, fy0), fx1 - fx0, fy1 - fy0, fill=False, ec="#d62728", label="playing field"))
        scale = 0.02 / max(max(e["axes_m_per_rad"]) for e in d["ellipses"])
        what = f"tip velocity for unit joint speeds (1 m/s drawn {scale:.3f} m long)"
        for k, e in enumerate(d["ellipses"]):
            w, h = (2 * v * scale for v in e["axes_m_per_rad"])
            ax_b.add_patch(Ellipse((e["x_m"], e["y_m"]), w, h, angle=np.degrees(e["angle_rad"]), fc="#9ecae1",
                                   ec="#1f77b4", alpha=0.7, label=what if k == 0 else None))
        p = d["pose"]
        ax_b.plot([p["x_m"]], [p["y_m"]], "k*", ms=10, label=f"pen: |det J| = {p['manipulability']:.2e} m^3")
        line = d["line"]
        ax_b.plot([line["a_m"][0], line["b_m"][0]], [line["a_m"][1], line["b_m"][1]], color="#ff7f0e", lw=2,
                  label="the line drawn (right)")
        ax_b.set_aspect("equal")
        ax_b.set_xlim(bx0 - 0.01, bx1 + 0.01)
        ax_b.set_ylim(by0 - 0.01, by1 + 0.06)
        ax_b.set_xlabel("x (m)")
        ax_b.set_ylabel("y (m)")
        ax_b.set_title("manipulability ellipses over the board (pen vertical)")
        ax_b.legend(fontsize=7, loc="upper left")
        t = np.asarray(line["t_s"])
        est = np.asarray(line["estimate_n"], float)
        obs = np.asarray(line["observable"])
        ax_f.plot(t, line["true_n"], "k-", lw=2, label="true contact force (the pen's spring)")
        ax_f.plot(t, est, color="#1f77b4", lw=1, alpha=0.5, label="estimate J^-T tau from the currents")
        ax_f.plot(t, np.where(obs, est, np.nan), color="#1f77b4", lw=2,
                  label="... where both pitch drives turn (friction known)")
        true = np.asarray(line["true_n"])
        ax_f.fill_between(t, 0.9 * true, 1.1 * true, color="0.85", label="+-10 % of the true force")
        e = line["errors"]
        ax_f.set_title("normal force on the pen: mean error "
                       + ("n/a" if e["mean_rel"] is None else f"{e['mean_rel'] * 100:.1f} %")
                       + ", 95th percentile " + ("n/a" if e["p95_rel"] is None else f"{e['p95_rel'] * 100:.1f} %"))
        ax_f.set_xlabel("time (s)")
        ax_f.set_ylabel("force (N)")
        ax_f.set_ylim(-1.0, 3.5)
        ax_f.legend(fontsize=7, loc="lower center")
        ax_f.grid(alpha=0.3)
    save_png(fig, path)
