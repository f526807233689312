"""Step responses of the drives on the nonlinear twin, measured as the thesis did (figs. 3.7-3.9).

:func:`step_response` steps one drive of the simulated arm (friction,
clearance, quantization, gravity) and measures the raw step setpoint against
the motor-side encoder angle; :func:`tune_report` designs the gains
(:func:`ttt_sm.twin.tuning.design_gains`), steps every drive and writes one
plot per drive and the Bode plot: what ``ttt-sm tune`` prints
(:func:`report_text`).  docs/tuning.md explains the method.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..files import save_figure
from ..params import ArmParams
from .gains import Gains, check_drive
from .sim import ArmSim
from .tuning import gains_for, plot_loops

if TYPE_CHECKING:
    from matplotlib.figure import Figure

#: Poses (rad) the step responses start from, per drive; the other joints are
#: held there by their controllers.  Drive 1 turns the folded arm; drive 2
#: lifts the outstretched arm from hanging (the heaviest load it sees); drive 3
#: lifts the forearm through the horizontal of gravity (q2 + q3 from -0.2 to
#: 0.3 rad: the gear load changes sides, so the clearance is crossed).
STEP_POSES: dict[int, tuple[float, float, float, float]] = {
    1: (0.0, 0.6, -1.2, 0.0),
    2: (0.0, 0.3, 0.0, 0.0),
    3: (0.0, 1.0, -1.2, 0.0),
}
#: Thesis step sizes (figs. 3.7-3.9).
STEP_RAD = {1: 1.0, 2: 1.0, 3: 0.5}
#: Holding time before the step, s.
PRE_ROLL_S = 0.3
#: Drive 2's step starts where it came to rest hanging unpowered for this long, s.
UNPOWERED_SETTLE_S = 1.0
#: The static error is the largest |error| over this last part of the run, s.
STATIC_WINDOW_S = 0.3
#: Settling band, fraction of the step.
SETTLING_BAND = 0.02


def settling_band_rad(step_rad: float) -> float:
    """Half-width of the settling band for a step of `step_rad`: ``SETTLING_BAND`` of it, rad.

    The one definition both :func:`step_response` (``settling_time_s``) and
    :func:`plot_step` (the band it draws) use.
    """
    return SETTLING_BAND * abs(step_rad)


@dataclass(frozen=True, eq=False)
class StepMetrics:
    """A step response of one drive on the nonlinear twin, measured on the encoder.

    Times are from the step.  ``static_error_rad`` is the largest |setpoint -
    encoder angle| over the last ``STATIC_WINDOW_S`` of the run;
    ``settling_time_s`` is when the error last left the band of
    ``SETTLING_BAND`` times the step; ``rise_time_s`` from 10 % to 90 %;
    ``overshoot_pct`` the largest excursion past the setpoint in % of the step.
    """

    drive: int
    step_rad: float
    rise_time_s: float
    settling_time_s: float
    overshoot_pct: float
    error_at_0_5s_rad: float
    static_error_rad: float
    max_abs_duty: float
    t: np.ndarray
    setpoint: np.ndarray
    encoder: np.ndarray
    load: np.ndarray
    rad_per_count: float

    @property
    def settling_band_rad(self) -> float:
        """Half-width of the band ``settling_time_s`` is measured against, rad."""
        return settling_band_rad(self.step_rad)


def step_response(params: ArmParams, gains: Gains, drive: int, step_rad: float, seconds: float = 1.5,
                  seed: int = 0) -> StepMetrics:
    """Step one drive on the nonlinear twin and measure the response on its encoder.

    The arm powers on at ``STEP_POSES[drive]`` (drive 2 first hangs
    unpowered for ``UNPOWERED_SETTLE_S`` and comes to rest near zero), the drives
    take their true offsets, hold for ``PRE_ROLL_S``, then drive `drive`'s
    raw setpoint steps by `step_rad` for `seconds`.
    """
    drive = check_drive(drive)
    d = drive - 1
    sim = ArmSim(params, gains, seed=seed, q0=STEP_POSES[drive])
    if drive == 2:
        sim.settle_unpowered(UNPOWERED_SETTLE_S)
    sim.assume_initialised()
    hold = np.append(sim.q_encoder, sim.truth.q[3])
    sim.set_setpoints(hold)
    sim.run_for(PRE_ROLL_S, record=False)
    target = hold.copy()
    target[d] += step_rad
    start = hold[d]
    sim.set_setpoints(target)
    tr = sim.run_for(seconds)
    t = tr.t - tr.t[0] + sim.dt  # row k is the state after k + 1 steps from the step
    enc = tr.q_encoder[:, d]
    err = target[d] - enc
    frac = (enc - start) / step_rad
    band = settling_band_rad(step_rad)
    outside = np.flatnonzero(np.abs(err) > band)
    settling = float(t[outside[-1] + 1]) if outside.size and outside[-1] + 1 < len(t) else (
        0.0 if not outside.size else math.inf)
    t10 = t[np.argmax(frac >= 0.1)] if np.any(frac >= 0.1) else math.inf
    t90 = t[np.argmax(frac >= 0.9)] if np.any(frac >= 0.9) else math.inf
    i05 = int(np.argmin(np.abs(t - 0.5)))
    static = float(np.max(np.abs(err[t > seconds - STATIC_WINDOW_S])))
    return StepMetrics(
        drive=drive, step_rad=float(step_rad), rise_time_s=float(t90 - t10), settling_time_s=settling,
        overshoot_pct=float(max(0.0, np.max(frac) - 1.0) * 100.0), error_at_0_5s_rad=float(abs(err[i05])),
        static_error_rad=static, max_abs_duty=float(np.max(np.abs(tr.duty[:, d]))),
        t=t, setpoint=np.full_like(t, target[d]), encoder=enc, load=tr.q_true[:, d].copy(),
        rad_per_count=params.drives[d].rad_per_count,
    )


def step_figure(m: StepMetrics) -> Figure:
    """A step response like thesis figs. 3.7-3.9, with every metric of :class:`StepMetrics` drawn.

    Left: the raw step setpoint and the encoder angle, the settling band
    (``settling_band_rad``, the one ``settling_time_s`` uses) around the
    setpoint, the 10 % and 90 % points of the rise time and the settling
    time.  Right: |setpoint - encoder| on a log scale, so that the slew (a
    radian), the band (hundredths) and the static error (an encoder count,
    1e-5 rad) show on one axis, with the same band, the error at 0.5 s, the
    window of the static error and one encoder count.
    """
    from matplotlib.figure import Figure  # no pyplot: no global backend state

    band = m.settling_band_rad
    start = m.setpoint[0] - m.step_rad
    target = m.setpoint[0]
    # the hold before the step, then the step itself at t = 0
    t = np.concatenate([[-0.05, 0.0, 0.0], m.t])
    sp = np.concatenate([[start, start, target], m.setpoint])
    enc = np.concatenate([[start, start, start], m.encoder])
    fig = Figure(figsize=(11.0, 4.4), dpi=80)
    a1, a2 = fig.subplots(1, 2)
    fig.suptitle(f"Drive {m.drive}: a {m.step_rad:g} rad step of the position setpoint on the simulated arm "
                 "(friction, gear clearance, gravity, encoder counts)", fontsize=11)

    a1.axhspan(target - band, target + band, color="C2", alpha=0.25, lw=0, gid="settling_band",
               label=f"settling band: setpoint ± {SETTLING_BAND * 100:g} % of the step (± {band:.3g} rad)")
    a1.plot(t, sp, "k--", lw=1.0, label="setpoint (the raw step)")
    a1.plot(t, enc, "C0", lw=1.4, label="encoder angle (what the controller sees)")
    frac = (m.encoder - start) / m.step_rad
    for level in (0.1, 0.9):
        if np.any(frac >= level):
            i = int(np.argmax(frac >= level))
            a1.plot(m.t[i], m.encoder[i], "o", color="C1", ms=5,
                    label=f"10 % and 90 % of the step: rise time {m.rise_time_s:.3f} s" if level == 0.1 else None)
    a1.axvline(m.settling_time_s, color="C2", ls="-", lw=1.2, gid="settling_time",
               label=f"settled: |error| last leaves the band at {m.settling_time_s:.3f} s")
    a1.set_xlabel("time after the step (s)")
    a1.set_ylabel(f"joint {m.drive} angle q{m.drive} (rad)")
    a1.set_title(f"Response (overshoot {m.overshoot_pct:.2f} % of the step)", fontsize=10)
    a1.legend(loc="lower right", fontsize=8)
    a1.grid(alpha=0.3)

    err = np.abs(m.setpoint - m.encoder)
    floor = 0.1 * m.rad_per_count  # an error of exactly 0 has no logarithm
    a2.semilogy(m.t, np.maximum(err, floor), "C3", lw=1.1, label="|error| = |setpoint - encoder angle|")
    a2.axhspan(floor, band, color="C2", alpha=0.25, lw=0, gid="settling_band_error",
               label=f"inside the settling band (< {band:.3g} rad)")
    a2.axvline(m.settling_time_s, color="C2", lw=1.2, label=f"settling time {m.settling_time_s:.3f} s")
    i05 = int(np.argmin(np.abs(m.t - 0.5)))
    a2.plot(m.t[i05], max(err[i05], floor), "s", color="k", ms=5,
            label=f"error at 0.5 s (the thesis' number): {m.error_at_0_5s_rad:.1e} rad")
    a2.axvspan(m.t[-1] - STATIC_WINDOW_S, m.t[-1], color="0.6", alpha=0.25, lw=0,
               label=f"last {STATIC_WINDOW_S:g} s: static error = largest |error| there, "
                     f"{m.static_error_rad:.1e} rad")
    a2.axhline(m.rad_per_count, color="k", ls=":", lw=0.9,
               label=f"one encoder count ({m.rad_per_count:.1e} rad): the finest step it can see")
    a2.set_ylim(floor, 2.0 * abs(m.step_rad))
    a2.set_xlim(0.0, m.t[-1])
    a2.set_xlabel("time after the step (s)")
    a2.set_ylabel("|error| (rad, log scale)")
    a2.set_title("Error: slew, settling band, static error", fontsize=10)
    a2.legend(loc="upper right", fontsize=7.5)
    a2.grid(alpha=0.3, which="both")
    fig.tight_layout()
    return fig


def plot_step(m: StepMetrics, path: Path) -> Path:
    """Write :func:`step_figure` of a step response to a PNG file; returns the path."""
    fig = step_figure(m)
    path.parent.mkdir(parents=True, exist_ok=True)
    return save_figure(fig, path)


#: The Bode plot :func:`tune_report` writes beside the step plots.
LOOPS_PNG = "loops_bode.png"


def tune_report(params: ArmParams, out_dir: Path | str, preset: str = "ours") -> list[dict[str, Any]]:
    """Take a tuning preset's gains, step every drive on the twin, write one PNG per drive and the Bode plot.

    ``preset``: "ours" (:func:`~.tuning.design_gains`, the files ``step_drive{1,2,3}.png`` and
    ``LOOPS_PNG``) or "thesis" (:func:`~.tuning.thesis_gains`, the same names with ``_thesis``).
    Returns one dict per drive with exactly the keys ``drive``, ``step_rad``,
    ``rise_time_s``, ``settling_time_s``, ``overshoot_pct``,
    ``error_at_0_5s_rad``, ``static_error_rad``, ``inner_phase_margin_deg``,
    ``outer_phase_margin_deg``, ``outer_gain_margin_db`` and ``plot``.
    """
    out = Path(out_dir)
    gains = gains_for(params, preset)
    tag = "" if preset == "ours" else f"_{preset}"
    plot_loops(params, gains, out / LOOPS_PNG.replace(".png", f"{tag}.png"))
    rows = []
    for drive in (1, 2, 3):
        m = step_response(params, gains, drive, STEP_RAD[drive])
        g = gains.drive(drive)
        png = plot_step(m, out / f"step_drive{drive}{tag}.png")
        rows.append({
            "drive": drive, "step_rad": m.step_rad, "rise_time_s": m.rise_time_s,
            "settling_time_s": m.settling_time_s, "overshoot_pct": m.overshoot_pct,
            "error_at_0_5s_rad": m.error_at_0_5s_rad, "static_error_rad": m.static_error_rad,
            "inner_phase_margin_deg": g.inner_phase_margin_deg,
            "outer_phase_margin_deg": g.outer_phase_margin_deg,
            "outer_gain_margin_db": g.outer_gain_margin_db, "plot": str(png),
        })
    return rows


#: The columns of :func:`report_text`: report key, header, width, number format, what it is.
REPORT_COLUMNS: tuple[tuple[str, str, int, str, str], ...] = (
    ("drive", "drive", 5, "d", "drive 1 turns the base (q1), drives 2 and 3 the pitch joints (q2, q3)"),
    ("step_rad", "step", 5, ".2f", "size of the setpoint step, rad"),
    ("rise_time_s", "rise s", 7, ".3f", "rise time: from 10 % to 90 % of the step, s"),
    ("settling_time_s", "settle s", 8, ".3f",
     f"settling time: when |error| last left the band of {SETTLING_BAND * 100:g} % of the step, s"),
    ("overshoot_pct", "overshoot %", 11, ".2f", "largest excursion past the setpoint, % of the step"),
    ("error_at_0_5s_rad", "e(0.5s)", 9, ".2e", "|error| 0.5 s after the step, rad (the thesis' figs. 3.7-3.9)"),
    ("static_error_rad", "static", 9, ".2e",
     f"static error: largest |error| over the last {STATIC_WINDOW_S:g} s of the run, rad"),
    ("inner_phase_margin_deg", "PM in", 6, ".1f", "phase margin of the inner (speed) loop, deg"),
    ("outer_phase_margin_deg", "PM out", 6, ".1f", "phase margin of the outer (position) loop, deg"),
    ("outer_gain_margin_db", "GM out dB", 9, ".1f", "gain margin of the outer (position) loop, dB"),
)


def report_text(rows: list[dict[str, Any]]) -> str:
    """:func:`tune_report`'s rows as a table, a line per column saying what it is, and the plots."""
    header = " ".join(f"{name:>{w}}" for _, name, w, _, _ in REPORT_COLUMNS)
    body = [" ".join(f"{r[key]:>{w}{fmt}}" for key, _, w, fmt, _ in REPORT_COLUMNS) for r in rows]
    width = max(len(name) for _, name, _, _, _ in REPORT_COLUMNS)
    legend = ["", "columns (error = setpoint - encoder angle):",
              *(f"  {name:<{width}}  {meaning}" for _, name, _, _, meaning in REPORT_COLUMNS)]
    plots = [f"step plot (every column but the margins drawn): {r['plot']}" for r in rows if r.get("plot")]
    if plots:
        first = Path(rows[0]["plot"])
        tag = first.stem.removeprefix("step_drive1")
        plots.append(f"open loops (Bode, the margins drawn): {first.parent / LOOPS_PNG.replace('.png', tag + '.png')}")
    return "\n".join([header, *body, *legend, "", *plots])


__all__ = [
    "STEP_POSES", "STEP_RAD", "PRE_ROLL_S", "UNPOWERED_SETTLE_S", "STATIC_WINDOW_S", "SETTLING_BAND",
    "StepMetrics", "step_response", "settling_band_rad", "step_figure", "plot_step", "tune_report",
    "report_text", "REPORT_COLUMNS", "LOOPS_PNG",
]
