"""The twin's error type."""

from __future__ import annotations


class SimError(ValueError):
    """An invalid request to the simulated arm (bad pose, bad setpoints)."""


__all__ = ["SimError"]
