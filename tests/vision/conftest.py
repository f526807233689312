"""Fixtures of the vision tests: the parameters and simulated photos."""

from __future__ import annotations

import pytest

from ttt_sm.params import ArmParams, load_params


@pytest.fixture(scope="session")
def params() -> ArmParams:
    return load_params()
