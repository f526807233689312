"""What the camera reader keeps about its link: how hard it tries to reopen it, and what it has seen.

:class:`ReconnectPolicy` bounds the reader's reopening of a lost port
(exponential backoff, bounded in count and time); :class:`LinkCounters`
counts frames, rejections, gaps and reconnects as they happen, and
:class:`LinkStats` is their snapshot (:attr:`~.reader.SerialCameraReader.stats`;
docs/smartcam.md lists the fields).
"""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True)
class ReconnectPolicy:
    """How hard the reader tries to (re)open the port: exponential backoff, bounded in count and time.

    Attempt ``k`` (0-based) waits ``min(max_delay_s, first_delay_s * factor**k)``
    after the previous one; the reader gives up after ``max_attempts`` failed
    opens or ``max_duration_s`` since the link went down, whichever comes first.
    """

    first_delay_s: float = 0.05
    max_delay_s: float = 1.0
    factor: float = 2.0
    max_attempts: int = 100
    max_duration_s: float = 60.0

    def __post_init__(self) -> None:
        if not (0 <= self.first_delay_s <= self.max_delay_s) or self.factor < 1:
            raise ValueError(f"reconnect policy needs 0 <= first_delay_s <= max_delay_s and factor >= 1, got {self}")
        if self.max_attempts < 1 or not self.max_duration_s >= 0:
            raise ValueError(f"reconnect policy needs max_attempts >= 1 and max_duration_s >= 0, got {self}")

    def delay_s(self, attempt: int) -> float:
        """Wait before attempt ``attempt + 1``, seconds."""
        return float(min(self.max_delay_s, self.first_delay_s * self.factor ** min(attempt, 64)))


@dataclass(frozen=True)
class LinkStats:
    """A snapshot of what the reader has seen (counts since it was made)."""

    frames_ok: int
    rejected: dict[str, int]
    """Rejected lines (and garbage runs) by :class:`~.errors.Reason` value."""
    gaps: int
    """Times the sequence number jumped forward by more than one."""
    frames_missed: int
    """Frames the gaps skipped, in total."""
    duplicates: int
    seq_restarts: int
    """Times the sequence number went back (the camera restarted)."""
    disconnects: int
    reconnects: int
    silences: int
    """Times the port stayed open but no valid frame came for ``silence_s``."""
    statuses: int
    garbage_bytes: int
    skipped_bytes: int
    """Bytes dropped after an open up to the first '$' (the end of a line sent before the port opened)."""
    bytes_read: int

    @property
    def rejected_total(self) -> int:
        return sum(self.rejected.values())


@dataclass
class LinkCounters:
    """The reader's running counts; :meth:`snapshot` turns them into :class:`LinkStats`."""

    frames_ok: int = 0
    rejected: dict[str, int] = field(default_factory=dict)
    gaps: int = 0
    frames_missed: int = 0
    duplicates: int = 0
    seq_restarts: int = 0
    disconnects: int = 0
    reconnects: int = 0
    silences: int = 0
    statuses: int = 0
    garbage_bytes: int = 0
    bytes_read: int = 0

    def snapshot(self, skipped_bytes: int) -> LinkStats:
        """The counts so far; ``skipped_bytes``: the framer's count of bytes dropped after an open."""
        return LinkStats(self.frames_ok, dict(self.rejected), self.gaps, self.frames_missed, self.duplicates,
                         self.seq_restarts, self.disconnects, self.reconnects, self.silences, self.statuses,
                         self.garbage_bytes, skipped_bytes, self.bytes_read)
