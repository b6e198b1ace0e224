"""Shared fixtures of the Python tests: short runs of the three cases."""

from __future__ import annotations

import os

import pytest
from hypothesis import settings

import adaptimp
from adaptimp import SimResult

# Property tests draw the same examples on every run (CI must not be flaky);
# `HYPOTHESIS_PROFILE=explore pytest` draws new ones for a deeper search.
settings.register_profile("deterministic", derandomize=True, database=None)
settings.register_profile("explore", derandomize=False)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "deterministic"))

# Long enough to have rows after the 2 s settling time (SPEC §12), short enough
# to keep the suite fast: 60 000 steps per case at the paper's Ts = 50 µs.
T_SHORT = 3.0


@pytest.fixture(scope="session")
def runs() -> dict[str, SimResult]:
    """The paper scenario of each case, cut to T = 3 s."""
    return {case: adaptimp.simulate(case, T=T_SHORT) for case in adaptimp.CASES}


@pytest.fixture
def close_figures():
    """Close every pyplot figure a test made."""
    yield
    import matplotlib.pyplot as plt

    plt.close("all")
