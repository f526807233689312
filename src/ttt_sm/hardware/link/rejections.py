"""Why the link refused bytes or a frame: the firmware's reasons, by number, and one refusal's record.

Both ends count their refusals by :class:`Reason`, the numbers of the
firmware's ``TTT_REJ_*`` (``firmware/include/ttt_fw/link.h``); the
firmware reports its counts in a ``HEARTBEAT_REPLY``, one per reason.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum


class Reason(IntEnum):
    """Why bytes or a frame were rejected (the same numbers as the firmware's ``TTT_REJ_*``)."""

    COBS = 0  # not valid COBS
    CRC = 1  # CRC mismatch
    SHORT = 2  # fewer bytes than a header and a CRC
    OVERLONG = 3  # no 0x00 within the longest frame
    UNKNOWN_TYPE = 4  # no such message type (or not one this side takes)
    PARTIAL = 5  # body shorter than its type's: a frame cut short
    LENGTH = 6  # body longer than its type's
    DUPLICATE = 7  # sequence number seen last
    OUT_OF_ORDER = 8  # sequence number behind the last one
    LATE = 9  # setpoints for a step already past
    REFUSED = 10  # valid, but not in this state
    VALUE = 11  # a field out of range


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
