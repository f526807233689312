"""The whiteboard's one error type."""

from __future__ import annotations


class WhiteboardError(ValueError):
    """A whiteboard call got a value it cannot use (cell, region, stroke, file)."""
