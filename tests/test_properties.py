"""Property tests (hypothesis).

1. Random physical scenes (n <= 4 masses, springs and dashpots between masses and to
   walls, so K and C are positive semi-definite, small rationals): the exact, modal and
   certified routes agree with the arb reference within their bounds, and pass ``verify()``.
2. Random malformed input to every scene builder and to the TOML loader only ever raises
   ``SceneError``.
"""

from __future__ import annotations

import contextlib
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from laplace_springs import Scene, SceneError, solve
from laplace_springs.bench.reference import reference_motion_arb, relative_error
from laplace_springs.model.scene_files import scene_from_toml_text

TIMES = np.array([0.0, 0.4, 1.1, 3.0, 8.5])
SMALL = ["1/2", "1", "3/2", "2", "3", "1/3", "5/4"]
SETTINGS = {"deadline": None, "suppress_health_check": [HealthCheck.too_slow]}


# ----------------------------------------------------------------------------- physical scenes


@st.composite
def physical_scenes(draw, max_masses: int = 4):
    """Masses joined to each other and to walls by springs and dashpots (PSD K and C)."""
    n = draw(st.integers(1, max_masses))
    names = [f"m{i + 1}" for i in range(n)]
    masses = {name: draw(st.sampled_from(SMALL)) for name in names}
    nodes = [*names, "wall"]
    pairs = [(a, b) for i, a in enumerate(nodes) for b in nodes[i + 1:]]
    springs, dashpots = {}, {}
    for kind, table, chance in (("k", springs, 0.6), ("c", dashpots, 0.35)):
        for index, (a, b) in enumerate(pairs):
            if draw(st.floats(0, 1)) < chance:
                table[f"{kind}{index}"] = (a, b, draw(st.sampled_from(SMALL)))
    x0 = [draw(st.sampled_from(["0", "1", "-1/2", "2"])) for _ in names]
    v0 = [draw(st.sampled_from(["0", "0", "1", "-3/2"])) for _ in names]
    return Scene.from_components(masses=masses, springs=springs, dashpots=dashpots, x0=x0, v0=v0)


def _scale_free_error(values, reference) -> float:
    size = float(np.max(np.abs(reference)))
    return relative_error(values, reference) if size > 0 else float(np.max(np.abs(values)))


def _within_bounds(sol, scene, tolerance):
    values, errors = sol.evaluate(TIMES, return_error=True)
    reference = reference_motion_arb(scene, list(TIMES), digits=30)
    assert _scale_free_error(values, reference) < tolerance
    assert np.all(np.abs(values - reference.astype(float)) <= errors)


@settings(max_examples=12, **SETTINGS)
@given(physical_scenes(max_masses=3))
def test_the_three_routes_agree_with_the_reference(scene):
    for method in ("exact", "modal", "certified"):
        sol = solve(scene, method=method)
        _within_bounds(sol, scene, 1e-11)
        assert sol.verify()


@settings(max_examples=3, **SETTINGS)
@given(physical_scenes(max_masses=4).filter(lambda s: s.n == 4))
def test_exact_route_on_four_masses(scene):
    _within_bounds(solve(scene, method="exact"), scene, 1e-11)


@settings(max_examples=15, **SETTINGS)
@given(physical_scenes(max_masses=6))
def test_auto_and_modal_routes_match_the_arb_reference(scene):
    for method in ("auto", "modal"):
        _within_bounds(solve(scene, method=method), scene, 1e-11)


# ----------------------------------------------------------------------------- malformed input

_TEXT = st.text(alphabet="0123456789+-*/^().,eE kmxytpisqrt_[]{}=\"'#\\\n", max_size=30)
_ATOMS = st.one_of(
    st.none(), st.booleans(), st.integers(-10**30, 10**30),
    st.floats(allow_nan=True, allow_infinity=True), st.complex_numbers(max_magnitude=1e6),
    _TEXT, st.sampled_from(["1/0", "0/0", "nan", "inf", "-inf", "1e400", "2**10**10", "sqrt(-1)",
                            "k", "x0", "t", "pi", "E", "exp(1000000)", "()", "", "1/2", "-1", "0"]),
    st.binary(max_size=4), st.fractions(), st.decimals(allow_nan=True, allow_infinity=True),
)
_VALUES = st.recursive(_ATOMS, lambda inner: st.one_of(
    st.lists(inner, max_size=4), st.tuples(inner, inner),
    st.dictionaries(st.one_of(_TEXT, st.integers()), inner, max_size=3)), max_leaves=12)


def _matrix_like():
    """Mostly well-shaped matrices of junk entries, sometimes junk of any shape."""
    square = st.integers(1, 3).flatmap(
        lambda n: st.lists(st.lists(_ATOMS, min_size=n, max_size=n), min_size=n, max_size=n))
    return st.one_of(square, _VALUES)


_DECLARED = st.one_of(
    st.none(), _VALUES,
    st.lists(st.sampled_from(["k", "c", "x0", "t", "nan", "I", "sin", "", "k k", "é", 3, None]), max_size=4),
    st.dictionaries(st.sampled_from(["k", "c", "t", "m1"]),
                    st.one_of(st.sampled_from(["positive", "real", "nonnegative", "negative", "a note"]),
                              _ATOMS), max_size=3),
)


def _only_scene_errors(build) -> None:
    with contextlib.suppress(SceneError):
        build()


@settings(max_examples=100, **SETTINGS)
@given(M=_matrix_like(), C=st.one_of(st.none(), _matrix_like()), K=st.one_of(st.none(), _matrix_like()),
       x0=_VALUES, v0=_VALUES, names=st.one_of(st.none(), _VALUES), layout=st.one_of(st.just("horizontal"), _ATOMS),
       parameters=_DECLARED)
def test_from_matrices_raises_only_scene_error(M, C, K, x0, v0, names, layout, parameters):
    _only_scene_errors(lambda: Scene.from_matrices(M=M, C=C, K=K, x0=x0, v0=v0, names=names, layout=layout,
                                                   parameters=parameters))


@settings(max_examples=60, **SETTINGS)
@given(A=_matrix_like(), B=st.one_of(st.none(), _matrix_like()), x0=_VALUES, v0=_VALUES)
def test_from_normalized_raises_only_scene_error(A, B, x0, v0):
    _only_scene_errors(lambda: Scene.from_normalized(A=A, B=B, x0=x0, v0=v0))


_NODES = st.sampled_from(["m1", "m2", "wall", "Ceiling", "nowhere", "", 3])
_COMPONENT = st.one_of(st.tuples(_NODES, _NODES, _ATOMS), _VALUES)


@settings(max_examples=100, **SETTINGS)
@given(masses=st.one_of(st.dictionaries(st.one_of(st.sampled_from(["m1", "m2", "wall"]), _TEXT), _ATOMS,
                                         max_size=3), _VALUES),
       springs=st.one_of(st.dictionaries(_TEXT, _COMPONENT, max_size=3), _VALUES),
       dashpots=st.one_of(st.dictionaries(_TEXT, _COMPONENT, max_size=3), _VALUES),
       x0=st.one_of(st.none(), _VALUES), v0=st.one_of(st.none(), _VALUES), parameters=_DECLARED)
def test_from_components_raises_only_scene_error(masses, springs, dashpots, x0, v0, parameters):
    _only_scene_errors(lambda: Scene.from_components(masses=masses, springs=springs, dashpots=dashpots,
                                                     x0=x0, v0=v0, parameters=parameters))


_TOML_VALUE = st.one_of(
    st.sampled_from(['"1"', '"1/2"', "2", "0.5", '"k"', '"1/0"', '"nan"', "nan", "inf", "true", '"wall"',
                     '["m1", "wall", "1"]', '["m1", "m1", 1]', '[["1", 0], [0, "1"]]', '[1, 2]', "[]",
                     '{m1 = "1"}', '"2**10**10"', '"sqrt(-2)"', "-1", "1979-05-27", '"x"']),
    _TEXT.map(lambda s: '"' + s.replace("\\", "").replace('"', "") + '"'))
_TOML_LINE = st.one_of(
    st.builds(lambda k, v: f"{k} = {v}", st.sampled_from(
        ["title", "layout", "names", "m1", "m2", "k1", "c1", "x0", "v0", "M", "C", "K", "A", "B", "bogus",
         "k", "c"]),
        _TOML_VALUE),
    st.sampled_from(["[masses]", "[springs]", "[dashpots]", "[initial]", "[matrices]", "[normalized]",
                     "[masses.m1]", "[[masses]]", "junk", "= 1", "[unknown]", "[parameters]"]),
)


@settings(max_examples=150, **SETTINGS)
@given(st.lists(_TOML_LINE, max_size=12).map("\n".join) | _TEXT)
def test_toml_text_raises_only_scene_error(text):
    _only_scene_errors(lambda: scene_from_toml_text(text))


def test_toml_templates_are_reachable():
    """The line strategy can build valid scenes (so the property above reaches the builders)."""
    text = '[masses]\nm1 = "1"\n[springs]\nk1 = ["m1", "wall", "1"]\n[initial]\nx0 = ["1"]'
    assert scene_from_toml_text(text).n == 1
    assert math.isclose(float(solve(scene_from_toml_text(text), method="modal").evaluate(0.0)[0, 0]), 1.0)


@pytest.mark.parametrize("entry", ["1/0", "0/0", float("nan"), float("inf"), "k**", None, [1], "1e400000"])
def test_known_bad_entries(entry):
    with pytest.raises(SceneError):
        Scene.from_matrices(M=[[entry]], x0=[0], v0=[0])
