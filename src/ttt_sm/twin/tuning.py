"""Tuning the cascade controllers from the parameter file, and checking them on the twin.

The thesis tuned its PIDs by hand on the real arm (section 3.2, note).  Here
the gains are computed: each drive's linear model is built from the
parameter file with python-control (armature circuit, motor and load
inertias with viscous friction, the gear's stiffness and damping, the 1 ms
sampling with a zero-order hold, a one-sample computation delay and the
filtered-derivative speed estimate), the inner speed PI and the outer
position loop are shaped to the crossover targets of ``[control]`` within
phase- and gain-margin limits, and the margins of both sampled loops are
measured with :func:`control.margin`.  :func:`step_response` then steps a
drive on the nonlinear twin (friction, clearance, quantization, gravity) and
measures it as the thesis did (figs. 3.7-3.9): the raw step setpoint against
the motor-side encoder angle.  docs/tuning.md explains the method.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING, Any

import control as ct
import numpy as np

from ..params import ArmParams, ParameterError
from .control import DriveGains, Gains, check_drive, max_joint_speed, speed_filter_alpha

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


def _design_inner(params: ArmParams, drive: int) -> tuple[float, float]:
    """Speed PI (kp, ki): the highest crossover <= the target that keeps the margins."""
    dt = params.control.dt
    pd = ct.c2d(drive_plant(params, drive, compliant=True), dt, "zoh")
    g = ct.series(ct.ss(ct.tf([1.0], [1.0, 0.0], dt)), pd, speed_estimator(params))
    omega = _freq_grid(dt)
    f = params.control.inner_crossover_hz
    while f > 0.05 * params.control.inner_crossover_hz:
        w = 2 * math.pi * f
        zc = np.exp(1j * w * dt)
        g_c = _response(g, np.array([w]))[0]
        for ratio in INNER_PI_RATIOS:
            wi = w / ratio
            shape = 1.0 + wi * dt * zc / (zc - 1.0)
            kp = 1.0 / abs(shape * g_c)
            pm, gm, _ = _quick_margins(ct.series(g, _pi(kp, kp * wi, dt)), omega)
            if pm >= MIN_PHASE_MARGIN_DEG and gm >= MIN_GAIN_MARGIN_DB:
                return float(kp), float(kp * wi)
        f *= CROSSOVER_STEP
    raise TuningError(f"{params.source}: drive {drive}: no speed PI keeps {MIN_PHASE_MARGIN_DEG:g} deg / "
                      f"{MIN_GAIN_MARGIN_DB:g} dB down to 5 % of inner_crossover_hz; check [drive.{drive}] "
                      "(gear stiffness and damping, inertias) and [control] speed_filter_hz")


def _design_outer(params: ArmParams, drive: int, kp_w: float, ki_w: float) -> tuple[float, float]:
    """Position P (or PI, see OUTER_PI_RATIO) with the inner loop closed, same rule as the inner loop."""
    dt = params.control.dt
    trial = DriveGains(1.0, 0.0, 0.0, 0.0, 0.0, kp_w, ki_w, 0.0, 0, 0, 0, 0, 0, 0)
    _, t_q = loop_models(params, drive, trial)  # with kp_pos = 1, ki_pos = 0: just the plant
    omega = _freq_grid(dt)
    f = params.control.outer_crossover_hz
    while f > 0.05 * params.control.outer_crossover_hz:
        w = 2 * math.pi * f
        zc = np.exp(1j * w * dt)
        wi = 0.0 if OUTER_PI_RATIO is None else w / OUTER_PI_RATIO
        shape = 1.0 + wi * dt * zc / (zc - 1.0)
        kp = 1.0 / abs(shape * _response(t_q, np.array([w]))[0])
        pm, gm, _ = _quick_margins(ct.series(t_q, _pi(kp, kp * wi, dt)), omega)
        if pm >= MIN_PHASE_MARGIN_DEG and gm >= MIN_GAIN_MARGIN_DB:
            return float(kp), float(kp * wi)
        f *= CROSSOVER_STEP
    raise TuningError(f"{params.source}: drive {drive}: no position gain keeps {MIN_PHASE_MARGIN_DEG:g} deg / "
                      f"{MIN_GAIN_MARGIN_DB:g} dB down to 5 % of outer_crossover_hz; lower "
                      "[control] outer_crossover_hz below the speed loop's crossover")


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
                       inner_crossover_hz=0.0, inner_phase_margin_deg=0.0, inner_gain_margin_db=0.0,
                       outer_crossover_hz=0.0, outer_phase_margin_deg=0.0, outer_gain_margin_db=0.0)
        inner, outer = loop_models(params, drive, g)
        pm_i, gm_i, fc_i = loop_margins(inner)
        pm_o, gm_o, fc_o = loop_margins(outer)
        out.append(DriveGains(**{**asdict(g), "inner_crossover_hz": fc_i, "inner_phase_margin_deg": pm_i,
                                 "inner_gain_margin_db": gm_i, "outer_crossover_hz": fc_o,
                                 "outer_phase_margin_deg": pm_o, "outer_gain_margin_db": gm_o}))
    return Gains(drives=(out[0], out[1], out[2]))


# ---- step responses on the nonlinear twin ------------------------------------

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
    from .plant import ArmSim  # plant imports this module for its default gains

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
    fig.savefig(path)
    return path


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
    fig.savefig(path)
    return path


#: The Bode plot :func:`tune_report` writes beside the step plots.
LOOPS_PNG = "loops_bode.png"


def tune_report(params: ArmParams, out_dir: Path | str) -> list[dict[str, Any]]:
    """Design the gains, step every drive on the twin, write one PNG per drive and the Bode plot (``LOOPS_PNG``).

    Returns one dict per drive with exactly the keys ``drive``, ``step_rad``,
    ``rise_time_s``, ``settling_time_s``, ``overshoot_pct``,
    ``error_at_0_5s_rad``, ``static_error_rad``, ``inner_phase_margin_deg``,
    ``outer_phase_margin_deg``, ``outer_gain_margin_db`` and ``plot``.
    """
    out = Path(out_dir)
    gains = design_gains(params)
    plot_loops(params, gains, out / LOOPS_PNG)
    rows = []
    for drive in (1, 2, 3):
        m = step_response(params, gains, drive, STEP_RAD[drive])
        g = gains.drive(drive)
        png = plot_step(m, out / f"step_drive{drive}.png")
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
        plots.append(f"open loops (Bode, the margins drawn): {Path(rows[0]['plot']).parent / LOOPS_PNG}")
    return "\n".join([header, *body, *legend, "", *plots])


__all__ = [
    "TuningError", "drive_plant", "speed_estimator", "loop_models", "loop_margins", "design_gains",
    "StepMetrics", "step_response", "settling_band_rad", "step_figure", "plot_step", "margin_points",
    "loops_figure", "plot_loops", "tune_report",
    "report_text", "REPORT_COLUMNS", "LOOPS_PNG", "STEP_POSES", "STEP_RAD",
]
