"""The C structs the PC and the firmware share, written once: each field's name, C type, length and comment.

Three structs cross the boundary between the firmware's C and the PC's
ctypes bindings (:mod:`.native`): ``ttt_board`` (what the board is),
``ttt_sensors`` (what it read this control step) and ``ttt_cascade`` (the
controller's arrays, whose lengths are ``ttt_sm.twin.layout``'s).  Each is a
:class:`CStruct` here, its fields in memory order.  From these tables:

* :mod:`.native` builds its ctypes Structures (:meth:`CStruct.ctypes_fields`);
* ``firmware/include/ttt_fw/structs.h`` is generated (``python -m
  ttt_sm.hardware.generate``), the typedefs fw.h and cascade.h use;

so a field added, moved or retyped here moves in C and in Python alike.
``tests/hardware/test_generated.py`` compiles ``offsetof``/``sizeof`` of
every field and compares them with the ctypes Structures.

The tables live beside the bindings rather than in ``ttt_sm.twin.layout``:
those are flat arrays of the compiled step, in numbers; these are C structs
with C types, a matter of the firmware's boundary only.
"""

from __future__ import annotations

import ctypes
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

from ..twin import layout

#: The arm's drives: 1-3 in the thesis, indexed 0-2 in C (the controller's blocks' count).
DRIVES = layout.DRIVES

#: The ctypes type of each C type a table may use; ``ttt_real`` (real.h) is the build's, given when the
#: Structure is built.
CTYPES: dict[str, Any] = {
    "double": ctypes.c_double,
    "float": ctypes.c_float,
    "int32_t": ctypes.c_int32,
    "uint32_t": ctypes.c_uint32,
    "uint16_t": ctypes.c_uint16,
    "uint8_t": ctypes.c_uint8,
}
REAL = "ttt_real"


@dataclass(frozen=True)
class Length:
    """An array length: the C constant that names it, its value, and what it counts."""

    name: str
    value: int
    doc: str = ""


N_DRIVES = Length("TTT_DRIVES", DRIVES, "the arm's drives (drive 1 of the thesis is index 0)")
#: The lengths the generated header defines itself (the controller's blocks' are layout.h's).
DEFINES = (N_DRIVES,)


def block_length(b: layout.Block) -> Length:
    """The length of a controller block, ``TTT_N_<prefix>`` of layout.h."""
    return Length(f"TTT_N_{b.prefix}", b.size)


@dataclass(frozen=True)
class CField:
    """One member: ``ctype name[dims[0]][dims[1]]...;`` and its comment (none if empty)."""

    name: str
    ctype: str
    dims: tuple[Length, ...] = ()
    doc: str = ""

    def ctypes_type(self, real: Any) -> Any:
        """Its ctypes type, `real` standing for ``ttt_real``; arrays nest as C's do (the last length innermost)."""
        if self.ctype == REAL:
            if real is None:
                raise ValueError(f"{self.name}: a ttt_real field needs the build's real type")
            t = real
        else:
            t = CTYPES[self.ctype]
        for dim in reversed(self.dims):
            t = t * dim.value
        return t


@dataclass(frozen=True)
class CStruct:
    """A C struct, ``typedef struct <name> {...} <name>;``: its fields in memory order."""

    name: str
    doc: str
    fields: tuple[CField, ...]

    def ctypes_fields(self, real: Any = None) -> list[tuple[str, Any]]:
        """The ``_fields_`` of its ctypes Structure; `real` is ``ttt_real``'s ctypes type if a field uses it."""
        return [(f.name, f.ctypes_type(real)) for f in self.fields]


def struct(name: str, doc: str, rows: Iterable[tuple[str, str, tuple[Length, ...], str]]) -> CStruct:
    """A :class:`CStruct` from ``(name, ctype, dims, doc)`` rows."""
    return CStruct(name, doc, tuple(CField(*row) for row in rows))


CASCADE = struct("ttt_cascade", "The cascade controller's memory (cascade.h): the blocks of layout.h.", [
    ("cp", REAL, (N_DRIVES, block_length(layout.CP)), "per-drive parameters, cp[d][TTT_CP_*]"),
    ("cg", REAL, (block_length(layout.CG),), "global parameters, cg[TTT_CG_*]"),
    ("cs", REAL, (N_DRIVES, block_length(layout.CS)), "per-drive state, cs[d][TTT_CS_*]"),
    ("cgs", REAL, (block_length(layout.CGS),), "global state, cgs[TTT_CGS_*]"),
    ("act", REAL, (block_length(layout.ACT),), "outputs, act[TTT_ACT_*]: the H-bridges and the servo"),
    ("cm", "int32_t", (N_DRIVES,), "each drive's mode, TTT_MODE_*"),
])

BOARD = struct("ttt_board", "What the board is: told to the PC in the handshake.", [
    ("rad_per_count", "double", (N_DRIVES,), "joint angle of one encoder count (rad)"),
    ("limit_min_rad", "float", (N_DRIVES,), "each joint's range (rad), ..."),
    ("limit_max_rad", "float", (N_DRIVES,), "... (fw.c rejects setpoints far outside it)"),
    ("servo_min_rad", "float", (), "the pen servo's range (rad), ..."),
    ("servo_max_rad", "float", (), "... its setpoints must lie in it"),
    ("servo_safe_rad", "float", (), "where the pen goes in SAFE_STOP (rad)"),
    ("control_period_us", "uint32_t", (), "the control step (us)"),
    ("watchdog_steps", "uint32_t", (), "setpoints missing this many steps -> SAFE_STOP (50 at 1 kHz: 50 ms)"),
    ("status_every", "uint32_t", (), "a STATUS frame every this many control steps"),
    ("late_steps", "uint32_t", (), "setpoints this many steps past their step are late"),
])

SENSORS = struct("ttt_sensors", "What the board read this control step.", [
    ("counts", "int32_t", (N_DRIVES,), "encoder counts since power-on"),
    ("index_count", "int32_t", (N_DRIVES,), "counts latched at each drive's last index edge"),
    ("index_edges", "uint16_t", (N_DRIVES,), "index edges seen"),
    ("index", "uint8_t", (), "bit d: drive d's index switch level"),
    ("current_a", "float", (N_DRIVES,), "armature currents (A)"),
    ("servo_adc", "uint16_t", (), "the pen servo's feedback wire (its potentiometer's wiper), ADC counts"),
])

#: Every shared struct, in the order the generated header declares them.
STRUCTS = (CASCADE, BOARD, SENSORS)
