"""The firmware's cascade controller, compiled C loaded with ctypes: the same commands as the PC's.

:class:`NativeCascade` holds a ``ttt_cascade`` struct (``firmware/include/
ttt_fw/cascade.h``) and offers the commands of
:class:`ttt_sm.twin.cascade.CascadeController`: ``step(counts)``,
``set_setpoints``, ``set_offset_estimate``, ``hold``, ``set_mode``,
``set_open_duty``.  Its parameters are the PC controller's (the gains
download of a real arm): the same rows, converted to the firmware's number
type.  Drives are numbered 1, 2, 3 where a method takes a drive number.
"""

from __future__ import annotations

import ctypes
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..params import ArmParams
from ..twin import _cascade as C
from ..twin.cascade import CascadeController
from ..twin.control import Gains, check_drive
from .firmware import FirmwareError, Precision

_REAL = {"float": ctypes.c_float, "double": ctypes.c_double}
_NUMPY = {"float": np.float32, "double": np.float64}


def _struct(real: Any) -> type[ctypes.Structure]:
    class Cascade(ctypes.Structure):
        _fields_ = [
            ("cp", (real * C.N_CP) * 3),
            ("cg", real * C.N_CG),
            ("cs", (real * C.N_CS) * 3),
            ("cgs", real * C.N_CGS),
            ("act", real * C.N_ACT),
            ("cm", ctypes.c_int32 * 3),
        ]
    return Cascade


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
        for name, (restype, argtypes) in signatures.items():
            fn = getattr(self.lib, name)
            fn.restype = restype
            fn.argtypes = argtypes


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
        self.cp[:] = pc.cp[:, :C.N_CP]
        self.cg[:] = pc.cg[:C.N_CG]
        self.cgs[C.CGS_SV_SET] = servo_angle
        self._counts = (ctypes.c_int32 * 3)()
        self._q = (lib.real * 4)()

    # numpy views of the struct's blocks (the firmware's own number type)
    @property
    def cp(self) -> np.ndarray:
        return np.ctypeslib.as_array(self.c.cp)

    @property
    def cg(self) -> np.ndarray:
        return np.ctypeslib.as_array(self.c.cg)

    @property
    def cs(self) -> np.ndarray:
        return np.ctypeslib.as_array(self.c.cs)

    @property
    def cgs(self) -> np.ndarray:
        return np.ctypeslib.as_array(self.c.cgs)

    @property
    def act(self) -> np.ndarray:
        return np.ctypeslib.as_array(self.c.act)

    @property
    def modes(self) -> np.ndarray:
        return np.ctypeslib.as_array(self.c.cm)

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


__all__ = ["FirmwareLibrary", "NativeCascade"]
