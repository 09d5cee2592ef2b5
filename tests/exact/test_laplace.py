"""The forward transform ls.laplace against a textbook table and against SymPy."""

from __future__ import annotations

import mpmath
import pytest
import sympy as sp

import laplace_springs as ls

s, t = ls.s, ls.t
a, b = sp.Rational(-1, 2), sp.Integer(3)

# (f, F) from any table of Laplace transforms (e.g. Abramowitz & Stegun 29.3)
TABLE = [
    ("1", 1 / s),
    ("t**3", 6 / s**4),
    ("exp(-t/2)", 1 / (s - a)),
    ("sin(3*t)", b / (s**2 + b**2)),
    ("cos(3*t)", s / (s**2 + b**2)),
    ("sinh(3*t)", b / (s**2 - b**2)),
    ("cosh(3*t)", s / (s**2 - b**2)),
    ("t*sin(3*t)", 2 * b * s / (s**2 + b**2) ** 2),
    ("t*cos(3*t)", (s**2 - b**2) / (s**2 + b**2) ** 2),
    ("exp(-t/2)*cos(3*t)", (s - a) / ((s - a) ** 2 + b**2)),
    ("exp(-t/2)*sin(3*t)", b / ((s - a) ** 2 + b**2)),
    ("t**2*exp(-t/2)", 2 / (s - a) ** 3),
    ("Heaviside(t - 2)", sp.exp(-2 * s) / s),
    ("(t - 2)*Heaviside(t - 2)", sp.exp(-2 * s) / s**2),
    ("DiracDelta(t - 3)", sp.exp(-3 * s)),
    ("DiracDelta(t)", sp.Integer(1)),
    ("sin(t - 1)*Heaviside(t - 1)", sp.exp(-s) / (s**2 + 1)),
    ("Heaviside(t - 1) - Heaviside(t - 3)", (sp.exp(-s) - sp.exp(-3 * s)) / s),
]


@pytest.mark.parametrize(("f", "F"), TABLE)
def test_the_table(f, F):
    assert sp.simplify(ls.laplace(f) - F) == 0


@pytest.mark.parametrize("f", ["t**2*exp(-t)*sin(2*t)", "cosh(t/3)*cos(t)", "Heaviside(t - 1)*exp(-t)",
                               "(1 + t)*Heaviside(t - 2)*cos(t)"])
def test_agrees_with_sympy_and_with_quadrature(f):
    F = ls.laplace(f)
    g = ls.model.forcing.parse_forcing(f, "f")
    by_sympy = sp.laplace_transform(g, t, s, noconds=True)
    for point in (sp.Rational(3, 2), sp.Integer(4), sp.Rational(17, 3)):
        ours = complex(F.subs(s, point))
        assert ours == pytest.approx(complex(by_sympy.subs(s, point)), rel=1e-13)
        with mpmath.workdps(30):  # ∫₀^∞ f(t) e^{-st} dt, an independent route
            integrand = sp.lambdify(t, g * sp.exp(-point * t), modules="mpmath")
            breaks = [0, 1, 2, 4, 8, mpmath.inf]
            assert ours == pytest.approx(float(mpmath.quad(integrand, breaks)), rel=1e-12)


def test_round_trip_with_the_inverse():
    f = ls.model.forcing.parse_forcing("3*exp(-t)*cos(2*t) + t**2 + 5", "f")
    assert sp.simplify(ls.inverse_laplace(ls.laplace(f), s, t) - f) == 0


def test_parameters_are_declared_and_text_is_never_run(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    w = sp.Symbol("w", positive=True)
    assert sp.simplify(ls.laplace("sin(w*t)", parameters=["w"]) - w / (s**2 + w**2)) == 0
    with pytest.raises(ls.SceneError, match="unknown name 'w'"):
        ls.laplace("sin(w*t)")
    with pytest.raises(ls.SceneError):
        ls.laplace("__import__('os').system('touch x')")
    assert not (tmp_path / "x").exists()


def test_another_time_symbol_and_transform_variable():
    tau, p = sp.symbols("tau p")
    assert ls.laplace(sp.exp(-2 * tau), tau, p) == 1 / (p + 2)


def test_outside_the_class_is_refused_with_the_reason():
    with pytest.raises(ls.SceneError, match="not supported"):
        ls.laplace("cos(t**2)")
