"""Flat memoryviews of the compiled steps' memory: plain Python numbers for the hot accessors."""

from __future__ import annotations

from typing import Any

import numpy as np


def flat_view(a: np.ndarray) -> Any:
    """A flat memoryview of `a`'s memory: its items read and written as plain Python numbers."""
    return memoryview(a.reshape(-1))  # type: ignore[arg-type]  # numpy's stubs lack __buffer__
