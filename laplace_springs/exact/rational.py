"""Exact algebra over ℚ in python-flint: the fast path for scenes with rational entries.

SymPy's fraction-free adjugate of λ²M + λC + K and its partial fractions over ℚ(λ) are
exact but slow (a damped chain of 12 unequal masses: 13 s). For a scene whose M, C, K,
x0 and v0 are rational, everything the exact motion needs is computed here with
python-flint instead, and only what the scene needs:

- Δ(λ) = det(λ²M + λC + K) and the numerators N_i(λ) = (adj(λ)·r(λ))_i of
  X_i = N_i/Δ, by exact determinants and solves at the integers λ = 0, 1, 2, ... and
  interpolation: adj(x)·r(x) = det P(x) · P(x)⁻¹ r(x) (the adjugate itself is never
  formed; :func:`rational_adjugate` builds it the same way when it is asked for);
- the principal parts of N/D at the roots of each irreducible factor q of D, as
  residues h_k in the number field ℚ[x]/(q), by truncated power series in u = λ − ρ
  whose coefficients are reduced modulo q (:func:`rational_partial_fractions`).

Everything is exact rational arithmetic (``fmpq``, ``fmpq_poly``, ``fmpq_mat``); the
results are the same polynomials SymPy computes (the tests check them against SymPy's
adjugate and partial fractions).

Examples
--------
The seed's Example 2 (A = [[3, -1], [-2, 2]], B = I/5, x0 = (1, 0)):

>>> from laplace_springs.model.scene import Scene
>>> scene = Scene.from_normalized(A=[[3, -1], [-2, 2]], B=[["0.2", 0], [0, "0.2"]],
...                               x0=[1, 0], v0=[0, 0])
>>> delta, (numerators,) = rational_transform(scene)
>>> delta
x^4 + 2/5*x^3 + 126/25*x^2 + x + 4
>>> numerators[0]     # (λ² + λ/5 + 2)(λ + 1/5): adj(λ)[0, 0]·r_0(λ), r = (λ + 1/5, 0)
x^3 + 2/5*x^2 + 51/25*x + 2/5
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import flint
import sympy as sp

from ..model.scene import Scene

__all__ = ["RationalPencil", "RationalGroup", "fmpq_of", "rational_pencil", "initial_vector",
           "interpolate", "solve_at_integers", "rational_transform", "rational_adjugate",
           "to_poly", "from_poly", "rational_partial_fractions", "invert_mod"]

#: (M, C, K) as exact rational matrices.
RationalPencil = tuple[flint.fmpq_mat, flint.fmpq_mat, flint.fmpq_mat]


def fmpq_of(value: sp.Expr) -> flint.fmpq | None:
    """A SymPy Rational as an ``fmpq``; None for anything else (irrational, symbolic).

    >>> fmpq_of(sp.Rational(-2, 3)), fmpq_of(sp.sqrt(2))
    (-2/3, None)
    """
    if not getattr(value, "is_Rational", False):
        return None
    return flint.fmpq(int(value.p), int(value.q))


def _matrix(matrix: sp.MatrixBase, point: dict | None = None) -> flint.fmpq_mat | None:
    """A SymPy matrix (at ``point``) as an ``fmpq_mat``; None if an entry is not rational."""
    entries = []
    for e in matrix:
        value = fmpq_of(e.xreplace(point) if point else e)
        if value is None:
            return None
        entries.append(value)
    return flint.fmpq_mat(matrix.rows, matrix.cols, entries)


def rational_pencil(scene: Scene, point: dict | None = None) -> RationalPencil | None:
    """(M, C, K) of ``scene`` (at ``point``, a value per parameter) over ℚ, or None when
    an entry is not rational there."""
    M, C, K = (_matrix(m, point) for m in (scene.M, scene.C, scene.K))
    if M is None or C is None or K is None:
        return None
    return M, C, K


def initial_vector(scene: Scene, pencil: RationalPencil,
                   point: dict | None = None) -> list[flint.fmpq_poly] | None:
    """r(λ) = M(λ x0 + v0) + C x0 over ℚ (None when x0 or v0 is not rational)."""
    M, C, _ = pencil
    x0, v0 = _matrix(scene.x0, point), _matrix(scene.v0, point)
    if x0 is None or v0 is None:
        return None
    slope, offset = M * x0, M * v0 + C * x0
    return [flint.fmpq_poly([offset[i, 0], slope[i, 0]]) for i in range(scene.n)]


def interpolate(xs: Sequence[int], ys: Sequence[flint.fmpq]) -> flint.fmpq_poly:
    """The polynomial of degree < len(xs) through (xs, ys), by divided differences.

    >>> interpolate([0, 1, 2], [flint.fmpq(1), flint.fmpq(2), flint.fmpq(5)])
    x^2 + 1
    """
    coefficients = list(ys)
    for j in range(1, len(xs)):
        for i in range(len(xs) - 1, j - 1, -1):
            coefficients[i] = (coefficients[i] - coefficients[i - 1]) / (xs[i] - xs[i - j])
    poly = flint.fmpq_poly([coefficients[-1]])
    for i in range(len(xs) - 2, -1, -1):
        poly = poly * flint.fmpq_poly([-xs[i], 1]) + coefficients[i]
    return poly


def _pencil_at(pencil: RationalPencil, x: int) -> flint.fmpq_mat:
    M, C, K = pencil
    return M * (x * x) + C * x + K


def solve_at_integers(pencil: RationalPencil, vectors: Sequence[Sequence[flint.fmpq_poly]]
                      ) -> tuple[flint.fmpq_poly, list[list[flint.fmpq_poly]]] | None:
    """Δ(λ) and, for each w in ``vectors``, the numerators adj(λ)·w(λ); None if Δ ≡ 0.

    adj(P(x))·w(x) = det P(x) · P(x)⁻¹ w(x) at integers x with det P(x) ≠ 0 (all the
    vectors in one solve), then interpolation (deg adj ≤ 2n − 2, deg Δ ≤ 2n).
    """
    n = pencil[0].nrows()
    width = max((wi.degree() for w in vectors for wi in w), default=0)
    count = 2 * n - 1 + max(0, width)
    xs: list[int] = []
    dets: list[flint.fmpq] = []
    nodes: list[int] = []
    columns: list[flint.fmpq_mat] = []
    x = 0
    while len(xs) < 2 * n + 1 or len(nodes) < count:
        if x > count + 2 * n + 1:  # Δ has at most 2n integer roots unless it vanishes
            return None
        P = _pencil_at(pencil, x)
        det = P.det()
        if len(xs) < 2 * n + 1:
            xs.append(x)
            dets.append(det)
        if det != 0 and len(nodes) < count and vectors:
            rhs = flint.fmpq_mat(n, len(vectors), [w[i](x) for i in range(n) for w in vectors])
            nodes.append(x)
            columns.append(P.solve(rhs) * det)
        x += 1
    delta = interpolate(xs, dets)
    if delta == 0:
        return None
    numerators = [[interpolate(nodes, [column[i, k] for column in columns]) for i in range(n)]
                  for k in range(len(vectors))]
    return delta, numerators


def rational_transform(scene: Scene) -> tuple[flint.fmpq_poly, list[list[flint.fmpq_poly]]] | None:
    """Δ(λ) and the numerators N_i(λ) of the free motion X_i = N_i/Δ, over ℚ.

    None when an entry of M, C, K, x0, v0 is not rational, or Δ ≡ 0. The numerators
    come as one list (the pieces of a forced scene are built elsewhere).
    """
    pencil = rational_pencil(scene)
    if pencil is None:
        return None
    r = initial_vector(scene, pencil)
    if r is None:
        return None
    return solve_at_integers(pencil, [r])


def rational_adjugate(pencil: RationalPencil) -> list[list[flint.fmpq_poly]] | None:
    """adj(λ²M + λC + K) over ℚ, entry [i][j], by inverses at integers and interpolation
    (None if Δ ≡ 0)."""
    n = pencil[0].nrows()
    if n == 1:
        return [[flint.fmpq_poly([1])]]
    nodes: list[int] = []
    inverses: list[flint.fmpq_mat] = []
    x = 0
    while len(nodes) < 2 * n - 1:
        if x > 4 * n + 1:
            return None
        P = _pencil_at(pencil, x)
        det = P.det()
        if det != 0:
            nodes.append(x)
            inverses.append(P.inv() * det)
        x += 1
    return [[interpolate(nodes, [inverse[i, j] for inverse in inverses]) for j in range(n)]
            for i in range(n)]


def to_poly(poly: flint.fmpq_poly, gen: sp.Symbol, domain=sp.QQ) -> sp.Poly:
    """An ``fmpq_poly`` as a SymPy Poly in ``gen`` over ℚ (``domain=None``: ℤ when the
    coefficients are integers, as ``sympy.Poly(expr, gen)`` chooses).

    >>> s = sp.Symbol("s")
    >>> to_poly(flint.fmpq_poly([1, 0, flint.fmpq(1, 2)]), s), to_poly(flint.fmpq_poly([2, 1]), s, None)
    (Poly(1/2*s**2 + 1, s, domain='QQ'), Poly(s + 2, s, domain='ZZ'))
    """
    coeffs = [sp.Rational(int(c.p), int(c.q)) for c in reversed(poly.coeffs())] or [sp.S.Zero]
    if domain is None:
        domain = sp.ZZ if all(c.q == 1 for c in coeffs) else sp.QQ
    return sp.Poly(coeffs, gen, domain=domain)


def from_poly(poly: sp.Poly) -> flint.fmpq_poly | None:
    """A univariate SymPy Poly over ℚ or ℤ as an ``fmpq_poly``; None over other domains.

    >>> from_poly(sp.Poly(sp.Symbol("s")**2 / 3 - 1, sp.Symbol("s")))
    1/3*x^2 + (-1)
    """
    if len(poly.gens) != 1 or not (poly.domain.is_QQ or poly.domain.is_ZZ):
        return None
    to_sympy = poly.domain.to_sympy
    coeffs = [fmpq_of(to_sympy(c)) for c in reversed(poly.all_coeffs())]
    known = [c for c in coeffs if c is not None]
    return flint.fmpq_poly(known) if len(known) == len(coeffs) else None


# ---------------------------------------------------------------------------
# partial fractions over ℚ, residues in ℚ[x]/(q)
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class RationalGroup:
    """The principal parts of each numerator at the roots of one irreducible factor.

    Attributes
    ----------
    factor : flint.fmpq_poly
        Monic q, irreducible over ℚ.
    multiplicity : int
        m, with q^m exactly dividing the denominator.
    residues : tuple of tuple of flint.fmpq_poly
        ``residues[i][k - 1]`` is h_k (deg < deg q) for numerator i: the coefficient of
        1/(λ − ρ)^k at every root ρ of q is h_k(ρ).
    """

    factor: flint.fmpq_poly
    multiplicity: int
    residues: tuple[tuple[flint.fmpq_poly, ...], ...]


def invert_mod(a: flint.fmpq_poly, q: flint.fmpq_poly) -> flint.fmpq_poly:
    """a⁻¹ modulo q (a must be a unit: gcd(a, q) = 1).

    >>> q = flint.fmpq_poly([1, 0, 1])   # x² + 1
    >>> invert_mod(flint.fmpq_poly([1, 1]), q)   # (1 + x)(1 − x)/2 = 1 mod x² + 1
    (-1/2)*x + 1/2
    """
    g, s, _ = a.xgcd(q)
    if g.degree() != 0:
        raise ZeroDivisionError(f"{a} is not invertible modulo {q}")
    return (s / g.coeffs()[0]) % q


def _taylor(p: flint.fmpq_poly, q: flint.fmpq_poly, order: int) -> list[flint.fmpq_poly]:
    """p^{(j)}(ρ)/j! reduced modulo q, j < order."""
    out = []
    for j in range(order):
        out.append(p % q)
        p = p.derivative() / (j + 1)
    return out


def _series_mul(a: list[flint.fmpq_poly], b: list[flint.fmpq_poly], q: flint.fmpq_poly
                ) -> list[flint.fmpq_poly]:
    zero = flint.fmpq_poly([])
    return [sum((a[i] * b[j - i] for i in range(j + 1)), zero) % q for j in range(len(a))]


def _series_inv(b: list[flint.fmpq_poly], q: flint.fmpq_poly) -> list[flint.fmpq_poly]:
    inv0 = invert_mod(b[0], q)
    out = [inv0]
    zero = flint.fmpq_poly([])
    for j in range(1, len(b)):
        acc = sum((b[i] * out[j - i] for i in range(1, j + 1)), zero)
        out.append((-inv0 * acc) % q)
    return out


def _cofactor_inverse(q: flint.fmpq_poly, m: int, rest: flint.fmpq_poly) -> list[flint.fmpq_poly]:
    """Series in u of 1/(Q1(u)^m R(ρ + u)) with q(ρ + u) = u·Q1(u), rest = D/q^m."""
    Q1 = _taylor(q, q, m + 1)[1:]
    series = _taylor(rest, q, m)
    for _ in range(m):
        series = _series_mul(series, Q1, q)
    return _series_inv(series, q)


def rational_partial_fractions(numerators: Sequence[flint.fmpq_poly], denominator: flint.fmpq_poly,
                               factors: Sequence[tuple[flint.fmpq_poly, int]] | None = None
                               ) -> tuple[list[flint.fmpq_poly], list[RationalGroup]]:
    """Partial fractions of N_i/D over ℚ: polynomial parts and one group per factor of D.

    Parameters
    ----------
    numerators : sequence of flint.fmpq_poly
    denominator : flint.fmpq_poly
        Nonzero.
    factors : sequence of (fmpq_poly, int), optional
        The irreducible factors of D with multiplicities, in the order wanted (any
        scaling); by default flint's factorisation.

    Returns
    -------
    quotients : list of flint.fmpq_poly
        The polynomial part of each N_i/D.
    groups : list of RationalGroup
        One per factor, residues for every numerator (zero where the pole cancels).

    Examples
    --------
    1/((x + 1)²(x² + 1)) = 1/(2(x + 1)²) + 1/(2(x + 1)) − x/(2(x² + 1)), and
    −x/(2(x² + 1)) = Σ_{ρ = ±i} (−1/4)/(x − ρ): residues h_2 = h_1 = 1/2 at −1, h = −1/4
    at ±i (SymPy's :func:`~laplace_springs.exact.partial_fractions.partial_fractions`
    gives the same):

    >>> D = flint.fmpq_poly([1, 1]) ** 2 * flint.fmpq_poly([1, 0, 1])
    >>> _, groups = rational_partial_fractions([flint.fmpq_poly([1])], D)
    >>> sorted((g.factor.degree(), g.multiplicity, g.residues[0]) for g in groups)
    [(1, 2, (1/2, 1/2)), (2, 1, ((-1/4),))]
    """
    if factors is None:
        _, factors = denominator.factor()
    monic = [(f / f.coeffs()[-1], m) for f, m in factors]
    lc = denominator.coeffs()[-1]
    quotients = [N // denominator for N in numerators]
    groups = []
    for index, (q, m) in enumerate(monic):
        rest = flint.fmpq_poly([lc])
        for j, (other, mult) in enumerate(monic):
            if j != index:
                rest *= other ** mult
        inverse = _cofactor_inverse(q, m, rest)
        residues = []
        for N in numerators:
            H = _series_mul(_taylor(N, q, m), inverse, q)
            residues.append(tuple(H[m - k] for k in range(1, m + 1)))
        groups.append(RationalGroup(q, m, tuple(residues)))
    return quotients, groups
