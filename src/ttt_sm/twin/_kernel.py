"""The simulated arm's 1 kHz loop: the controller's step and the plant's step, fused.

:func:`run_steps` runs ``n`` control steps; each is the cascade controller's
step (``_cascade.cascade_step``: encoder counts in, actuator commands out)
followed by the plant's step (``_plant.plant_step``: actuator commands in,
motion and sensors out).  The two keep their own state; they meet only in
the counts the plant writes and the commands ``act`` the controller writes,
as a microcontroller and the arm it drives do.  The duty computed in one
step reaches the H-bridge in the next (the one-sample delay is in the
controller).

One compiled function runs the whole loop, so that a call costs what one
kernel call always cost: it takes the controller's float buffer and modes
and the plant's float and integer buffers, and slices the named blocks
(rows ``CR_*``, ``PR_*``) out of them itself.  Both steps and their
per-drive parts are inlined into it (``inline="always"``, numba's IR
inliner): a call between compiled functions passes every array as its
unpacked fields, which cost ~60 ns per control step before they were
inlined, and the inlined loop is ~20 % faster than the single kernel it
replaces.  An optional record
buffer ``rec[k, REC_*]`` gets one row per control step.

``NUMBA_DISABLE_JIT=1`` runs the same code as plain Python (slowly) for a
debugger.  docs/model.md derives the equations.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numba import njit

from ..params import values as servo_formula
from . import _cascade, _plant, layout
from ._cascade import cascade_step
from ._plant import plant_step
from .layout import (
    ACT_DUTY,
    ACT_SV_DUTY,
    CGS_SV_SET,
    CP_RPC,
    CR_ACT,
    CR_CG,
    CR_CGS,
    CR_CP,
    CR_CS,
    CS_OFFSET,
    CS_R_F,
    CS_R_RAW,
    CS_W_MEAS,
    CS_W_REF,
    PGS_SV_CMD,
    PGS_SV_Q,
    PGS_T,
    PI_COUNTS,
    PP_N,
    PR_PG,
    PR_PGS,
    PR_PP,
    PR_PS,
    PS_I,
    PS_Q,
    PS_TH,
    REC_CURRENT,
    REC_DUTY,
    REC_Q_ENC,
    REC_Q_MOTOR,
    REC_Q_TRUE,
    REC_R_F,
    REC_R_RAW,
    REC_T,
    REC_W_MEAS,
    REC_W_REF,
)


def _sources_fingerprint() -> str:
    """SHA-256 of the source files the fused loop is compiled from: the two steps, their layout, the servo's formula.

    numba's disk cache checks only the file of the function it caches: after
    an edit of ``_cascade.py``, ``_plant.py``, ``layout.py`` or the servo's
    calibration in ``params/values.py`` alone it would load the fused loop compiled
    from the old code.  Its cache key includes the contents of the
    function's closure, so the loop closes over this fingerprint.
    """
    return layout.fingerprint(*(str(m.__file__) for m in (_cascade, _plant, layout, servo_formula)))


def _compile_run_steps(fingerprint: str) -> Any:
    """The fused loop, compiled (or loaded from numba's cache) for these sources of the steps."""

    @njit(cache=True)
    def run_steps(n: int, cf: np.ndarray, cm: np.ndarray, pf: np.ndarray, pi: np.ndarray, rec: np.ndarray) -> None:
        """Run `n` control steps in place; fill `rec[:n]` if it has at least n rows.

        `cf`: the controller's float buffer (rows ``layout.CR_*``), `cm`: its modes;
        `pf`: the plant's float buffer (rows ``layout.PR_*``), `pi`: its integer state.
        """
        fingerprint  # noqa: B018  (a closure variable: part of numba's cache key)
        # the blocks are rows: slicing them costs nothing (a reshape would call into numba's runtime)
        cp, cs = cf[CR_CP:CR_CP + 3], cf[CR_CS:CR_CS + 3]
        cg, cgs, act = cf[CR_CG], cf[CR_CGS], cf[CR_ACT]
        pp, ps = pf[PR_PP:PR_PP + 3], pf[PR_PS:PR_PS + 3]
        pg, pgs = pf[PR_PG], pf[PR_PGS]
        counts = pi[:, PI_COUNTS]  # the wires from the encoders to the controller
        record = rec.shape[0] >= n
        for k in range(n):
            cascade_step(cp, cg, cs, cgs, cm, counts, act)
            plant_step(pp, pg, ps, pgs, pi, act)
            if record:
                rec[k, REC_T] = pgs[PGS_T]
                for d in range(3):
                    rec[k, REC_R_RAW + d] = cs[d, CS_R_RAW]
                    rec[k, REC_R_F + d] = cs[d, CS_R_F]
                    rec[k, REC_Q_ENC + d] = counts[d] * cp[d, CP_RPC] + cs[d, CS_OFFSET]
                    rec[k, REC_Q_TRUE + d] = ps[d, PS_Q]
                    rec[k, REC_Q_MOTOR + d] = ps[d, PS_TH] / pp[d, PP_N]
                    rec[k, REC_CURRENT + d] = ps[d, PS_I]
                    rec[k, REC_DUTY + d] = act[ACT_DUTY + d]
                    rec[k, REC_W_REF + d] = cs[d, CS_W_REF]
                    rec[k, REC_W_MEAS + d] = cs[d, CS_W_MEAS]
                rec[k, REC_R_RAW + 3] = cgs[CGS_SV_SET]
                rec[k, REC_R_F + 3] = pgs[PGS_SV_CMD]
                rec[k, REC_Q_TRUE + 3] = pgs[PGS_SV_Q]
                rec[k, REC_DUTY + 3] = act[ACT_SV_DUTY]

    return run_steps


run_steps = _compile_run_steps(_sources_fingerprint())
