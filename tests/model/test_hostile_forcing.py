"""Hostile forcing (issue 22): inputs that pass the text limits and would run for minutes.

Every attempt is refused at once with a LimitError that names the entry and the Limits
field, in a child process with a time limit (a regression would hang there, not here);
inputs within the limits give the right transform (checked against the Laplace integral
by mpmath quadrature, which shares no code with the transform), and the size estimate
is never below the atoms the transform forms (property tests).
"""

from __future__ import annotations

import mpmath
import pytest
import sympy as sp
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import laplace_springs as ls
from laplace_springs.model import forcing
from laplace_springs.model.errors import LimitError, SceneError
from laplace_springs.model.forcing import input_transform, parse_forcing
from laplace_springs.model.forcing_size import forcing_size
from laplace_springs.model.symbols import TIME as t
from tests._hostile import attempts

SETTINGS = {"deadline": None, "suppress_health_check": [HealthCheck.too_slow]}

_SETUP = """
import sympy as sp
import laplace_springs as ls
t = ls.t
T = sp.Symbol("t")
def scene(f):
    return ls.Scene.from_matrices(M=[[1]], C=[["1/10"]], K=[[1]], x0=[0], v0=[0], forcing=[f])
def pair(**kw):
    return ls.Scene.from_components(masses={"m1": 1, "m2": 1},
        springs={"k1": ("ground", "m1", 1), "k2": ("m1", "m2", 1)},
        dashpots={"c": ("ground", "m1", "1/10")}, **kw)
"""

#: name -> (expression run in the child, the Limits field its refusal names)
_REFUSED = {
    "power 1000 (text)": ("scene('t**1000')", "max_forcing_degree"),
    "power 1000 exp (text)": ("scene('t**1000*exp(-t)')", "max_forcing_degree"),
    "trig sum to the 30th (text)": ("scene('(cos(t)+sin(2*t)+cos(3*t)+sin(5*t))**30')",
                                    "max_forcing_terms"),
    "binomial 1000 (text)": ("scene('(t + 1)**1000 / 10**300')", "max_forcing_degree"),
    "cosine to the 10^5": ("scene(sp.cos(t)**100000)", "max_forcing_terms"),
    "10^4 steps (SymPy)": ("scene(sp.Add(*[sp.Heaviside(t - k, evaluate=False) for k in range(10_000)]))",
                           "max_forcing_terms"),
    "10^4 cosines (SymPy)": ("scene(sp.Add(*[sp.cos(k * t, evaluate=False) for k in range(1, 10_001)]))",
                             "max_forcing_terms"),
    "degree 10^5 (SymPy)": ("scene(sp.Add(*[t**k for k in range(100_001)]))", "max_forcing_terms"),
    "degree 10^5 in a plain Symbol t": ("scene(T**100_000)", "max_forcing_degree"),
    "power tower argument": ("scene(sp.cos((t + 1)**1000))", "max_forcing_degree"),
    "huge exponent": ("scene(sp.Pow(sp.cos(t) + sp.sin(t), 10**30, evaluate=False))",
                      "max_forcing_terms"),
    "40 steps": ("scene(sp.Add(*[sp.Heaviside(t - sp.Rational(k, 3)) for k in range(40)]))",
                 "max_forcing_delays"),
    "20 phases": ("scene(sp.Add(*[sp.cos(t + sp.Rational(1, k)) for k in range(1, 21)]))",
                  "max_forcing_constants"),
    "with_forcing": ("pair().with_forcing({'m2': 't**1000'})", "max_forcing_degree"),
    "support motion": ("pair(support_motion={'ground': '(cos(t)+sin(2*t))**300'})",
                       "max_forcing_terms"),
    "laplace": ("ls.laplace('(cos(t)+sin(2*t)+cos(3*t)+sin(5*t))**30')", "max_forcing_terms"),
    "periodic window": ("scene(ls.periodic(sp.cos(t)**300, 1))", "max_forcing_terms"),
}


def test_the_issue_inputs_are_refused_at_once_naming_the_entry_and_the_limit():
    found = attempts(_SETUP, {name: source for name, (source, _) in _REFUSED.items()}, timeout=90)
    for name, (_, field) in _REFUSED.items():
        outcome = found[name]
        assert outcome.kind == "LimitError", (name, outcome)
        assert f"Limits.{field}" in outcome.text, (name, outcome.text)
        assert any(entry in outcome.text for entry in ("forcing[", "forcing.", "support_motion", "f:")), \
            (name, outcome.text)


@pytest.mark.parametrize(("text", "field", "value"), [
    ("cos(t) + cos(2*t) + cos(3*t)", "max_forcing_terms", 4),
    ("Heaviside(t - 1) + Heaviside(t - 2) + Heaviside(t - 3)", "max_forcing_delays", 2),
    ("cos(t + 1/2) + sin(2*t + 1/3)", "max_forcing_constants", 1),
    ("t**4", "max_forcing_degree", 3),
])
def test_each_limit_is_read_at_call_time(set_limits, text, field, value):
    ls.Scene.from_matrices(M=[[1]], K=[[1]], x0=[0], v0=[0], forcing=[text])  # within the defaults
    set_limits(**{field: value})
    with pytest.raises(LimitError, match=rf"forcing\[0\].*Limits\.{field}"):
        ls.Scene.from_matrices(M=[[1]], K=[[1]], x0=[0], v0=[0], forcing=[text])


def _laplace_by_quadrature(f, s0, breaks=()):
    """∫₀^∞ f(t) e^{−s0 t} dt by mpmath quadrature, split at the switching times."""
    with mpmath.workdps(20):
        points = sorted({*range(41), *breaks}) + [mpmath.inf]  # unit pieces: oscillations
        return mpmath.quad(lambda x: f(x) * mpmath.exp(-s0 * x), points)


def test_inputs_just_within_the_limits_have_the_right_transform():
    s = sp.Symbol("s")
    cases = [  # (expression, the same function in mpmath, switching times)
        (sp.cos(t) ** 30, lambda x: mpmath.cos(x) ** 30, ()),
        (sp.Add(*[sp.cos(k * t) for k in range(1, 41)]),
         lambda x: sum(mpmath.cos(k * x) for k in range(1, 41)), ()),
        (t**32 * sp.exp(-3 * t), lambda x: x**32 * mpmath.exp(-3 * x), ()),
        (sp.Add(*[sp.Heaviside(t - k) for k in range(32)]),
         lambda x: sum(1 for k in range(32) if x >= k), tuple(range(32))),
    ]
    for f, reference, breaks in cases:
        F = input_transform(parse_forcing(f, "f"), "f", s).as_expr()
        for s0 in (2, 5):
            value = complex(sp.N(F.subs(s, s0), 30))
            expected = _laplace_by_quadrature(reference, s0, breaks)
            assert abs(value - complex(expected)) <= 1e-12 * abs(complex(expected)), (f, s0)


# ----------------------------------------------------------------------------
# properties
# ----------------------------------------------------------------------------

_RATIONALS = st.fractions(min_value=-3, max_value=3, max_denominator=4).map(sp.Rational)
_RATES = st.integers(min_value=1, max_value=4)
_ATOM = st.one_of(
    st.just(t), _RATIONALS,
    _RATES.map(lambda b: sp.cos(b * t)), _RATES.map(lambda b: sp.sin(b * t + sp.Rational(1, 2))),
    _RATES.map(lambda a: sp.exp(-a * t)), _RATES.map(lambda a: sp.cosh(a * t)),
    st.integers(min_value=1, max_value=3).map(lambda k: sp.Heaviside(t - k)),
)


def _combine(children):
    return st.one_of(
        st.lists(children, min_size=2, max_size=3).map(lambda parts: sp.Add(*parts)),
        st.lists(children, min_size=2, max_size=3).map(lambda parts: sp.Mul(*parts)),
        st.tuples(children, st.integers(min_value=2, max_value=4)).map(lambda p: p[0] ** p[1]),
    )


_EXPRESSIONS = st.recursive(_ATOM, _combine, max_leaves=8)


def _atoms(f):
    """The atoms input_transform forms for f, or None when f is outside the forcing class."""
    try:
        terms = sp.Add.make_args(forcing._expanded(f))
        return [atom for term in terms for atom in forcing._term_atoms(term)]
    except forcing._Unsupported:
        return None


@settings(max_examples=150, **SETTINGS)
@given(_EXPRESSIONS)
def test_the_size_estimate_is_never_below_the_atoms_formed(f):
    atoms = _atoms(f)
    if atoms is None:
        return
    size = forcing_size(f)
    assert size.terms >= len(atoms), (f, size, len(atoms))
    assert size.degree >= max((atom.power for atom in atoms), default=0), (f, size)


@settings(max_examples=25, **SETTINGS)
@given(st.lists(st.tuples(_RATIONALS, st.integers(0, 3), st.integers(0, 4), _RATIONALS,
                          st.integers(0, 3)), min_size=1, max_size=5), st.sampled_from([2, 3]))
def test_transforms_agree_with_the_laplace_integral(terms, s0):
    """Σ c·t^k·cos(b t + φ)·H(t − τ): the summed fractions against mpmath quadrature."""
    f = sp.Add(*[c * t**k * sp.cos(b * t + phi) * sp.Heaviside(t - tau)
                 for c, k, b, phi, tau in terms])
    if f == 0:
        return
    try:
        F = input_transform(parse_forcing(f, "f"), "f", sp.Symbol("s")).as_expr()
    except SceneError:
        pytest.fail(f"{f} refused")
    mp_terms = [(mpmath.mpf(c.p) / c.q, k, b, mpmath.mpf(phi.p) / phi.q, tau)
                for c, k, b, phi, tau in terms]

    def reference(x):
        return sum(c * x**k * mpmath.cos(b * x + phi) for c, k, b, phi, tau in mp_terms if x >= tau)

    expected = _laplace_by_quadrature(reference, s0, [tau for *_, tau in terms if tau > 0])
    value = sp.N(F.subs(sp.Symbol("s"), s0), 30)
    scale = max(1.0, *(abs(float(c)) for c, *_ in terms))
    assert abs(complex(value) - complex(expected)) <= 1e-12 * scale, (f, value, expected)


@pytest.mark.parametrize("make", [
    lambda: ls.Scene.from_matrices(M=[[1]], K=[[1]], x0=[1], v0=[0], forcing=["Heaviside(t - 1e400)"]),
    lambda: ls.Scene.from_matrices(M=[[1]], K=[[1]], x0=[1], v0=[0], forcing=["DiracDelta(t - 1e400)"]),
    lambda: ls.Scene.from_matrices(M=[[1]], K=[[1]], x0=[1], v0=[0], forcing=["Heaviside(1e-400*t - 1)"]),
    lambda: ls.Scene.from_components(masses={"m": 1}, springs={"k": ("wall", "m", 1)}, x0=[0], v0=[0],
                                     support_motion={"wall": "Heaviside(t - 1e400)"}),
])
def test_a_switch_beyond_float64_times_is_refused_when_the_scene_is_built(make):
    """Found by an attack: accepted, then evaluate raised a bare OverflowError."""
    with pytest.raises(SceneError, match=r"switches at t = 1\.00e\+400.*MAX_MAGNITUDE"):
        make()


def test_a_switch_just_inside_the_limit_still_solves():
    scene = ls.Scene.from_matrices(M=[[1]], K=[[1]], x0=[1], v0=[0],
                                   forcing=["Heaviside(t - 1e299)"])
    values = ls.solve(scene).evaluate([3.0])
    assert abs(values[0, 0] - mpmath.cos(3)) < 1e-14  # the step never acts before 1e299
    on = ls.Scene.from_matrices(M=[[1]], K=[[1]], x0=[0], v0=[0], forcing=["Heaviside(t + 1e400)"])
    assert abs(ls.solve(on).evaluate([3.0])[0, 0] - (1 - mpmath.cos(3))) < 1e-14  # on from t = 0


def test_inverse_laplace_refuses_huge_degrees_before_working():
    """Found by an attack: 1/s**1000 ran for minutes."""
    for F in ("1/s**1000", "1/(s**2 + 1)**300"):
        with pytest.raises(LimitError, match=r"multiplicity \d+, above the limit 128 \(Limits\.max_pole_multiplicity\)"):
            ls.inverse_laplace(F, ls.s, ls.t)
    assert sp.simplify(ls.inverse_laplace("1/s**3", ls.s, ls.t) - t**2 / 2) == 0
