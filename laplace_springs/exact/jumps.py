"""What happens at t = 0⁺ when M is singular: initial jumps of massless nodes.

A massless node (a zero diagonal entry of M) carries no inertia, so its row of
M x'' + C x' + K x = 0 is a constraint, not an equation of motion: a node joined only
by springs sits where the springs balance, a node with a dashpot obeys a first-order
law. Initial data that disagree with the constraint cannot be kept: the motion jumps
at t = 0⁺. The Laplace route handles this without special cases. The transform of the
distributional problem with data x(0⁻) = x0, x'(0⁻) = v0 is

    X(λ) = adj(λ)·[M(λ x0 + v0) + C x0] / Δ(λ),

the formula of :mod:`laplace_springs.exact.resolvent`, and its expansion at λ = ∞,

    X(λ) = P(λ) + x(0⁺)/λ + x'(0⁺)/λ² + O(λ⁻³),

gives the state just after the jump (initial value theorem) and, through the
polynomial part P(λ) = Σ p_k λ^k, any impulses Σ p_k δ^(k)(t) in x itself.

**Physics of the jump.** Writing y = x·H(t) + Σ p_k δ^(k) and matching the δ terms
of M y'' + C y' + K y = M(x0 δ' + v0 δ) + C x0 δ gives, as a polynomial identity,

    (λ²M + λC + K) P(λ) + λ M Δx + M Δv + C Δx = 0,    Δx = x(0⁺) − x0, Δv = x'(0⁺) − v0,

which without impulses says M Δx = 0 (massive positions are continuous) and
M Δv + C Δx = 0 (no impulse through the masses: their velocities are continuous,
and a node with an invertible dashpot block cannot jump). :func:`jump_residuals`
evaluates this identity; :meth:`Solution.verify` uses it.

**No impulses in physical scenes.** For symmetric positive semi-definite M, C, K
with Δ ≢ 0, X(λ) is strictly proper: pairing the transformed equation with X̄ for
large real λ bounds X in the M-, C- and K-seminorms, M + C + K is positive
definite, and on ker M ∩ ker C (which r(λ) is orthogonal to) K is definite, so
X(λ) → 0. Impulses (P ≠ 0) need non-symmetric or indefinite data; they are
reported, and x(t) is then the motion for t > 0.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import sympy as sp

from ..model.scene import Scene
from .resolvent import Resolvent

__all__ = ["InitialJump", "initial_jump", "jump_residuals", "laurent_at_infinity"]


def laurent_at_infinity(numerator: sp.Poly, denominator: sp.Poly,
                        count: int) -> tuple[sp.Poly, list[sp.Expr]]:
    """Polynomial part and the first ``count`` coefficients of N/D at λ = ∞.

    N/D = q(λ) + a_1/λ + a_2/λ² + ...; a_1 and a_2 are f(0⁺) and f'(0⁺) of the
    inverse transform f of the proper part (the initial value theorem).

    Parameters
    ----------
    numerator, denominator : sympy.Poly
        Polynomials in the same variable; the denominator nonzero.
    count : int
        How many coefficients a_1, ..., a_count to return.

    Returns
    -------
    (sympy.Poly, list)
        q(λ) and [a_1, ..., a_count] (exact).

    Examples
    --------
    >>> import sympy as sp
    >>> s = sp.Symbol("s")
    >>> q, a = laurent_at_infinity(sp.Poly(s**3 + 2, s), sp.Poly(s**2 + 1, s), 2)
    >>> q.as_expr(), a
    (s, [-1, 2])
    """
    field = numerator.domain.unify(denominator.domain).get_field()
    quotient, remainder = numerator.set_domain(field).div(denominator.set_domain(field))
    d = denominator.degree()
    to_sympy = field.to_sympy
    delta = [to_sympy(denominator.nth(j)) for j in range(d + 1)]
    r = [to_sympy(remainder.nth(j)) if not remainder.is_zero else sp.S.Zero for j in range(d)]
    coefficients: list[sp.Expr] = []
    for k in range(1, count + 1):
        # r_{d-k} = Σ_{j=1..k} a_j δ_{d-k+j}  (coefficient of λ^{d-k} in D·Σ a_j λ^{-j})
        known = r[d - k] if d - k >= 0 else sp.S.Zero
        known -= sum((coefficients[j - 1] * delta[d - k + j] for j in range(1, k)), sp.S.Zero)
        coefficients.append(sp.cancel(known / delta[d]))
    return quotient, coefficients


@dataclass(frozen=True)
class InitialJump:
    """The state just after t = 0 and what jumped (all zero when M is invertible).

    Attributes
    ----------
    x_plus, v_plus : sympy.ImmutableMatrix
        x(0⁺) and x'(0⁺), n x 1, exact: where the closed form :attr:`Solution.x` starts.
    position, velocity : sympy.ImmutableMatrix
        The jumps x(0⁺) − x0 and x'(0⁺) − v0.
    impulses : sympy.ImmutableMatrix
        n x p: x_i contains Σ_k impulses[i, k]·δ^(k)(t) at t = 0 (p = 0, no columns,
        for every physical scene; see the module notes).
    """

    x_plus: sp.ImmutableMatrix
    v_plus: sp.ImmutableMatrix
    position: sp.ImmutableMatrix
    velocity: sp.ImmutableMatrix
    impulses: sp.ImmutableMatrix

    @property
    def is_continuous(self) -> bool:
        """True when the initial data are kept: no jump and no impulse."""
        return (self.impulses.cols == 0 and all(e == 0 for e in self.position)
                and all(e == 0 for e in self.velocity))


def _impulse_matrix(quotients: Sequence[sp.Poly], n: int) -> sp.ImmutableMatrix:
    width = max((q.degree() + 1 for q in quotients if not q.is_zero), default=0)
    rows = [[q.domain.to_sympy(q.nth(k)) if not q.is_zero else sp.S.Zero for k in range(width)]
            for q in quotients]
    return sp.ImmutableMatrix(n, width, [e for row in rows for e in row])


def initial_jump(resolvent: Resolvent, numerators: Sequence[sp.Poly] | None = None,
                 denominator: sp.Poly | None = None) -> InitialJump:
    """x(0⁺), x'(0⁺), the jumps and any impulses, from X(λ) = N_i(λ)/Δ(λ) at λ = ∞.

    ``numerators`` and ``denominator`` replace the resolvent's free-response X(λ) when
    inputs act from t = 0 (the transform of everything switched on at t = 0: a step
    force moves a spring-only massless node at once, an impulse can put δ into x).

    Examples
    --------
    A massless node between a wall spring (3) and a spring (2) to a unit mass: it
    starts where the springs balance, x1(0⁺) = 2·x2(0)/(3 + 2), whatever x1(0) says.

    >>> from laplace_springs.model.scene import Scene
    >>> from laplace_springs.exact.resolvent import resolvent
    >>> scene = Scene.from_matrices(M=[[0, 0], [0, 1]], K=[[5, -2], [-2, 2]],
    ...                             x0=[1, 5], v0=[0, 0])
    >>> jump = initial_jump(resolvent(scene))
    >>> jump.x_plus.T, jump.position.T, jump.is_continuous
    (Matrix([[2, 5]]), Matrix([[1, 0]]), False)
    """
    scene = resolvent.scene
    numerators = resolvent.numerators if numerators is None else numerators
    denominator = resolvent.determinant if denominator is None else denominator
    expansions = [laurent_at_infinity(N, denominator, 2) for N in numerators]
    x_plus = sp.ImmutableMatrix([a[0] for _, a in expansions])
    v_plus = sp.ImmutableMatrix([a[1] for _, a in expansions])
    return InitialJump(
        x_plus=x_plus,
        v_plus=v_plus,
        position=sp.ImmutableMatrix((x_plus - scene.x0).applyfunc(sp.cancel)),
        velocity=sp.ImmutableMatrix((v_plus - scene.v0).applyfunc(sp.cancel)),
        impulses=_impulse_matrix([q for q, _ in expansions], scene.n),
    )


def jump_residuals(scene: Scene, position, velocity, impulses=None, load=None) -> list[sp.Expr]:
    """Coefficients of (λ²M + λC + K)P(λ) + λ M Δx + M Δv + C Δx − J(λ); zero for the true jump.

    Parameters
    ----------
    scene : Scene
    position, velocity : column matrices
        Δx = x(0⁺) − x0 and Δv = x'(0⁺) − v0 of a candidate solution.
    impulses : matrix, optional
        n x p coefficients of δ^(k) in x (none by default).
    load : matrix, optional
        n x q coefficients J_k of δ^(k)(t) in the forcing (impulsive inputs at t = 0;
        J(λ) = Σ J_k λ^k is the polynomial part of the input's transform).

    Returns
    -------
    list of sympy expressions
        All zero when the jump obeys the momentum balance at t = 0 (see the module
        notes). Where a massless node then sits is fixed by its constraint row, part of
        the equations for t > 0 and checked with them at t = 0⁺.

    Examples
    --------
    A massless node (coordinate 0) may jump; the unit mass (coordinate 1) may not:

    >>> from laplace_springs.model.scene import Scene
    >>> scene = Scene.from_matrices(M=[[0, 0], [0, 1]], K=[[5, -2], [-2, 2]],
    ...                             x0=[1, 5], v0=[0, 0])
    >>> jump_residuals(scene, [-3, 0], [0, 0])
    [0, 0, 0, 0]
    >>> jump_residuals(scene, [0, 1], [0, 0])
    [0, 0, 0, 1]
    """
    s = scene
    dx, dv = sp.Matrix(list(position)), sp.Matrix(list(velocity))
    at_zero = s.M * dv + s.C * dx
    at_one = s.M * dx
    impulses = sp.zeros(s.n, 0) if impulses is None else sp.Matrix(impulses)
    load = sp.zeros(s.n, 0) if load is None else sp.Matrix(load)
    if not impulses.cols and not load.cols:
        return list(at_zero) + list(at_one)
    lam = sp.Dummy("lambda")
    P = sum((impulses[:, k] * lam**k for k in range(impulses.cols)), sp.zeros(s.n, 1))
    J = sum((load[:, k] * lam**k for k in range(load.cols)), sp.zeros(s.n, 1))
    total = (lam**2 * s.M + lam * s.C + s.K) * P + lam * at_one + at_zero - J
    width = max(impulses.cols + 2, load.cols, 2)
    return [sp.Poly(sp.expand(e), lam).nth(k) for e in total for k in range(width)]
