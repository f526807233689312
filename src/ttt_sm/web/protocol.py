"""The cockpit's WebSocket protocol: what a page may send, checked before anything runs.

A page is a view: it sends *commands* (one JSON object per WebSocket text
message) and draws the *frames* and replies the session sends back
(:mod:`.session`).  Every message is checked here first, field by field:
its ``type`` must be one of :data:`COMMANDS`, its fields those the command
declares (no others), each of the declared type and range, the whole message
at most :data:`MAX_MESSAGE_BYTES`.  What is wrong raises
:class:`ProtocolError` with one line naming it (``step: 'n' must be a whole
number from 1 to 100000, got -3``); the server sends that back as an
``error`` message and the session goes on, unchanged.

Nothing here runs code from a message: conditions and breakpoint specs are
text that the debugger parses with the project's grammar
(:mod:`ttt_sm.runtime.conditions`), never ``eval``.

The commands, with their fields (``?``: optional, default in brackets):

===================  ==========================================================
``hello``            ``page?`` (text): a page joins; the session answers with
                     ``session`` (what it runs) and a full ``frame``
``run``, ``pause``   run until a breakpoint or a pause; pause
``step``             ``n?`` [1]: control steps
``tick``             ``n?`` [1]: chart ticks
``next``             ``timeout_s?`` [10]: run to the next transition
``speed``            ``value``: 0.1 .. 10 times real time, or ``"max"``
``break``            ``spec``: a breakpoint as ``ttt-sm debug`` writes it
                     (``enter Control.wait_1``, ``when q_true[1] > 90deg``)
``break_delete``     ``breakpoint``: a breakpoint number, or ``"all"``
``break_enable``     ``breakpoint``, ``enabled`` (true/false)
``set``              ``chart``, ``name``, ``value`` (text as typed, a number or
                     a flag), ``force?`` [false]
``release``          ``chart?``, ``name?``: one forced input, or all
``post``             ``chart``, ``event``, ``data?`` {name: number/text/flag}
``replay``           ``tick``: go back (or forward, as far as the run has been)
                     to that chart tick
``timeline``         ``chart``, ``seconds?`` [20]: when its states were active
``coverage_run``     ``files``: names of the session's scenario files
``coverage_scenario`` ``name``, ``text``: a scenario file's text, run
``coverage_load``    ``report``: the JSON of ``ttt-sm scenario run --coverage --json``
``coverage_clear``   colour no coverage
``ack``              ``frame``: the page has drawn that frame (for the latency figure)
``game_symbol``      ``symbol``: ``"X"`` or ``"O"``, the manipulator's (the
                     Tic-tac-toe page's Symbol; before the first move only)
``game_cell``        ``row``, ``column`` (1..5): the person draws there
``game_play``        the Tic-tac-toe page's Play
``game_stop``        its Stop: the arm returns to its start pose, then stops
``game_engine``      ``engine``: ``"strong"`` or ``"thesis"``, the manipulator's
                     game algorithm (before the first move only)
``game_new``         a new game: a new robot from power-on, paused (Run starts it)
``operate_trigger``  ``symbol`` (``"X"``, ``"O"`` or ``"sine"``),
                     ``magnitude_cm`` (0 .. 10), ``speed`` (0 .. 5): the
                     Operational page's Trigger (:mod:`.operate`)
``operate_stop``     its Stop_simulation: the arm returns to its start pose
``safety_reset``     every page's Reset of the Safety chart (docs/safety.md):
                     its ``reset`` event, posted as ``post Safety reset``
                     is; refused while the chart has not tripped
===================  ==========================================================

Every command may carry ``id`` (a number or a short text), echoed in its reply.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

#: The longest message a page may send (a scenario file's text or a coverage report fits).
MAX_MESSAGE_BYTES = 512 * 1024
#: The longest breakpoint spec, condition, name or short text.
MAX_TEXT = 500
#: The longest scenario text sent from a page.
MAX_SCENARIO_BYTES = 256 * 1024
#: A step, tick or replay asks for at most this many (the debugger bounds the time too).
MAX_COUNT = 1_000_000
#: Speeds offered by the pages, besides "max" (the session takes any from 0.1 to 10).
SPEEDS = (0.1, 0.25, 0.5, 1.0, 2.0, 5.0, 10.0)


class ProtocolError(ValueError):
    """A message that is not a command the session takes; the text names what is wrong."""


@dataclass(frozen=True)
class Command:
    """A checked command: its type, its fields (defaults filled in) and the page's ``id``."""

    type: str
    args: dict[str, Any] = field(default_factory=dict)
    id: int | str | None = None


Check = Callable[[str, str, Any], Any]


def _describe(value: Any) -> str:
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
                                f" got {_describe(value)}")
        return value
    return check


def number(lo: float, hi: float) -> Check:
    def check(cmd: str, name: str, value: Any) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) \
                or not lo <= value <= hi:
            raise ProtocolError(f"{cmd}: {name!r} must be a number from {lo:g} to {hi:g}, got {_describe(value)}")
        return float(value)
    return check


def text(max_len: int = MAX_TEXT, *, allow_empty: bool = False) -> Check:
    def check(cmd: str, name: str, value: Any) -> str:
        if not isinstance(value, str):
            raise ProtocolError(f"{cmd}: {name!r} must be text, got {_describe(value)}")
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
                            f" got {_describe(value)}")
    return value


def flag(cmd: str, name: str, value: Any) -> bool:
    if not isinstance(value, bool):
        raise ProtocolError(f"{cmd}: {name!r} must be true or false, got {_describe(value)}")
    return value


def scalar(cmd: str, name: str, value: Any) -> bool | int | float | str:
    """A value typed for an input or an event's datum: a flag, a finite number or a short text."""
    if isinstance(value, bool):
        return value
    if isinstance(value, (int, float)):
        if not math.isfinite(value) or abs(value) > 1e12:
            raise ProtocolError(f"{cmd}: {name!r} must be a finite number (|x| <= 1e12), got {_describe(value)}")
        return value
    if isinstance(value, str):
        return text(100)(cmd, name, value)
    raise ProtocolError(f"{cmd}: {name!r} must be a number, a flag or a text, got {_describe(value)}")


def speed(cmd: str, name: str, value: Any) -> float | None:
    if value == "max":
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) \
            or not SPEEDS[0] <= value <= SPEEDS[-1]:
        raise ProtocolError(f"{cmd}: {name!r} must be a number from {SPEEDS[0]:g} to {SPEEDS[-1]:g}"
                            f" (times real time) or \"max\", got {_describe(value)}")
    return float(value)


def bp_id(cmd: str, name: str, value: Any) -> int | None:
    if value == "all":
        return None
    return integer(1, 10**9)(cmd, name, value)


def names_list(max_items: int) -> Check:
    def check(cmd: str, name: str, value: Any) -> list[str]:
        if not isinstance(value, list) or not value or len(value) > max_items:
            raise ProtocolError(f"{cmd}: {name!r} must be a list of 1 to {max_items} names, got {_describe(value)}")
        return [identifier(cmd, f"{name}[{i}]", v) for i, v in enumerate(value)]
    return check


def event_data(cmd: str, name: str, value: Any) -> dict[str, Any]:
    if not isinstance(value, dict) or len(value) > 16:
        raise ProtocolError(f"{cmd}: {name!r} must be an object of at most 16 name: value pairs,"
                            f" got {_describe(value)}")
    return {identifier(cmd, f"{name} key", k): scalar(cmd, f"{name}.{k}", v) for k, v in value.items()}


def report(cmd: str, name: str, value: Any) -> dict[str, Any]:
    """A coverage report's JSON (checked in detail against the charts by :mod:`.coverage`)."""
    if not isinstance(value, dict):
        raise ProtocolError(f"{cmd}: {name!r} must be the JSON object that `ttt-sm scenario run --coverage"
                            f" --json` prints, got {_describe(value)}")
    return value


def symbol(cmd: str, name: str, value: Any) -> str:
    if value not in ("X", "O"):
        raise ProtocolError(f"{cmd}: {name!r} must be \"X\" or \"O\", got {_describe(value)}")
    return str(value)


def engine(cmd: str, name: str, value: Any) -> str:
    if value not in ("strong", "thesis"):
        raise ProtocolError(f"{cmd}: {name!r} must be \"strong\" or \"thesis\", got {_describe(value)}")
    return str(value)


def shape(cmd: str, name: str, value: Any) -> str:
    if value not in ("X", "O", "sine"):
        raise ProtocolError(f"{cmd}: {name!r} must be \"X\", \"O\" or \"sine\", got {_describe(value)}")
    return str(value)


@dataclass(frozen=True)
class Field:
    check: Check
    required: bool = True
    default: Any = None


def _opt(check: Check, default: Any = None) -> Field:
    return Field(check, False, default)


#: Every command a page may send, with its fields.
COMMANDS: Mapping[str, Mapping[str, Field]] = {
    "hello": {"page": _opt(identifier, "charts")},
    "run": {},
    "pause": {},
    "step": {"n": _opt(integer(1, MAX_COUNT), 1)},
    "tick": {"n": _opt(integer(1, MAX_COUNT), 1)},
    "next": {"timeout_s": _opt(number(0.001, 3600.0), 10.0)},
    "speed": {"value": Field(speed)},
    "break": {"spec": Field(text())},
    "break_delete": {"breakpoint": Field(bp_id)},
    "break_enable": {"breakpoint": Field(integer(1, 10**9)), "enabled": Field(flag)},
    "set": {"chart": Field(identifier), "name": Field(identifier), "value": Field(scalar),
            "force": _opt(flag, False)},
    "release": {"chart": _opt(identifier), "name": _opt(identifier)},
    "post": {"chart": Field(identifier), "event": Field(identifier), "data": _opt(event_data, {})},
    "replay": {"tick": Field(integer(0, 10**9))},
    "timeline": {"chart": Field(identifier), "seconds": _opt(number(0.01, 3600.0), 20.0)},
    "coverage_run": {"files": Field(names_list(200))},
    "coverage_scenario": {"name": Field(text(200)), "text": Field(text(MAX_SCENARIO_BYTES))},
    "coverage_load": {"report": Field(report)},
    "coverage_clear": {},
    "ack": {"frame": Field(integer(0, 2**53))},
    "game_symbol": {"symbol": Field(symbol)},
    "game_cell": {"row": Field(integer(1, 5)), "column": Field(integer(1, 5))},
    "game_play": {},
    "game_stop": {},
    "game_engine": {"engine": Field(engine)},
    "game_new": {},
    "operate_trigger": {"symbol": Field(shape), "magnitude_cm": Field(number(0.0, 10.0)),
                        "speed": Field(number(0.0, 5.0))},
    "operate_stop": {},
    "safety_reset": {},
}


def parse_command(message: str | bytes) -> Command:
    """Check one message from a page; :class:`ProtocolError` names what is wrong."""
    if isinstance(message, bytes):
        if len(message) > MAX_MESSAGE_BYTES:
            raise ProtocolError(f"message of {len(message)} bytes; at most {MAX_MESSAGE_BYTES}")
        try:
            message = message.decode("utf-8")
        except UnicodeDecodeError:
            raise ProtocolError("message is not UTF-8 text") from None
    if len(message) > MAX_MESSAGE_BYTES:
        raise ProtocolError(f"message of {len(message)} characters; at most {MAX_MESSAGE_BYTES}")
    try:
        data = json.loads(message, parse_constant=_no_constant)
    except RecursionError:
        raise ProtocolError("message is nested too deeply") from None
    except ValueError as exc:
        raise ProtocolError(f"message is not JSON: {exc}") from None
    return check_command(data)


def _no_constant(name: str) -> Any:
    raise ValueError(f"{name} is not JSON")


def check_command(data: Any) -> Command:
    """Check a decoded message (see :func:`parse_command`)."""
    if not isinstance(data, dict):
        raise ProtocolError(f"a command is a JSON object with a \"type\", got {_describe(data)}")
    kind = data.get("type")
    if not isinstance(kind, str):
        raise ProtocolError(f"a command needs a \"type\" (text): one of {', '.join(COMMANDS)}")
    fields = COMMANDS.get(kind)
    if fields is None:
        raise ProtocolError(f"unknown command type {_describe(kind)}; commands: {', '.join(COMMANDS)}")
    msg_id = data.get("id")
    if msg_id is not None and (isinstance(msg_id, bool) or not (
            (isinstance(msg_id, int) and abs(msg_id) < 2**53) or (isinstance(msg_id, str) and len(msg_id) <= 64))):
        raise ProtocolError(f"{kind}: 'id' must be a whole number or a text of at most 64 characters,"
                            f" got {_describe(msg_id)}")
    unknown = [k for k in data if k not in fields and k not in ("type", "id")]
    if unknown:
        known = ", ".join(fields) or "none"
        raise ProtocolError(f"{kind}: unknown field{'s' if len(unknown) > 1 else ''}"
                            f" {', '.join(repr(k) for k in unknown[:5])}; fields: {known}")
    args: dict[str, Any] = {}
    for name, spec in fields.items():
        if name not in data:
            if spec.required:
                raise ProtocolError(f"{kind}: missing field {name!r}")
            args[name] = spec.default
            continue
        args[name] = spec.check(kind, name, data[name])
    return Command(kind, args, msg_id)
