"""The stiff-and-extreme battery against a certified arb matrix exponential.

``reference_motion_arb`` doubles its working precision until every ball radius is below
10^-digits of max |x|, so each reference is converged by construction (independent of
the transform route: no partial fractions, no roots). Solutions and references are
cached per module, in memory.
"""

from __future__ import annotations

from decimal import Decimal
from functools import cache

import mpmath
import numpy as np
import pytest

import laplace_springs as ls
from laplace_springs.bench.battery import KINDS, BatteryCase, battery_cases
from laplace_springs.bench.reference import reference_motion_arb, relative_error

CASES = {case.name: case for case in battery_cases()}


@cache
def _solution(name: str, method: str = "auto") -> ls.Solution:
    return ls.solve(CASES[name].scene, method=method)


@cache
def _reference(name: str, digits: int) -> np.ndarray:
    case = CASES[name]
    return reference_motion_arb(case.scene, case.times, digits=digits)


def _times(case: BatteryCase) -> np.ndarray:
    return np.array([float(v) for v in case.times])


def test_battery_covers_every_kind():
    assert len(CASES) >= 20
    assert {case.kind for case in CASES.values()} == set(KINDS)


@pytest.mark.parametrize("name", list(CASES))
def test_times_are_exact_binary64(name):
    for text in CASES[name].times:
        assert Decimal(float(text)) == Decimal(text), text


@pytest.mark.parametrize("method", ["auto", "certified"])
@pytest.mark.parametrize("name", list(CASES))
def test_float64_within_1e_12(name, method):
    # "certified" is the bench's ours-certified; "auto" is ours (the default route)
    case = CASES[name]
    solution = _solution(name, method)
    assert method == "auto" or solution.method == method
    values = solution.evaluate(_times(case))
    assert relative_error(values, _reference(name, 40)) <= 1e-12


@pytest.mark.parametrize("name", list(CASES))
def test_error_estimate_bounds_the_error(name):
    case = CASES[name]
    values, error = _solution(name).evaluate(_times(case), return_error=True)
    reference = _reference(name, 40)
    scale = max(abs(float(r)) for r in reference.ravel())
    with mpmath.workdps(50):
        actual = np.array([[float(abs(mpmath.mpf(v) - r)) for v, r in zip(vr, rr)]
                           for vr, rr in zip(values, reference)])
    # the reference itself is certified to 1e-40 of max |x|
    assert np.all(error + 1e-38 * scale >= actual)
    assert error.max() <= 1e-12 * scale


@pytest.mark.parametrize("name", ["near-critical-above-1e-14", "separated-real-c1e6",
                                  "near-exceptional-point", "near-resonance-1e-8",
                                  "stiffness-ratio-1e8"])
def test_mpmath_evaluation_to_50_digits(name):
    case = CASES[name]
    times = case.times[::4]
    values = _solution(name).evaluate(np.array(times), dps=50)
    reference = reference_motion_arb(case.scene, times, digits=60)
    with mpmath.workdps(70):
        scale = max(abs(r) for r in reference.ravel())
        diff = max(abs(v - r) for v, r in zip(values.ravel(), reference.ravel()))
        assert diff <= mpmath.mpf(10) ** -45 * scale
