"""Hostile input, generated (hypothesis): text never runs, nothing hangs, no silent garbage.

1. Text built from the grammar's tokens, Python fragments and junk goes through the parser:
   the result is a finite real SymPy expression or a SceneError, within a second, and no
   eval/exec/sympify is ever called.
2. Random times and precisions go through ``evaluate`` on every route: a ValueError naming
   the value, or finite values with finite, nonnegative bounds that hold against the
   textbook solution cos(2t).
"""

from __future__ import annotations

import builtins
import math
import time
from contextlib import contextmanager

import mpmath
import numpy as np
import pytest
import sympy
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from laplace_springs import LimitError, Scene, SceneError, solve
from laplace_springs.bench.reference import reference_motion_arb
from laplace_springs.limits import limits
from laplace_springs.model.numbers import parse_expression
from laplace_springs.model.symbols import TIME

SETTINGS = {"deadline": None, "suppress_health_check": [HealthCheck.too_slow]}

_TOKENS = st.sampled_from([
    "1", "0", "2", "10", "0.5", "1e300", "1e-300", "9" * 50, "1e4000", ".", "e", "E", "pi", "t",
    "k", "c", "x", "nan", "inf", "oo", "zoo", "I", "j", "__import__", "os", "system", "'ls'", '"',
    "lambda", ":", "exec", "eval", "open", "import", "[", "]", "{", "}", ";", "@", "$", "\\", "#",
    "+", "-", "*", "/", "**", "^", "(", ")", ",", " ", "exp", "sin", "cos", "sinh", "cosh",
    "sqrt", "Abs", "Heaviside", "DiracDelta", "exp(", "exp(exp(", "**10**", "10**10**10", "é", "\x00",
])
_TEXT = st.one_of(st.lists(_TOKENS, max_size=25).map("".join), st.text(max_size=40))
_PARAMETERS = {"k": sympy.Symbol("k", positive=True), "c": sympy.Symbol("c", positive=True)}


@contextmanager
def nothing_evaluated():
    """eval, exec, sympify and parse_expr raise when given text while the body runs.

    (SymPy sympifies its own objects, e.g. in ``1 + E``, and imports modules lazily.)
    """
    saved = builtins.eval, builtins.exec, sympy.sympify, sympy.parse_expr

    def refusing_text(original):
        def guarded(value, *args, **kwargs):
            if isinstance(value, (str, bytes)):
                raise AssertionError(f"text was evaluated: {value!r}")
            return original(value, *args, **kwargs)  # code objects: the import system
        return guarded

    builtins.eval, builtins.exec, sympy.sympify, sympy.parse_expr = map(refusing_text, saved)
    try:
        yield
    finally:
        builtins.eval, builtins.exec, sympy.sympify, sympy.parse_expr = saved


@settings(max_examples=400, **SETTINGS)
@given(text=_TEXT)
def test_parser_returns_a_finite_value_or_a_scene_error_quickly(text):
    started = time.perf_counter()
    with nothing_evaluated():
        try:
            value = parse_expression(text, "K[0,0]", variables=_PARAMETERS)
        except SceneError as error:
            assert str(error).startswith("K[0,0]: ")
            value = None
    assert time.perf_counter() - started < 1.0, text  # a guard against a hang
    if value is not None:
        assert isinstance(value, sympy.Expr)
        assert not value.has(sympy.nan, sympy.zoo, sympy.oo, -sympy.oo, sympy.I)
        assert value.free_symbols <= {*_PARAMETERS.values(), TIME}


# ----------------------------------------------------------------------------- evaluate

_ROUTES = ("exact", "modal", "certified")


@pytest.fixture(scope="module")
def solutions():
    scene = Scene.from_matrices(M=[[1]], K=[[4]], x0=[1], v0=[0])  # x = cos 2t
    return {method: solve(scene, method=method) for method in _ROUTES}


_TIMES = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.floats(0, 1e6),
    st.integers(-10, 10**6),
    st.sampled_from(["0.1", "1/3", "-1", "nan", "abc", "1e400", "t", "", "exp(1)"]),
)
_DPS = st.one_of(st.none(), st.integers(-5, 60), st.sampled_from([0, 10_001, 10**9]),
                 st.floats(allow_nan=True), st.sampled_from(["30", True]))


def _bad_time(value) -> bool:
    if isinstance(value, str):
        return value in ("-1", "nan", "abc", "1e400", "t", "")
    return not math.isfinite(value) or value < 0


def _bad_dps(dps) -> bool:
    return dps is not None and (not isinstance(dps, int) or isinstance(dps, bool)
                                or not 1 <= dps <= 10_000)


@settings(max_examples=120, **SETTINGS)
@given(times=st.lists(_TIMES, min_size=1, max_size=4), dps=_DPS, route=st.sampled_from(_ROUTES))
def test_evaluate_refuses_bad_times_and_precisions_and_bounds_the_rest(solutions, times, dps, route):
    sol = solutions[route]
    if any(_bad_time(value) for value in times) or _bad_dps(dps):
        with pytest.raises(ValueError):
            sol.evaluate(times, dps=dps, return_error=True)
        return
    dps = None if dps is None else min(dps, 40)  # keep the draw fast
    values, bounds = sol.evaluate(times, dps=dps, return_error=True)
    with mpmath.workdps(60):
        for value, bound, time_ in zip(values[0], bounds[0], times):
            reference = mpmath.cos(2 * _exact_time(time_))
            assert mpmath.isfinite(value) and mpmath.isfinite(bound) and bound >= 0
            assert abs(mpmath.mpf(value) - reference) <= bound + 2.0**-1074


def _exact_time(value):
    """The time a valid entry denotes, at the working precision: floats by their binary value."""
    if value == "exp(1)":
        return mpmath.e
    if isinstance(value, str):
        rational = sympy.Rational(value)
        return mpmath.mpf(rational.p) / rational.q
    return mpmath.mpf(value)


def test_float_times_of_every_route_agree_with_the_textbook():
    scene = Scene.from_matrices(M=[[1]], K=[[4]], x0=[1], v0=[0])
    times = np.array([0.0, 0.1, 1e3, 1e6])
    for method in _ROUTES:
        values, bounds = solve(scene, method=method).evaluate(times, return_error=True)
        with mpmath.workdps(60):
            exact = np.array([float(mpmath.cos(2 * mpmath.mpf(value))) for value in times])
        assert np.all(np.abs(values[0] - exact) <= bounds[0] + 1e-300), method


# ----------------------------------------------------------------------------- extreme scales

EXTREMES = {
    "stiff at the limit": {"M": [[1]], "K": [["1e300"]], "x0": [1], "v0": [0]},
    "tiny mass, huge spring": {"M": [["1e-300"]], "K": [["1e300"]], "x0": [1], "v0": [0]},
    "huge mass, tiny spring": {"M": [["1e300"]], "K": [["1e-300"]], "x0": [1], "v0": [0]},
    "huge displacement": {"M": [[1]], "K": [[1]], "x0": ["1e300"], "v0": [0]},
    "huge damping": {"M": [[1]], "C": [["1e300"]], "K": [[1]], "x0": [1], "v0": [0]},
}


@pytest.mark.filterwarnings("error::RuntimeWarning")  # the engines' overflows stay inside
@pytest.mark.parametrize("name", EXTREMES)
def test_scenes_at_the_limits_are_solved_within_their_bounds(name):
    scene = Scene.from_matrices(**EXTREMES[name])
    times = [0.0, 1.0, 1e3]
    values, bounds = solve(scene).evaluate(times, return_error=True)
    reference = reference_motion_arb(scene, times, digits=30).astype(float)
    assert np.all(np.isfinite(values)) and np.all(np.isfinite(bounds))
    assert np.all(np.abs(values - reference) <= bounds)


@pytest.mark.filterwarnings("ignore::RuntimeWarning")
def test_a_failing_float64_eigen_solver_is_a_scene_error_naming_the_way_out():
    scene = Scene.from_matrices(**EXTREMES["tiny mass, huge spring"])
    with pytest.raises(SceneError, match="use method='certified'"):
        solve(scene, method="modal")


def test_a_scene_beyond_the_numeric_size_limit_is_refused_at_once_for_that_reason():
    n = limits().general_modal_max_coordinates + 1
    masses = {f"m{i}": 1 for i in range(1, n + 1)}
    nodes = ["wall", *masses, "wall"]
    springs = {f"k{i}": (nodes[i], nodes[i + 1], 1) for i in range(n + 1)}
    # one irrational dashpot on one mass: damping that is not classical and an entry the
    # krylov route (rational entries only) does not take, so only the general route applies
    scene = Scene.from_components(masses=masses, springs=springs, x0={"m1": 1},
                                  dashpots={"c": ("ground", "m1", "sqrt(2)/10")})
    started = time.perf_counter()
    with pytest.raises(LimitError, match=f"> Limits.general_modal_max_coordinates = {limits().general_modal_max_coordinates:,}"):
        solve(scene)  # "auto": every engine's refusal, the general route's size among them
    assert time.perf_counter() - started < 10  # a guard against a hang
    rational = Scene.from_components(masses=masses, springs=springs, x0={"m1": 1},
                                     dashpots={"c": ("ground", "m1", "1/10")})
    assert solve(rational).method == "krylov"  # the sparse route takes it, at once


@pytest.mark.parametrize("name", ["tiny mass, huge spring", "huge damping"])
def test_a_derivative_whose_scale_is_beyond_float64_is_a_clear_error(name):
    """ρ = 1e300: S₀ρ² overflows, and no bound of x'' can be judged against it (an engine
    gave x''(0) = 0 with a bound of 5e-324 where x''(0) = −(c·v0 + k·x0)/m = −1 once the
    scale was allowed to be inf); the error says so instead of Python's errno text."""
    scene = Scene.from_matrices(**EXTREMES[name])
    with pytest.raises(OverflowError, match=r"x''\(t\): the contract's scale S₀·ρ\^2 is beyond"):
        solve(scene).evaluate([0.0, 1.0], derivative=2)
