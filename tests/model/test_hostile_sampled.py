"""Hostile sampled data (issue 22): every value is a real float64 number or a SceneError
naming its index; complex values are never made real with only a NumPy warning, and
numbers beyond the float64 range never raise a bare OverflowError."""

from __future__ import annotations

import decimal
import warnings
from fractions import Fraction

import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st

import laplace_springs as ls
from laplace_springs.model.errors import LimitError, SceneError


@pytest.mark.parametrize(("values", "fragment"), [
    (np.array([0, 1j, 0]), "sampled values[1] = 1j is complex; samples must be real"),
    ([0, complex(0, 2), 0], "sampled values[1] = 2j is complex"),
    ([0, 10**400, 0], "sampled values[1] = 1000"),
    ([0, Fraction(10**400, 3), 0], "is beyond the float64 range"),
    ([0, decimal.Decimal("1e400"), 0], "is beyond the float64 range"),
    ([0, float("inf"), 0], "sampled values[1] = inf is not finite"),
    ([0, True, 0], "sampled values[1] = True is a boolean, not a number"),
    ([0, "1", 0], "sampled values[1] = '1' is not a number"),
    ([0, None, 0], "sampled values[1] = None is not a number"),
    ([0, sp.Symbol("k"), 0], "sampled values[1] = k is not a number"),
    ([0, sp.I, 0], "sampled values[1] = I is complex"),
    ([[0], [1], [2]], "one-dimensional"),
    ([[0], [1, 2], [2]], "must be a flat sequence of numbers"),
    ("012", "must be a sequence of numbers"),
], ids=["numpy complex", "complex", "huge int", "huge Fraction", "huge Decimal", "inf", "bool",
        "text", "None", "Symbol", "sympy I", "column", "ragged", "a string"])
def test_bad_values_are_named_by_index(values, fragment):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no ComplexWarning: an error instead
        with pytest.raises(SceneError) as caught:
            ls.sampled([0, 1, 2], values)
    assert fragment in str(caught.value)
    if "beyond" in fragment or "1000" in fragment:
        assert "float64 range" in str(caught.value) and len(str(caught.value)) < 200


def test_times_are_checked_the_same_way():
    with pytest.raises(SceneError, match=r"sampled times\[1\] = 1j is complex"):
        ls.sampled([0, 1j], [1, 1])
    with pytest.raises(SceneError, match=r"strictly increasing: times\[2\] = 1.0 follows times\[1\] = 2.0"):
        ls.sampled([0, 2, 1], [0, 0, 0])


def test_exact_real_values_of_every_kind_are_their_float64():
    values = [1, Fraction(1, 3), decimal.Decimal("0.1"), np.float32(0.5), sp.Rational(2, 3),
              sp.Float("1.25"), complex(3, 0), np.int8(-4)]
    f = ls.sampled(range(len(values)), values)
    assert f.values.tolist() == [1.0, 1 / 3, 0.1, 0.5, 2 / 3, 1.25, 3.0, -4.0]


def test_the_caller_s_array_is_copied_and_the_result_is_read_only():
    values = np.array([0.0, 1.0, 0.0])
    f = ls.sampled([0, 1, 2], values)
    values[1] = 5.0
    assert f.values.tolist() == [0.0, 1.0, 0.0] and not f.values.flags.writeable


def test_the_number_of_samples_is_limited_before_conversion(set_limits):
    set_limits(max_samples=100)
    with pytest.raises(LimitError, match=r"101 samples, more than the limit 100 \(Limits.max_samples\)"):
        ls.sampled(np.arange(101.0), np.zeros(101))


@settings(max_examples=200, deadline=None)
@given(st.lists(st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.integers(),
                          st.fractions(), st.complex_numbers(), st.booleans(), st.none(),
                          st.text(max_size=3), st.decimals()), min_size=2, max_size=6))
def test_any_values_give_float64_samples_or_a_scene_error(values):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        try:
            f = ls.sampled(range(len(values)), values)
        except SceneError as exc:
            assert "sampled values[" in str(exc) or "sampled values must" in str(exc)
            return
    assert f.values.dtype == np.float64 and np.all(np.isfinite(f.values))
    for value, stored in zip(values, f.values):
        assert stored == float(value.real if isinstance(value, complex) else value)
