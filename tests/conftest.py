"""Shared independent references for the tests (see laplace_springs.reference)."""

from __future__ import annotations

import pytest

from laplace_springs.reference import reference_motion, relative_error

__all__ = ["reference_motion", "relative_error"]


@pytest.fixture
def reference():
    return reference_motion
