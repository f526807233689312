"""What a field of a cockpit command may hold: one check per kind of value, each naming what is wrong.

A command declares its fields where it is handled (:func:`.commands.spec.command`),
each with one of these checks; :mod:`.protocol` runs them on every message
before the session sees it.  A check takes the command's type, the field's name
and the value as decoded from JSON, and returns the value the handler gets (a
default filled in, ``"max"`` read as None, ...) or raises :class:`ProtocolError`
with one line: ``step: 'n' must be a whole number from 1 to 100000, got -3``.

Nothing here runs code from a message: conditions and breakpoint specs are
text that the debugger parses with the project's grammar
(:mod:`ttt_sm.runtime.conditions`), never ``eval``.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from ..runtime.jsonable import dumps

#: The longest breakpoint spec, condition, name or short text.
MAX_TEXT = 500
#: The longest scenario text sent from a page.
MAX_SCENARIO_BYTES = 256 * 1024
#: A step, tick or replay asks for at most this many (the debugger bounds the time too).
MAX_COUNT = 1_000_000
#: Speeds offered by the pages, besides "max" (the session takes any from 0.1 to 10).
SPEEDS = (0.1, 0.25, 0.5, 1.0, 2.0, 5.0, 10.0)


class ProtocolError(ValueError):
    """A message that is not a command the session takes; the text names what is wrong.

    ``msg_id`` and ``command``: the message's ``id`` and ``type``, when it had them well formed (the error
    reply echoes them)."""

    msg_id: int | str | None = None
    command: str | None = None


#: A field's check: ``check(command type, field name, value)`` -> the value the handler gets.
Check = Callable[[str, str, Any], Any]


@dataclass(frozen=True)
class Field:
    """One field of a command: its check, whether a message must carry it, and its default."""

    check: Check
    required: bool = True
    default: Any = None


def optional(check: Check, default: Any = None) -> Field:
    """A field a message may leave out: the handler gets ``default`` then."""
    return Field(check, False, default)


def describe(value: Any) -> str:
    """A value as an error message quotes it: JSON where it is JSON, at most 60 characters."""
    text = json.dumps(value, allow_nan=False) if _plain(value) else repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _plain(value: Any) -> bool:
    try:
        json.dumps(value, allow_nan=False)
    except (TypeError, ValueError, RecursionError):
        return False
    return True


def integer(lo: int, hi: int) -> Check:
    def check(cmd: str, name: str, value: Any) -> int:
        if isinstance(value, bool) or not isinstance(value, int) or not lo <= value <= hi:
            raise ProtocolError(f"{cmd}: {name!r} must be a whole number from {lo} to {hi},"
                                f" got {describe(value)}")
        return value
    return check


def number(lo: float, hi: float) -> Check:
    def check(cmd: str, name: str, value: Any) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) \
                or not lo <= value <= hi:
            raise ProtocolError(f"{cmd}: {name!r} must be a number from {lo:g} to {hi:g}, got {describe(value)}")
        return float(value)
    return check


def text(max_len: int = MAX_TEXT, *, allow_empty: bool = False) -> Check:
    def check(cmd: str, name: str, value: Any) -> str:
        if not isinstance(value, str):
            raise ProtocolError(f"{cmd}: {name!r} must be text, got {describe(value)}")
        if len(value) > max_len:
            raise ProtocolError(f"{cmd}: {name!r} is {len(value)} characters long; at most {max_len}")
        if not allow_empty and not value.strip():
            raise ProtocolError(f"{cmd}: {name!r} is empty")
        if any(ord(c) < 32 and c not in "\t\n\r" for c in value):
            raise ProtocolError(f"{cmd}: {name!r} holds control characters")
        return value
    return check


def identifier(cmd: str, name: str, value: Any) -> str:
    """A chart, datum, event or file name: letters, digits, ``_ . -``, at most 100 characters."""
    if not isinstance(value, str) or not value or len(value) > 100 \
            or not all(c.isalnum() or c in "_.-" for c in value) or not value.isascii():
        raise ProtocolError(f"{cmd}: {name!r} must be a name (letters, digits, _ . -; at most 100),"
                            f" got {describe(value)}")
    return value


def flag(cmd: str, name: str, value: Any) -> bool:
    if not isinstance(value, bool):
        raise ProtocolError(f"{cmd}: {name!r} must be true or false, got {describe(value)}")
    return value


def scalar(cmd: str, name: str, value: Any) -> bool | int | float | str:
    """A value typed for an input or an event's datum: a flag, a finite number or a short text."""
    if isinstance(value, bool):
        return value
    if isinstance(value, (int, float)):
        if not math.isfinite(value) or abs(value) > 1e12:
            raise ProtocolError(f"{cmd}: {name!r} must be a finite number (|x| <= 1e12), got {describe(value)}")
        return value
    if isinstance(value, str):
        return text(100)(cmd, name, value)
    raise ProtocolError(f"{cmd}: {name!r} must be a number, a flag or a text, got {describe(value)}")


def speed(cmd: str, name: str, value: Any) -> float | None:
    """Times real time, :data:`SPEEDS`' range, or ``"max"`` (None: as fast as it goes)."""
    if value == "max":
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) \
            or not SPEEDS[0] <= value <= SPEEDS[-1]:
        raise ProtocolError(f"{cmd}: {name!r} must be a number from {SPEEDS[0]:g} to {SPEEDS[-1]:g}"
                            f" (times real time) or \"max\", got {describe(value)}")
    return float(value)


def bp_id(cmd: str, name: str, value: Any) -> int | None:
    """A breakpoint's number, or ``"all"`` (None)."""
    if value == "all":
        return None
    return integer(1, 10**9)(cmd, name, value)


def names_list(max_items: int) -> Check:
    def check(cmd: str, name: str, value: Any) -> list[str]:
        if not isinstance(value, list) or not value or len(value) > max_items:
            raise ProtocolError(f"{cmd}: {name!r} must be a list of 1 to {max_items} names, got {describe(value)}")
        return [identifier(cmd, f"{name}[{i}]", v) for i, v in enumerate(value)]
    return check


def event_data(cmd: str, name: str, value: Any) -> dict[str, Any]:
    """An event's data: at most 16 ``name: scalar`` pairs."""
    if not isinstance(value, dict) or len(value) > 16:
        raise ProtocolError(f"{cmd}: {name!r} must be an object of at most 16 name: value pairs,"
                            f" got {describe(value)}")
    return {identifier(cmd, f"{name} key", k): scalar(cmd, f"{name}.{k}", v) for k, v in value.items()}


def report(cmd: str, name: str, value: Any) -> dict[str, Any]:
    """A coverage report's JSON (checked in detail against the charts by :mod:`.coverage`)."""
    if not isinstance(value, dict):
        raise ProtocolError(f"{cmd}: {name!r} must be the JSON object that `ttt-sm scenario run --coverage"
                            f" --json` prints, got {describe(value)}")
    return value


def one_of(*choices: str) -> Check:
    """One of a few texts (``"X"`` or ``"O"``)."""
    quoted = [dumps(c) for c in choices]
    said = quoted[0] if len(quoted) == 1 else f"{', '.join(quoted[:-1])} or {quoted[-1]}"

    def check(cmd: str, name: str, value: Any) -> str:
        if value not in choices:
            raise ProtocolError(f"{cmd}: {name!r} must be {said}, got {describe(value)}")
        return str(value)
    return check
