"""The resolvent (λ²M + λC + K)⁻¹ as an exact adjugate over the determinant Δ(λ).

Taking the Laplace transform of M x'' + C x' + K x = 0 with x(0) = x0, x'(0) = v0 gives

    (λ²M + λC + K) X(λ) = M(λ x0 + v0) + C x0,

so X(λ) = adj(λ) r(λ) / Δ(λ) with Δ(λ) = det(λ²M + λC + K). The seed writes the same
thing in normalised form, (λ²I + λB + A)⁻¹ = (λ²M + λC + K)⁻¹ M with A = M⁻¹K, B = M⁻¹C.
Everything here is fraction-free polynomial arithmetic (SymPy's DomainMatrix Bareiss
adjugate over ℚ[λ] or ℤ[params][λ]): no floats for exact input.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property

import sympy as sp
from sympy.polys.matrices import DomainMatrix

from ..limits import limits
from ..model.equations import expanded_size
from ..model.errors import LimitError
from ..model.scene import Scene
from ..model.symbols import lam
from .rational import initial_vector, rational_adjugate, rational_pencil, solve_at_integers, to_poly

__all__ = ["lam", "Resolvent", "resolvent"]



def _poly(expr: sp.Expr) -> sp.Poly:
    return sp.Poly(expr, lam)


@dataclass(frozen=True, eq=False)
class Resolvent:
    """Exact resolvent of a scene: Δ(λ), adj(λ) and the transform X(λ).

    Build it with :func:`resolvent`. Attributes
    ----------
    scene : Scene
        The scene it belongs to.
    determinant : sympy.Poly
        Δ(λ) = det(λ²M + λC + K), in the variable :data:`lam`.
    numerators : tuple of sympy.Poly
        N_i(λ) with X_i(λ) = N_i(λ)/Δ(λ), i.e. adj(λ)·[M(λx0 + v0) + C x0].
    adjugate : sympy.ImmutableMatrix
        adj(λ²M + λC + K), polynomial entries in λ (built on first use for a rational
        scene, whose Δ and N_i come without it).
    """

    scene: Scene
    determinant: sp.Poly
    numerators: tuple[sp.Poly, ...]
    known_adjugate: sp.ImmutableMatrix | None = field(default=None, repr=False)

    @cached_property
    def adjugate(self) -> sp.ImmutableMatrix:
        """adj(λ²M + λC + K), polynomial entries in λ."""
        if self.known_adjugate is not None:
            return self.known_adjugate
        pencil = rational_pencil(self.scene)
        entries = rational_adjugate(pencil) if pencil is not None else None
        if entries is not None:
            return sp.ImmutableMatrix([[to_poly(e, lam, domain=None).as_expr() for e in row]
                                       for row in entries])
        adjugate, _ = _adjugate_and_determinant(sp.Matrix(self.pencil()))
        return sp.ImmutableMatrix(adjugate.applyfunc(sp.expand))

    def __repr__(self) -> str:
        """``Resolvent(2 coordinates, Δ(λ) = 25λ⁴ + ...)``: the scaled Δ(λ), shortened if long.

        >>> from laplace_springs.model.scene import Scene
        >>> resolvent(Scene.from_matrices(M=[[1]], C=[[2]], K=[[5]], x0=[1], v0=[0]))
        Resolvent(1 coordinate, Δ(λ) = lambda**2 + 2*lambda + 5)
        """
        delta = sp.sstr(self.integer_characteristic_polynomial.as_expr())
        if len(delta) > 80:
            cut = delta.rfind(" + ", 0, 70)
            cut = max(cut, delta.rfind(" - ", 0, 70))
            delta = f"{delta[:cut if cut > 0 else 70]} + ... (degree {self.determinant.degree()})"
        n = self.scene.n
        return f"Resolvent({n} coordinate{'' if n == 1 else 's'}, Δ(λ) = {delta})"

    @property
    def variable(self) -> sp.Symbol:
        """The transform variable λ."""
        return lam

    @cached_property
    def characteristic_polynomial(self) -> sp.Poly:
        """det(λ²I + λB + A) = Δ(λ)/det(M): the monic form of the normalised system."""
        return self.determinant.monic()

    @cached_property
    def integer_characteristic_polynomial(self) -> sp.Poly:
        """Δ(λ) scaled to integer coefficients with content 1 and positive leading term.

        This is how the seed prints it (Example 2: 25λ⁴ + 10λ³ + 126λ² + 25λ + 100).
        For symbolic coefficients it is the monic :attr:`characteristic_polynomial`.
        """
        monic = self.characteristic_polynomial
        if not monic.domain.is_QQ:
            return monic
        _, integer = monic.clear_denoms(convert=True)
        return integer.primitive()[1]

    def pencil(self) -> sp.ImmutableMatrix:
        """The matrix λ²M + λC + K."""
        s = self.scene
        return sp.ImmutableMatrix(lam**2 * s.M + lam * s.C + s.K)

    def matrix(self) -> sp.ImmutableMatrix:
        """(λ²M + λC + K)⁻¹ = adj(λ)/Δ(λ), entry by entry."""
        delta = self.determinant.as_expr()
        return sp.ImmutableMatrix(self.adjugate.applyfunc(lambda e: sp.cancel(e / delta)))

    def normalized(self) -> sp.ImmutableMatrix:
        """The seed's R(λ) = (λ²I + λB + A)⁻¹ = adj(λ) M / Δ(λ)."""
        delta = self.determinant.as_expr()
        product = self.adjugate * self.scene.M
        return sp.ImmutableMatrix(product.applyfunc(lambda e: sp.cancel(sp.expand(e) / delta)))

    def initial_vector(self) -> sp.ImmutableMatrix:
        """r(λ) = M(λ x0 + v0) + C x0, the right-hand side the initial data give."""
        s = self.scene
        return sp.ImmutableMatrix((s.M * (lam * s.x0 + s.v0) + s.C * s.x0).applyfunc(sp.expand))

    def transform(self) -> sp.ImmutableMatrix:
        """X(λ), one rational function per coordinate (common factors cancelled)."""
        delta = self.determinant.as_expr()
        return sp.ImmutableMatrix([sp.cancel(N.as_expr() / delta) for N in self.numerators])


def _adjugate_and_determinant(P: sp.Matrix) -> tuple[sp.Matrix, sp.Expr]:
    """Fraction-free adjugate and determinant of a polynomial matrix."""
    if P.shape == (1, 1):
        return sp.Matrix([[1]]), P[0, 0]
    dM = DomainMatrix.from_Matrix(P)
    if dM.domain.is_EX:  # entries such as √2 or π: SymPy's adj_det over EX raises TypeError
        return (sp.Matrix(P).adjugate(method="berkowitz").applyfunc(sp.expand),
                sp.expand(P.det(method="berkowitz")))
    adj, det = dM.adj_det()
    return adj.to_Matrix(), dM.domain.to_sympy(det)


def resolvent(scene: Scene) -> Resolvent:
    """Exact resolvent of a scene.

    Parameters
    ----------
    scene : Scene
        Masses, damping, stiffness and initial data.

    Returns
    -------
    Resolvent
        Δ(λ), adj(λ) and the numerators of X(λ) = adj(λ) r(λ)/Δ(λ).

    Examples
    --------
    The seed's Example 2 (A = [[3, -1], [-2, 2]], B = 0.2 I):

    >>> from laplace_springs.model.scene import Scene
    >>> scene = Scene.from_normalized(A=[[3, -1], [-2, 2]], B=[["0.2", 0], [0, "0.2"]],
    ...                               x0=[1, 0], v0=[0, 0])
    >>> R = resolvent(scene)
    >>> R.integer_characteristic_polynomial.as_expr()
    25*lambda**4 + 10*lambda**3 + 126*lambda**2 + 25*lambda + 100
    >>> R.normalized()[0, 0]
    (25*lambda**2 + 5*lambda + 50)/(25*lambda**4 + 10*lambda**3 + 126*lambda**2 + 25*lambda + 100)
    """
    fast = _rational_resolvent(scene)
    if fast is not None:
        return fast
    P = lam**2 * scene.M + lam * scene.C + scene.K
    _check_expansion(P)
    adjugate, det = _adjugate_and_determinant(sp.Matrix(P))
    adjugate = adjugate.applyfunc(sp.expand)
    determinant = _poly(sp.expand(det))
    rhs = scene.M * (lam * scene.x0 + scene.v0) + scene.C * scene.x0
    numerators = tuple(_poly(sp.expand(e)) for e in adjugate * rhs)
    return Resolvent(scene, determinant, numerators, sp.ImmutableMatrix(adjugate))


def _check_expansion(P: sp.MatrixBase) -> None:
    """A LimitError, before anything is expanded, when det(P) and its adjugate could form
    more than Limits.max_resolvent_terms terms: the permanent of the entries' expanded
    sizes (Ryser's formula up to 12 coordinates, the product of the row sums beyond, which
    is larger) bounds the products of the Leibniz expansion."""
    n = P.rows
    sizes = [[expanded_size(P[i, j]) if P[i, j] != 0 else 0 for j in range(n)]
             for i in range(n)]
    most = limits().max_resolvent_terms
    bound = _permanent(sizes) if n <= 12 else math.prod(sum(row) for row in sizes)
    if bound > most:
        i, j = max(((i, j) for i in range(n) for j in range(n)), key=lambda ij: sizes[ij[0]][ij[1]])
        raise LimitError(
            f"the symbolic resolvent det(λ²M + λC + K) could expand to about {bound:.3g} terms, "
            f"more than Limits.max_resolvent_terms = {most:,} (its entry [{i},{j}] alone expands "
            f"to {sizes[i][j]:,} terms); give some parameters values, or solve with numbers")


def _permanent(sizes: list[list[int]]) -> int:
    """The permanent of a small non-negative integer matrix (Ryser's formula)."""
    n = len(sizes)
    total = 0
    for mask in range(1, 1 << n):
        columns = [j for j in range(n) if mask >> j & 1]
        product = 1
        for row in sizes:
            product *= sum(row[j] for j in columns)
            if not product:
                break
        total += product if (n - len(columns)) % 2 == 0 else -product
    return total


def _rational_resolvent(scene: Scene) -> Resolvent | None:
    """Δ and the N_i of a scene with rational M, C, K, x0, v0 by python-flint (solves at
    integer λ and interpolation, :mod:`laplace_springs.exact.rational`), the adjugate
    left for later; None for any other scene (or Δ ≡ 0)."""
    pencil = rational_pencil(scene)
    r = initial_vector(scene, pencil) if pencil is not None else None
    found = solve_at_integers(pencil, [r]) if pencil is not None and r is not None else None
    if found is None:
        return None
    delta, (numerators,) = found
    return Resolvent(scene, to_poly(delta, lam, domain=None),
                     tuple(to_poly(N, lam, domain=None) for N in numerators))
