"""The firmware's cascade controller, compiled C loaded with ctypes: the same commands as the PC's.

:class:`NativeCascade` holds a ``ttt_cascade`` struct (``firmware/include/
ttt_fw/cascade.h``) and offers the commands of
:class:`ttt_sm.twin.cascade.CascadeController`: ``step(counts)``,
``set_setpoints``, ``set_offset_estimate``, ``hold``, ``set_mode``,
``set_open_duty``.  Its parameters are the PC controller's (the gains
download of a real arm): the same rows, converted to the firmware's number
type.  Drives are numbered 1, 2, 3 where a method takes a drive number.

The ctypes Structures of the structs the C shares (:class:`Board`,
:class:`SensorsIn`, the cascade's) are built from the tables of
:mod:`.structs`, which the firmware's ``structs.h`` is generated from.
"""

from __future__ import annotations

import ctypes
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..params import ArmParams
from ..twin import layout
from ..twin.cascade import CascadeController
from ..twin.gains import Gains, check_drive
from . import structs
from .firmware import FirmwareError, Precision
from .link.protocol import Reason

_REAL = {"float": ctypes.c_float, "double": ctypes.c_double}
_NUMPY = {"float": np.float32, "double": np.float64}


def _struct(real: Any) -> type[ctypes.Structure]:
    """``ttt_cascade`` (structs.h) of a build whose ``ttt_real`` is `real`."""
    class Cascade(ctypes.Structure):
        _fields_ = structs.CASCADE.ctypes_fields(real)
    return Cascade


class Board(ctypes.Structure):
    """``ttt_board`` (structs.h): what the board is, told to the PC in the handshake."""

    _fields_ = structs.BOARD.ctypes_fields()


class SensorsIn(ctypes.Structure):
    """``ttt_sensors`` (structs.h): what the board read this control step."""

    _fields_ = structs.SENSORS.ctypes_fields()


#: The watchdog's limit: setpoints missing this long stop the drives (s).
WATCHDOG_S = 0.050
#: Setpoints more than this late (s) are rejected.
LATE_S = 0.002


def board_for(params: ArmParams, servo_safe_rad: float, status_every: int | None = None) -> Board:
    """The board description of an arm built to the parameter file (the emulator's board).

    `servo_safe_rad` is where the pen goes when the watchdog stops the arm
    (the pen lifted); a STATUS goes out every `status_every` control steps
    (default: every chart step).
    """
    b = Board()
    dt = params.control.dt
    for d, p in enumerate(params.drives):
        b.rad_per_count[d] = p.rad_per_count
        b.limit_min_rad[d] = p.limit_min_rad
        b.limit_max_rad[d] = p.limit_max_rad
    s = params.servo
    b.servo_min_rad, b.servo_max_rad = s.min_rad, s.max_rad
    b.servo_safe_rad = servo_safe_rad
    b.control_period_us = int(round(dt * 1e6))
    b.watchdog_steps = int(round(WATCHDOG_S / dt))
    b.status_every = params.control.chart_divider if status_every is None else status_every
    b.late_steps = int(round(LATE_S / dt))
    return b


class FirmwareLibrary:
    """A loaded firmware shared object (:func:`.firmware.build`) and its function signatures."""

    def __init__(self, path: Path, precision: Precision) -> None:
        self.path = Path(path)
        self.precision = precision
        self.lib = ctypes.CDLL(str(self.path))
        real = _REAL[precision]
        self.real = real
        self.dtype = _NUMPY[precision]
        size = self.lib.ttt_real_size()
        if size != ctypes.sizeof(real):
            raise FirmwareError(f"{self.path}: built with a {size}-byte ttt_real, expected {precision}")
        self.Cascade = _struct(real)
        ptr = ctypes.POINTER(self.Cascade)
        counts = ctypes.POINTER(ctypes.c_int32)
        signatures: dict[str, tuple[Any, list[Any]]] = {
            "ttt_cascade_init": (None, [ptr]),
            "ttt_cascade_step": (None, [ptr, counts]),
            "ttt_cascade_set_setpoints": (None, [ptr, ctypes.POINTER(real), ctypes.c_int]),
            "ttt_cascade_set_offset": (None, [ptr, ctypes.c_int, real]),
            "ttt_cascade_hold": (None, [ptr, ctypes.c_int, real]),
            "ttt_cascade_set_mode": (None, [ptr, ctypes.c_int, ctypes.c_int32, real]),
            "ttt_cascade_set_open_duty": (None, [ptr, ctypes.c_int, real]),
            "ttt_cascade_angle": (real, [ptr, ctypes.c_int, ctypes.c_int32]),
        }
        fw = ctypes.c_void_p
        u8p = ctypes.POINTER(ctypes.c_uint8)
        signatures.update({
            "ttt_fw_size": (ctypes.c_size_t, []),
            "ttt_fw_init": (None, [fw, ctypes.POINTER(Board)]),
            "ttt_fw_rx": (None, [fw, u8p, ctypes.c_size_t]),
            "ttt_fw_tx": (ctypes.c_size_t, [fw, u8p, ctypes.c_size_t]),
            "ttt_fw_control_step": (None, [fw, ctypes.POINTER(SensorsIn)]),
            "ttt_fw_sense": (None, [fw, ctypes.POINTER(SensorsIn)]),
            "ttt_fw_cascade": (ptr, [fw]),
            "ttt_fw_state": (ctypes.c_uint8, [fw]),
            "ttt_fw_frames_ok": (ctypes.c_uint32, [fw]),
            "ttt_fw_rejections": (ctypes.c_uint32, [fw, ctypes.c_int]),
            "ttt_fw_lost": (ctypes.c_uint32, [fw]),
            "ttt_fw_step": (ctypes.c_uint32, [fw]),
            "ttt_fw_last_setpoint_step": (ctypes.c_uint32, [fw]),
            "ttt_fw_setpoints_ok": (ctypes.c_uint32, [fw]),
            "ttt_crc16": (ctypes.c_uint16, [u8p, ctypes.c_size_t]),
            "ttt_cobs_encode": (ctypes.c_size_t, [u8p, ctypes.c_size_t, u8p]),
            "ttt_cobs_decode": (ctypes.c_int, [u8p, ctypes.c_size_t, u8p]),
            "ttt_frame_encode": (ctypes.c_size_t, [ctypes.c_uint8, ctypes.c_uint16, u8p, ctypes.c_size_t, u8p]),
        })
        for name, (restype, argtypes) in signatures.items():
            fn = getattr(self.lib, name)
            fn.restype = restype
            fn.argtypes = argtypes


class _ReadOnly:
    """A read-only attribute that reads `name` of the C side (a subclass says how)."""

    def __init__(self, name: str) -> None:
        self.name = name

    def __set__(self, obj: Any, value: Any) -> None:
        raise AttributeError(f"{self.name} is read from the C side; it cannot be set")


class _StructView(_ReadOnly):
    """A numpy view of block `name` of the ctypes struct ``self.c``: assign into it (``[:] = ...``)."""

    def __get__(self, obj: Any, owner: type | None = None) -> np.ndarray:
        return np.ctypeslib.as_array(getattr(obj.c, self.name))


class _FirmwareCount(_ReadOnly):
    """What the firmware's getter `name` returns for ``self.ptr``: a count or a state number."""

    def __get__(self, obj: Any, owner: type | None = None) -> int:
        return int(getattr(obj.lib.lib, self.name)(obj.ptr))


class NativeCascade:
    """The C cascade controller with the PC controller's parameters (the gains download).

    Parameters
    ----------
    lib : FirmwareLibrary
        The loaded firmware.
    params, gains, servo_angle
        As for :class:`~ttt_sm.twin.cascade.CascadeController`, whose
        parameter rows are converted to the firmware's number type.
    """

    def __init__(self, lib: FirmwareLibrary, params: ArmParams, gains: Gains, servo_angle: float) -> None:
        self.lib = lib
        self.c = lib.Cascade()
        self._ref = ctypes.byref(self.c)
        lib.lib.ttt_cascade_init(self._ref)
        pc = CascadeController(params, gains, servo_angle)
        self.cp[:] = pc.cp[:, :layout.N_CP]
        self.cg[:] = pc.cg[:layout.N_CG]
        self.cgs[layout.CGS_SV_SET] = servo_angle
        self._counts = (ctypes.c_int32 * structs.DRIVES)()  # ttt_cascade_step's counts[TTT_DRIVES]
        self._q = (lib.real * 4)()

    # numpy views of the struct's blocks (the firmware's own number type)
    cp, cg, cs = _StructView("cp"), _StructView("cg"), _StructView("cs")
    cgs, act, modes = _StructView("cgs"), _StructView("act"), _StructView("cm")

    def step(self, counts: Sequence[int] | np.ndarray) -> None:
        """One control step: encoder `counts` (3 integers) in, :attr:`act` out."""
        k = self._counts
        k[0], k[1], k[2] = int(counts[0]), int(counts[1]), int(counts[2])
        self.lib.lib.ttt_cascade_step(self._ref, k)

    def set_setpoints(self, q_des: Sequence[float] | np.ndarray, fr_sw: bool = False) -> None:
        """Drives 1-3 in encoder coordinates (rad), q4 the servo angle (rad); `fr_sw` the slow filters."""
        q = self._q
        q[0], q[1], q[2], q[3] = (float(v) for v in q_des[:4])
        self.lib.lib.ttt_cascade_set_setpoints(self._ref, q, 1 if fr_sw else 0)

    def set_offset_estimate(self, drive: int, offset_rad: float) -> None:
        self.lib.lib.ttt_cascade_set_offset(self._ref, check_drive(drive) - 1, float(offset_rad))

    def hold(self, drive: int, q_rad: float) -> None:
        self.lib.lib.ttt_cascade_hold(self._ref, check_drive(drive) - 1, float(q_rad))

    def set_mode(self, drive: int, mode: int, hold_rad: float | None = None) -> None:
        self.lib.lib.ttt_cascade_set_mode(self._ref, check_drive(drive) - 1, int(mode),
                                          0.0 if hold_rad is None else float(hold_rad))

    def set_open_duty(self, drive: int, duty: float) -> None:
        self.lib.lib.ttt_cascade_set_open_duty(self._ref, check_drive(drive) - 1, float(duty))

    def angle(self, drive: int, count: int) -> float:
        """Drive `drive`'s encoder angle for `count`, as the firmware computes it (rad)."""
        return float(self.lib.lib.ttt_cascade_angle(self._ref, check_drive(drive) - 1, int(count)))


class NativeFirmware:
    """The whole firmware core (``ttt_fw``, fw.h): link, cascade, watchdog, in the C that would be flashed.

    Bytes go in with :meth:`rx`, come out with :meth:`tx`; :meth:`step`
    runs one control step on the board's sensor readings.  The accessors
    read the firmware's own counters.
    """

    def __init__(self, lib: FirmwareLibrary, board: Board) -> None:
        self.lib = lib
        self.board = board
        f = lib.lib
        self._mem = ctypes.create_string_buffer(int(f.ttt_fw_size()))
        self.ptr = ctypes.cast(self._mem, ctypes.c_void_p)
        f.ttt_fw_init(self.ptr, ctypes.byref(board))
        self.sensors = SensorsIn()
        self._sensors_ref = ctypes.byref(self.sensors)
        self._out = (ctypes.c_uint8 * 4096)()
        self.cascade = f.ttt_fw_cascade(self.ptr).contents

    def rx(self, data: bytes) -> None:
        """Bytes received from the PC, in any chunking."""
        buf = (ctypes.c_uint8 * len(data)).from_buffer_copy(data) if data else (ctypes.c_uint8 * 1)()
        self.lib.lib.ttt_fw_rx(self.ptr, buf, len(data))

    def tx(self) -> bytes:
        """Everything the firmware has to send now."""
        out = bytearray()
        while True:
            n = self.lib.lib.ttt_fw_tx(self.ptr, self._out, len(self._out))
            out += bytes(self._out[:n])
            if n < len(self._out):
                return bytes(out)

    def sense(self) -> None:
        """Take :attr:`sensors` (fill it first) without a control step (``ttt_fw_sense``)."""
        self.lib.lib.ttt_fw_sense(self.ptr, self._sensors_ref)

    def step(self) -> None:
        """One control step on :attr:`sensors` (fill it first); the commands are in :attr:`act`."""
        self.lib.lib.ttt_fw_control_step(self.ptr, self._sensors_ref)

    @property
    def act(self) -> np.ndarray:
        return np.ctypeslib.as_array(self.cascade.act)

    state = _FirmwareCount("ttt_fw_state")
    frames_ok = _FirmwareCount("ttt_fw_frames_ok")
    lost = _FirmwareCount("ttt_fw_lost")
    steps = _FirmwareCount("ttt_fw_step")
    #: The control step at which the last setpoints were accepted.
    last_setpoint_step = _FirmwareCount("ttt_fw_last_setpoint_step")
    #: SETPOINTS frames the firmware acted on.
    setpoints_ok = _FirmwareCount("ttt_fw_setpoints_ok")

    def rejections(self) -> dict[int, int]:
        """The firmware's rejection counters, by reason number (``TTT_REJ_*``)."""
        return {r: int(self.lib.lib.ttt_fw_rejections(self.ptr, r)) for r in range(len(Reason))}


__all__ = ["FirmwareLibrary", "NativeCascade", "NativeFirmware", "Board", "SensorsIn", "board_for"]
