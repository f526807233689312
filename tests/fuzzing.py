"""Settings shared by the fuzz tests of every input surface (docs/reliability.md).

Each surface has a quick property test in the default run (a few hundred
cases) and a long one under the ``soak`` marker (thousands of cases).  Both
are derandomized, so the default run, ``make soak`` and CI see the same cases
every time and a red run means a change, not luck.  ``make fuzz`` runs the
soak tests on fresh random cases (``TTT_SM_FUZZ_RANDOM=1``) to look for what
the fixed cases miss; what it finds becomes a named case in the surface's
tests before it is fixed.  The property is always
the same: the surface raises nothing but the project's own error type, and
its message is one line that names the file, line or argument.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis.strategies import SearchStrategy

#: Fresh random cases in the soak run (``make fuzz``) instead of the fixed ones (``make soak``).
RANDOM = os.environ.get("TTT_SM_FUZZ_RANDOM", "") not in ("", "0")
#: Cases per surface in the default run, and in the soak run.
QUICK_EXAMPLES = 200
SOAK_EXAMPLES = 5000

_COMMON: dict[str, Any] = dict(deadline=None, database=None,
                               suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much,
                                                      HealthCheck.data_too_large])


def fuzz(*strategies: SearchStrategy[Any], quick: int = QUICK_EXAMPLES, soak: int = SOAK_EXAMPLES
         ) -> Callable[[Callable[..., None]], tuple[Callable[..., None], Callable[..., None]]]:
    """Turn a property into ``(quick_test, soak_test)``: bind both to ``test_...`` names."""
    def wrap(check: Callable[..., None]) -> tuple[Callable[..., None], Callable[..., None]]:
        quick_test = settings(derandomize=True, max_examples=quick, **_COMMON)(given(*strategies)(check))
        soak_test = pytest.mark.soak(settings(max_examples=soak, derandomize=not RANDOM, **_COMMON)(
            given(*strategies)(check)))
        return quick_test, soak_test
    return wrap


def one_line(message: str, names: str, limit: int = 1500) -> None:
    """The message is one line (no huge value formatted into it) and names ``names`` (a file, an argument).

    The limit leaves room for the lists of valid names some messages give (a chart's 50 states).
    """
    assert "\n" not in message, message
    assert len(message) <= limit, message[:200]
    assert names in message, message
