"""Why the link refused bytes or a frame: the firmware's reasons, by number, and one refusal's record.

Both ends count their refusals by :class:`Reason` (its table is in
:mod:`.protocol`, from which the firmware's ``TTT_REJ_*`` in
``firmware/include/ttt_fw/protocol.h`` are generated); the firmware
reports its counts in a ``HEARTBEAT_REPLY``, one per reason.
"""

from __future__ import annotations

from dataclasses import dataclass

from .protocol import Reason

N_REASONS = len(Reason)


@dataclass(frozen=True)
class Rejection:
    """Bytes that were not a valid frame, or a valid frame refused: why, and what it was."""

    reason: Reason
    detail: str
    size: int
    """Wire bytes it covers (0 for a frame refused after decoding)."""

    def __str__(self) -> str:
        return f"{self.reason.name.lower()}: {self.detail}"


__all__ = ["N_REASONS", "Reason", "Rejection"]
