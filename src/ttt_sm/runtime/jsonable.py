"""Strict JSON for everything ``ttt_sm`` prints or writes: :func:`jsonable` and :func:`dumps`.

JSON has no NaN and no infinity.  Python's :func:`json.dumps` writes them as
the bare words ``NaN`` and ``Infinity`` by default, which most JSON readers
(``jq``, JavaScript's ``JSON.parse``, Go, Rust's serde) refuse, so one such
value would make a whole ``--json`` document or trace file unreadable.  Here a
non-finite number becomes ``null`` (the value is not a number, and ``null``
is JSON's "no value"), and :func:`dumps` passes ``allow_nan=False`` so that a
non-finite number that slipped past :func:`jsonable` is an error at the
writer, not a broken file at the reader.

This module is the one place that turns results into JSON: the command
line's ``--json`` output, the charts' traces (:mod:`.listeners`), the game
record and the debugger all go through it.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
from collections.abc import Mapping
from typing import Any

_KEY_TYPES = (str, int, float, bool, type(None))


def jsonable(value: Any) -> Any:
    """A copy of ``value`` that :func:`json.dumps` writes as strict JSON.

    Dataclass instances and named tuples become dicts, numpy arrays and scalars lists and
    numbers (anything with ``tolist``), paths strings, tuples lists; NaN and
    ±infinity become ``None`` (``null``).  Anything else becomes its
    ``repr``, so a chart's data of any type can be traced.
    """
    if value is None or isinstance(value, (bool, int, str)):
        return value
    if isinstance(value, float):  # numpy's float64 too
        return float(value) if math.isfinite(value) else None
    if isinstance(value, Mapping):
        return {(k if isinstance(k, _KEY_TYPES) else str(k)): jsonable(v) for k, v in value.items()}
    if isinstance(value, tuple) and hasattr(value, "_asdict"):  # a named tuple (the arm's Sensors)
        return jsonable(value._asdict())
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return jsonable(dataclasses.asdict(value))
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    tolist = getattr(value, "tolist", None)  # numpy arrays and scalars
    if callable(tolist):
        return jsonable(tolist())
    return repr(value)


def dumps(value: Any, **kwargs: Any) -> str:
    """``json.dumps(jsonable(value), allow_nan=False, **kwargs)``: strict JSON text of ``value``."""
    return json.dumps(jsonable(value), allow_nan=False, **kwargs)
