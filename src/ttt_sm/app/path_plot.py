"""The path plot of one drawing: where the pen went against where it was sent, and why.

Thesis section 3.5 compares the desired path, the path forward kinematics
gives from the encoders and the true one (figs. 3.15-3.20).  ``ttt-sm draw``
writes this plot for each drawing (``paths_*.png``):

- **left, the drawing seen from above** (x right, y away from the robot, as
  the board picture and the thesis' fig. 3.26): the desired path with the pen
  down (black) and up (grey, dashed: travel, lowering and lifting, where the
  desired pose may also jump), the true pen tip where it touched the board
  (the ink) and where it was in the air, and numbered starts of the strokes;
- **right, over time**: which state of the Control chart was active (one
  colour per state, also shading the panels below); the pen's height, desired
  and true, against the board surface; and the error along the path: the
  distance of the ink from the desired pen-down path (what ``rms_error_mm``
  and ``max_error_mm`` summarise) and how far the encoders' view (forward
  kinematics of the encoder angles) is from the true tip.

"True" values are the simulation's ground truth (``sim.truth``): a real arm
shows only the desired path and the encoders' view.  The plot is drawn from
a :class:`PathData` of plain arrays; :mod:`.drawing` records them.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..files import save_figure

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

#: A jump of the desired pose larger than this within one chart step is called out, m.
JUMP_M = 0.005
#: Colours: desired pen down / pen up, true tip on the board / in the air, encoders' view.
DESIRED_DOWN = "k"
DESIRED_UP = "0.6"
TRUE_INK = "C0"
TRUE_AIR = "#9ecae1"
ENCODERS = "C1"
PEN_UP_LABEL = "desired, pen up (no ink): travel, lowering, lifting, the step to the waiting pose"


@dataclass(frozen=True)
class PathData:
    """What one drawing's path plot shows (lengths in m, times in s of simulated time).

    Attributes
    ----------
    t : array, shape (N,)
        Time of each chart step recorded.
    desired : array, shape (N, 3)
        The Control chart's X_out, Y_out, Z_out.
    fk_encoder : array, shape (N, 3)
        Forward kinematics of the encoder angles (what the PC knows).
    fk_true : array, shape (N, 3)
        The true tool tip (ground truth).
    strokes : list of (points (M, 2), times (M,), error_m (M,))
        The ink this drawing laid: the true tip's path on the board, and each
        point's distance from the desired pen-down path.
    runs : list of array (K, 2)
        The desired pen-down path, one polyline per stroke.
    tip_vs_encoders_m : array, shape (N,)
        |fk_encoder - true tip| in x, y while the pen touched the board, NaN while lifted.
    states : list of (time, label)
        When each state of the Control chart became active (``"parent.leaf"``).
    surface_z : float
        Height of the board surface.
    field_bounds : (x_min, x_max, y_min, y_max)
        The playing field; `cell_size` its cells' side, `cells` per row.
    notes : list of str
        Lines added under the plot's footnote.
    """

    t: np.ndarray
    desired: np.ndarray
    fk_encoder: np.ndarray
    fk_true: np.ndarray
    strokes: list[tuple[np.ndarray, np.ndarray, np.ndarray]]
    runs: list[np.ndarray]
    tip_vs_encoders_m: np.ndarray
    states: list[tuple[float, str]]
    surface_z: float
    field_bounds: tuple[float, float, float, float]
    cell_size: float
    cells: int = 5
    notes: list[str] = field(default_factory=list)


def state_spans(states: list[tuple[float, str]], t_end: float) -> list[tuple[float, float, str]]:
    """(start, end, label) of each state's stay, from the change list; the last ends at `t_end`.

    A state entered at `t_end` itself (the ``wait_1`` a drawing ends in) has no span.
    """
    ends = [t for t, _ in states[1:]] + [t_end]
    return [(t0, t1, label) for (t0, label), t1 in zip(states, ends, strict=True) if t1 > t0]


def path_figure(d: PathData, title: str, subtitle: str = "") -> Figure:
    """The path plot as a matplotlib figure (see the module docstring for what it shows)."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(14.0, 9.0), dpi=80)
    grid = fig.add_gridspec(3, 2, width_ratios=(1.0, 1.25), height_ratios=(0.3, 1.0, 1.0),
                            left=0.055, right=0.985, top=0.875, bottom=0.25, wspace=0.16, hspace=0.1)
    xy = fig.add_subplot(grid[:, 0])
    strip = fig.add_subplot(grid[0, 1])
    zax = fig.add_subplot(grid[1, 1], sharex=strip)
    eax = fig.add_subplot(grid[2, 1], sharex=strip)
    t0 = float(d.t[0])
    spans = [(a - t0, b - t0, label) for a, b, label in state_spans(d.states, float(d.t[-1]))]
    colours = _state_colours([label for _, _, label in spans])

    _xy_panel(xy, d)
    _state_strip(strip, spans, colours)
    from matplotlib.patches import Patch

    fig.legend(handles=[Patch(color=c, label=label) for label, c in colours.items()], loc="upper left",
               bbox_to_anchor=(strip.get_position().x0 - 0.005, 0.185), ncol=3, fontsize=8, frameon=False,
               handlelength=1.2, columnspacing=1.2,
               title="states of the Control chart (sub-chart.state), in the order they came", title_fontsize=8.5,
               alignment="left")
    for ax in (zax, eax):
        for a, b, label in spans:
            ax.axvspan(a, b, color=colours[label], alpha=0.18, lw=0, zorder=0)
    _height_panel(zax, d, t0)
    _error_panel(eax, d, t0)

    fig.text(0.055, 0.975, title, ha="left", va="top", fontsize=14)
    if subtitle:
        fig.text(0.055, 0.935, subtitle, ha="left", va="top", fontsize=9.5, color="0.3")
    notes = ["'true' = the simulation's ground truth (sim.truth): a real arm shows only the desired path "
             "and the encoders' view."]
    if _jumps(d).size:
        notes.append("After the step to the waiting pose the true tool tip leaves the straight dashed line: "
                     "the setpoint filters smooth each joint, not the path.")
    notes += d.notes
    fig.text(0.055, 0.012, "\n".join(notes), ha="left", va="bottom", fontsize=8.5, color="0.25")
    return fig


def save_path_plot(d: PathData, path: str | Path, title: str, subtitle: str = "") -> Path:
    """Write :func:`path_figure` to a PNG file; returns the path."""
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    return save_figure(path_figure(d, title, subtitle), p)


# ----------------------------------------------------------------------------- panels


def _pen_down(d: PathData) -> np.ndarray:
    return np.asarray(d.desired[:, 2] <= d.surface_z)


def _split(mask: np.ndarray) -> list[slice]:
    """Runs of True in `mask`, each extended by one sample so that neighbouring runs join."""
    edges = np.flatnonzero(np.diff(np.concatenate(([0], mask.astype(np.int8), [0]))))
    return [slice(a, min(b + 1, len(mask))) for a, b in zip(edges[::2], edges[1::2], strict=True)]


def _xy_panel(ax: Axes, d: PathData) -> None:
    mm = 1e3
    down = _pen_down(d)
    des = d.desired * mm
    # the field's lines and cell labels for orientation (cell (1, 1) at the top right)
    fx0, fx1, fy0, fy1 = (v * mm for v in d.field_bounds)
    L = d.cell_size * mm
    for k in range(0, d.cells + 1):
        ls = ":" if k in (0, d.cells) else (0, (4, 4))
        ax.plot([fx0, fx1], [fy1 - k * L] * 2, color="0.75", ls=ls, lw=0.8, zorder=0)
        ax.plot([fx1 - k * L] * 2, [fy0, fy1], color="0.75", ls=ls, lw=0.8, zorder=0)
    ax.plot([], [], color="0.75", ls=(0, (4, 4)), lw=0.8, label="the field's lines; (row, column) labels its cells")
    for i, sl in enumerate(_split(~down)):
        ax.plot(des[sl, 0], des[sl, 1], color=DESIRED_UP, ls="--", lw=1.0, zorder=1,
                label=PEN_UP_LABEL if i == 0 else None)
    air = ~_touching(d)
    for i, sl in enumerate(_split(air)):
        ax.plot(d.fk_true[sl, 0] * mm, d.fk_true[sl, 1] * mm, color=TRUE_AIR, lw=1.0, zorder=2,
                label="true tool tip in the air" if i == 0 else None)
    for i, run in enumerate(d.runs):
        ax.plot(run[:, 0] * mm, run[:, 1] * mm, color=DESIRED_DOWN, lw=1.0, zorder=3,
                label="desired, pen down (X_out, Y_out of the Control chart)" if i == 0 else None)
    for i, (pts, _, _) in enumerate(d.strokes):
        ax.plot(pts[:, 0] * mm, pts[:, 1] * mm, color=TRUE_INK, lw=1.6, alpha=0.8, zorder=4,
                label="true pen tip on the board: the ink" if i == 0 else None)
    for i, run in enumerate(d.runs):
        ax.annotate(str(i + 1), run[0] * mm, fontsize=8, color="w", ha="center", va="center", zorder=6,
                    bbox={"boxstyle": "circle,pad=0.15", "facecolor": "k", "edgecolor": "none"})
    ax.plot([], [], "o", color="k", ms=7, label="n: where pen-down stroke n starts")
    # the view: the pen-down path widened to the whole cells it lies in, so that their lines frame
    # it (travel runs off the view towards the waiting pose)
    lo = np.min([r.min(axis=0) for r in d.runs], axis=0) * mm
    hi = np.max([r.max(axis=0) for r in d.runs], axis=0) * mm
    for axis, top in ((0, fx1), (1, fy1)):  # cell edges lie at top - k L, k = 0..cells
        k_lo = np.clip(np.ceil((top - lo[axis]) / L - 1e-6), 0, d.cells)
        k_hi = np.clip(np.floor((top - hi[axis]) / L + 1e-6), 0, d.cells)
        lo[axis], hi[axis] = min(lo[axis], top - k_lo * L), max(hi[axis], top - k_hi * L)
    cx, cy = (lo + hi) / 2
    half = float(np.max(hi - lo)) / 2 + 3.0
    ax.set_xlim(cx - half, cx + half)
    ax.set_ylim(cy - half, cy + half)
    for r in range(d.cells):  # label the cells whose centre is in view, at their top left corner
        for c in range(d.cells):
            if abs(fx1 - (c + 0.5) * L - cx) < half and abs(fy1 - (r + 0.5) * L - cy) < half:
                ax.text(fx1 - (c + 1) * L + 1.0, fy1 - r * L - 1.0, f"({r + 1}, {c + 1})", fontsize=8,
                        color="0.55", ha="left", va="top", zorder=0, clip_on=True)
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm): away from the robot")
    ax.set_title("The drawing seen from above (robot at the bottom)\n"
                 "the ink hides the desired path: its error is plotted on the right", fontsize=10.5)
    ax.legend(loc="upper left", bbox_to_anchor=(0.0, -0.08), fontsize=8.5, ncol=1, frameon=False)
    ax.grid(alpha=0.2)


def _jumps(d: PathData) -> np.ndarray:
    """Indices i where the desired pose jumps more than JUMP_M from sample i to i + 1."""
    return np.flatnonzero(np.linalg.norm(np.diff(d.desired, axis=0), axis=1) > JUMP_M)


def _touching(d: PathData) -> np.ndarray:
    return np.isfinite(d.tip_vs_encoders_m)


def _state_colours(labels: list[str]) -> dict[str, tuple[float, float, float, float]]:
    """One colour per state, in order of first appearance: eight distinct hues, then their light tints.

    Blue (C0) and orange (C1) are left out: they are the lines drawn over the states' shading
    (``TRUE_INK``, ``ENCODERS``), which would vanish on a state of their own colour.
    """
    from matplotlib import colormaps

    hues = (2, 3, 4, 5, 6, 7, 8, 9)  # tab10 without C0 and C1
    palette = [colormaps["tab10"](i) for i in hues] + [colormaps["tab20"](2 * i + 1) for i in hues]
    order = list(dict.fromkeys(labels))
    return {label: palette[i % len(palette)] for i, label in enumerate(order)}


def _state_strip(ax: Axes, spans: list[tuple[float, float, str]],
                 colours: dict[str, tuple[float, float, float, float]]) -> None:
    total = spans[-1][1] - spans[0][0]
    for a, b, label in spans:
        ax.axvspan(a, b, color=colours[label], lw=0, gid=f"state:{label}")
        leaf = label.rsplit(".", 1)[-1]
        if (b - a) > 0.011 * total * len(leaf):  # room for the name inside its band
            ax.text((a + b) / 2, 0.5, leaf, ha="center", va="center", fontsize=8, color="w", clip_on=True)
    ax.set_yticks([])
    ax.tick_params(labelbottom=False)
    ax.set_xlim(spans[0][0], spans[-1][1])
    ax.set_ylim(0, 1)
    ax.set_title("Which state of the Control chart was active (its colours shade the panels below)", fontsize=10)


def _height_panel(ax: Axes, d: PathData, t0: float) -> None:
    t = d.t - t0
    mm = 1e3
    ax.plot(t, d.desired[:, 2] * mm, color=DESIRED_DOWN, lw=1.0, ls="--", label="desired Z_out")
    ax.plot(t, d.fk_true[:, 2] * mm, color=TRUE_INK, lw=1.3, label="true tool tip")
    ax.axhline(d.surface_z * mm, color="0.3", lw=0.8, label="board surface: below it the pen touches")
    for i in _jumps(d):
        ax.annotate("desired jumps to the waiting pose: a step (thesis: wait_1),\n"
                    "slow setpoint filters (fr_sw) make the arm follow smoothly",
                    (t[i + 1], d.desired[i + 1, 2] * mm), xytext=(-12, -6), textcoords="offset points",
                    ha="right", va="top", fontsize=8, color="0.2",
                    arrowprops={"arrowstyle": "->", "color": "0.4", "lw": 0.8})
    ax.set_ylabel("pen height z (mm)")
    ax.tick_params(labelbottom=False)
    ax.legend(loc="upper left", fontsize=8, ncol=3)
    ax.grid(alpha=0.25)
    top = float(np.nanmax(d.desired[:, 2])) * mm
    ax.set_ylim(min(-5.0, float(np.nanmin(d.fk_true[:, 2])) * mm - 2.0), top * 1.35 + 2.0)


def _error_panel(ax: Axes, d: PathData, t0: float) -> None:
    mm = 1e3
    for i, (_, times, err) in enumerate(d.strokes):
        ax.plot(times - t0, err * mm, color=TRUE_INK, lw=1.0, gid="ink_error",
                label="ink: distance of the true tip from the desired pen-down path" if i == 0 else None)
    ax.plot(d.t - t0, d.tip_vs_encoders_m * mm, color=ENCODERS, lw=1.0, gid="encoders_vs_true",
            label="encoders' view: |forward kinematics of the encoders - true tip| (pen down)")
    ax.set_ylabel("error along the path (mm)")
    ax.set_xlabel("time since the command (s)")
    ax.set_ylim(bottom=0.0)
    ax.legend(loc="upper left", fontsize=8)
    ax.grid(alpha=0.25)


__all__ = ["PathData", "path_figure", "save_path_plot", "state_spans", "JUMP_M", "PEN_UP_LABEL"]
