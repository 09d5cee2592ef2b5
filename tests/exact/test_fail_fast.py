"""Fail fast or answer fast (issue 11, item 5): the exact stage refuses at once what it
cannot finish, and keeps answering what it can. Since issue 12 (item 4) a symbolic factor
of degree >= 3 is answered at once with a sum over its roots (tests/exact/test_root_sums.py
checks those values in depth); rational factors above the degree limit stay refused.

The wall-time asserts guard hangs (minutes before this change), not speed targets: their
limits are generous. Values are checked against independent routes: mpmath's Talbot
inversion, the matrix-exponential reference, residue identities.
"""

from __future__ import annotations

import time

import mpmath
import pytest
import sympy as sp

import laplace_springs as ls
from laplace_springs.bench.reference import reference_motion, relative_error
from laplace_springs.exact import assembly
from laplace_springs.exact.assembly import exact_motion
from laplace_springs.exact.partial_fractions import partial_fractions
from laplace_springs.exact.screening import screen_scene
from laplace_springs.limits import limits
from laplace_springs.numeric.mp_expr import numeric_value

s, t = sp.symbols("s t")
a = sp.Symbol("a")
m1, m2, k1, k2, c, w = sp.symbols("m1 m2 k1 k2 c w", positive=True)
HANG_GUARD = 2.0  # seconds; the refusals below took minutes (or never ended) before


def refused(call) -> tuple[str, float]:
    """The InversionError message of ``call()`` and the seconds it took."""
    start = time.perf_counter()
    with pytest.raises(ls.InversionError) as info:
        call()
    return str(info.value), time.perf_counter() - start


def damped_pair(**kw) -> ls.Scene:
    """The issue's symbolic damped two-mass scene: Δ is an irreducible symbolic quartic."""
    kw.setdefault("x0", [1, 0])
    return ls.Scene.from_matrices(M=[[m1, 0], [0, m2]], C=[[c, -c], [-c, c]],
                                  K=[[k1 + k2, -k2], [-k2, k2]], v0=[0, 0], **kw)


def chain(masses, springs, damping=0, x0=None) -> ls.Scene:
    """Masses in a row between two walls; springs[i] joins node i-1 and node i."""
    n = len(masses)

    def tridiagonal(values):
        A = sp.zeros(n, n)
        for i in range(n):
            A[i, i] = values[i] + values[i + 1]
            if i + 1 < n:
                A[i, i + 1] = A[i + 1, i] = -values[i + 1]
        return A.tolist()

    return ls.Scene.from_matrices(M=sp.diag(*masses).tolist(), C=tridiagonal([damping] * (n + 1)),
                                  K=tridiagonal(springs), x0=x0 or [1] + [0] * (n - 1),
                                  v0=[0] * n)


def irreducible_chain(n: int) -> ls.Scene:
    """Masses 1..n, damped: Δ(λ) is irreducible over ℚ, of degree 2n (the refusal names it)."""
    springs = [2] + [sp.Rational(3, 2) if i % 2 == 0 else 1 for i in range(1, n + 1)]
    return chain(list(range(1, n + 1)), springs, damping=sp.Rational(1, 20))


# -- symbolic factors of degree >= 3: answered at once with sums over roots ---------------
NUMBERS = {m1: 1, m2: 2, k1: 3, k2: 5, c: sp.Rational(1, 10)}


def answered(call):
    """The result of ``call()`` and the seconds it took."""
    start = time.perf_counter()
    result = call()
    return result, time.perf_counter() - start


def test_symbolic_damped_pair_is_answered_at_once():
    sol, seconds = answered(lambda: ls.solve(damped_pair()))
    assert seconds < HANG_GUARD  # before: refused in 1 ms; before that, 222 s
    assert all(e.atoms(sp.RootSum) for e in sol.x)
    value = sol.x[0].subs(NUMBERS).subs(ls.t, sp.Rational(13, 10)).evalf(30)
    reference = reference_motion(damped_pair().subs(NUMBERS), ["1.3"])
    assert relative_error([value], [reference[0, 0]]) < 1e-25


def test_symbolic_damped_pair_is_answered_at_once_even_without_the_screen(monkeypatch):
    # the partial-fraction engine builds the sums right after factoring, with no gcd
    monkeypatch.setattr(assembly, "screen_scene", lambda scene: None)
    motion, seconds = answered(lambda: exact_motion(damped_pair()))
    assert seconds < HANG_GUARD
    assert all(e.atoms(sp.RootSum) for e in motion.x)


def test_forced_symbolic_damped_pair_is_answered_at_once():
    scene = damped_pair(x0=[0, 0], forcing=[sp.cos(w * ls.t), sp.Heaviside(ls.t - 2)])
    sol, seconds = answered(lambda: ls.solve(scene))
    assert seconds < HANG_GUARD
    assert sol.transient.atoms(sp.RootSum) and not sol.steady_state.atoms(sp.RootSum)
    numbers = {**NUMBERS, w: sp.Rational(3, 2)}
    numeric = ls.solve(scene.subs(numbers), method="exact")  # CRootOf terms, no sums
    value = sol.x[1].subs(numbers).subs(ls.t, sp.Rational(37, 10)).evalf(30)
    assert relative_error([value], [numeric.evaluate(["3.7"], dps=30)[1, 0]]) < 1e-25


@pytest.mark.parametrize("F, degree", [
    (1 / (s**4 + a * s + 1), 4),
    (1 / (s**3 + a * s + 1), 3),
    ((s + 1) / ((s**5 + a * s + 1) * (s**2 + 1)), 5),
])
def test_symbolic_transform_is_answered_or_refused_at_once(F, degree):
    # with root_sums (what the exact stage asks for) a sum over the roots; without, a refusal
    pf, seconds = answered(lambda: partial_fractions(F, s, closed_form=True, root_sums=True))
    assert seconds < HANG_GUARD
    assert any(g.degree == degree and not g.residues for g in pf.groups)
    message, seconds = refused(lambda: partial_fractions(F, s, closed_form=True))
    assert seconds < HANG_GUARD
    assert f"degree {degree}" in message and "symbolic coefficients" in message
    assert "substitute numbers for a" in message and "root_sums=True" in message


def test_symbolic_quadratic_factors_still_invert():
    b, d = sp.symbols("b d", positive=True)
    F = 1 / ((s**2 + a * s + b) * (s**2 + c * s + d))
    f = ls.inverse_laplace(F, s, t)
    values = {a: sp.Rational(1, 3), b: 2, c: sp.Rational(1, 2), d: 5}
    reference = mpmath.invertlaplace(
        lambda z: 1 / ((z**2 + z / 3 + 2) * (z**2 + z / 2 + 5)), 1.3, method="talbot")
    value = complex(sp.N(f.subs(values).subs(t, sp.Rational(13, 10)), 30))
    assert abs(value.imag) < 1e-25
    assert abs(value.real - float(reference)) < 1e-14


def test_unexcited_symbolic_quartic_cancels_and_is_not_refused():
    # A damped symbolic pair decoupled from an excited mass: Δ has the pair's irreducible
    # symbolic quartic, but every numerator cancels it; the answer is the single mass's
    # cos(√(k0/m0) t). Before, the engine computed the quartic's (zero) residues: minutes.
    m0, k0 = sp.symbols("m0 k0", positive=True)
    scene = ls.Scene.from_matrices(
        M=sp.diag(m0, m1, m2).tolist(), C=[[0, 0, 0], [0, c, -c], [0, -c, c]],
        K=[[k0, 0, 0], [0, k1 + k2, -k2], [0, -k2, k2]], x0=[1, 0, 0], v0=[0, 0, 0])
    start = time.perf_counter()
    motion = exact_motion(scene)
    assert time.perf_counter() - start < 10
    expected = [sp.cos(sp.sqrt(k0 / m0) * ls.t), 0, 0]
    assert [sp.simplify(x - e) for x, e in zip(motion.substituted(), expected)] == [0, 0, 0]


def test_rational_quartic_beside_a_symbolic_mass_is_not_refused():
    # Δ = (m0 λ² + k0)·(a rational, irreducible, damped quartic): the screen must see that
    # the quartic does not depend on the parameters (it divides Δ at a second point).
    m0, k0 = sp.symbols("m0 k0", positive=True)
    scene = ls.Scene.from_matrices(
        M=sp.diag(m0, 1, 2).tolist(), C=[[0, 0, 0], [0, 1, -1], [0, -1, 1]],
        K=[[k0, 0, 0], [0, 3, -2], [0, -2, 2]], x0=[1, 1, 0], v0=[0, 0, 0])
    screen_scene(scene)  # no refusal
    x = exact_motion(scene).x
    pair = ls.Scene.from_matrices(M=[[1, 0], [0, 2]], C=[[1, -1], [-1, 1]],
                                  K=[[3, -2], [-2, 2]], x0=[1, 0], v0=[0, 0])
    times = ["0.37", "1.3", "4.1"]
    reference = reference_motion(pair, times)
    values = [[numeric_value(x[i].subs(ls.t, sp.Rational(time_)), 30) for time_ in times]
              for i in (1, 2)]
    assert relative_error(values, reference) < 1e-25


def test_symbolic_uniform_chain_still_solves():
    # 3 masses m, springs k: Δ = (mλ² + 2k)(m²λ⁴ + 4mkλ² + 2k²), an even quartic
    m, k = sp.symbols("m k", positive=True)
    scene = chain([m] * 3, [k] * 4)
    x = ls.solve(scene).substituted()
    numbers = {m: 2, k: 3}
    times = ["0.37", "1.3", "4.1"]
    reference = reference_motion(chain([2] * 3, [3] * 4), times)
    values = [[sp.N(e.subs(numbers).subs(ls.t, sp.Rational(time_)), 30) for time_ in times]
              for e in x]
    assert relative_error(values, reference) < 1e-25


# -- numeric factors above the degree limit --------------------------------------------
def test_degree_200_transform_is_refused_at_once():
    # s**200 + 2s + 2 is irreducible (Eisenstein at 2)
    message, seconds = refused(lambda: ls.inverse_laplace(1 / (s**200 + 2 * s + 2), s, t))
    assert seconds < HANG_GUARD
    assert "degree 200" in message and f"Limits.max_exact_factor_degree = {limits().max_exact_factor_degree}" in message
    assert "modal" in message and "certified" in message


def test_issue_example_names_the_large_factor():
    # s**200 + s + 1 = (s**2 + s + 1)·(an irreducible factor of degree 198)
    message, seconds = refused(lambda: ls.inverse_laplace(1 / (s**200 + s + 1), s, t))
    assert seconds < HANG_GUARD
    assert "degree 198" in message


def test_the_limit_is_exact():
    top = limits().max_exact_factor_degree
    partial_fractions(1 / (s**top + 2 * s + 2), s, closed_form=True)  # allowed
    message, _ = refused(lambda: partial_fractions(1 / (s**(top + 1) + 2 * s + 2), s,
                                                   closed_form=True))
    assert f"degree {top + 1}" in message


def test_a_factor_at_the_limit_inverts_exactly():
    top = limits().max_exact_factor_degree
    f = ls.inverse_laplace(1 / (s**top + 2 * s + 2), s, t)
    with mpmath.workdps(40):  # at t = 6, f is not tiny (near t = 0 it is t**(top-1)/(top-1)!)
        reference = mpmath.invertlaplace(lambda z: 1 / (z**top + 2 * z + 2), 6, method="talbot")
        value = mpmath.mpf(str(numeric_value(f.subs(t, 6), 40)))
        assert abs(value - reference) < mpmath.mpf(10) ** -25 * abs(reference)


def test_partial_fractions_alone_still_answer_at_degree_200():
    start = time.perf_counter()
    pf = ls.partial_fractions(1 / (s**200 + 2 * s + 2), s)
    assert time.perf_counter() - start < HANG_GUARD
    (group,) = pf.groups
    q, (h,) = group.factor, group.residues
    assert group.degree == 200
    assert (h * q.diff()).rem(q).as_expr() == 1  # residue of 1/q at a simple root: 1/q'(ρ)


def test_thirteen_mass_chain_is_solved_in_named_numbers():
    # degree 26 > Limits.max_exact_factor_degree: once refused, now written in named
    # numbers (rho_j, alpha_j, beta_j, c_j) whose values come from certified enclosures
    scene = irreducible_chain(13)
    start = time.perf_counter()
    sol = ls.solve(scene, method="exact")
    values = sol.evaluate(["1.5"], dps=30)
    assert time.perf_counter() - start < 10 * HANG_GUARD
    assert sol.method == "exact" and not sol.x[0].atoms(sp.CRootOf)
    assert relative_error(values, reference_motion(scene, ["1.5"], dps=40)) < 1e-25


def test_forced_thirteen_mass_chain_is_refused_at_once():
    free = irreducible_chain(13)
    scene = ls.Scene.from_matrices(M=free.M, C=free.C, K=free.K, x0=free.x0, v0=free.v0,
                                   forcing=[sp.Heaviside(ls.t - 1)] + [0] * 12)
    message, seconds = refused(lambda: ls.solve(scene, method="exact"))
    assert seconds < HANG_GUARD
    assert "degree 26" in message
    # "auto" takes it by the inputs' own dynamics (tests/numeric/test_exo.py)
    assert ls.solve(scene).method.endswith("+exo")


def test_large_scene_is_refused_on_size():
    n = limits().max_exact_coordinates + 1
    start = time.perf_counter()
    with pytest.raises(ls.LimitError) as info:  # a limit of the package, named
        ls.solve(chain([1] * n, [1] * (n + 1)), method="exact")
    message, seconds = str(info.value), time.perf_counter() - start
    assert seconds < HANG_GUARD
    assert f"Limits.max_exact_coordinates = {limits().max_exact_coordinates}" in message and str(n) in message


def test_nine_mass_chain_whose_factors_are_small_still_solves():
    # a uniform chain's Δ (degree 18) splits into small factors: cheap exact terms
    scene = chain([1] * 9, [1] * 10, x0=[1, 0, 0, 2, 0, 0, 0, 0, 0])
    times = ["0.37", "1.3", "4.1"]
    values = ls.solve(scene, method="exact").evaluate(times)
    assert relative_error(values, reference_motion(scene, times)) < 1e-13


def test_a_resolvent_too_large_to_expand_is_refused_before_expanding() -> None:
    """K = (k0 + ... + k9)**40 with the ten k declared (2·10⁹ terms once expanded) ran
    `solve` past 60 s in SymPy's expand; it is a LimitError naming the entry, at once.
    A fully symbolic damped chain of three masses (a bound of 165 terms) still solves,
    and its x(t) agrees with the matrix-exponential reference at chosen values."""
    ks = [f"k{i}" for i in range(10)]
    scene = ls.Scene.from_matrices(M=[[1]], K=[["(" + "+".join(ks) + ")**40"]], x0=[1],
                                   v0=[0], parameters=ks)
    start = time.perf_counter()
    with pytest.raises(ls.LimitError, match=r"Limits.max_resolvent_terms = 100,000 \(its "
                                            r"entry \[0,0\] alone expands to 2,054,455,635"):
        ls.solve(scene)
    assert time.perf_counter() - start < HANG_GUARD
    names = ["m0", "m1", "m2"]
    nodes = ["wall", *names, "wall"]
    links = list(zip(nodes, nodes[1:]))
    chain = ls.Scene.from_components(
        masses={m: m for m in names},
        springs={f"k{i}": (p, q, f"k{i}") for i, (p, q) in enumerate(links)},
        dashpots={f"c{i}": (p, q, f"c{i}") for i, (p, q) in enumerate(links)},
        x0=[1, 0, 0], v0=[0, 0, 0],
        parameters=[*names, *(f"k{i}" for i in range(4)), *(f"c{i}" for i in range(4))])
    x = ls.solve(chain).x
    by_name = {str(symbol): symbol for symbol in chain.free_symbols}
    values = {by_name[name]: value for name, value in zip(
        [*names, "k0", "k1", "k2", "k3", "c0", "c1", "c2", "c3"],
        [1, 2, sp.Rational(3, 2), 1, 2, 1, 3, sp.Rational(1, 10), sp.Rational(1, 3), 1,
         sp.Rational(1, 5)])}
    numeric = chain.subs({str(k): v for k, v in values.items()})
    times = [sp.Rational(1, 2), 2]
    expected = reference_motion(numeric, times)
    for j, time_value in enumerate(times):
        for i in range(3):
            got = complex(x[i].subs(values).subs(ls.t, time_value).evalf(30)).real
            assert abs(got - float(expected[i][j])) <= 1e-12 * max(1.0, abs(float(expected[i][j])))
