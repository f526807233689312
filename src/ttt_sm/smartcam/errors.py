"""The errors of the camera serial link: each says what was wrong, where, and what to do."""

from __future__ import annotations

from enum import StrEnum


class Reason(StrEnum):
    """Why a line from the camera was rejected.

    Transmission damage shows as the framing and checksum reasons; a line whose
    checksum is right but whose content is wrong was *sent* wrong (a camera
    bug) and gets a content reason.  See docs/smartcam.md, "Rejections".
    """

    # framing: found by the framer before a line is complete
    GARBAGE = "garbage"                      # bytes outside any sentence (before a '$')
    TRUNCATED = "truncated"                  # a sentence cut short: a new '$' or a disconnect came first
    OVERLONG = "overlong"                    # longer than the longest valid sentence, no end in sight
    BAD_FRAMING = "bad_framing"              # no '$' start, no CR LF end, or bytes that are not printable ASCII
    # checksum
    NO_CHECKSUM = "no_checksum"              # no '*' before the end of the line
    BAD_CHECKSUM_FORMAT = "bad_checksum_format"  # not exactly 4 upper-case hex digits after '*'
    CHECKSUM_MISMATCH = "checksum_mismatch"  # CRC-16 of the body differs from the one sent
    # content (the checksum was right)
    UNKNOWN_SENTENCE = "unknown_sentence"    # neither TTT (frame) nor TTS (status)
    FIELD_COUNT = "field_count"              # not 25 percentages (or not level and text for a status)
    BAD_SEQUENCE = "bad_sequence"            # sequence number not a decimal 0..65535
    NON_NUMERIC = "non_numeric"              # a percentage that is not a number
    NOT_FINITE = "not_finite"                # NaN or infinity
    OUT_OF_RANGE = "out_of_range"            # a number outside 0..100
    BAD_NUMBER_FORMAT = "bad_number_format"  # in range but not written with exactly one decimal
    BAD_STATUS = "bad_status"                # a status level other than INFO, WARN, ERROR or an overlong text


class SerialLinkError(Exception):
    """Base of the errors of the camera serial link."""


class EncodeError(SerialLinkError, ValueError):
    """A frame or status that cannot be put on the wire (wrong count, NaN, outside 0..100)."""


class FrameError(SerialLinkError, ValueError):
    """A line from the camera that the strict decoder rejects.

    ``reason`` is a :class:`Reason`, ``detail`` says what exactly (which field,
    which value), ``line`` holds the raw bytes (possibly cut, for the log).
    """

    def __init__(self, reason: Reason, detail: str, line: bytes = b"") -> None:
        self.reason = reason
        self.detail = detail
        self.line = line
        super().__init__(f"{reason.value}: {detail}; line {snippet(line)}")


class PortUnavailable(SerialLinkError):
    """The camera's port could not be opened within the reconnect policy's bounds."""


class LinkLost(SerialLinkError):
    """The camera's port went away and did not come back within the reconnect policy's bounds."""


class CameraSilent(SerialLinkError):
    """The port is open but no valid frame arrived within the time asked for."""


def snippet(line: bytes, limit: int = 48) -> str:
    """The first ``limit`` bytes of ``line`` as a Python bytes literal, '...' when cut (for log messages)."""
    if len(line) <= limit:
        return repr(bytes(line))
    return repr(bytes(line[:limit])) + f"...(+{len(line) - limit} bytes)"
