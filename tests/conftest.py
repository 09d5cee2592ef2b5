"""Shared independent references for the tests (see laplace_springs.bench.reference)."""

from __future__ import annotations

import contextlib
import os

import pytest
from hypothesis import settings

from laplace_springs.bench.reference import reference_motion, relative_error
from laplace_springs.limits import using_limits

# The suite is deterministic: property tests draw the same examples on every run and
# machine, so CI cannot fail on a draw nobody saw. HYPOTHESIS_PROFILE=explore draws new
# examples each run (what to use while hunting for bugs).
settings.register_profile("ci", derandomize=True, print_blob=True)
settings.register_profile("explore", derandomize=False, print_blob=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))

__all__ = ["reference_motion", "relative_error"]


@pytest.fixture
def reference():
    return reference_motion


@pytest.fixture
def set_limits():
    """``set_limits(field=value, ...)``: run the rest of the test under other limits."""
    with contextlib.ExitStack() as stack:
        yield lambda **changes: stack.enter_context(using_limits(**changes))
