"""Tuning the cascade controllers from the parameter file: linear models, margins, gains.

The thesis tuned its PIDs by hand on the real arm (section 3.2, note).  Here
the gains are computed: each drive's linear model is built from the
parameter file with python-control (armature circuit, motor and load
inertias with viscous friction, the gear's stiffness and damping, the 1 ms
sampling with a zero-order hold, a one-sample computation delay and the
filtered-derivative speed estimate), the inner speed PI and the outer
position loop are shaped to the crossover targets of ``[control]`` within
phase- and gain-margin limits, and the margins of both sampled loops are
measured with :func:`control.margin`.  ``step_response.py`` then steps each
drive on the nonlinear twin.  docs/tuning.md explains the method.

This module knows nothing of the simulated arm (which designs its default
gains here), so the two import one way.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING

import control as ct
import numpy as np

from ..files import save_figure
from ..params import TUNING_PRESETS, ArmParams, ParameterError
from .gains import DriveGains, Gains, check_drive, max_joint_speed, speed_filter_alpha

if TYPE_CHECKING:
    from matplotlib.figure import Figure


class TuningError(ParameterError):
    """No controller meets the margin limits for a drive's model (see the message).

    A :class:`~ttt_sm.params.ParameterError`: the parameter file asks for loops
    its drives cannot have; the message names the file and the keys to change.
    """


# ---- design rules ------------------------------------------------------------

#: Minimum phase margin (deg) and gain margin (dB) the design accepts for
#: either loop, on the model with the compliant gear.
MIN_PHASE_MARGIN_DEG = 50.0
MIN_GAIN_MARGIN_DB = 6.0

#: Ratios crossover / PI zero tried for the speed loop, most integral action first.
INNER_PI_RATIOS = (4.0, 5.0, 6.0, 8.0, 10.0)

#: Ratio crossover / PI zero of the position loop; None: no outer integral.
#: The inner speed integrator already integrates the position error
#: (``integral(kp_pos e - w) dt = kp_pos integral(e) dt - delta q``), so the
#: cascade has no static error without one; an outer integrator adds a slow
#: pole-zero pair that, after a long slew in the speed clamp, leaves a tail of
#: several mrad decaying over a second (docs/tuning.md shows it).
OUTER_PI_RATIO: float | None = None

#: Speed feedforward gain: the setpoint filter's derivative added to the
#: speed setpoint, so a ramp is tracked without a following error.
SPEED_FEEDFORWARD = 1.0

#: Crossovers are tried from the target down in steps of this factor.
CROSSOVER_STEP = 0.95


# ---- linear models -----------------------------------------------------------

def drive_plant(params: ArmParams, drive: int, compliant: bool = True) -> ct.StateSpace:
    """Continuous linear model of a DC drive: PWM duty -> motor-side joint angle (rad).

    With `compliant` the gear is a spring with damping between the motor and
    the load (states: current, motor speed and angle, load speed and angle,
    all at the joint side); without it motor and load are one rigid inertia
    (states: current, speed, angle).  Coulomb friction, clearance and
    gravity are left out (they are the nonlinear twin's business).
    """
    p = params.drives[check_drive(drive) - 1]
    n = p.gear_ratio
    r, ind, kt, v = p.resistance_ohm, p.inductance_h, p.torque_constant, p.supply_v
    jm, bm = p.rotor_inertia * n**2, p.motor_viscous * n**2
    jl, bl = p.load_inertia, p.load_viscous
    if not compliant:
        j, b = jm + jl, bm + bl
        a = [[-r / ind, -kt * n / ind, 0.0], [kt * n / j, -b / j, 0.0], [0.0, 1.0, 0.0]]
        return ct.ss(a, [[v / ind], [0.0], [0.0]], [[0.0, 0.0, 1.0]], 0.0)
    k, c = p.gear_stiffness, p.gear_damping
    a = [[-r / ind, -kt * n / ind, 0.0, 0.0, 0.0],
         [kt * n / jm, -(bm + c) / jm, -k / jm, c / jm, k / jm],
         [0.0, 1.0, 0.0, 0.0, 0.0],
         [0.0, c / jl, k / jl, -(bl + c) / jl, -k / jl],
         [0.0, 0.0, 0.0, 1.0, 0.0]]
    return ct.ss(a, [[v / ind], [0.0], [0.0], [0.0], [0.0]], [[0.0, 0.0, 1.0, 0.0, 0.0]], 0.0)


def speed_estimator(params: ArmParams) -> ct.StateSpace:
    """The kernel's speed estimate: backward difference, then a first-order filter (discrete)."""
    dt = params.control.dt
    a = speed_filter_alpha(params.control)
    return ct.ss(ct.tf([a, -a], [dt, -dt * (1.0 - a)], dt))


def _pi(kp: float, ki: float, dt: float) -> ct.StateSpace:
    """Discrete PI as the kernel runs it: integrate first (backward Euler), then add."""
    return ct.ss(ct.tf([kp + ki * dt, -kp], [1.0, -1.0], dt))


def loop_models(params: ArmParams, drive: int, gains: DriveGains,
                compliant: bool = True) -> tuple[ct.StateSpace, ct.StateSpace]:
    """Open loops (inner, outer) of a drive's sampled cascade, both discrete.

    inner: broken at the PWM duty, ``C_w * z^-1 * P_zoh * F`` (F: speed estimate);
    outer: broken at the encoder angle, with the inner loop closed.
    """
    dt = params.control.dt
    pd = ct.c2d(drive_plant(params, drive, compliant), dt, "zoh")
    delay = ct.ss(ct.tf([1.0], [1.0, 0.0], dt))
    f = speed_estimator(params)
    forward = ct.series(delay, pd)
    c_pi = _pi(gains.kp_speed, gains.ki_speed, dt)
    c_w = c_pi
    if gains.kd_speed:  # derivative on the measured speed only
        c_w = c_pi + ct.ss(ct.tf([gains.kd_speed, -gains.kd_speed], [dt, 0.0], dt))
    inner = ct.series(forward, f, c_w)
    # speed setpoint -> encoder angle with the inner loop closed
    t_q = ct.series(c_pi, ct.feedback(forward, ct.series(f, c_w)))
    c_q = _pi(gains.kp_pos, gains.ki_pos, dt)
    if gains.kd_pos:
        c_q = c_q + gains.kd_pos * f
    outer = ct.series(t_q, c_q)
    return inner, outer


def _freq_grid(dt: float) -> np.ndarray:
    return np.logspace(-1.0, math.log10(math.pi / dt) - 1e-6, 4000)


def _response(sys: ct.StateSpace, omega: np.ndarray) -> np.ndarray:
    """Frequency response of a SISO discrete state-space system at `omega` (rad/s), vectorised."""
    z = np.exp(1j * omega * sys.dt)
    n = sys.A.shape[0]
    m = z[:, None, None] * np.eye(n) - sys.A[None, :, :]
    x = np.linalg.solve(m, np.broadcast_to(sys.B[:, :1].astype(complex), (len(z), n, 1)))
    return (sys.C[0] @ x)[:, 0] + sys.D[0, 0]


def _quick_margins(sys: ct.StateSpace, omega: np.ndarray) -> tuple[float, float, float]:
    """(phase margin deg, gain margin dB, crossover Hz) from a dense grid: the worst crossings."""
    resp = _response(sys, omega)
    mag = np.abs(resp)
    phase = np.unwrap(np.angle(resp))
    pm, wc = math.inf, math.nan
    for i in np.flatnonzero((mag[:-1] - 1.0) * (mag[1:] - 1.0) <= 0.0):
        m = (math.degrees(phase[i]) + 180.0) % 360.0
        m = m - 360.0 if m > 180.0 else m
        if m < pm:
            pm, wc = m, omega[i]
    gm = math.inf
    ph = np.degrees(phase) + 180.0
    for i in np.flatnonzero(np.floor(ph[:-1] / 360.0) != np.floor(ph[1:] / 360.0)):
        gm = min(gm, -20.0 * math.log10(max(mag[i], 1e-300)))
    return pm, gm, wc / (2 * math.pi)


def loop_margins(loop: ct.StateSpace) -> tuple[float, float, float]:
    """(phase margin deg, gain margin dB, first crossover Hz) of a discrete loop, with control.margin.

    Evaluated on a dense frequency grid up to the Nyquist frequency (an FRD
    model): a polynomial transfer function of a 1 ms loop is too
    ill-conditioned to trust.  The margins are the worst over all crossings
    (the gear resonance can cross |L| = 1 a second time); the crossover is
    the first frequency where |L| falls through 1.
    """
    pm, gm_db, _, _, fc = _margins(loop)
    return pm, gm_db, fc


def margin_points(loop: ct.StateSpace) -> tuple[float, float, float, float]:
    """Where :func:`loop_margins` reads the margins: (phase margin deg, at Hz, gain margin dB, at Hz).

    The phase margin at its gain crossover (|L| = 1), the gain margin at its
    phase crossover (-180 deg), both control.margin's; NaN where there is none.
    """
    pm, gm_db, f_pm, f_gm, _ = _margins(loop)
    return pm, f_pm, gm_db, f_gm


def _margins(loop: ct.StateSpace) -> tuple[float, float, float, float, float]:
    """(pm deg, gm dB, f at pm Hz, f at gm Hz, first crossover Hz) with control.margin on a dense FRD."""
    omega = _freq_grid(loop.dt)
    resp = _response(loop, omega)
    frd = ct.frd(resp, omega)
    gm, pm, wpc, wgc = ct.margin(frd)
    gm_db = math.inf if not np.isfinite(gm) else 20.0 * math.log10(gm)
    below = np.flatnonzero(np.abs(resp) < 1.0)
    wc = float(omega[below[0]]) if below.size else math.nan
    hz = 1 / (2 * math.pi)
    return float(pm), float(gm_db), float(wgc) * hz, float(wpc) * hz, wc * hz


def _highest_crossover_pi(g: ct.StateSpace, dt: float, target_hz: float,
                          ratios: Sequence[float | None]) -> tuple[float, float] | None:
    """The PI (kp, ki) around `g` with the highest crossover <= `target_hz` that keeps the margins.

    From the target down by :data:`CROSSOVER_STEP` to 5 % of it, each of
    `ratios` (integral corner = crossover / ratio; None: no integral) in turn;
    the gain puts the open loop's magnitude at 1 at the crossover.  None when
    no crossover down there keeps the margins.
    """
    omega = _freq_grid(dt)
    f = target_hz
    while f > 0.05 * target_hz:
        w = 2 * math.pi * f
        zc = np.exp(1j * w * dt)
        g_c = _response(g, np.array([w]))[0]
        for ratio in ratios:
            wi = 0.0 if ratio is None else w / ratio
            shape = 1.0 + wi * dt * zc / (zc - 1.0)
            kp = 1.0 / abs(shape * g_c)
            pm, gm, _ = _quick_margins(ct.series(g, _pi(kp, kp * wi, dt)), omega)
            if pm >= MIN_PHASE_MARGIN_DEG and gm >= MIN_GAIN_MARGIN_DB:
                return float(kp), float(kp * wi)
        f *= CROSSOVER_STEP
    return None


def _design_inner(params: ArmParams, drive: int) -> tuple[float, float]:
    """Speed PI (kp, ki): the highest crossover <= the target that keeps the margins."""
    dt = params.control.dt
    pd = ct.c2d(drive_plant(params, drive, compliant=True), dt, "zoh")
    g = ct.series(ct.ss(ct.tf([1.0], [1.0, 0.0], dt)), pd, speed_estimator(params))
    gains = _highest_crossover_pi(g, dt, params.control.inner_crossover_hz, INNER_PI_RATIOS)
    if gains is None:
        raise TuningError(f"{params.source}: drive {drive}: no speed PI keeps {MIN_PHASE_MARGIN_DEG:g} deg / "
                          f"{MIN_GAIN_MARGIN_DB:g} dB down to 5 % of inner_crossover_hz; check [drive.{drive}] "
                          "(gear stiffness and damping, inertias) and [control] speed_filter_hz")
    return gains


def _design_outer(params: ArmParams, drive: int, kp_w: float, ki_w: float) -> tuple[float, float]:
    """Position P (or PI, see OUTER_PI_RATIO) with the inner loop closed, same rule as the inner loop."""
    trial = DriveGains(1.0, 0.0, 0.0, 0.0, 0.0, kp_w, ki_w, 0.0, 0, 0, 0, 0, 0, 0)
    _, t_q = loop_models(params, drive, trial)  # with kp_pos = 1, ki_pos = 0: just the plant
    gains = _highest_crossover_pi(t_q, params.control.dt, params.control.outer_crossover_hz, (OUTER_PI_RATIO,))
    if gains is None:
        raise TuningError(f"{params.source}: drive {drive}: no position gain keeps {MIN_PHASE_MARGIN_DEG:g} deg / "
                          f"{MIN_GAIN_MARGIN_DB:g} dB down to 5 % of outer_crossover_hz; lower "
                          "[control] outer_crossover_hz below the speed loop's crossover")
    return gains


#: A drive's margins before they are measured (:func:`_with_margins` fills them in).
_NO_MARGINS = {"inner_crossover_hz": 0.0, "inner_phase_margin_deg": 0.0, "inner_gain_margin_db": 0.0,
               "outer_crossover_hz": 0.0, "outer_phase_margin_deg": 0.0, "outer_gain_margin_db": 0.0}


def _with_margins(params: ArmParams, drive: int, g: DriveGains) -> DriveGains:
    """`g` with the margins and crossovers of its sampled loop models (:func:`loop_margins`)."""
    inner, outer = loop_models(params, drive, g)
    pm_i, gm_i, fc_i = loop_margins(inner)
    pm_o, gm_o, fc_o = loop_margins(outer)
    return replace(g, inner_crossover_hz=fc_i, inner_phase_margin_deg=pm_i, inner_gain_margin_db=gm_i,
                   outer_crossover_hz=fc_o, outer_phase_margin_deg=pm_o, outer_gain_margin_db=gm_o)


@lru_cache(maxsize=8)
def design_gains(params: ArmParams) -> Gains:
    """Design every drive's cascade from the parameter file; margins with control.margin.

    Pure function of `params` (memoised: python-control takes about a second).
    """
    out = []
    for drive in (1, 2, 3):
        p = params.drives[drive - 1]
        kp_w, ki_w = _design_inner(params, drive)
        kp_q, ki_q = _design_outer(params, drive, kp_w, ki_w)
        g = DriveGains(kp_pos=kp_q, ki_pos=ki_q, kd_pos=0.0, kff_speed=SPEED_FEEDFORWARD,
                       max_speed_rad_s=max_joint_speed(p), kp_speed=kp_w, ki_speed=ki_w, kd_speed=0.0,
                       **_NO_MARGINS)
        out.append(_with_margins(params, drive, g))
    return Gains(drives=(out[0], out[1], out[2]))


#: The tuning presets of ``[tuning] preset`` (docs/tuning.md): "ours", designed by :func:`design_gains`;
#: "thesis", the thesis' structure with gains set by hand to reproduce its step responses (:func:`thesis_gains`).
PRESETS = TUNING_PRESETS

#: The "thesis" preset's gains per drive, set by hand on the twin as the thesis set its own on the arm
#: (section 3.2, note: "tuning the controllers has been done experimentally"): position PID (kp 1/s, ki
#: 1/s^2, kd), speed PID (kp s/rad, ki 1/rad, kd), no speed feedforward (the thesis' fig. 3.6 has none).
#: Chosen so that the 1 rad (drives 1, 2) and 0.5 rad (drive 3) steps of ``step_response`` leave
#: |error| at 0.5 s of the order of the thesis' 0.007, 0.0035 and 0.003 rad.
THESIS_GAINS: tuple[tuple[float, float, float, float, float, float], ...] = (
    (11.5, 0.0, 0.0, 0.67, 9.3, 0.0),
    (16.0, 0.0, 0.0, 0.81, 10.2, 0.0),
    (17.5, 0.0, 0.0, 0.51, 7.8, 0.0),
)


@lru_cache(maxsize=8)
def thesis_gains(params: ArmParams) -> Gains:
    """The "thesis" preset: the thesis' cascade (position PID, speed PID) with hand-set gains, margins measured.

    The gains are :data:`THESIS_GAINS` whatever the parameter file (the thesis'
    were numbers, not a design); the speed clamp is the drive's, as in
    :func:`design_gains`; the margins are those of the same sampled loop models.
    """
    out = []
    for drive in (1, 2, 3):
        kp_q, ki_q, kd_q, kp_w, ki_w, kd_w = THESIS_GAINS[drive - 1]
        g = DriveGains(kp_pos=kp_q, ki_pos=ki_q, kd_pos=kd_q, kff_speed=0.0,
                       max_speed_rad_s=max_joint_speed(params.drives[drive - 1]), kp_speed=kp_w, ki_speed=ki_w,
                       kd_speed=kd_w, **_NO_MARGINS)
        out.append(_with_margins(params, drive, g))
    return Gains(drives=(out[0], out[1], out[2]))


def gains_for(params: ArmParams, preset: str | None = None) -> Gains:
    """The gains of a tuning preset (default: the parameter file's ``[tuning] preset``).

    Raises :class:`TuningError` naming the presets for an unknown one.
    """
    name = params.tuning.preset if preset is None else preset
    if name == "ours":
        return design_gains(params)
    if name == "thesis":
        return thesis_gains(params)
    raise TuningError(f"unknown tuning preset {name!r}; choose from {', '.join(PRESETS)}")


def loops_figure(params: ArmParams, gains: Gains) -> Figure:
    """Bode plots of every drive's inner and outer open loop, with the margins drawn where they are read.

    Compliant gear model; the inner loop also with a rigid gear (dotted).  On
    each curve a dot marks the crossover (|L| = 1); in the phase plot a bar
    from -180 deg up to the curve is the phase margin there, in the
    magnitude plot a bar from the curve up to 0 dB at the -180 deg crossing
    is the gain margin.
    """
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D

    omega = _freq_grid(params.control.dt)[1000:]
    f = omega / (2 * math.pi)
    fig = Figure(figsize=(12.0, 8.4), dpi=80)
    axes = fig.subplots(2, 2, sharex=True)
    fig.subplots_adjust(left=0.07, right=0.985, top=0.9, bottom=0.25, hspace=0.1, wspace=0.14)
    fig.suptitle("Open loops of the drives' cascades, sampled at 1 ms, as the design model has them "
                 "(docs/tuning.md)", fontsize=12)
    names = ("inner loop L_w: speed PI, broken at the PWM duty", "outer loop L_q: position P, the inner loop closed")
    for drive in (1, 2, 3):
        g = gains.drive(drive)
        inner, outer = loop_models(params, drive, g)
        rigid, _ = loop_models(params, drive, g, compliant=False)
        color = f"C{drive - 1}"
        for col, loop in enumerate((inner, outer)):
            r = _response(loop, omega)
            db = 20 * np.log10(np.abs(r))
            ph = np.degrees(np.unwrap(np.angle(r)))
            ph -= 360.0 * np.round((ph[0] + 90.0) / 360.0)  # start near -90 deg (an integrator)
            pm, f_pm, gm, f_gm = margin_points(loop)
            mag_ax, ph_ax = axes[0, col], axes[1, col]
            mag_ax.semilogx(f, db, color, lw=1.1,
                            label=f"drive {drive}: phase margin {pm:.0f}° at {f_pm:.1f} Hz, "
                                  f"gain margin {gm:.1f} dB at {f_gm:.0f} Hz")
            ph_ax.semilogx(f, ph, color, lw=1.1)
            if math.isfinite(f_pm):
                mag_ax.plot(f_pm, 0.0, "o", color=color, ms=5)
                ph_at = float(np.interp(f_pm, f, ph))
                ph_ax.plot([f_pm, f_pm], [ph_at - pm, ph_at], color=color, lw=3, alpha=0.55,
                           solid_capstyle="butt", gid=f"pm_drive{drive}_{col}")
            if math.isfinite(f_gm):
                db_at = float(np.interp(f_gm, f, db))
                mag_ax.plot([f_gm, f_gm], [db_at, db_at + gm], color=color, lw=3, alpha=0.55,
                            solid_capstyle="butt", gid=f"gm_drive{drive}_{col}")
            if col == 0:
                mag_ax.semilogx(f, 20 * np.log10(np.abs(_response(rigid, omega))), color, lw=0.7, ls=":")
    for col in (0, 1):
        axes[0, col].axhline(0.0, color="k", lw=0.7)
        axes[1, col].axhline(-180.0, color="k", lw=0.7)
        axes[0, col].set_ylim(-40, 40)
        axes[1, col].set_ylim(-360, 0)
        axes[0, col].set_title(names[col], fontsize=10)
        axes[1, col].set_xlabel("frequency (Hz)")
        for ax in axes[:, col]:
            ax.grid(alpha=0.3, which="both")
        handles, _ = axes[0, col].get_legend_handles_labels()
        extra = [Line2D([], [], color="k", lw=0.7, label="0 dB: |L| = 1; a dot marks the crossover"),
                 Line2D([], [], color="0.5", lw=3, alpha=0.55,
                        label="bars: the margins, where they are read (gain: up to 0 dB at -180°)")]
        if col == 0:
            extra.append(Line2D([], [], color="0.3", lw=0.7, ls=":", label="dotted: the same loop with a rigid gear"))
        axes[1, col].legend(handles=handles + extra, fontsize=8, loc="upper left", bbox_to_anchor=(0.0, -0.14),
                            frameon=False)
    axes[0, 0].set_ylabel("|L| (dB)")
    axes[1, 0].set_ylabel("phase of L (deg)")
    axes[1, 1].text(0.02, 0.04, "-180°: a phase margin is the distance above this line at the crossover",
                    transform=axes[1, 1].transAxes, fontsize=8, color="0.3")
    return fig


def plot_loops(params: ArmParams, gains: Gains, path: Path) -> Path:
    """Write :func:`loops_figure` to a PNG file; returns the path."""
    fig = loops_figure(params, gains)
    path.parent.mkdir(parents=True, exist_ok=True)
    return save_figure(fig, path)


__all__ = [
    "PRESETS", "THESIS_GAINS", "thesis_gains", "gains_for",
    "TuningError", "drive_plant", "speed_estimator", "loop_models", "loop_margins", "margin_points", "design_gains",
    "loops_figure", "plot_loops",
]
