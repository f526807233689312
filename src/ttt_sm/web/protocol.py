"""The cockpit's WebSocket protocol: what a page may send, checked before anything runs.

A page is a view: it sends *commands* (one JSON object per WebSocket text
message) and draws the *frames* and replies the session sends back
(:mod:`.session`).  Every message is checked here first, field by field:
its ``type`` must be one of :data:`COMMANDS`, its fields those the command
declares (no others), each of the declared type and range, the whole message
at most :data:`MAX_MESSAGE_BYTES`.  What is wrong raises
:class:`~.fields.ProtocolError` with one line naming it (``step: 'n' must be a
whole number from 1 to 100000, got -3``); the server sends that back as an
``error`` message and the session goes on, unchanged.

The commands and their fields are declared where they are handled, one
function each (:mod:`.commands`: run control, breakpoints, inputs, history,
coverage, the Tic-tac-toe and Operational pages' own, the Safety chart's Reset);
the field checks are :mod:`.fields`.  Every command may carry ``id`` (a number
or a short text), echoed in its reply.
"""

from __future__ import annotations

import json
import types
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from .commands import SPECS
from .fields import Field, ProtocolError, describe

__all__ = ["COMMANDS", "MAX_MESSAGE_BYTES", "Command", "ProtocolError", "check_command", "parse_command"]

#: The longest message a page may send (a scenario file's text or a coverage report fits).
MAX_MESSAGE_BYTES = 512 * 1024

#: Every command a page may send, with its fields (from the commands' declarations, :mod:`.commands`).
COMMANDS: Mapping[str, Mapping[str, Field]] = types.MappingProxyType(
    {kind: spec.fields for kind, spec in SPECS.items()})


@dataclass(frozen=True)
class Command:
    """A checked command: its type, its fields (defaults filled in) and the page's ``id``."""

    type: str
    args: dict[str, Any] = field(default_factory=dict)
    id: int | str | None = None


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
    """Check a decoded message (see :func:`parse_command`).  The :class:`ProtocolError` carries the message's
    ``id`` (``.msg_id``) and ``type`` (``.command``) when they are well formed, for the error reply to echo."""
    if not isinstance(data, dict):
        raise ProtocolError(f"a command is a JSON object with a \"type\", got {describe(data)}")
    msg_id = data.get("id")
    known_id = msg_id if _good_id(msg_id) else None
    kind = data.get("type")
    try:
        return _check_fields(data)
    except ProtocolError as exc:
        exc.msg_id = known_id
        exc.command = kind if isinstance(kind, str) and kind in COMMANDS else None
        raise


def _good_id(msg_id: Any) -> bool:
    return not isinstance(msg_id, bool) and (
        (isinstance(msg_id, int) and abs(msg_id) < 2**53) or (isinstance(msg_id, str) and len(msg_id) <= 64))


def _check_fields(data: dict[str, Any]) -> Command:
    kind = data.get("type")
    if not isinstance(kind, str):
        raise ProtocolError(f"a command needs a \"type\" (text): one of {', '.join(COMMANDS)}")
    fields = COMMANDS.get(kind)
    if fields is None:
        raise ProtocolError(f"unknown command type {describe(kind)}; commands: {', '.join(COMMANDS)}")
    msg_id = data.get("id")
    if msg_id is not None and not _good_id(msg_id):
        raise ProtocolError(f"{kind}: 'id' must be a whole number or a text of at most 64 characters,"
                            f" got {describe(msg_id)}")
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
