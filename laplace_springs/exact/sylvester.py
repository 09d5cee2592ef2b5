"""Matrix functions by Sylvester's formula: cos(√A t), sin(√A t)/√A and e^{Bt}, exactly.

The seed's Example 1 writes the motion of ẍ + A x = 0 as

    x(t) = Ψ(t) x₀ + Φ(t) v₀,   Ψ(t) = cos(√A t),   Φ(t) = sin(√A t)/√A,

and builds both from Sylvester's auxiliary matrices Z_λ (the spectral projectors of
A); its first-order form y' = B y, y = (x, ẋ), gives e^{Bt} = Σ_λ e^{λt} Z_λ with
conjugate pairs folded into real cos/sin matrices. This module computes all of these
exactly in SymPy:

- :func:`spectral_decomposition` and :func:`sylvester_matrices`: eigenvalues from the
  factorisation of the characteristic polynomial over ℚ (rational, radicals for
  quadratic factors, ``CRootOf`` for irreducible factors of degree ≥ 3) and the
  projectors onto their generalised eigenspaces;
- :func:`matrix_function` (and its terms, :func:`matrix_function_terms`), with the named
  shortcuts :func:`expm`, :func:`cos_sqrt`, :func:`sinc_sqrt`: the confluent Sylvester
  formula f(A) = Σ_λ Σ_{k<m_λ} f⁽ᵏ⁾(λ)/k! (A − λI)ᵏ P_λ, real for real A;
- :func:`first_order_matrix`: the block matrix [[0, I], [−A, −B]] of y = (x, ẋ).

Input matrices must have rational entries. Eigenvalues are listed real ones first,
ascending, then complex ones by real part and size of imaginary part, α − iβ just
before α + iβ.

>>> import sympy as sp
>>> t = sp.Symbol("t")
>>> A = [[3, -1], [-2, 2]]
>>> cos_sqrt(A, t)
Matrix([
[  cos(t)/3 + 2*cos(2*t)/3, cos(t)/3 - cos(2*t)/3],
[2*cos(t)/3 - 2*cos(2*t)/3, 2*cos(t)/3 + cos(2*t)/3]])
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import Literal, TypeAlias

import sympy as sp
from sympy.polys.matrices import DomainMatrix

from ..kernels.first_order import SYMPY, first_order
from ..model.errors import SceneError
from ..model.numbers import TIME, to_exact
from .algebraic import AlgebraicRoot

__all__ = [
    "SpectralComponent",
    "cos_sqrt",
    "expm",
    "first_order_matrix",
    "matrix_function",
    "matrix_function_terms",
    "sinc_sqrt",
    "spectral_decomposition",
    "sylvester_matrices",
]

#: A SymPy matrix or a sequence of rows (entries as numbers.to_exact accepts them).
MatrixLike: TypeAlias = "sp.MatrixBase | Sequence[Sequence[object]]"
FunctionName = Literal["exp", "cos_sqrt", "sinc_sqrt"]
#: k-th derivative of f at a root, divided by k!, as (real part, imaginary part).
_Derivative = Callable[[int, "_Root"], tuple[sp.Expr, sp.Expr]]

_X = sp.Dummy("X")  # the polynomial variable standing for the matrix
_Y = sp.Symbol("x")  # a generic root of an irreducible factor (printed in CRootOf)
_W = sp.Dummy("w")  # √z in the derivatives of cos(√z t) and sin(√z t)/√z
_T = sp.Dummy("t", real=True)  # time while computing; the caller's t replaces it


# ---------------------------------------------------------------------------
# input
# ---------------------------------------------------------------------------
def _as_matrix(matrix: MatrixLike, name: str) -> sp.ImmutableMatrix:
    """``matrix`` as a square SymPy matrix of exact entries, or a SceneError.

    Entries go through :func:`laplace_springs.model.numbers.to_exact`, the project's one
    door for numbers: a float means its shortest decimal (``0.2`` is ``1/5``) and text
    is parsed without ``eval``.
    """
    rows = matrix.tolist() if isinstance(matrix, sp.MatrixBase) else matrix
    try:
        rows = [list(row) for row in rows]
    except TypeError as exc:
        raise SceneError(f"{name} must be a square matrix (a sequence of rows): {exc}") from exc
    n = len(rows)
    if n == 0 or any(len(row) != n for row in rows):
        lengths = sorted({len(row) for row in rows})
        raise SceneError(f"{name} must be a non-empty square matrix, got {n} rows of "
                         f"length {', '.join(map(str, lengths)) or 0}")
    return sp.ImmutableMatrix([[to_exact(value, f"{name}[{i},{j}]") for j, value in enumerate(row)]
                               for i, row in enumerate(rows)])


def _as_rational_matrix(matrix: MatrixLike, name: str) -> sp.ImmutableMatrix:
    """``matrix`` as a square matrix of rationals, or a SceneError naming the entry."""
    out = _as_matrix(matrix, name)
    for (i, j), entry in zip(_positions(out), out):
        if not entry.is_Rational:
            raise SceneError(
                f"{name}[{i},{j}] is {entry}; Sylvester's formula here needs rational "
                "entries (substitute numbers for symbols)")
    return out


def _positions(matrix: sp.MatrixBase) -> list[tuple[int, int]]:
    return [(i, j) for i in range(matrix.rows) for j in range(matrix.cols)]


def first_order_matrix(A: MatrixLike, B: MatrixLike | None = None) -> sp.ImmutableMatrix:
    """The 2n×2n matrix [[0, I], [−A, −B]] of ẍ + Bẋ + Ax = 0 written as y' = (·) y.

    With y = (x, ẋ) the second-order system becomes first order; this is the matrix
    the seed calls **B** in Example 1 (its displayed ODE has a sign misprint: the
    Mathematica matrix ``{{0,0,1,0},{0,0,0,1},{-3,1,0,0},{2,-2,0,0}}`` is the right one).

    Parameters
    ----------
    A : matrix-like, n×n
        Stiffness matrix divided by the masses, M⁻¹K. Exact entries (symbols allowed).
    B : matrix-like, n×n, optional
        Damping matrix divided by the masses, M⁻¹C; zero when omitted.

    Returns
    -------
    sympy.ImmutableMatrix
        The block matrix [[0, I], [−A, −B]].

    Raises
    ------
    SceneError
        If a matrix is not square, the shapes differ, or an entry is not a number.

    Examples
    --------
    >>> first_order_matrix([[3, -1], [-2, 2]])
    Matrix([
    [ 0,  0, 1, 0],
    [ 0,  0, 0, 1],
    [-3,  1, 0, 0],
    [ 2, -2, 0, 0]])
    >>> first_order_matrix([[2]], [[sp.Rational(1, 5)]])
    Matrix([
    [ 0,    1],
    [-2, -1/5]])
    """
    stiffness = _as_matrix(A, "A")
    n = stiffness.rows
    damping = sp.zeros(n, n) if B is None else _as_matrix(B, "B")
    if damping.shape != stiffness.shape:
        raise SceneError(f"B must have the shape of A, {stiffness.shape}; got {damping.shape}")
    Z, _, _ = first_order(sp.eye(n), damping, stiffness, [0] * n, [0] * n, SYMPY, massless=())
    return sp.ImmutableMatrix(Z)


# ---------------------------------------------------------------------------
# eigenvalues of one irreducible factor
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class _Root:
    """One root of an irreducible rational factor, with its real and imaginary parts.

    ``sign`` is the sign of the root if it is real, of its imaginary part otherwise;
    it is decided once, on the exact value, so that a proxy keeps it.
    """

    value: sp.Expr
    real: sp.Expr
    imag: sp.Expr
    is_real: bool
    sign: int

    @classmethod
    def real_root(cls, value: sp.Expr) -> _Root:
        return cls(value, value, sp.S.Zero, True, _sign(value))

    @classmethod
    def complex_root(cls, value: sp.Expr, real: sp.Expr, imag: sp.Expr) -> _Root:
        return cls(value, real, imag, False, _sign(imag))

    @property
    def upper(self) -> bool:
        """Is this the representative (Im > 0) of a conjugate pair?"""
        return not self.is_real and self.sign > 0

    def sort_key(self) -> tuple:
        re, im = _numeric(self.real), _numeric(self.imag)
        return (not self.is_real, re, abs(im), im)

    def proxy(self) -> tuple[_Root, dict[sp.Symbol, sp.Expr]]:
        """This root with symbols in place of a ``CRootOf`` and the map back.

        Expanding expressions that contain ``CRootOf`` is slow (SymPy rebuilds the
        polynomial at every visit); the assembly works on the symbols and the exact
        values are put in once, at the end.
        """
        if not self.value.has(sp.CRootOf):
            return self, {}
        if self.is_real:
            r = sp.Dummy("r", real=True)
            return _Root(r, r, sp.S.Zero, True, self.sign), {r: self.value}
        a, b = sp.Dummy("a", real=True), sp.Dummy("b", real=True)
        return (_Root(a + sp.I * b, a, b, False, self.sign),
                {a: self.real, b: self.imag})


def _numeric(value: sp.Expr) -> sp.Float:
    """A 40-digit value, for ordering and sign decisions on exact (distinct) numbers."""
    return sp.N(value, 40)


def _sign(value: sp.Expr) -> int:
    """Sign of an exact real algebraic number (exactly 0 only if it is 0)."""
    if value == 0:
        return 0
    return 1 if _numeric(value) > 0 else -1


def _roots(q: sp.Poly) -> list[_Root]:
    """Exact roots of a monic irreducible rational polynomial ``q`` in ``_Y``."""
    if q.degree() == 1:
        return [_Root.real_root(-q.nth(0))]
    if q.degree() == 2:
        return _quadratic_roots(q)
    expr = q.as_expr()
    out = []
    for index in range(q.degree()):
        root = AlgebraicRoot(expr, index)
        if root.is_real:
            out.append(_Root.real_root(root))
        else:
            out.append(_Root.complex_root(root, sp.re(root), sp.im(root)))
    return out


def _quadratic_roots(q: sp.Poly) -> list[_Root]:
    """Roots of y² + p y + s by the quadratic formula; ascending, or α − iβ before α + iβ."""
    p, s = q.nth(1), q.nth(0)
    disc = p**2 - 4 * s
    alpha = -p / 2
    if disc > 0:
        half = sp.sqrt(disc) / 2
        return [_Root.real_root(alpha - half), _Root.real_root(alpha + half)]
    beta = sp.sqrt(-disc) / 2
    return [_Root.complex_root(alpha - sp.I * beta, alpha, -beta),
            _Root.complex_root(alpha + sp.I * beta, alpha, beta)]


# ---------------------------------------------------------------------------
# spectral decomposition
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class SpectralComponent:
    """One eigenvalue of a matrix with its spectral projector and nilpotent part.

    Attributes
    ----------
    eigenvalue : sympy.Expr
        Exact eigenvalue λ: rational, a quadratic radical, or a ``CRootOf``.
    algebraic_multiplicity : int
        Multiplicity of λ as a root of the characteristic polynomial.
    index : int
        Multiplicity of λ as a root of the minimal polynomial (size of the largest
        Jordan block); 1 when A is diagonalisable on this eigenvalue.
    projector : sympy.ImmutableMatrix
        P_λ, the projector onto the generalised eigenspace along the others
        (Sylvester's auxiliary matrix Z_λ when the eigenvalues are distinct).
    nilpotent : sympy.ImmutableMatrix
        N_λ = (A − λI) P_λ; zero exactly when ``index == 1``.
    """

    eigenvalue: sp.Expr
    algebraic_multiplicity: int
    index: int
    projector: sp.ImmutableMatrix
    nilpotent: sp.ImmutableMatrix


@dataclass(frozen=True)
class _FactorBlock:
    """An irreducible factor q of the characteristic polynomial and its covariants.

    ``covariants[k][l]`` are rational matrices with (A − yI)ᵏ P_y = Σ_l yˡ·covariants[k][l]
    for *every* root y of q: the formulas are computed once in ℚ[y]/(q) and hold for
    each conjugate root alike.
    """

    factor: sp.Poly
    multiplicity: int
    index: int
    covariants: tuple[tuple[sp.ImmutableMatrix, ...], ...]
    roots: tuple[_Root, ...]


def _domain_matrix(A: sp.ImmutableMatrix) -> DomainMatrix:
    return DomainMatrix.from_Matrix(sp.Matrix(A)).convert_to(sp.QQ)


def _evaluate_at(poly: sp.Poly, A: DomainMatrix) -> DomainMatrix:
    """poly(A) by Horner's rule, exactly over ℚ."""
    n = A.shape[0]
    identity = DomainMatrix.eye(n, sp.QQ)
    out = DomainMatrix.zeros((n, n), sp.QQ)
    for c in poly.all_coeffs():
        out = out * A + identity * sp.QQ.from_sympy(c)
    return out


def _index(q: sp.Poly, multiplicity: int, A: DomainMatrix) -> int:
    """Smallest s with nullity(q(A)^s) = deg(q)·multiplicity: q's exponent in ψ."""
    if multiplicity == 1:
        return 1
    n, target = A.shape[0], q.degree() * multiplicity
    base = _evaluate_at(q, A)
    power = base
    for s in range(1, multiplicity):
        if n - power.rank() == target:
            return s
        power = power * base
    return multiplicity


def _reduce(expr: sp.Expr, psi: sp.Poly, q: sp.Poly) -> sp.Poly:
    """``expr`` in ℚ[x, y] reduced modulo ψ(x) and q(y), as a Poly in (x, y)."""
    _, remainder = sp.reduced(expr, [psi.as_expr(), q.as_expr()], _X, _Y)
    return sp.Poly(remainder, _X, _Y, domain=sp.QQ)


def _idempotent(psi: sp.Poly, q: sp.Poly, index: int) -> sp.Expr:
    """e(x) in ℚ[y]/(q)[x]: e ≡ 1 mod (x − y)^m and ≡ 0 mod ψ/(x − y)^m, so P_y = e(A).

    With ψ = (x − y)^m g(x) (modulo q(y)), e = g·T where T is the Taylor polynomial of
    1/g about x = y truncated at order m (the partial fraction of 1/ψ at y, times ψ).
    """
    m = index
    qx = q.as_expr().xreplace({_Y: _X})
    rest = sp.quo(psi, sp.Poly(qx, _X) ** m).as_expr()
    h = sp.quo(sp.Poly(qx - q.as_expr(), _X, _Y), sp.Poly(_X - _Y, _X, _Y)).as_expr()
    g = rest * h**m
    qy = sp.Poly(q.as_expr(), _Y)
    taylor = [sp.Poly(sp.diff(g, _X, j).xreplace({_X: _Y}) / math.factorial(j), _Y).rem(qy)
              for j in range(m)]
    inverse = taylor[0].invert(qy)
    series = [inverse]
    for k in range(1, m):
        total = sum((taylor[j] * series[k - j] for j in range(1, k + 1)), sp.Poly(0, _Y))
        series.append((-inverse * total).rem(qy))
    T = sum(c.as_expr() * (_X - _Y) ** k for k, c in enumerate(series))
    return sp.expand(g * T)


def _evaluate_covariant(poly: sp.Poly, powers: list[sp.Matrix], d: int
                        ) -> tuple[sp.ImmutableMatrix, ...]:
    """Σ c_jl x^j y^l ↦ (M_0, ..., M_{d−1}) with M_l = Σ_j c_jl A^j."""
    n = powers[0].rows
    out = [sp.zeros(n, n) for _ in range(d)]
    for (j, power), c in poly.terms():
        out[power] += c * powers[j]
    return tuple(sp.ImmutableMatrix(M) for M in out)


def _factor_blocks(A: sp.ImmutableMatrix) -> list[_FactorBlock]:
    """Factor the characteristic polynomial and compute every factor's covariants."""
    dm = _domain_matrix(A)
    charpoly = sp.Poly(dm.charpoly(), _X, domain=sp.QQ)
    factors = [(f.monic(), m) for f, m in charpoly.factor_list()[1]]
    indices = [_index(f, m, dm) for f, m in factors]
    psi = sp.prod((f**s for (f, _), s in zip(factors, indices)), start=sp.Poly(1, _X))
    powers = [sp.eye(A.rows)]
    for _ in range(1, psi.degree()):
        powers.append(powers[-1] * A)
    blocks = []
    for (f, m), s in zip(factors, indices):
        q = sp.Poly(f.as_expr().xreplace({_X: _Y}), _Y, domain=sp.QQ)
        e = _idempotent(psi, q, s)
        covariants = tuple(
            _evaluate_covariant(_reduce((_X - _Y) ** k * e, psi, q), powers, q.degree())
            for k in range(s))
        blocks.append(_FactorBlock(q, m, s, covariants, tuple(_roots(q))))
    return blocks


def _at_root(parts: tuple[sp.ImmutableMatrix, ...], value: sp.Expr) -> sp.ImmutableMatrix:
    """Σ_l valueˡ M_l, entries expanded (in a symbol standing for a ``CRootOf``)."""
    y = sp.Dummy("y") if value.has(sp.CRootOf) else value
    total = sum((y**k * M for k, M in enumerate(parts)), sp.zeros(*parts[0].shape))
    return sp.ImmutableMatrix(total.applyfunc(sp.expand)).xreplace({y: value})


def _at_root_parts(parts: tuple[sp.ImmutableMatrix, ...], root: _Root
                   ) -> tuple[sp.ImmutableMatrix, sp.ImmutableMatrix]:
    """Real and imaginary parts of Σ_l rˡ M_l for r = α + iβ, with no I in either."""
    re_power, im_power = sp.S.One, sp.S.Zero
    re_total, im_total = sp.zeros(*parts[0].shape), sp.zeros(*parts[0].shape)
    for M in parts:
        re_total += re_power * M
        im_total += im_power * M
        re_power, im_power = (sp.expand(re_power * root.real - im_power * root.imag),
                              sp.expand(re_power * root.imag + im_power * root.real))
    return (sp.ImmutableMatrix(re_total.applyfunc(sp.expand)),
            sp.ImmutableMatrix(im_total.applyfunc(sp.expand)))


def _ordered(blocks: list[_FactorBlock]) -> list[tuple[_FactorBlock, _Root]]:
    pairs = [(block, root) for block in blocks for root in block.roots]
    return sorted(pairs, key=lambda pair: pair[1].sort_key())


def spectral_decomposition(A: MatrixLike) -> tuple[SpectralComponent, ...]:
    """Eigenvalues of A with their spectral projectors and nilpotent parts, exactly.

    Parameters
    ----------
    A : matrix-like, n×n
        Rational entries: integers, ``Rational``, ``Fraction``, or floats and text
        read as the decimals they show (``0.2`` is 1/5, see ``numbers.to_exact``).
        Symbols and irrational numbers are refused.

    Returns
    -------
    tuple of SpectralComponent
        One per distinct eigenvalue. Real eigenvalues come first, ascending; then the
        complex ones by real part, then by the size of the imaginary part, each
        conjugate pair adjacent with the negative imaginary part first (the order of
        SymPy's ``Poly.all_roots``).

    Raises
    ------
    SceneError
        If A is not square or has a non-rational entry.

    Notes
    -----
    The eigenvalues come from ``Poly.factor_list`` of the characteristic polynomial
    over ℚ, never from numerical eigenvalues: a linear factor gives a rational, a
    quadratic one y² + py + s the radicals (−p ± √(p² − 4s))/2, and an irreducible
    factor of degree ≥ 3 its ``CRootOf`` roots (a subclass with flint evaluation).

    For each irreducible factor q with exponent m in the minimal polynomial ψ (found
    from the ranks of q(A)ˢ), the projector is P_y = e(A), where e(x) = g(x)·T(x),
    ψ = (x − y)ᵐ g, and T is the degree < m Taylor polynomial of 1/g about y: that is
    the partial-fraction decomposition 1/ψ = Σ r_i(x)/(x − λ_i)^{m_i} multiplied by ψ.
    For distinct eigenvalues it reduces to Sylvester's
    Z_i = Π_{j≠i}(A − λ_j I)/(λ_i − λ_j).
    The computation is done once per factor in ℚ[y]/(q(y)), so every root of q gets
    its projector by substitution and entries of a ``CRootOf`` projector are
    polynomials of degree < deg q in that root.

    Examples
    --------
    A defective matrix (one Jordan block for −1):

    >>> (c,) = spectral_decomposition([[0, 1], [-1, -2]])
    >>> c.eigenvalue, c.algebraic_multiplicity, c.index
    (-1, 2, 2)
    >>> c.projector, c.nilpotent
    (Matrix([
    [1, 0],
    [0, 1]]), Matrix([
    [ 1,  1],
    [-1, -1]]))
    """
    matrix = _as_rational_matrix(A, "A")
    out = []
    for block, root in _ordered(_factor_blocks(matrix)):
        parts = block.covariants
        nilpotent = (_at_root(parts[1], root.value) if block.index > 1
                     else sp.ImmutableMatrix(sp.zeros(matrix.rows, matrix.cols)))
        out.append(SpectralComponent(root.value, block.multiplicity, block.index,
                                     _at_root(parts[0], root.value), nilpotent))
    return tuple(out)


def sylvester_matrices(A: MatrixLike) -> dict[sp.Expr, sp.ImmutableMatrix]:
    """Sylvester's auxiliary matrices Z_λ of A, keyed by exact eigenvalue.

    For distinct eigenvalues Z_i = Π_{j≠i} (A − λ_j I)/(λ_i − λ_j); for repeated ones
    the projectors onto the generalised eigenspaces (see :func:`spectral_decomposition`
    for the construction and the order of the keys: real ascending, then complex).
    Always Z_λ Z_μ = δ_λμ Z_λ and Σ Z_λ = I.

    Parameters
    ----------
    A : matrix-like, n×n
        Rational entries.

    Returns
    -------
    dict
        ``{eigenvalue: ImmutableMatrix}``; complex eigenvalues have complex matrices.

    Examples
    --------
    The seed's Example 1, (1.4):

    >>> Z = sylvester_matrices([[3, -1], [-2, 2]])
    >>> Z
    {1: Matrix([
    [1/3, 1/3],
    [2/3, 2/3]]), 4: Matrix([
    [ 2/3, -1/3],
    [-2/3,  1/3]])}
    >>> Z[1] * Z[4]
    Matrix([
    [0, 0],
    [0, 0]])
    >>> list(sylvester_matrices([[0, 1], [-4, 0]]))
    [-2*I, 2*I]
    """
    return {c.eigenvalue: c.projector for c in spectral_decomposition(A)}


# ---------------------------------------------------------------------------
# scalar functions and their derivatives at an eigenvalue
# ---------------------------------------------------------------------------
def _exp_derivative(k: int, root: _Root) -> tuple[sp.Expr, sp.Expr]:
    """d^k/dz^k e^{zt} / k! = t^k e^{zt} / k!, split into real and imaginary parts."""
    scale = _T**k / math.factorial(k) * sp.exp(root.real * _T)
    if root.is_real:
        return scale, sp.S.Zero
    return scale * sp.cos(root.imag * _T), scale * sp.sin(root.imag * _T)


@lru_cache(maxsize=64)
def _sqrt_family_in_w(kind: str, k: int) -> sp.Expr:
    """k-th z-derivative / k! of c(z) = cos(√z t) or s(z) = sin(√z t)/√z, in w = √z."""
    expr = sp.cos(_W * _T) if kind == "cos" else sp.sin(_W * _T) / _W
    for _ in range(k):
        expr = sp.diff(expr, _W) / (2 * _W)  # d/dz = (1/2w) d/dw
    return sp.expand(expr / math.factorial(k))


def _sqrt_family_at_zero(kind: str, k: int) -> sp.Expr:
    """The removable values at z = 0 from the Taylor series in z.

    c⁽ᵏ⁾(0)/k! = (−1)ᵏ t²ᵏ/(2k)! and s⁽ᵏ⁾(0)/k! = (−1)ᵏ t²ᵏ⁺¹/(2k+1)!.
    """
    power = 2 * k if kind == "cos" else 2 * k + 1
    return (-1) ** k * _T**power / math.factorial(power)


def _sqrt_family_derivative(kind: str, k: int, root: _Root) -> tuple[sp.Expr, sp.Expr]:
    """Derivative of c or s at an eigenvalue: cos/sin for z > 0, cosh/sinh for z < 0."""
    if root.value == 0:
        return _sqrt_family_at_zero(kind, k), sp.S.Zero
    expr = _sqrt_family_in_w(kind, k)
    if root.is_real:
        w = sp.sqrt(root.value) if root.sign > 0 else sp.I * sp.sqrt(-root.value)
        return expr.xreplace({_W: w}), sp.S.Zero
    # z = α + iβ (β > 0) has √z = p + iq with p = √((|z| + α)/2), q = √((|z| − α)/2).
    p, q = sp.Dummy("p", positive=True), sp.Dummy("q", positive=True)
    re, im = sp.expand_complex(expr.xreplace({_W: p + sp.I * q})).as_real_imag()
    modulus = sp.sqrt(root.real**2 + root.imag**2)
    values = {p: sp.sqrt((modulus + root.real) / 2), q: sp.sqrt((modulus - root.real) / 2)}
    return re.xreplace(values), im.xreplace(values)


def _generic_derivative(f_of_z: sp.Expr, z: sp.Symbol) -> _Derivative:
    """Derivatives of a user's f(z) by differentiation, with limits at removable points."""
    def derivative(k: int, root: _Root) -> tuple[sp.Expr, sp.Expr]:
        expr = sp.diff(f_of_z, z, k) / math.factorial(k)
        if root.is_real:
            value = expr.subs(z, root.value)
            if value.has(sp.nan, sp.zoo, sp.oo, -sp.oo):
                value = sp.limit(expr, z, root.value)
            return value, sp.S.Zero
        a, b = sp.Dummy("a", real=True), sp.Dummy("b", real=True)
        re, im = sp.expand_complex(expr.subs(z, a + sp.I * b)).as_real_imag()
        values = {a: root.real, b: root.imag}
        return re.xreplace(values), im.xreplace(values)
    return derivative


_NAMED: dict[str, _Derivative] = {
    "exp": _exp_derivative,
    "cos_sqrt": lambda k, root: _sqrt_family_derivative("cos", k, root),
    "sinc_sqrt": lambda k, root: _sqrt_family_derivative("sinc", k, root),
}


# ---------------------------------------------------------------------------
# assembly: Σ basis(t) · matrix
# ---------------------------------------------------------------------------
def _split(scalar: sp.Expr, variables: tuple[sp.Symbol, ...]) -> list[tuple[sp.Expr, sp.Expr]]:
    """scalar = Σ coefficient·basis with the basis carrying all dependence on ``variables``."""
    out = []
    for term in sp.Add.make_args(sp.expand(scalar, deep=False, power_exp=False)):
        if variables:
            coefficient, basis = term.as_independent(*variables, as_Add=False)
        else:
            coefficient, basis = term.as_coeff_Mul()
        out.append((coefficient, basis))
    return out


def _terms(A: sp.ImmutableMatrix, derivative: _Derivative, variables: tuple[sp.Symbol, ...]
           ) -> list[tuple[sp.Expr, sp.ImmutableMatrix]]:
    """f(A) = Σ_λ Σ_k f⁽ᵏ⁾(λ)/k! (A − λI)ᵏ P_λ as (basis function, matrix) pairs.

    A conjugate pair contributes 2 Re(D Z) = 2 Re D · Re Z − 2 Im D · Im Z once, from
    its member with positive imaginary part, so no I survives for real A.
    """
    collected: dict[sp.Expr, sp.Matrix] = {}
    exact: dict[sp.Symbol, sp.Expr] = {}
    for block, exact_root in _ordered(_factor_blocks(A)):
        if not (exact_root.is_real or exact_root.upper):
            continue
        root, back = exact_root.proxy()
        exact.update(back)
        for k, parts in enumerate(block.covariants):
            re_d, im_d = derivative(k, root)
            if root.is_real:
                pieces = [(re_d, _at_root(parts, root.value))]
            else:
                re_z, im_z = _at_root_parts(parts, root)
                pieces = [(2 * re_d, re_z), (-2 * im_d, im_z)]
            for scalar, matrix in pieces:
                for coefficient, basis in _split(scalar, variables):
                    total = collected.setdefault(basis, sp.zeros(*A.shape))
                    collected[basis] = total + (coefficient * matrix).applyfunc(sp.expand)
    return [(basis.xreplace(exact), sp.ImmutableMatrix(M).xreplace(exact))
            for basis, M in collected.items() if not M.is_zero_matrix]


def _sum(terms: list[tuple[sp.Expr, sp.ImmutableMatrix]], shape: tuple[int, int]
         ) -> sp.ImmutableMatrix:
    out = sp.zeros(*shape)
    for basis, matrix in terms:
        out += basis * matrix
    return sp.ImmutableMatrix(out)


def _time(t: object) -> sp.Expr:
    """The caller's time: a SymPy expression or a number (text is never parsed)."""
    try:
        return sp.sympify(t, strict=True)
    except sp.SympifyError:
        raise TypeError(f"t must be a SymPy symbol or expression, got {t!r}") from None


def _prepare(f: FunctionName | Callable[[sp.Expr], sp.Expr], t: sp.Expr | None
             ) -> tuple[_Derivative, tuple[sp.Symbol, ...], dict[sp.Symbol, sp.Expr]]:
    """The derivative rule for ``f``, its variables, and the map back to the caller's symbols."""
    if isinstance(f, str):
        if f not in _NAMED:
            raise ValueError(f"unknown function {f!r}; expected one of {sorted(_NAMED)} "
                             "or a callable of one argument")
        return _NAMED[f], (_T,), {_T: TIME if t is None else _time(t)}
    if t is not None:
        raise TypeError("t is only for the named functions; a callable f carries its own symbols")
    z = sp.Dummy("z")
    f_of_z = sp.sympify(f(z), strict=True)  # an expression, never text
    symbols = sorted(f_of_z.free_symbols - {z}, key=sp.default_sort_key)
    real = {s: sp.Dummy(s.name, real=True) for s in symbols}
    derivative = _generic_derivative(f_of_z.xreplace(real), z)
    return derivative, tuple(real.values()), {v: s for s, v in real.items()}


def matrix_function_terms(A: MatrixLike, f: FunctionName | Callable[[sp.Expr], sp.Expr],
                          t: sp.Expr | None = None
                          ) -> tuple[tuple[sp.Expr, sp.ImmutableMatrix], ...]:
    """f(A) as a sum of scalar basis functions times constant real matrices.

    The form the seed prints: Ψ(t) = cos t·Z₁ + cos 2t·Z₄, or e^{Bt} = cos t·(2 Re Z_j)
    + sin t·(−2 Im Z_j) + ...; constant factors are moved into the matrices.

    Parameters
    ----------
    A : matrix-like, n×n
        Rational entries.
    f : {"exp", "cos_sqrt", "sinc_sqrt"} or callable
        ``"exp"``: e^{zt}; ``"cos_sqrt"``: cos(√z t); ``"sinc_sqrt"``: sin(√z t)/√z
        (entire in z). A callable takes a SymPy expression z and returns f(z) built from
        entire (or at least analytic on the spectrum) SymPy functions with real Taylor
        coefficients; its other symbols play the role of t.
    t : sympy.Expr, optional
        Time symbol or value for the named functions; ``laplace_springs.t`` by default.

    Returns
    -------
    tuple of (sympy.Expr, sympy.ImmutableMatrix)
        Pairs (basis function, matrix), real-eigenvalue terms first, each eigenvalue's
        terms in increasing powers of t.

    Examples
    --------
    >>> t = sp.Symbol("t")
    >>> for basis, Z in matrix_function_terms([[3, -1], [-2, 2]], "sinc_sqrt", t):
    ...     print(basis, Z.tolist())
    sin(t) [[1/3, 1/3], [2/3, 2/3]]
    sin(2*t) [[1/3, -1/6], [-1/3, 1/6]]
    """
    matrix = _as_rational_matrix(A, "A")
    derivative, variables, back = _prepare(f, t)
    terms = _terms(matrix, derivative, variables)
    return tuple((sp.sympify(basis, strict=True).xreplace(back), M) for basis, M in terms)


def matrix_function(A: MatrixLike, f: FunctionName | Callable[[sp.Expr], sp.Expr],
                    t: sp.Expr | None = None) -> sp.ImmutableMatrix:
    """f(A) by the confluent Sylvester formula, exactly; real for real A.

    Parameters
    ----------
    A : matrix-like, n×n
        Rational entries (as in :func:`spectral_decomposition`; no symbols).
    f : {"exp", "cos_sqrt", "sinc_sqrt"} or callable
        See :func:`matrix_function_terms`.
    t : sympy.Expr, optional
        Time symbol or value for the named functions; ``laplace_springs.t`` by default.

    Returns
    -------
    sympy.ImmutableMatrix
        f(A) = Σ_λ Σ_{k<m_λ} f⁽ᵏ⁾(λ)/k! (A − λI)ᵏ P_λ.

    Raises
    ------
    SceneError
        If A is not square or has an entry that is not a rational number.

    Notes
    -----
    **Algorithm.** Spectral projectors P_λ and nilpotent parts as in
    :func:`spectral_decomposition`; the sum runs over the index m_λ of each eigenvalue,
    so non-diagonalisable A gives tᵏe^{λt} terms. A conjugate pair λ, λ̄ enters once as
    2 Re(f(λ) Z_λ) = 2 Re f(λ)·Re Z_λ − 2 Im f(λ)·Im Z_λ, so no ``I`` is left for real A.

    **Precision and conditioning.** Exact throughout: no floating-point number is
    created, so defective and nearly defective spectra cost nothing in accuracy (they
    would ruin an eigenvector route). The price is expression size: entries of
    ``CRootOf`` eigenvalues are polynomials in the root, evaluated by ``sympy.N``.

    Examples
    --------
    >>> t = sp.Symbol("t")
    >>> matrix_function([[0, 1], [-1, -2]], "exp", t)
    Matrix([
    [t*exp(-t) + exp(-t),            t*exp(-t)],
    [         -t*exp(-t), -t*exp(-t) + exp(-t)]])
    >>> matrix_function([[1, 2], [0, 3]], lambda z: z**2)
    Matrix([
    [1, 8],
    [0, 9]])
    """
    matrix = _as_rational_matrix(A, "A")
    derivative, variables, back = _prepare(f, t)
    return _sum(_terms(matrix, derivative, variables), matrix.shape).xreplace(back)


def expm(B: MatrixLike, t: sp.Expr | None = None) -> sp.ImmutableMatrix:
    """The matrix exponential e^{Bt}, exact and real for a rational B.

    Parameters
    ----------
    B : matrix-like, n×n
        Rational entries, e.g. :func:`first_order_matrix` of a scene.
    t : sympy.Expr, optional
        Time symbol or exact value; ``laplace_springs.t`` by default.

    Returns
    -------
    sympy.ImmutableMatrix
        Σ_λ Σ_k tᵏe^{λt}/k! (B − λI)ᵏ P_λ, conjugate pairs as e^{αt}(cos βt, sin βt).

    Examples
    --------
    The seed's U(t) = e^{Bt} of Example 1 in first-order form, top-left block:

    >>> t = sp.Symbol("t")
    >>> U = expm(first_order_matrix([[3, -1], [-2, 2]]), t)
    >>> U[:2, :2]
    Matrix([
    [  cos(t)/3 + 2*cos(2*t)/3, cos(t)/3 - cos(2*t)/3],
    [2*cos(t)/3 - 2*cos(2*t)/3, 2*cos(t)/3 + cos(2*t)/3]])
    >>> U.has(sp.I)
    False
    """
    return matrix_function(B, "exp", t)


def cos_sqrt(A: MatrixLike, t: sp.Expr | None = None) -> sp.ImmutableMatrix:
    """Ψ(t) = cos(√A t), the seed's response to initial displacement of ẍ + Ax = 0.

    Uses the entire function c(z) = cos(√z t) = Σ (−1)ⁿ zⁿ t²ⁿ/(2n)!: no square root of
    A is taken, a zero eigenvalue gives 1 (and −t²/2 on its nilpotent part), a negative
    one (an unstable spring) gives cosh(√|λ| t).

    Parameters
    ----------
    A : matrix-like, n×n
        Rational entries, A = M⁻¹K.
    t : sympy.Expr, optional
        Time symbol or exact value; ``laplace_springs.t`` by default.

    Returns
    -------
    sympy.ImmutableMatrix

    Examples
    --------
    >>> t = sp.Symbol("t")
    >>> cos_sqrt([[1, 2], [2, 1]], t)
    Matrix([
    [cos(sqrt(3)*t)/2 + cosh(t)/2, cos(sqrt(3)*t)/2 - cosh(t)/2],
    [cos(sqrt(3)*t)/2 - cosh(t)/2, cos(sqrt(3)*t)/2 + cosh(t)/2]])
    """
    return matrix_function(A, "cos_sqrt", t)


def sinc_sqrt(A: MatrixLike, t: sp.Expr | None = None) -> sp.ImmutableMatrix:
    """Φ(t) = sin(√A t)/√A, the seed's response to initial velocity of ẍ + Ax = 0.

    Uses the entire function s(z) = sin(√z t)/√z = Σ (−1)ⁿ zⁿ t²ⁿ⁺¹/(2n+1)!, so a
    zero eigenvalue (a rigid-body mode) gives t, and t·P − (t³/6)·N on a Jordan
    block; a negative eigenvalue gives sinh(√|λ| t)/√|λ|.

    Parameters
    ----------
    A : matrix-like, n×n
        Rational entries, A = M⁻¹K.
    t : sympy.Expr, optional
        Time symbol or exact value; ``laplace_springs.t`` by default.

    Returns
    -------
    sympy.ImmutableMatrix

    Examples
    --------
    A free–free pair (rigid-body mode at 0, vibration at 16/3):

    >>> t = sp.Symbol("t")
    >>> Phi = sinc_sqrt([[4, -4], [sp.Rational(-4, 3), sp.Rational(4, 3)]], t)
    >>> Phi[0, 0]
    t/4 + 3*sqrt(3)*sin(4*sqrt(3)*t/3)/16
    """
    return matrix_function(A, "sinc_sqrt", t)
