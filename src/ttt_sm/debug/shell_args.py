"""What the ``ttt-sm debug`` commands read from their arguments: counts, simulated times, ``Chart.name``.

Each refuses a bad argument with a :class:`~.errors.DebugError` that names the command and what it expected.
"""

from __future__ import annotations

from .errors import DebugError


def parse_count(arg: str, what: str, default: int = 1) -> int:
    if not arg.strip():
        return default
    try:
        n = int(arg)
    except ValueError:
        raise DebugError(f"{what}: expected a whole number, got {arg.strip()!r}") from None
    return n


def parse_seconds(arg: str, what: str, default: float) -> float:
    if not arg.strip():
        return default
    try:
        return float(arg)
    except ValueError:
        raise DebugError(f"{what}: expected simulated seconds, got {arg.strip()!r}") from None


def parse_duration(arg: str, what: str, default: float, tick_s: float) -> float:
    """Simulated seconds from ``0.5``, ``0.5s``, ``500ms`` or ``250 ticks`` (chart ticks of ``tick_s``)."""
    text = arg.strip().lower()
    if not text:
        return default
    number, factor = text, 1.0
    for suffix, scale in (("ticks", tick_s), ("tick", tick_s), ("ms", 1e-3), ("s", 1.0)):
        if text.endswith(suffix):
            number, factor = text[:-len(suffix)].strip(), scale
            break
    try:
        return float(number) * factor
    except ValueError:
        raise DebugError(f"{what}: expected simulated time, e.g. {what} 0.5 (seconds), {what} 0.5s,"
                         f" {what} 500ms or {what} 250 ticks; got {arg.strip()!r}") from None


def parse_chart_dot(arg: str, what: str) -> tuple[str, str]:
    chart, dot, name = arg.partition(".")
    if not dot or not chart or not name or " " in name:
        raise DebugError(f"{what}: expected Chart.input, got {arg!r}")
    return chart, name
