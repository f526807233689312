"""The memory layouts of the compiled steps, written once: named fields of each flat array, in order.

The controller's step (``_cascade.py``, and its C port ``firmware/src/cascade.c``),
the plant's step (``_plant.py``) and the fused loop's record (``_kernel.py``)
work on flat float64 arrays indexed by named integer offsets (docs/model.md,
"The controller step").  This module is the one place those offsets are
defined: each array is a :class:`Block`, its fields in memory order, each
one or more numbers wide.  From the tables:

* the constants ``<PREFIX>_<FIELD>`` (the field's offset) and
  ``N_<PREFIX>`` (the block's length) are computed when this module is
  imported and become its attributes, plain ``int`` globals that numba
  freezes into the compiled code as constants (``from .layout import
  CP_RPC``);
* the firmware's header ``firmware/include/ttt_fw/layout.h`` is generated
  (``ttt_sm.hardware.generate``; ``python -m ttt_sm.hardware.generate
  --check`` says whether the committed file is current) from the blocks in
  :data:`FIRMWARE`, so the C port indexes its arrays with the same numbers.

Adding a field is one line in a table: every offset after it moves, in
Python at the next import, in C at the next ``python -m
ttt_sm.hardware.generate``.
"""

from __future__ import annotations

import hashlib
from collections.abc import Iterable, MutableMapping
from dataclasses import dataclass
from pathlib import Path


@dataclass(frozen=True)
class Field:
    """One named field of a block: ``width`` numbers from its offset on."""

    name: str
    doc: str = ""
    width: int = 1


@dataclass(frozen=True)
class Block:
    """A flat array's layout: its fields in memory order.

    The constant of field ``NAME`` is ``<prefix>_NAME``; the block's length
    is ``N_<prefix>`` unless ``counted`` is false (an enumeration, as the
    drive modes are, has no length).
    """

    prefix: str
    title: str
    fields: tuple[Field, ...]
    counted: bool = True

    @property
    def size(self) -> int:
        """Numbers in the block."""
        return sum(f.width for f in self.fields)

    def offsets(self) -> dict[str, int]:
        """``{<prefix>_<name>: offset}`` for every field, in memory order."""
        out, at = {}, 0
        for f in self.fields:
            out[f"{self.prefix}_{f.name}"] = at
            at += f.width
        return out

    def constants(self) -> dict[str, int]:
        """The offsets and, for a counted block, ``N_<prefix>``: the block's length."""
        out = self.offsets()
        if self.counted:
            out[f"N_{self.prefix}"] = self.size
        return out


def block(prefix: str, title: str, fields: Iterable[tuple[str, str] | tuple[str, str, int]],
          counted: bool = True) -> Block:
    """A :class:`Block` from ``(name, doc)`` or ``(name, doc, width)`` rows."""
    return Block(prefix, title, tuple(Field(*row) for row in fields), counted)


def constants(blocks: Iterable[Block]) -> dict[str, int]:
    """Every block's constants in one mapping; a name defined twice is an error."""
    out: dict[str, int] = {}
    for b in blocks:
        for name, value in b.constants().items():
            if name in out:
                raise ValueError(f"layout constant {name} defined twice (block {b.prefix})")
            out[name] = value
    return out


def export(namespace: MutableMapping[str, object], blocks: Iterable[Block]) -> dict[str, int]:
    """Put the blocks' constants into a module's `namespace` (its ``globals()``); return them."""
    out = constants(blocks)
    clash = sorted(set(out) & set(namespace))
    if clash:
        raise ValueError(f"layout constants shadow names of {namespace.get('__name__')}: {', '.join(clash)}")
    namespace.update(out)
    return out


def fingerprint(*files: str | Path) -> str:
    """SHA-256 of source files: what a compiled function that read them depends on (numba's cache)."""
    h = hashlib.sha256()
    for f in files:
        h.update(Path(f).read_bytes())
    return h.hexdigest()


def forget_stale_compilations(module_file: str, *depends_on: str | Path) -> None:
    """Drop numba's cached machine code of `module_file` when a file it was compiled against changed.

    numba's disk cache (``cache=True``) checks only the file a function is
    written in; the offsets it froze into the code come from this module.  A
    mark ``<module>.layout-<fingerprint>`` beside the cache says which
    layout the cached code was compiled with; when it is missing, the
    module's ``*.nbi``/``*.nbc`` files go, and numba compiles afresh.  Call
    it at the top of a module whose cached functions read layout constants,
    before any of them runs.  A cache folder that cannot be written is left
    alone (numba then caches elsewhere, or not at all).
    """
    src = Path(module_file)
    folder = src.parent / "__pycache__"
    mark = folder / f"{src.stem}.layout-{fingerprint(__file__, *depends_on)[:16]}"
    if mark.exists():
        return
    try:
        folder.mkdir(exist_ok=True)
        for old in [*folder.glob(f"{src.stem}.*.nbi"), *folder.glob(f"{src.stem}.*.nbc"),
                    *folder.glob(f"{src.stem}.layout-*")]:
            old.unlink(missing_ok=True)
        mark.touch()
    except OSError:
        pass


# ==== the controller (_cascade.py; firmware/src/cascade.c) ==========================================

#: The arm's DC drives: the rows of every per-drive block, and the drives the serial link speaks of.
DRIVES = 3

#: The servo's calibration, five numbers in the order of ``params.servo_duty``'s arguments after the
#: angle (``params.Servo.calibration``): the controller's ``cg`` and the plant's ``pg`` hold it alike.
SERVO_CALIBRATION = (
    ("SV_MIN", "servo: angle range (rad) ..."),
    ("SV_MAX", ""),
    ("SV_PMIN", "... the pulse widths at its ends and the PWM period (s)"),
    ("SV_PMAX", ""),
    ("SV_PERIOD", ""),
)

CP = block("CP", "per-drive parameter row cp[d, CP_*] (SI units; joint side)", [
    ("RPC", "joint angle of one encoder count (rad)"),
    ("KP_POS", "outer position PID: speed setpoint per rad (1/s), ..."),
    ("KI_POS", "... per rad s (1/s^2)"),
    ("KD_POS", "... per rad/s (dimensionless)"),
    ("KFF", "speed feedforward from the setpoint filter's derivative"),
    ("WMAX", "speed setpoint clamp (joint rad/s)"),
    ("KP_SPD", "inner speed PID: duty per rad/s (s/rad), ..."),
    ("KI_SPD", "... per rad (1/rad)"),
    ("KD_SPD", "... per rad/s^2 (s^2/rad)"),
    ("ALPHA_W", "speed filter: w += alpha * (w_raw - w)"),
])
CG = block("CG", "global parameters cg[CG_*]", [
    ("DT", "control step (s)"),
    ("SF_NORMAL", "setpoint filter, normal: a11 a12 b1 a21 a22 b2", 6),
    ("SF_SLOW", "setpoint filter, slow (fr_sw on): same layout", 6),
    *SERVO_CALIBRATION,
])
CS = block("CS", "per-drive state cs[d, CS_*]", [
    ("R_RAW", "position setpoint as given (encoder coordinates, rad)"),
    ("R_F", "filtered setpoint (rad)"),
    ("R_FD", "its derivative (rad/s)"),
    ("Q_PREV", "previous measured angle, for the speed estimate (rad)"),
    ("W_MEAS", "filtered speed estimate (rad/s)"),
    ("INT_POS", "outer integrator (rad/s)"),
    ("INT_SPD", "inner integrator (duty)"),
    ("W_REF", "speed setpoint (rad/s)"),
    ("DUTY_CMD", "duty computed this step (applied next step)"),
    ("OFFSET", "offset estimate of the encoder (rad)"),
    ("OPEN_DUTY", "duty in open-loop mode"),
])
CGS = block("CGS", "global state cgs[CGS_*]", [
    ("FR_SW", "1.0 while slow moves are selected (fr_sw)"),
    ("SV_SET", "servo angle setpoint (rad)"),
    ("SV_DUTY", "its PWM duty (0..1) ..."),
    ("SV_DUTY_OF", "... computed for this setpoint (NaN: not yet), so that it is computed once per setpoint"),
])
ACT = block("ACT", "outputs act[ACT_*]: what the plant (the H-bridges, the servo) receives", [
    ("DUTY", "3 values: PWM duty applied to each H-bridge now (-1..1)", DRIVES),
    ("BRIDGE", "3 values: 1.0 while the bridge is on, 0.0 while off (the motor coasts)", DRIVES),
    ("SV_DUTY", "servo PWM duty (0..1)"),
])
MODE = block("MODE", "modes cm[d] (integers)", [
    ("OFF", "controller and H-bridge off: the motor coasts (no current)"),
    ("CLOSED", "cascade control"),
    ("OPEN", "fixed duty (tests, experiments); duty 0 shorts the motor (brakes)"),
], counted=False)
CR = block("CR", "the twin's one float buffer cf[CR_*, :WIDTH]: each block a row or three", [
    ("CP", "3 rows: cp", DRIVES),
    ("CS", "3 rows: cs", DRIVES),
    ("CG", "cg"),
    ("CGS", "cgs"),
    ("ACT", "act"),
])
#: The controller's blocks, in the order the firmware's header lists them (the C struct holds them as
#: separate arrays: ``ttt_cascade`` in cascade.h).
FIRMWARE = (CP, CG, CS, CGS, ACT, MODE)

# ==== the plant (_plant.py) ==========================================================================

PP = block("PP", "per-drive parameter row pp[d, PP_*] (SI units; joint = load side)", [
    ("SUPPLY", "supply voltage (V)"),
    ("R", "armature resistance (ohm)"),
    ("KT", "torque constant = back-EMF constant (N m / A = V s / rad)"),
    ("JM", "rotor inertia (kg m^2, motor shaft)"),
    ("BM", "motor viscous friction (N m s / rad)"),
    ("TC", "motor Coulomb (= static) friction (N m)"),
    ("N", "gear ratio (motor angle / joint angle)"),
    ("JL", "load inertia (kg m^2, joint)"),
    ("BL", "load viscous friction (N m s / rad)"),
    ("CLEAR", "total gear clearance at the joint (rad)"),
    ("K", "gear stiffness at the joint when engaged (N m / rad)"),
    ("CG", "gear contact damping at the joint (N m s / rad)"),
    ("DTH_M", "motor angle of one encoder count (rad)"),
    ("QMIN", "hard stops (joint, rad)"),
    ("QMAX", ""),
    ("QIDX", "index switch angle (motor-side joint angle, rad)"),
    ("EL_DECAY", "exp(-h R / L): current decay over one sub-step"),
    ("EL_AVG", "(1 - exp(-h R / L)) L / (R h): mean of that decay over the sub-step"),
    # derived per sub-step h, so the sub-step multiplies instead of dividing
    ("INV_R", "1 / R"),
    ("INV_N", "1 / N"),
    ("H_JM", "h / Jm"),
    ("FC_H", "h Tc / Jm: speed change Coulomb friction can stop within one sub-step"),
    ("VISC_M", "1 / (1 + h Bm / Jm): implicit motor viscous friction"),
    ("H_JL", "h / Jl"),
    ("VISC_L", "1 / (1 + h Bl / Jl)"),
    ("TH_IDX", "motor angle of the index switch, N * index angle"),
])
PG = block("PG", "global parameters pg[PG_*]", [
    ("DT", "control step (s)"),
    ("NSUB", "sub-steps per control step (stored as a float)"),
    ("GRAV2", "g * (m2 c2 + (m3 + m_tool) L2): joint-2 gravity from sin(q2) (N m)"),
    ("GRAV23", "g * (m3 c3 + m_tool L3): gravity from sin(q2 + q3) on joints 2 and 3 (N m)"),
    *SERVO_CALIBRATION,
    ("SV_RATE", "servo: slew rate (rad/s), ..."),
    ("SV_TAU", "... lag time constant (s), ..."),
    ("SV_CLEAR", "... gear clearance (rad)"),
    ("I_NOISE", "standard deviation of the current measurement noise (A)"),
    ("SV_INV_TAU", "1 / PG_SV_TAU"),
    ("H", "the sub-step, PG_DT / PG_NSUB (s)"),
    ("FB_K", "servo feedback: ADC counts per rad of the output shaft (the calibration's slope)"),
    ("FB_C0", "ADC counts at 0 rad"),
    ("FB_NOISE", "rms noise of one reading (counts)"),
    ("FB_ALPHA", "the RC filter's step over one sub-step, 1 - exp(-h / tau) (1: no filter)"),
    ("FB_FULL", "the ADC's full scale, 2^bits - 1 (counts)"),
])
PS = block("PS", "per-drive float state ps[d, PS_*]", [
    ("I", "armature current (A)"),
    ("TH", "motor shaft angle (rad, absolute: the encoder's edges sit at fixed angles)"),
    ("WM", "motor shaft speed (rad/s)"),
    ("Q", "load (joint) angle (rad)"),
    ("WQ", "load speed (rad/s)"),
    ("I_MEAS", "measured current (A)"),
])
PGS = block("PGS", "global state pgs[PGS_*]", [
    ("T", "simulated time (s)"),
    ("SV_CMD", "angle the servo's PWM duty commands (rad)"),
    ("SV_TH", "servo's internal (motor-side) angle (rad)"),
    ("SV_Q", "servo output angle q4 after its gear clearance (rad)"),
    ("FB_V", "the feedback wire after the RC filter, as the angle it stands for (rad)"),
    ("FB_COUNTS", "the ADC's reading of it (integer counts, stored as a float)"),
])
PI = block("PI", "per-drive integer state pi[d, PI_*] (int64)", [
    ("C0", "counter value of the motor angle at power-on (counts are relative to it)"),
    ("COUNTS", "encoder counts"),
    ("INDEX", "index switch level (1: motor-side joint angle above the switch)"),
    ("INDEX_COUNT", "counts latched at the last index edge"),
    ("INDEX_EDGES", "number of index edges seen"),
    ("AT_LIMIT", "-1 / +1 when the load rests on its lower / upper hard stop, else 0"),
    ("RNG", "state of the current-noise generator (31-bit LCG)"),
    ("FB_RNG", "row 0 only: state of the servo feedback's noise generator (31-bit LCG)"),
])
PR = block("PR", "the plant's one float buffer pf[PR_*, :WIDTH]: each block a row or three", [
    ("PP", "3 rows: pp", 3),
    ("PS", "3 rows: ps", 3),
    ("PG", "pg"),
    ("PGS", "pgs"),
])

# ==== the fused loop's record (_kernel.py) ==========================================================

REC = block("REC", "record buffer rec[k, REC_*], one row per control step (after it)", [
    ("T", "simulated time (s)"),
    ("R_RAW", "4 columns: setpoints of drives 1-3, servo", 4),
    ("R_F", "4 columns: filtered setpoints, angle the servo duty commands", 4),
    ("Q_ENC", "3 columns: encoder angles", 3),
    ("Q_TRUE", "4 columns: true joint angles", 4),
    ("Q_MOTOR", "3 columns: motor angles over the gear ratio", 3),
    ("CURRENT", "3 columns: true currents", 3),
    ("DUTY", "4 columns: applied duty of drives 1-3, servo duty", 4),
    ("W_REF", "3 columns: speed setpoints", 3),
    ("W_MEAS", "3 columns: speed estimates", 3),
])

BLOCKS = (CP, CG, CS, CGS, ACT, MODE, CR, PP, PG, PS, PGS, PI, PR, REC)
#: Every constant of the tables, by name.
CONSTANTS = export(globals(), BLOCKS)
#: Numbers in the servo's calibration (``CG_SV_MIN`` and ``PG_SV_MIN`` on).
SERVO_CALIBRATION_SIZE = len(SERVO_CALIBRATION)
#: Columns of the controller's buffer (its longest block) and of the plant's.
CONTROLLER_WIDTH = max(b.size for b in (CP, CS, CG, CGS, ACT))
PLANT_WIDTH = max(b.size for b in (PP, PS, PG, PGS))


def __getattr__(name: str) -> int:
    # The constants are real attributes (put there by export above); this tells a type checker
    # that `from .layout import CP_RPC` is an int, and says what a misspelt name is not.
    raise AttributeError(f"module {__name__!r} has no layout constant {name!r} (twin/layout.py's tables)")
