"""Hostile parameter sets (issue 22): a sweep holds every set to the checks of
``Scene.subs`` (a negative mass declared real was evaluated), and what it accepts agrees
with solving that set alone.

The property test draws sets mixing good values with negative, zero, non-finite and
textual ones: the sweep and ``ls.solve(scene.subs(set))`` either both refuse (the sweep
naming the set) or agree, and the agreement is checked against the textbook motion of a
damped oscillator, which shares no code with either.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import laplace_springs as ls
from laplace_springs.model.errors import LimitError, SceneError

SCENE = ls.Scene.from_matrices(M=[["m"]], C=[["c"]], K=[["k"]], x0=[1], v0=[0],
                               parameters={"m": "real", "k": "positive", "c": "nonnegative"})
TIMES = [0.0, 0.7, 2.5]


def number(value: object) -> float:
    return float(Fraction(value)) if isinstance(value, str) else float(value)  # type: ignore[arg-type]


def textbook(m: float, c: float, k: float, t: float) -> float:
    """x(t) of m x'' + c x' + k x = 0, x(0) = 1, x'(0) = 0 (under-, critically or over-damped)."""
    if m == 0:  # massless: c x' + k x = 0, or k x = 0 (x = 0 after t = 0)
        return math.exp(-k / c * t) if c else 0.0
    a, w2 = c / (2 * m), k / m - (c / (2 * m)) ** 2
    if abs(w2) < 1e-15:
        return (1 + a * t) * math.exp(-a * t)
    if w2 > 0:
        w = math.sqrt(w2)
        return math.exp(-a * t) * (math.cos(w * t) + a / w * math.sin(w * t))
    r = math.sqrt(-w2)
    return math.exp(-a * t) * (math.cosh(r * t) + a / r * math.sinh(r * t))


@pytest.mark.parametrize(("values", "fragment"), [
    ({"m": [1, -1], "k": [1, 1], "c": [0, 0]}, "set 1 (c = 0.0, k = 1.0, m = -1.0): mass M[0,0] must be positive"),
    ({"m": [1], "k": [-1], "c": [0]}, "parameter 'k' must be a positive number, but set 0 has k = -1.0"),
    ({"m": [1], "k": [1], "c": [-0.5]}, "parameter 'c' must be a nonnegative number, but set 0 has c = -0.5"),
    ({"m": [1], "k": [float("nan")], "c": [0]}, "set 0 has k = nan"),
    ({"m": [1], "k": [np.inf], "c": [0]}, "set 0 has k = inf"),
    ({"m": [1], "k": [1j], "c": [0]}, "parameter 'k': expected a number, got 1j"),
    ({"m": [1], "k": ["__import__('os')"], "c": [0]}, "unexpected character '_' at column 1"),
    ({"m": [1], "k": ["1e400"], "c": [0]}, "has magnitude 1.00e+400"),
    ({"m": [1], "k": [1], "c": [0], "q": [1]}, "'q' is not a parameter of this scene"),
    ({"m": [1, 2], "k": [1], "c": [0]}, "the value arrays must have one length"),
    ({"m": [1], "k": [1]}, "no values for parameter(s) c"),
    ({"m": [[1, 2]], "k": [[1, 1]], "c": [[0, 0]]}, "must be a 1-D array"),
])
def test_bad_sets_are_refused_naming_the_set(values, fragment):
    with pytest.raises(SceneError) as caught:
        ls.sweep(SCENE, values, TIMES)
    assert fragment in str(caught.value)


def test_bad_times_and_too_many_sets():
    for times, fragment in (([-1.0], "is negative"), ([np.nan], "must be finite")):
        with pytest.raises(ValueError, match=fragment):
            ls.sweep(SCENE, {"m": [1], "k": [1], "c": [0]}, times)
    with pytest.raises(LimitError, match="Limits.sweep_max_sets"):
        ls.grid(m=np.ones(10**4), k=np.ones(10**4), c=np.ones(10**4))


_VALUE = st.one_of(st.floats(min_value=0.25, max_value=4.0), st.sampled_from(
    [0.0, -1.0, -1e-300, float("nan"), float("inf"), "1/2", "2", "-3", "1e400", "abc"]))


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(st.tuples(_VALUE, _VALUE, _VALUE), min_size=1, max_size=3))
def test_a_sweep_refuses_what_subs_refuses_and_agrees_with_the_rest(sets):
    values = {name: [s[i] for s in sets] for i, name in enumerate(("m", "k", "c"))}
    alone: list[object] = []
    for m, k, c in sets:
        try:
            alone.append(ls.solve(SCENE.subs({"m": m, "k": k, "c": c})).evaluate(TIMES)[0])
        except ValueError as exc:  # SceneError, LimitError: the set is refused
            alone.append(exc)
    try:
        swept = np.asarray(ls.sweep(SCENE, values, TIMES))
    except ValueError as exc:
        refused = [i for i, a in enumerate(alone) if isinstance(a, Exception)]
        assert refused, f"the sweep refused sets that solve alone: {exc}"
        return
    for row, (m, k, c), single in zip(swept, sets, alone):
        assert not isinstance(single, Exception), (m, k, c, single)
        reference = [textbook(number(m), number(c), number(k), t) for t in TIMES]
        assert np.allclose(row[0], reference, rtol=1e-9, atol=1e-12), (m, k, c)
        assert np.allclose(row[0], single, rtol=1e-12, atol=1e-14)
