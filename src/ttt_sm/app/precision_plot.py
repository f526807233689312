"""The figures of the staircase experiment (thesis figs. 3.15-3.18): one PNG per run.

Top: the position along the staircase's axis over time, mm: the desired
stairs, forward kinematics of the encoders and the sensor (its gaps are
readings out of its range).  Bottom: the three differences of section 3.5
on one time axis, mm, with the static and dynamic windows shaded (a symmetric log scale, so that
the lag of the stairs and the micrometres left at rest share it).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..files import save_figure
from .precision import DYNAMIC_WINDOW_S, STATIC_WINDOW_S, StaircaseResult


def staircase_figure(r: StaircaseResult):  # type: ignore[no-untyped-def]
    """The figure of one staircase run (a matplotlib Figure, no pyplot state)."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(11.0, 7.6), dpi=90)
    top, bottom = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [3, 2]})
    fig.subplots_adjust(left=0.09, right=0.98, top=0.9, bottom=0.08, hspace=0.08)
    fig_no = f"thesis fig. {r.thesis_figure}" if r.thesis_figure else "no thesis figure (section 3.5.2: as along X)"
    fig.suptitle(f"Precision along {r.axis.upper()}, {r.steps} steps ({r.step_mm:g} mm), tuning \"{r.tuning}\""
                 f" -- {fig_no}", fontsize=12)
    t, s = r.t, r.series
    top.step(t, s["desired"] * 1e3, where="post", color="k", lw=1.4, label="desired (the stairs)")
    top.plot(t, s["fk"] * 1e3, color="C0", lw=1.2, label="forward kinematics of the encoders")
    top.plot(t, s["sensor"] * 1e3, color="C3", lw=1.0, ls="--", label="triangulation sensor (true tool)")
    top.set_ylabel(f"{r.axis.upper()} of the tool (mm)")
    top.legend(loc="upper left", fontsize=9)
    top.grid(alpha=0.3)
    diffs = {"desired - FK (controllers, IK)": (s["desired"] - s["fk"], "C0"),
             "FK - sensor (clearances, deflection, lengths)": (s["fk"] - s["sensor"], "C2"),
             "desired - sensor (overall)": (s["desired"] - s["sensor"], "C3")}
    for label, (d, color) in diffs.items():
        bottom.plot(t, d * 1e3, color=color, lw=1.0, label=label)
    for t0 in r.stair_times:
        bottom.axvspan(t0 + r.hold_s - STATIC_WINDOW_S, t0 + r.hold_s, color="0.85", lw=0)
        bottom.axvspan(t0, t0 + DYNAMIC_WINDOW_S, color="#fde8d0", lw=0)
    bottom.axhline(r.clearance_bound_mm, color="C2", lw=0.7, ls=":")
    bottom.axhline(-r.clearance_bound_mm, color="C2", lw=0.7, ls=":",
                   label=f"clearance bound +-{r.clearance_bound_mm:.3f} mm")
    # symmetric log: the stairs' lag (mm) and the static differences (um) on one axis
    bottom.set_yscale("symlog", linthresh=0.01)
    span = max(r.step_mm, 3 * r.clearance_bound_mm) * 1.2
    bottom.set_ylim(-span, span)
    bottom.set_ylabel("difference (mm, log beyond 0.01)")
    bottom.set_xlabel("time from the start of the staircase (s)")
    bottom.grid(alpha=0.3)
    bottom.legend(loc="lower right", fontsize=8, ncol=2)
    bottom.text(0.01, 0.03, f"orange: dynamic window ({DYNAMIC_WINDOW_S:g} s after a step);"
                f" grey: static window (last {STATIC_WINDOW_S:g} s of a stair)",
                transform=bottom.transAxes, fontsize=8, color="0.3")
    top.set_xlim(float(np.min(t)), float(np.max(t)))
    return fig


def save_staircase_plot(r: StaircaseResult, path: Path) -> Path:
    """Write :func:`staircase_figure` of `r` to a PNG file; returns the path."""
    path.parent.mkdir(parents=True, exist_ok=True)
    return save_figure(staircase_figure(r), path)


__all__ = ["staircase_figure", "save_staircase_plot"]
