"""Scenes whose entries span hundreds of decades: answered in seconds, or refused at once.

A pair of masses of 1e-300 on springs of 1 with a dashpot of 1e-300 (frequencies of about
1e150, decay rates of about 0.1) ran ``ls.solve`` for minutes: the tiny engine refuses
M⁻¹K entries beyond 1e100, the certified engine's float64 bound misses the target (its
phases ωt are lost), and the exact route then waited on SymPy's CRootOf, which numbers
the roots of Δ's 2,000-bit quartic by some 500 bisections of polynomial arithmetic each
(:mod:`laplace_springs.exact.isolation`). Free scenes with rational entries now name such
roots (flint) and are solved in about a second; where roots cannot be named (a forced
scene, an inverse transform, ``modes``) the factor is refused at once by
Limits.max_exact_isolation, naming the scene's extreme entries.

References: x(t) = Σ_ρ adj(P(ρ))·r(ρ)/Δ'(ρ)·e^{ρt} (the textbook residue form of the
Laplace solution, P(λ) = λ²M + λC + K, r(λ) = M(λx0 + v0) + Cx0), with the roots of Δ
enclosed by arb at 3,000 bits in this file; one case is checked against an mpmath matrix
exponential at 300 digits. The hang guard is a child process with a time limit
(tests/_hostile.py): a regression fails with the case's name, it does not hang the run.
"""

from __future__ import annotations

import ast
from fractions import Fraction

import flint
import mpmath
import numpy as np
import pytest

from tests._hostile import attempts

#: (m, k, c) of the pair wall -k- m1 -k- m2, a dashpot c from m1 to the wall, x0 = (1, 0):
#: each ran past 60 s before (most of them for minutes), by the exact route.
HANGING = [
    ("1e-300", "1e-300", "1e300"), ("1e-300", "1", "1e-300"), ("1e-300", "1e300", "1e-300"),
    ("1e-200", "1e-300", "1e300"), ("1e-200", "1", "1e-300"), ("1e-200", "1", "1e300"),
    ("1e-200", "1e300", "1e-300"), ("1e-100", "1e-300", "1e300"), ("1e-100", "1", "1e-300"),
    ("1e-100", "1e300", "1e-300"), ("1e100", "1e300", "1e-300"), ("1e100", "1e300", "1"),
    ("1", "1", "1e-300"),
]
#: ... and these took 5 to 50 s (solve and evaluate).
SLOW = [("1e-300", "1", "1"), ("1e-300", "1", "1e300"), ("1e-300", "1e300", "1e300"),
        ("1e-100", "1e300", "1e300")]
TIMES = [0.0, 1.0, 10.0]

SETUP = f"""
import laplace_springs as ls

def pair(m, k, c, forcing=None):
    return ls.Scene.from_components(
        masses={{"m1": m, "m2": m}}, springs={{"k1": ("wall", "m1", k), "k2": ("m1", "m2", k)}},
        dashpots={{"c1": ("wall", "m1", c)}} if c != "0" else {{}}, x0={{"m1": 1}},
        forcing=None if forcing is None else {{"m1": forcing}})

def run(m, k, c):
    sol = ls.solve(pair(m, k, c))
    values, bounds = sol.evaluate({TIMES!r}, return_error=True)
    return sol.method, values.tolist(), bounds.tolist()
"""


def _arb(text: str) -> flint.arb:
    value = Fraction(text)
    return flint.arb(flint.fmpq(value.numerator, value.denominator))


def pair_reference(m: str, k: str, c: str, times: list[float], prec: int = 3000,
                   forced: bool = False) -> np.ndarray:
    """x(t) of the pair by residues at arb-enclosed roots (2 x len(times), float64); with
    ``forced``, driven by cos t on m1 (F(λ) = λ/(λ² + 1) more in r₁, and the poles ±i)."""
    old = flint.ctx.prec
    flint.ctx.prec = prec
    try:
        fm, fk, fc = (Fraction(v) for v in (m, k, c))
        q = [flint.fmpq(v.numerator, v.denominator) for v in
             (fk * fk, fc * fk, 3 * fk * fm, fc * fm, fm * fm)]  # Δ = (mλ²+cλ+2k)(mλ²+k) − k²
        delta = flint.fmpq_poly(q)
        am, ak, ac = (_arb(v) for v in (m, k, c))
        out = np.zeros((2, len(times)))
        sums = [[flint.acb(0) for _ in times] for _ in range(2)]
        for rho, multiplicity in delta.complex_roots():
            assert multiplicity == 1
            d = 4 * am * am * rho**3 + 3 * ac * am * rho**2 + 6 * ak * am * rho + ac * ak   # Δ'(ρ)
            r1 = am * rho + ac                              # r(λ) = M(λx0) + Cx0, x0 = (1, 0)
            if forced:
                r1 += rho / (rho**2 + 1)
            residues = ((am * rho**2 + ak) * r1 / d, ak * r1 / d)   # adj(P(ρ))·r(ρ)/Δ'(ρ)
            for j, t in enumerate(times):
                grow = (rho * _arb(str(Fraction(t)))).exp()
                for i in range(2):
                    sums[i][j] += residues[i] * grow
        if forced:  # the poles ±i: 2 Re[adj(P(i))·e₁/(2Δ(i)) e^{it}], adj(P)·e₁ = (mλ² + k, k)
            i = flint.acb(0, 1)
            at_i = (am * i * i + ac * i + 2 * ak) * (am * i * i + ak) - ak * ak
            for j, t in enumerate(times):
                wave = (i * _arb(str(Fraction(t)))).exp() / (2 * at_i)
                sums[0][j] += 2 * ((am * i * i + ak) * wave).real
                sums[1][j] += 2 * (ak * wave).real
        for i in range(2):
            for j in range(len(times)):
                assert sums[i][j].real.rad() < 1e-30 * max(1.0, abs(float(sums[i][j].real.mid())))
                out[i, j] = float(sums[i][j].real.mid())
        return out
    finally:
        flint.ctx.prec = old


def test_the_residue_reference_agrees_with_a_matrix_exponential():
    """The reference of this file against e^{At}z0 of the first-order system in mpmath."""
    with mpmath.workdps(300):
        m, k, c = (mpmath.mpf(v) for v in ("1e-300", "1", "1e-300"))
        A = mpmath.matrix([[0, 0, 1, 0], [0, 0, 0, 1],
                           [-2 * k / m, k / m, -c / m, 0], [k / m, -k / m, 0, 0]])
        expm = [[float((mpmath.expm(A * t) * mpmath.matrix([1, 0, 0, 0]))[i]) for t in TIMES]
                for i in range(2)]
    assert np.allclose(pair_reference("1e-300", "1", "1e-300", TIMES), expm, rtol=1e-15, atol=1e-300)


def test_pairs_with_extreme_entries_are_solved_in_seconds_within_their_bounds():
    cases = {",".join(spec): f"run{spec!r}" for spec in HANGING + SLOW}
    found = attempts(SETUP, cases, timeout=40 + 4 * len(cases))
    for name, outcome in found.items():
        assert outcome.ok, (name, outcome.kind, outcome.text)
        method, values, bounds = ast.literal_eval(outcome.text)
        reference = pair_reference(*name.split(","), TIMES)
        error = np.abs(np.array(values) - reference)
        assert np.all(error <= np.array(bounds)), (name, method, values, reference.tolist(), bounds)


def test_an_ordinary_scene_in_extreme_units_keeps_its_fast_engine_and_written_out_roots():
    """m = 1e-300, k = 4e-300, c = 2e-300: M⁻¹K and M⁻¹C are ordinary, the tiny engine
    serves it; a pair of 2 g masses on springs of 2e9 N/m with a dashpot of 0.35 N·s/m keeps
    CRootOf in x (its isolation work, about 2e4, is below the limits)."""
    found = attempts(SETUP + """
def si_form():
    import sympy as sp
    x = ls.solve(pair("0.002", "2e9", "0.35"), method="exact").x
    return sorted({type(atom).__name__ for atom in x.atoms(sp.CRootOf, sp.Symbol)})
""", {"extreme units": "run('1e-300', '4e-300', '2e-300')", "SI pair": "si_form()"}, timeout=120)
    method, values, bounds = ast.literal_eval(found["extreme units"].text)
    assert method == "tiny"
    reference = pair_reference("1e-300", "4e-300", "2e-300", TIMES)
    assert np.all(np.abs(np.array(values) - reference) <= np.array(bounds))
    assert found["SI pair"].text == "['AlgebraicRoot', 'Symbol']", found["SI pair"]  # t, no names


@pytest.mark.parametrize("entries", [("1e-300", "1", "1e-300"), ("1", "1", "1e-300")])
def test_where_roots_cannot_be_named_the_factor_is_refused_at_once(entries):
    """A forced pair (cos t on m1), an inverse transform with the same Δ, ``modes`` and the
    CRootOf definitions of the named roots: each ran for minutes before."""
    m, k, c = entries
    found = attempts(SETUP + f"""
import laplace_springs as ls
forced = pair({m!r}, {k!r}, {c!r}, forcing="cos(t)")
free = pair({m!r}, {k!r}, {c!r})
delta = ls.resolvent(free).determinant.as_expr().subs(ls.lam, ls.s)
""", {
        "auto": "ls.solve(forced).method",
        "exact": "ls.solve(forced, method='exact')",
        "inverse": "ls.inverse_laplace(1 / delta, ls.s, ls.t)",
        "modes": "ls.modes(free)",
        "definitions": "ls.solve(free, method='exact').substituted()",
    }, timeout=120)
    smallest = "M[0,0] = 1e-300" if m == "1e-300" else "C[0,0] = 1e-300"
    # "auto": the exo engine serves the forced pair where the exact route refuses and its
    # scenes hold in float64 (tests/test_attack_forced_small.py checks the values)
    expected = {"exact": "InversionError", "inverse": "InversionError",
                "modes": "LimitError", "definitions": "InversionError"}
    served = "'exact+exo'" if m == "1e-300" else "'certified+exo'"
    assert found["auto"].ok and found["auto"].text == served, found["auto"]
    for name, kind in expected.items():
        outcome = found[name]
        assert outcome.kind == kind, (name, outcome)
        assert "> Limits.max_exact_isolation = 2,000,000" in outcome.text, (name, outcome.text)
        assert "ls.using_limits(max_exact_isolation=" in outcome.text, (name, outcome.text)
    for name in expected.keys() & {"auto", "exact"}:  # the scene's own entries, by name and value
        assert f"{smallest} and K[0,0] = 2 are entries of this scene" in found[name].text
    assert "method='certified').poles" in found["modes"].text


# ----------------------------------------------------------------------------- one mass

MASSES = ["1e-300", "1e-200", "1e-100", "1e100", "1e300"]
SPRINGS = ["1e-300", "1", "1e300"]
DASHPOTS = ["0", "1e-300", "1", "1e300"]
ONE_SETUP = f"""
import laplace_springs as ls

def one(m, k, c):
    scene = ls.Scene.from_matrices(M=[[m]], C=[[c]], K=[[k]], x0=[1], v0=[0])
    sol = ls.solve(scene)
    values, bounds = sol.evaluate({TIMES!r}, return_error=True)
    return sol.method, values.tolist(), bounds.tolist()
"""


def _log10(value: Fraction) -> int:
    """About log10 of a positive fraction (from the digits of its numerator and denominator)."""
    return len(str(value.numerator)) - len(str(value.denominator))


def one_mass_reference(m: str, k: str, c: str, times: list[float]) -> list[float]:
    """m x'' + c x' + k x = 0 from x = 1 at rest: x = (r₂e^{r₁t} − r₁e^{r₂t})/(r₂ − r₁), the
    roots r₁ = q/m, r₂ = k/q with q = −(c + √(c² − 4mk))/2 (no cancellation), in mpmath at
    50 digits beyond those of the largest |r|·t (a phase ωt of 1e301 takes 301 of them)."""
    fm, fk, fc = (Fraction(v) for v in (m, k, c))
    rates = [fk / fm, fc / fm] + ([fk / fc] if fc else [])  # |r|² ≤ k/m·…, |r| ≤ c/m, k/c
    digits = 60 + max(0, max(_log10(rate) for rate in rates if rate) + 1)
    out = []
    with mpmath.workdps(digits):
        m_, k_, c_ = (mpmath.mpf(v) for v in (m, k, c))
        q = -(c_ + mpmath.sqrt(mpmath.mpc(c_ * c_ - 4 * m_ * k_))) / 2
        r1, r2 = q / m_, k_ / q
        for t in times:
            value = (r2 * mpmath.exp(r1 * t) - r1 * mpmath.exp(r2 * t)) / (r2 - r1)
            out.append(float(value.real))
    return out


def test_one_mass_across_the_range_is_served_within_its_bounds():
    """Every (m, k, c) of the family solves and evaluates at t = 0, 1, 10 within its bound.
    m = 1e100, k = 1e-300, c = 1e300 raised OverflowError (the modal engine's γ² of 1e400 in
    Python floats) and m = 1e300, k = 1e-300, c = 1 ZeroDivisionError (γ² of 1e-600)."""
    specs = [(m, k, c) for m in MASSES for k in SPRINGS for c in DASHPOTS]
    found = attempts(ONE_SETUP, {",".join(spec): f"one{spec!r}" for spec in specs},
                     timeout=60 + 3 * len(specs))
    for name, outcome in found.items():
        assert outcome.ok, (name, outcome.kind, outcome.text)
        method, values, bounds = ast.literal_eval(outcome.text)
        reference = one_mass_reference(*name.split(","), TIMES)
        error = np.abs(np.array(values[0]) - reference)
        assert np.all(error <= np.array(bounds[0])), (name, method, values, reference, bounds)


def test_undamped_pairs_beyond_float64_in_the_classical_route_are_served():
    """m = 1e-300..1e-100 on springs of 1e300, undamped: M^(-1/2) K M^(-1/2) overflows
    float64 (1e600), and scipy's eigh_tridiagonal raised 'array must not contain infs or
    NaNs' out of ls.solve; a pair with m = 1e100, k = 1e-300, c = 1e300 raised the modal
    engine's OverflowError."""
    specs = [("1e-300", "1e300", "0"), ("1e-200", "1e300", "0"), ("1e-100", "1e300", "0"),
             ("1e100", "1e-300", "1e300"), ("1e300", "1e-300", "1")]
    found = attempts(SETUP, {",".join(spec): f"run{spec!r}" for spec in specs}, timeout=120)
    for name, outcome in found.items():
        assert outcome.ok, (name, outcome.kind, outcome.text)
        method, values, bounds = ast.literal_eval(outcome.text)
        reference = pair_reference(*name.split(","), TIMES)
        assert np.all(np.abs(np.array(values) - reference) <= np.array(bounds)), (name, method)



def test_forced_pairs_within_the_limit_are_answered_within_their_bounds():
    """Pairs driven by cos t on m1 whose isolation work is within Limits.max_exact_isolation
    (k²·D·b of 1.8e6 and 8.9e5 for the first two, 2.5 s and 4.7 s before) are answered by
    the exact route; the reference adds the poles ±i of the input to the residue form."""
    specs = [("1e-100", "1", "1"), ("1e100", "1", "1"), ("1e-300", "1e300", "1"),
             ("1e-200", "1e-300", "1e-300")]
    found = attempts(SETUP + f"""
def forced(m, k, c):
    sol = ls.solve(pair(m, k, c, forcing="cos(t)"))
    values, bounds = sol.evaluate({TIMES!r}, return_error=True)
    return sol.method, values.tolist(), bounds.tolist()
""", {",".join(spec): f"forced{spec!r}" for spec in specs}, timeout=180)
    for name, outcome in found.items():
        assert outcome.ok, (name, outcome.kind, outcome.text)
        method, values, bounds = ast.literal_eval(outcome.text)
        reference = pair_reference(*name.split(","), TIMES, forced=True)
        error = np.abs(np.array(values) - reference)
        assert np.all(error <= np.array(bounds)), (name, method, values, reference.tolist(), bounds)


def test_float_modes_of_an_irrational_pair_beyond_float64_scales_have_its_frequencies():
    """Masses of √2·1e-300 and 1e-300 on springs of 1 (irrational: the float64 modes): the
    first-order matrix with entries of 1 and 1e300 gave LAPACK eigenvalues of 6e-13 and
    1.5e-12 where the frequencies are about 1e150. Reference: the undamped frequencies of
    (m₁λ² + 2)(m₂λ² + 1) − 1 = 0 by the quadratic formula in λ² (the dashpot of 1e-300
    moves them by about 1e-300 of their size), in mpmath at 50 digits."""
    found = attempts("""
import laplace_springs as ls
scene = ls.Scene.from_components(masses={"m1": "1e-300*sqrt(2)", "m2": "1e-300"},
    springs={"k1": ("wall", "m1", 1), "k2": ("m1", "m2", 1)},
    dashpots={"c1": ("wall", "m1", "1e-300")}, x0={"m1": 1})
""", {"modes": "sorted(float(mode.natural_frequency) for mode in ls.modes(scene))"}, timeout=60)
    assert found["modes"].ok, found["modes"]
    frequencies = ast.literal_eval(found["modes"].text)
    with mpmath.workdps(50):
        m1, m2 = mpmath.sqrt(2) * mpmath.mpf("1e-300"), mpmath.mpf("1e-300")
        # m1 m2 w⁴ − (m1 + 2 m2) w² + 1 = 0 for w² = −λ²
        a, b = m1 * m2, -(m1 + 2 * m2)
        root = mpmath.sqrt(b * b - 4 * a)
        expected = sorted(float(mpmath.sqrt((-b + sign * root) / (2 * a))) for sign in (-1, 1))
    assert np.allclose(frequencies, expected, rtol=1e-13, atol=0), (frequencies, expected)
