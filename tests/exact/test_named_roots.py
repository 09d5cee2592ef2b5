"""Exact motions in named numbers (ρ_j, α_j, β_j, r_j, c_j): large rational scenes.

Every value is checked against references built independently from the matrices: the
40-digit mpmath matrix exponential of the first-order system
(:func:`laplace_springs.bench.reference.reference_motion`), mpmath's eigenvalues of the
first-order matrix for the named roots, and for the g-basis the exponential of the
companion matrix of Δ (never the code's own formulas).
"""

from __future__ import annotations

import mpmath
import pytest
import sympy as sp

import laplace_springs as ls
from laplace_springs.bench.reference import first_order_matrix_mp, reference_motion, relative_error
from laplace_springs.cli import main
from laplace_springs.exact.assembly import exact_motion
from laplace_springs.exact.named import NamedNumber, expand_names
from laplace_springs.limits import limits

TIMES = ["0", "0.7", "3.1", "17.5"]


def tridiagonal(n: int, diagonal=2) -> sp.Matrix:
    K = sp.zeros(n, n)
    for i in range(n):
        K[i, i] = diagonal
        if i:
            K[i, i - 1] = K[i - 1, i] = -1
    return K


def damped_chain(n: int) -> ls.Scene:
    """n unequal masses (k + 2)/2, dashpots to the wall (k mod 3 + 1)/10: Δ irreducible."""
    return ls.Scene.from_matrices(M=sp.diag(*[sp.Rational(k + 2, 2) for k in range(n)]),
                                  C=sp.diag(*[sp.Rational(k % 3 + 1, 10) for k in range(n)]),
                                  K=tridiagonal(n), x0=[1] + [0] * (n - 1), v0=[0] * n)


def named_numbers(exprs) -> set:
    return {a for e in exprs for a in sp.sympify(e).atoms(sp.Function) if isinstance(a, NamedNumber)}


def values_at(exprs, times, dps=30) -> list[list]:
    return [[sp.N(e.subs(ls.t, sp.Rational(tv)), dps) for tv in times] for e in exprs]


def built(quantity: NamedNumber) -> bool:
    """Whether the exact (CRootOf) definition of a named number has been built."""
    return type(quantity).__dict__["definition"].value is not None


@pytest.fixture(scope="module")
def chain8():
    return ls.solve(damped_chain(8), method="exact")


def test_large_chain_is_named_and_matches_the_matrix_exponential(chain8):
    x = chain8.x
    assert named_numbers(x)
    reference = reference_motion(chain8.scene, TIMES, dps=40)
    assert relative_error(values_at(x, TIMES), reference) < 1e-25
    assert relative_error(chain8.evaluate(TIMES), reference) < 1e-13
    digits = chain8.evaluate(TIMES, dps=30)
    assert relative_error(digits, reference) < 1e-28


def test_named_roots_are_the_eigenvalues(chain8):
    with mpmath.workdps(40):
        eigenvalues = mpmath.eig(first_order_matrix_mp(chain8.scene), left=False, right=False)
    upper = sorted((z for z in eigenvalues if z.imag > 0), key=lambda z: z.imag)
    terms = chain8.motion.terms[0]
    assert len(terms) == len(upper) == 8
    for j, term in enumerate(sorted(terms, key=lambda term: term.beta.index)):
        with mpmath.workdps(40):
            alpha, beta = (mpmath.mpf(str(sp.N(v, 35))) for v in (term.alpha, term.beta))
            assert abs(mpmath.mpc(alpha, beta) - upper[j]) < mpmath.mpf(10) ** -30


def test_sixteen_masses_match_the_matrix_exponential():
    # degree 32 > Limits.max_exact_factor_degree: the named form takes any degree
    scene = damped_chain(16)
    assert 2 * scene.n > limits().max_exact_factor_degree
    sol = ls.solve(scene, method="exact")
    times = ["0.3", "5.5"]
    reference = reference_motion(scene, times, dps=40)
    assert relative_error(sol.evaluate(times, dps=30), reference) < 1e-28
    assert relative_error(sol.evaluate(times), reference) < 1e-13


def test_undamped_chain_has_roots_on_the_imaginary_axis():
    scene = ls.Scene.from_matrices(M=sp.diag(1, 2, 3, 5), K=tridiagonal(4, 3),
                                   x0=[1, 0, 0, 0], v0=[0, 0, 0, sp.Rational(1, 2)])
    sol = ls.solve(scene, method="exact")
    assert named_numbers(sol.x)
    assert all(term.alpha == 0 for row in sol.motion.terms for term in row)  # exactly
    reference = reference_motion(scene, TIMES, dps=40)
    assert relative_error(values_at(sol.x, TIMES), reference) < 1e-25


def test_real_and_complex_roots_of_one_factor():
    # Δ irreducible of degree 6 with two real roots and two conjugate pairs
    scene = ls.Scene.from_matrices(M=sp.diag(1, 2, 3), C=sp.diag(3, 1, 4), K=tridiagonal(3),
                                   x0=[1, 0, 0], v0=[0, 1, 0])
    sol = ls.solve(scene, method="exact")
    kinds = {term.kind for row in sol.motion.terms for term in row}
    assert kinds == {"real", "oscillatory"}
    reference = reference_motion(scene, TIMES, dps=40)
    assert relative_error(values_at(sol.x, TIMES), reference) < 1e-25


def test_crootof_only_when_asked():
    scene = ls.Scene.from_matrices(M=sp.diag(1, 2, 3), C=sp.diag(1, 2, 4) / 10, K=tridiagonal(3),
                                   x0=[1, 0, 0], v0=[0, 0, 0])
    sol = ls.solve(scene, method="exact")
    text, latex = str(sol.x), sol.latex()
    sol.evaluate(TIMES)
    names = named_numbers(sol.x)
    assert names and not any(built(q) for q in names)
    assert "CRootOf" not in text and "CRootOf" not in latex and "rho" in latex
    expanded = expand_names(sol.x[0])
    assert expanded.has(sp.CRootOf) and not named_numbers([expanded])
    reference = reference_motion(scene, TIMES, dps=40)
    assert relative_error([[sp.N(expanded.subs(ls.t, sp.Rational(tv)), 30) for tv in TIMES]],
                          reference[:1]) < 1e-25
    substituted = sol.substituted()
    assert substituted[1].has(sp.CRootOf) and not named_numbers(substituted)


def test_formula_is_small_enough_to_read():
    sol = ls.solve(damped_chain(12), method="exact")
    for row, expr in zip(sol.motion.terms, sol.x):
        assert len(row) == 12  # one damped oscillation per root pair
        assert sp.count_ops(expr) <= 12 * len(row)
        assert len(str(expr)) <= 70 * len(row)
    text = str(sol.x[0])  # the roots in order of frequency, c_2 before c_10
    places = [text.index(f"exp(t*alpha_{j})") for j in range(1, 13)]
    assert places == sorted(places)
    shown = {q: value for q, value in sol.definitions.items() if isinstance(q, NamedNumber)}
    assert len(shown) == 12 * 3 + 12 * 12 * 2  # ρ, α, β per pair; c per term and part
    assert all(len(str(value)) < 100 for value in shown.values())
    assert "CRootOf" not in sol.latex()


def test_verify_checks_the_named_form():
    scene = ls.Scene.from_matrices(M=sp.diag(1, 2, 3), C=sp.diag(1, 2, 4) / 10, K=tridiagonal(3),
                                   x0=[1, 0, 0], v0=[0, 0, 0])
    check = ls.solve(scene, method="exact").verify(samples=["1.3"])
    assert check.ok


def companion_g(delta: sp.Poly, k: int, times, dps: int = 40) -> list:
    """g_k(t) = L⁻¹[λ^k/Δ](t) = y^(k)(t), y the impulse response of 1/Δ: the state
    (y, y', ..., y^(d−1)) is exp(A t)·e_d/lc, A Δ's companion matrix."""
    coeffs = [sp.Rational(c) for c in delta.all_coeffs()]
    d, lc = len(coeffs) - 1, coeffs[0]
    with mpmath.workdps(dps):
        A = mpmath.zeros(d, d)
        for i in range(d - 1):
            A[i, i + 1] = 1
        for j in range(d):
            c = coeffs[d - j]
            A[d - 1, j] = -mpmath.mpf(c.p) / c.q / (mpmath.mpf(lc.p) / lc.q)
        start = mpmath.zeros(d, 1)
        start[d - 1] = 1 / (mpmath.mpf(lc.p) / lc.q)
        return [(mpmath.expm(A * mpmath.mpf(sp.Rational(tv).p) / sp.Rational(tv).q) * start)[k]
                for tv in times]


def test_g_basis_with_double_roots():
    # two equal damped chains side by side: Δ = q², q irreducible of degree 6
    half = (sp.diag(1, 2, 3), sp.diag(1, 2, 4) / 10, tridiagonal(3))
    M, C, K = (sp.diag(m, m) for m in half)
    scene = ls.Scene.from_matrices(M=M, C=C, K=K, x0=[1, 0, 0, 0, 1, 0], v0=[0] * 6)
    motion = exact_motion(scene)
    assert motion.named_roots
    delta = motion.g_denominator
    times = ["0.5", "4.25"]
    for k in (0, 5, 11):
        terms = motion.g_terms[k] if k in motion.g_indices else None
        if terms is None:
            continue
        assert any(term.power == 1 for term in terms)  # t·e^{αt}: the double roots
        g = motion.g_basis[k]
        values = [sp.N(g.subs(ls.t, sp.Rational(tv)), 30) for tv in times]
        reference = companion_g(delta, k, times)
        with mpmath.workdps(40):
            for value, expected in zip(values, reference):
                assert abs(mpmath.mpf(str(value)) - expected) <= mpmath.mpf(10) ** -25 * abs(expected)
    reference = reference_motion(scene, TIMES, dps=40)
    assert relative_error(values_at(motion.x, TIMES), reference) < 1e-25


def test_cli_prints_the_named_form(tmp_path, capsys):
    n = 6
    scene = damped_chain(n)

    def rows(matrix) -> str:
        return "[" + ", ".join("[" + ", ".join(f'"{matrix[i, j]}"' for j in range(n)) + "]"
                               for i in range(n)) + "]"

    path = tmp_path / "chain.toml"
    path.write_text(f"[matrices]\nM = {rows(scene.M)}\nC = {rows(scene.C)}\nK = {rows(scene.K)}\n"
                    f"[initial]\nx0 = {['1'] + ['0'] * (n - 1)}\nv0 = {['0'] * n}\n".replace("'", '"'))
    assert main(["solve", str(path), "--formula"]) == 0
    out = capsys.readouterr().out
    assert "c_1*cos(t*beta_1)" in out and "exp(t*alpha_1)" in out
    assert "rho_1 = root of Delta near" in out and "c_1 = 2*re(N_1(rho_1)/Delta'(rho_1))" in out
    assert "CRootOf" not in out
