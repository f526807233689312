"""Plain stages that need no chart: joint-space moves."""

from __future__ import annotations

import numpy as np

from .scheduler import Signals


class JointMoveStage:
    """A joint stage that moves all joints linearly from `q_from` to `q_to`.

    The move lasts long enough that no joint exceeds `max_speed` (rad/s); the
    task pose is ignored (set it to NaN so IK is skipped).  Used to get from the
    power-on pose to a pose above the board without crossing it, before the
    Control chart's start_stop exists.
    """

    def __init__(self, q_from: np.ndarray, q_to: np.ndarray, chart_dt: float, max_speed: float = 0.8) -> None:
        q_from = np.asarray(q_from, dtype=float)
        q_to = np.asarray(q_to, dtype=float)
        span = float(np.max(np.abs(q_to - q_from)))
        n = max(1, int(np.ceil(span / (max_speed * chart_dt))))
        self.samples = q_from + (np.arange(1, n + 1)[:, None] / n) * (q_to - q_from)
        self.index = 0

    @property
    def done(self) -> bool:
        """True once the target has been sent."""
        return self.index >= len(self.samples)

    def tick(self, signals: Signals) -> None:
        """Replace the joint setpoints with the next sample of the move."""
        signals.task = np.full(4, np.nan)
        signals.q_set = self.samples[min(self.index, len(self.samples) - 1)].copy()
        self.index += 1
