"""Tests of laplace_springs.exact.sylvester.

Expected values come from the seed's printed results (Example 1: (1.4), Φ(t), Ψ(t),
Z_j, Z_2j and U(t) = e^{Bt}) or from an independent oracle: mpmath's matrix
exponential at 40 digits, whose blocks for the first-order matrix [[0, I], [−A, 0]]
are [[cos(√A t), sin(√A t)/√A], [·, ·]].
"""

from __future__ import annotations

import random

import mpmath
import pytest
import sympy as sp

from laplace_springs.exact.sylvester import (
    cos_sqrt,
    expm,
    first_order_matrix,
    matrix_function,
    matrix_function_terms,
    sinc_sqrt,
    spectral_decomposition,
    sylvester_matrices,
)
from laplace_springs.model.errors import SceneError
from laplace_springs.model.numbers import TIME
from laplace_springs.numeric.mp_expr import numeric_value

t = sp.Symbol("t")
IU, R = sp.I, sp.Rational

# --- the seed, Example 1 -------------------------------------------------------
A_SEED = sp.Matrix([[3, -1], [-2, 2]])
Z1_SEED = R(1, 3) * sp.Matrix([[1, 1], [2, 2]])
Z4_SEED = R(1, 3) * sp.Matrix([[2, -1], [-2, 1]])
PHI_SEED = sp.sin(t) / 3 * sp.Matrix([[1, 1], [2, 2]]) + sp.sin(2 * t) / 6 * sp.Matrix([[2, -1], [-2, 1]])
PSI_SEED = sp.cos(t) / 3 * sp.Matrix([[1, 1], [2, 2]]) + sp.cos(2 * t) / 3 * sp.Matrix([[2, -1], [-2, 1]])
B_SEED = sp.Matrix([[0, 0, 1, 0], [0, 0, 0, 1], [-3, 1, 0, 0], [2, -2, 0, 0]])
ZJ_SEED = R(1, 6) * sp.Matrix([[1, 1, -IU, -IU], [2, 2, -2 * IU, -2 * IU], [IU, IU, 1, 1], [2 * IU, 2 * IU, 2, 2]])
Z2J_SEED = R(1, 12) * sp.Matrix([[4, -2, -2 * IU, IU], [-4, 2, 2 * IU, -IU],
                                 [8 * IU, -4 * IU, 4, -2], [-8 * IU, 4 * IU, -4, 2]])
U_COS_T = R(1, 3) * sp.Matrix([[1, 1, 0, 0], [2, 2, 0, 0], [0, 0, 1, 1], [0, 0, 2, 2]])
U_SIN_T = R(1, 3) * sp.Matrix([[0, 0, 1, 1], [0, 0, 2, 2], [-1, -1, 0, 0], [-2, -2, 0, 0]])
U_COS_2T = R(1, 3) * sp.Matrix([[2, -1, 0, 0], [-2, 1, 0, 0], [0, 0, 2, -1], [0, 0, -2, 1]])
U_SIN_2T = R(1, 3) * sp.Matrix([[0, 0, 1, R(-1, 2)], [0, 0, -1, R(1, 2)], [-4, 2, 0, 0], [4, -2, 0, 0]])
U_SEED = (sp.cos(t) * U_COS_T + sp.sin(t) * U_SIN_T
          + sp.cos(2 * t) * U_COS_2T + sp.sin(2 * t) * U_SIN_2T)

# --- other matrices ------------------------------------------------------------
A_FREE_FREE = sp.Matrix([[4, -4], [R(-4, 3), R(4, 3)]])   # eigenvalues 0 and 16/3
CRITICAL = sp.Matrix([[0, 1], [-1, -2]])                   # double eigenvalue −1, one block
CUBIC = sp.Matrix([[0, 0, 1], [1, 0, 1], [0, 1, 0]])       # companion of x³ − x − 1
ROT = sp.Matrix([[0, 1], [-1, 0]])
JORDAN_PAIR = sp.Matrix(sp.BlockMatrix([[ROT, sp.eye(2)], [sp.zeros(2), ROT]]))  # ±i, index 2
CHAIN = sp.Matrix([[2, -1, 0], [-1, 2, -1], [0, -1, 2]])   # eigenvalues 2, 2 ± √2

TIMES = (R(7, 10), R(23, 10))
DPS = 40
TOL = mpmath.mpf("1e-30")


def _mp(matrix: sp.MatrixBase) -> mpmath.matrix:
    return mpmath.matrix([[mpmath.mpf(int(sp.Rational(e).p)) / int(sp.Rational(e).q)
                           for e in row] for row in matrix.tolist()])


def _value(expr: sp.Expr, tv: sp.Rational) -> mpmath.mpf:
    # numeric_value is sympy.N with each CRootOf evaluated once (flint), not per occurrence
    value = numeric_value(sp.sympify(expr).xreplace({t: tv}), DPS + 10)
    return mpmath.mpf(sp.Float(value, DPS + 10)._mpf_)


def _max_error(exact: sp.MatrixBase, reference: mpmath.matrix, tv: sp.Rational) -> mpmath.mpf:
    return max(abs(_value(exact[i, j], tv) - reference[i, j])
               for i in range(exact.rows) for j in range(exact.cols))


def _oracle_exp(matrix: sp.MatrixBase, tv: sp.Rational) -> mpmath.matrix:
    return mpmath.expm(_mp(matrix) * (mpmath.mpf(int(tv.p)) / int(tv.q)))


def _oracle_blocks(A: sp.MatrixBase, tv: sp.Rational) -> tuple[mpmath.matrix, mpmath.matrix]:
    """(cos(√A t), sin(√A t)/√A) as blocks of mpmath's exp([[0, I], [−A, 0]] t)."""
    n = A.rows
    H = mpmath.zeros(2 * n, 2 * n)
    for i in range(n):
        H[i, n + i] = 1
        for j in range(n):
            H[n + i, j] = -_mp(A)[i, j]
    E = mpmath.expm(H * (mpmath.mpf(int(tv.p)) / int(tv.q)))
    return E[0:n, 0:n], E[0:n, n:2 * n]


def _is_zero(matrix: sp.MatrixBase) -> bool:
    return sp.Matrix(matrix).applyfunc(lambda e: sp.simplify(sp.expand(e))).is_zero_matrix


# ==============================================================================
# Sylvester's auxiliary matrices
# ==============================================================================
def test_seed_example1_eigenvalues_and_auxiliary_matrices():
    Z = sylvester_matrices(A_SEED)
    assert list(Z) == [1, 4]
    assert Z[1] == Z1_SEED
    assert Z[4] == Z4_SEED


@pytest.mark.parametrize("matrix", [A_SEED, B_SEED, CRITICAL, first_order_matrix(A_FREE_FREE)])
def test_projectors_are_complementary_idempotents(matrix):
    Z = list(sylvester_matrices(matrix).values())
    n = matrix.rows
    for i, Zi in enumerate(Z):
        assert _is_zero(Zi * Zi - Zi)
        for Zk in Z[i + 1:]:
            assert _is_zero(Zi * Zk)
    assert _is_zero(sum(Z, sp.zeros(n, n)) - sp.eye(n))


def test_seed_first_order_auxiliary_matrices():
    Z = sylvester_matrices(B_SEED)
    # real parts equal (all zero), then |Im| ascending, −iβ before +iβ
    assert list(Z) == [-IU, IU, -2 * IU, 2 * IU]
    assert Z[IU] == ZJ_SEED
    assert Z[2 * IU] == Z2J_SEED
    assert Z[-IU] == ZJ_SEED.conjugate()
    assert Z[-2 * IU] == Z2J_SEED.conjugate()


def test_ordering_real_ascending_then_complex():
    # eigenvalues −1 (double in the 3×3 block), 2, and ±i
    matrix = sp.diag(2, ROT, sp.Matrix([[-1, 1], [0, -1]]))
    assert list(sylvester_matrices(matrix)) == [-1, 2, -IU, IU]


def test_quadratic_factor_gives_radicals():
    Z = sylvester_matrices(CHAIN)
    assert list(Z) == [2 - sp.sqrt(2), 2, 2 + sp.sqrt(2)]
    # eigenvector (1, ±√2, 1)/2 of the fixed-free chain, from the textbook solution
    v = sp.Matrix([1, -sp.sqrt(2), 1]) / 2
    assert _is_zero(Z[2 + sp.sqrt(2)] - v * v.T)


def test_cubic_factor_gives_crootof_projectors():
    Z = sylvester_matrices(CUBIC)
    keys = list(Z)
    assert all(isinstance(k, sp.CRootOf) for k in keys)
    assert keys[0].is_real and not keys[1].is_real
    assert sp.im(sp.N(keys[1])) < 0 < sp.im(sp.N(keys[2]))
    with mpmath.workdps(30):
        total = sum((sp.Matrix(M) for M in Z.values()), sp.zeros(3, 3))
        for i in range(3):
            for j in range(3):
                assert abs(complex(sp.N(total[i, j], 30)) - (i == j)) < 1e-25
        for lam, M in Z.items():
            residual = (CUBIC - lam * sp.eye(3)) * M  # λ simple: (A − λI) Z_λ = 0
            assert max(abs(complex(sp.N(e, 30))) for e in residual) < 1e-25


def test_spectral_decomposition_defective():
    (component,) = spectral_decomposition(CRITICAL)
    assert component.eigenvalue == -1
    assert component.algebraic_multiplicity == 2 and component.index == 2
    assert component.projector == sp.eye(2)
    assert component.nilpotent == CRITICAL + sp.eye(2)


def test_spectral_decomposition_rigid_body_mode():
    components = spectral_decomposition(first_order_matrix(A_FREE_FREE))
    zero = components[0]
    assert zero.eigenvalue == 0 and zero.index == 2
    assert not zero.nilpotent.is_zero_matrix
    assert all(c.index == 1 for c in components[1:])


def test_repeated_but_diagonalisable_eigenvalue_has_index_one():
    (component,) = spectral_decomposition(3 * sp.eye(3))
    assert component.algebraic_multiplicity == 3 and component.index == 1
    assert component.nilpotent.is_zero_matrix


# ==============================================================================
# cos(√A t), sin(√A t)/√A, e^{Bt} against the seed
# ==============================================================================
def test_seed_phi_and_psi_exactly():
    assert _is_zero(sinc_sqrt(A_SEED, t) - PHI_SEED)
    assert _is_zero(cos_sqrt(A_SEED, t) - PSI_SEED)
    assert cos_sqrt(A_SEED, t) == sp.expand(PSI_SEED)  # printed as the seed prints it


def test_seed_phi_and_psi_numerically():
    with mpmath.workdps(30):
        for tv in (R(1, 3), R(7, 10), R(23, 10), R(10)):
            assert _max_error(sinc_sqrt(A_SEED, t), _mp_seed(PHI_SEED, tv), tv) < 1e-28
            assert _max_error(cos_sqrt(A_SEED, t), _mp_seed(PSI_SEED, tv), tv) < 1e-28


def _mp_seed(matrix: sp.MatrixBase, tv: sp.Rational) -> mpmath.matrix:
    return mpmath.matrix([[_value(e, tv) for e in row] for row in matrix.tolist()])


def test_seed_psi_terms_are_cos_t_z1_plus_cos_2t_z4():
    terms = matrix_function_terms(A_SEED, "cos_sqrt", t)
    assert terms == ((sp.cos(t), Z1_SEED), (sp.cos(2 * t), Z4_SEED))


def test_seed_first_order_matrix():
    assert first_order_matrix(A_SEED) == B_SEED
    damped = first_order_matrix(A_SEED, sp.eye(2) / 5)
    assert damped[2:, 2:] == -sp.eye(2) / 5 and damped[2:, :2] == -A_SEED


def test_seed_exponential_exactly():
    U = expm(B_SEED, t)
    assert _is_zero(U - U_SEED)
    assert not U.has(IU)


def test_seed_exponential_terms_are_the_printed_matrices():
    terms = dict(matrix_function_terms(B_SEED, "exp", t))
    assert terms == {sp.cos(t): U_COS_T, sp.sin(t): U_SIN_T,
                     sp.cos(2 * t): U_COS_2T, sp.sin(2 * t): U_SIN_2T}


def test_default_time_symbol_is_the_package_t():
    assert cos_sqrt(A_SEED).free_symbols == {TIME}


def test_numeric_time_gives_exact_numbers():
    U = expm(B_SEED, sp.pi / 2)
    assert U_SEED.subs(t, sp.pi / 2) == U


# ==============================================================================
# closed forms from outside the code: Jordan blocks and zero eigenvalues
# ==============================================================================
def test_critical_damping_gives_t_exp_terms():
    # (A + I)² = 0, so e^{At} = e^{−t}(I + t(A + I)) exactly (Cayley–Hamilton)
    expected = sp.exp(-t) * (sp.eye(2) + t * (CRITICAL + sp.eye(2)))
    assert _is_zero(expm(CRITICAL, t) - expected)


def test_nilpotent_stiffness_series():
    # A = [[0,1],[0,0]], A² = 0: cos(√A t) = I − t²A/2, sin(√A t)/√A = tI − t³A/6
    N = sp.Matrix([[0, 1], [0, 0]])
    assert cos_sqrt(N, t) == sp.eye(2) - t**2 / 2 * N
    assert sinc_sqrt(N, t) == t * sp.eye(2) - t**3 / 6 * N
    assert sinc_sqrt([[0]], t) == sp.Matrix([[t]])
    assert cos_sqrt([[0]], t) == sp.Matrix([[1]])


def test_free_free_rigid_body_term_is_t_times_projector():
    # Sylvester by hand: eigenvalues 0 and 16/3, Z_0 = (A − 16/3 I)/(0 − 16/3) = I − 3A/16
    terms = dict(matrix_function_terms(A_FREE_FREE, "sinc_sqrt", t))
    assert terms[t] == sp.Matrix([[1, 3], [1, 3]]) / 4


def test_unstable_spring_gives_cosh_and_sinh():
    A = sp.Matrix([[1, 2], [2, 1]])  # eigenvalues −1 and 3
    assert cos_sqrt(A, t).has(sp.cosh) and sinc_sqrt(A, t).has(sp.sinh)
    assert not cos_sqrt(A, t).has(IU)


# ==============================================================================
# the independent oracle: mpmath.expm at 40 digits
# ==============================================================================
EXP_CASES = {
    "seed-damped": first_order_matrix(A_SEED, sp.eye(2) / 5),
    "critical": CRITICAL,
    "free-free": first_order_matrix(A_FREE_FREE),
    "cubic": CUBIC,
    "jordan-pair": JORDAN_PAIR,
    "chain-damped": first_order_matrix(CHAIN, sp.diag(R(1, 10), 0, R(1, 5))),
    "critical-2dof": first_order_matrix(sp.eye(2), 2 * sp.eye(2)),
}


@pytest.mark.parametrize("name", sorted(EXP_CASES))
def test_expm_against_mpmath(name):
    B = EXP_CASES[name]
    U = expm(B, t)
    assert not U.has(IU)
    with mpmath.workdps(DPS):
        for tv in TIMES:
            assert _max_error(U, _oracle_exp(B, tv), tv) < TOL


SQRT_CASES = {
    "seed": A_SEED,
    "free-free": A_FREE_FREE,
    "unstable": sp.Matrix([[1, 2], [2, 1]]),
    "defective-positive": sp.Matrix([[1, 1], [0, 1]]),
    "defective-negative": sp.Matrix([[-1, 1], [0, -1]]),
    "defective-zero": sp.Matrix([[0, 1], [0, 0]]),
    "complex": sp.Matrix([[1, 2], [-2, 1]]),
    "cubic": CUBIC,
    "chain": CHAIN,
}


@pytest.mark.parametrize("name", sorted(SQRT_CASES))
def test_cos_sqrt_and_sinc_sqrt_against_first_order_exponential(name):
    A = SQRT_CASES[name]
    Psi, Phi = cos_sqrt(A, t), sinc_sqrt(A, t)
    assert not Psi.has(IU) and not Phi.has(IU)
    with mpmath.workdps(DPS):
        for tv in TIMES:
            psi_ref, phi_ref = _oracle_blocks(A, tv)
            assert _max_error(Psi, psi_ref, tv) < TOL
            assert _max_error(Phi, phi_ref, tv) < TOL


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_random_integer_matrices_against_mpmath(seed):
    rng = random.Random(seed)
    B = sp.Matrix(3, 3, [rng.randint(-3, 3) for _ in range(9)])
    U = expm(B, t)
    assert not U.has(IU)
    with mpmath.workdps(DPS):
        assert _max_error(U, _oracle_exp(B, R(7, 10)), R(7, 10)) < TOL


# ==============================================================================
# general f
# ==============================================================================
def test_callable_polynomial_is_the_matrix_power():
    A = sp.Matrix([[1, 2], [0, 3]])
    assert matrix_function(A, lambda z: z**2) == A**2
    assert matrix_function(CRITICAL, lambda z: z**3 - 2 * z) == CRITICAL**3 - 2 * CRITICAL


def test_callable_exponential_matches_the_oracle():
    B = first_order_matrix(A_SEED, sp.eye(2) / 5)
    U = matrix_function(B, lambda z: sp.exp(z * t))
    assert not U.has(IU)
    with mpmath.workdps(DPS):
        for tv in TIMES:
            assert _max_error(U, _oracle_exp(B, tv), tv) < TOL


def test_callable_with_removable_singularity_uses_the_limit():
    # sin(√z t)/√z at the zero eigenvalue of a free-free pair is its limit t
    f = matrix_function(A_FREE_FREE, lambda z: sp.sin(sp.sqrt(z) * t) / sp.sqrt(z))
    with mpmath.workdps(DPS):
        for tv in TIMES:
            assert _max_error(f, _oracle_blocks(A_FREE_FREE, tv)[1], tv) < TOL


# ==============================================================================
# errors
# ==============================================================================
@pytest.mark.parametrize("bad, match", [
    ([[1, 2, 3], [4, 5, 6]], "square"),
    ([1, 2], "square"),
    ([], "square"),
    ([[sp.Symbol("k"), 1], [1, 1]], r"A\[0,0\] is k; .*rational"),
    ([[sp.sqrt(2), 1], [1, 1]], "rational"),
    ([["abc$", 1], [1, 1]], r"A\[0,0\]: expected a number"),
    ([[float("nan"), 1], [1, 1]], "finite"),
])
def test_bad_matrices_raise_scene_error(bad, match):
    with pytest.raises(SceneError, match=match):
        expm(bad, t)


def test_floats_and_text_mean_their_decimals():
    # the project's number convention (numbers.to_exact): 0.2 is 1/5, never a binary float
    U = expm([[0.2]], t)
    assert sp.Matrix([[sp.exp(t / 5)]]) == U and not U.has(sp.Float)
    assert sylvester_matrices([["3", -1], [-2, "2.0"]]) == {1: Z1_SEED, 4: Z4_SEED}


def test_first_order_matrix_shape_mismatch():
    with pytest.raises(SceneError, match="shape"):
        first_order_matrix(A_SEED, sp.eye(3))


def test_first_order_matrix_allows_symbols():
    k, m = sp.symbols("k m", positive=True)
    assert first_order_matrix([[k / m]])[1, 0] == -k / m


def test_time_given_as_text_is_refused_not_parsed():
    with pytest.raises(TypeError, match="t must be a SymPy symbol"):
        expm(A_SEED, "t")


def test_unknown_function_name_and_t_with_callable():
    with pytest.raises(ValueError, match="unknown function"):
        matrix_function(A_SEED, "tan")
    with pytest.raises(TypeError, match="named functions"):
        matrix_function(A_SEED, lambda z: z, t)
