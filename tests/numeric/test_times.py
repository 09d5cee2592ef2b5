"""Evaluation times (numeric/times.py): exact beyond float64's integers, clear errors beyond
its range."""

from __future__ import annotations

import re
from fractions import Fraction

import numpy as np
import pytest
import sympy as sp

import laplace_springs as ls
from laplace_springs.numeric.times import as_times


@pytest.mark.parametrize("time", [10**400, 2**1100, Fraction(10**400, 3), sp.Integer(10)**400,
                                  10**(10**5), -10**400],
                         ids=["1e400", "2^1100", "fraction", "sympy", "1e100000", "negative"])
def test_a_time_beyond_float64_is_a_clear_error(time) -> None:
    with pytest.raises(ValueError, match=r"times\[1\] = .* is beyond the float64 range"):
        as_times([1.0, time])
    with pytest.raises(ValueError, match="beyond the float64 range"):
        ls.solve(ls.load_scene("wall-pair")).evaluate([time], dps=30)


@pytest.mark.parametrize("time", [2**60 + 1, 3**40, Fraction(2**70 + 1, 7)],
                         ids=["2^60+1", "3^40", "fraction"])
def test_an_exact_time_beyond_2_to_53_keeps_its_low_part(time) -> None:
    times = as_times([time])
    assert abs(Fraction(float(times.hi[0])) + Fraction(float(times.lo[0])) - Fraction(time)) \
        <= Fraction(time) / 2**104
    assert times.lo[0] != 0


def test_the_span_is_the_first_and_last_time() -> None:
    assert as_times([3.0, 0.5, 2.0]).span == (0.5, 3.0)
    assert as_times(["1/3", 0, 7]).span == (0.0, 7.0)
    assert as_times([2.0, 1.0]).subset([1]).span == (1.0, 1.0)


@pytest.mark.parametrize("times, shape", [
    ([[0.0, 1.0], [2.0, 3.0]], (2, 2)), ([[0.5], [1.5]], (2, 1)),
    (np.arange(4.0).reshape(2, 2), (2, 2)), (np.arange(3.0)[:, None], (3, 1)),
    (np.zeros((1, 2, 1)), (1, 2, 1))])
def test_times_with_more_than_one_axis_are_refused_not_flattened(times, shape) -> None:
    message = re.escape(f"times must be a 1-D array (or a number), got shape {shape}")
    with pytest.raises(ValueError, match=message):
        as_times(times)
    sol = ls.solve(ls.load_scene("wall-pair"))
    with pytest.raises(ValueError, match=message):
        sol.evaluate(times)
    assert sol.evaluate(0.5).shape == sol.evaluate([0.5]).shape == (sol.scene.n, 1)
