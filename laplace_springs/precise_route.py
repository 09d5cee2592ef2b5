"""Precise numeric route: the modal decomposition in ball arithmetic, for stiff scenes.

The float64 route (:mod:`laplace_springs.numeric_route`) loses digits when the scales of
a scene span many decades (stiffness ratios of 1e8, mass ratios of 1e-6): its
eigenvectors are only as good as ε times their condition numbers. It knows this and says
so through its error estimate. This route is what "auto" does next for large scenes:

1. The first-order matrix Z and state y₀ are built from the exact scene data in
   python-flint ``arb`` balls (massless nodes held by dashpots included, as in
   :func:`~laplace_springs.numeric_route.certified_motion`).
2. ``acb_mat.eig(left=True, right=True)`` gives certified enclosures of every eigenvalue
   λₖ and of the left and right eigenvector matrices L ≈ R⁻¹. The weights are
   wₖ = R[:n, k]·(L y₀)ₖ, so x(t) = Re Σₖ wₖ e^{λₖ t}.
3. Evaluation is one ball product W·E with Eₖⱼ = λₖᵖ e^{λₖ tⱼ}; the float64 result is the
   ball's midpoint and the returned error its radius plus the final rounding. When the
   radius exceeds 1e-17 of max |x|, the decomposition is recomputed at twice the bits.

Flint isolates eigenvalues only when they are simple. Rigid-body motions (directions r
with K r = C r = 0, e.g. a free–free chain) give the double eigenvalue 0; they are split
off exactly first: with Nₗ the left null vectors of K and C, Nₗᵀ M x(t) = Nₗᵀ M (x₀ + v₀ t)
fixes the rigid part, and the rest moves in the complement Q = ker(Nₗᵀ M) as the smaller
scene (QᵀMQ, QᵀCQ, QᵀKQ). Other repeated eigenvalues (symmetric frequencies, critical
damping) make :func:`decompose_precise` return ``None``; "auto" then falls back as
:func:`laplace_springs.solve` documents.

Measured (2 cores): a 20-mass chain with alternating springs 1 and 1e8 is solved and
evaluated at 50 times in about 0.2 s with error 1e-16, where float64 gives 1.3e-7; the
eigen-decomposition of a 50-mass chain takes 0.6 s at 128 bits.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import sympy as sp

from .numeric_route import Block, Modes, NumericSolution, _arb_first_order, _arb_matrix

if TYPE_CHECKING:
    from .scene import Scene

__all__ = ["PreciseModes", "decompose_precise", "solve_precise"]

#: Relative radius (to max |x|) above which the evaluation recomputes at twice the bits.
TARGET = 1e-17
#: Highest working precision (bits) for evaluation.
MAX_BITS = 4096
#: Largest first-order size this route attempts (ball eigen-decomposition is O(N³)).
MAX_ORDER = 200


@dataclass(frozen=True, eq=False)
class _Split:
    """x(t) = lift·q(t) + offset + slope·t, q the motion of the scene ``inner`` (exact)."""

    inner: Scene
    lift: sp.Matrix
    offset: sp.Matrix
    slope: sp.Matrix


@dataclass(frozen=True, eq=False)
class _Balls:
    """The decomposition at one precision: eigenvalues, weights and rigid part as balls."""

    bits: int
    rates: list
    weights: object  # acb_mat, n x N
    affine: tuple | None = None  # (offset, slope) as n x 1 arb_mat, for a split scene


def _nullspace(rows: sp.Matrix) -> sp.Matrix:
    """An exact basis (columns) of {y : rows·y = 0}, by python-flint's integer nullspace."""
    from flint import fmpz_mat

    integer = []
    for i in range(rows.rows):
        scale = sp.ilcm(*[sp.Rational(e).q for e in rows.row(i)], 1)
        integer.append([int(e * scale) for e in rows.row(i)])
    basis, rank = fmpz_mat(integer).nullspace()
    return sp.Matrix([[int(basis[i, j]) for j in range(rank)] for i in range(rows.cols)])


def rigid_split(scene: Scene) -> _Split | None:
    """Split off the rigid-body motion (K r = C r = 0) exactly; None if there is none.

    Also None for massless nodes, symbolic or non-rational entries, or when the
    complement's mass matrix is singular (then the split would not be a scene).

    Examples
    --------
    Two free masses joined by a spring: the centre of mass drifts at the mean velocity.

    >>> from laplace_springs import Scene
    >>> split = rigid_split(Scene.from_matrices(M=[[1, 0], [0, 1]], K=[[1, -1], [-1, 1]],
    ...                                         x0=[1, 0], v0=[0, 2]))
    >>> split.offset.T, split.slope.T, split.inner.M
    (Matrix([[1/2, 1/2]]), Matrix([[1, 1]]), Matrix([[2]]))
    """
    matrices = (scene.M, scene.C, scene.K, scene.x0, scene.v0)
    if any(not e.is_Rational for m in matrices for e in m) or scene.M.det() == 0:
        return None
    right = _nullspace(scene.K.col_join(scene.C))
    if right.cols == 0:
        return None
    left = _nullspace(scene.K.T.col_join(scene.C.T))
    lift = _nullspace(left.T * scene.M)
    fixed = left.T * scene.M * right
    if left.cols != right.cols or fixed.det() == 0 or lift.cols == 0:
        return None
    inner_mass = lift.T * scene.M * lift
    if inner_mass.det() == 0:
        return None
    solve = fixed.inv() * left.T * scene.M
    offset, slope = right * solve * scene.x0, right * solve * scene.v0
    pseudo = (lift.T * lift).inv() * lift.T
    q0, dq0 = pseudo * (scene.x0 - offset), pseudo * (scene.v0 - slope)
    if lift * q0 != scene.x0 - offset or lift * dq0 != scene.v0 - slope:
        return None
    from .scene import Scene as _Scene

    inner = _Scene.from_matrices(M=inner_mass, C=lift.T * scene.C * lift, K=lift.T * scene.K * lift,
                                 x0=list(q0), v0=list(dq0))
    return _Split(inner, lift, offset, slope)


@dataclass(frozen=True, eq=False)
class PreciseModes(Modes):
    """:class:`~laplace_springs.numeric_route.Modes` whose values come from ball arithmetic.

    The float fields (rates, weights, ...) are the balls' midpoints, for display and the
    closed form; :meth:`values` and :meth:`error_estimate` use the balls themselves.
    """

    scene: Scene | None = None
    balls: list = field(default_factory=list)
    split: _Split | None = None

    def _decomposition(self, bits: int) -> _Balls | None:
        for known in self.balls:
            if known.bits == bits:
                return known
        found = _balls(self.scene, self.split, bits)
        if found is not None:
            self.balls.append(found)
        return found

    def values_and_errors(self, times: np.ndarray, order: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """d^order x/dt^order at the times and a bound on its error, float64.

        Recomputed at twice the bits (up to :data:`MAX_BITS`) while the balls' radii
        exceed :data:`TARGET` times max |x|; the bound returned is always the radius.
        """
        times = np.asarray(times, dtype=float)
        bits, best = self.balls[0].bits, None
        while bits <= MAX_BITS:
            balls = self._decomposition(bits)
            if balls is not None:
                best = _evaluate(balls, times, order)
                scale = float(np.max(np.abs(best[0]), initial=0.0))
                if np.all(np.isfinite(best[1])) and float(np.max(best[1], initial=0.0)) <= TARGET * scale:
                    break
            bits *= 2
        mid, rad = best
        return mid, rad + np.abs(mid) * 2.0**-53

    def values(self, times: np.ndarray, order: int = 0) -> np.ndarray:
        return self.values_and_errors(times, order)[0]

    def error_estimate(self, times: np.ndarray) -> np.ndarray:
        """A certified bound: the balls' radii plus the rounding to float64."""
        return self.values_and_errors(times)[1]


def _balls(scene: Scene, split: _Split | None, bits: int) -> _Balls | None:
    """Eigenvalues and weights at ``bits``, or None if flint cannot isolate the eigenvalues."""
    from flint import acb_mat, ctx

    moving = split.inner if split is not None else scene
    n, digits = moving.n, int(bits / 3.33) + 10
    with ctx.workprec(bits):
        Z, y0 = _arb_first_order(moving, digits)
        try:
            rates, L, R = acb_mat(Z).eig(left=True, right=True)
        except ValueError:
            return None
        c = L * acb_mat(y0)
        size = len(rates)
        weights = acb_mat(n, size, [R[i, k] * c[k, 0] for i in range(n) for k in range(size)])
        if split is None:
            return _Balls(bits, list(rates), weights)
        lift, offset, slope = (acb_mat(_arb_matrix(m, digits)) for m in (split.lift, split.offset, split.slope))
        return _Balls(bits, list(rates), lift * weights, (offset, slope))


def _evaluate(balls: _Balls, times: np.ndarray, order: int) -> tuple[np.ndarray, np.ndarray]:
    """Midpoints and radii of Re W·E, E[k, j] = λₖ^order e^{λₖ tⱼ}, as float arrays."""
    from flint import acb, acb_mat, arb, ctx

    n, size = balls.weights.nrows(), len(balls.rates)
    with ctx.workprec(balls.bits):
        stamps = [arb(float(tv)) for tv in times]  # floats are read by their binary value
        entries = [(rate**order) * (rate * acb(tv)).exp() for rate in balls.rates for tv in stamps]
        values = balls.weights * acb_mat(size, len(times), entries)
        if balls.affine is not None and order <= 1:
            offset, slope = balls.affine
            ramp = [stamp if order == 0 else arb(1) for stamp in stamps]
            values = values + slope * acb_mat(1, len(times), ramp)
            if order == 0:
                values = values + offset * acb_mat(1, len(times), [1] * len(times))
        parts = [values[i, j].real for i in range(n) for j in range(len(times))]
    mid = np.array([float(p.mid()) for p in parts]).reshape(n, len(times))
    rad = np.array([float(p.rad()) for p in parts]).reshape(n, len(times))
    return mid, rad


def decompose_precise(scene: Scene, *, bits: int = 128, max_bits: int = 1024) -> PreciseModes | None:
    """The modal decomposition in ball arithmetic, or None if eigenvalues are not simple.

    The precision is doubled from ``bits`` up to ``max_bits`` while flint cannot isolate
    the eigenvalues; truly repeated ones never separate, and then the answer is None.

    Examples
    --------
    Two masses whose springs differ by eight decades:

    >>> from laplace_springs import Scene
    >>> scene = Scene.from_matrices(M=[[1, 0], [0, 1]], K=[[100000001, -100000000],
    ...     [-100000000, 100000000]], x0=[1, 0], v0=[0, 0])
    >>> modes = decompose_precise(scene)
    >>> modes.values(np.array([0.0, 1.0])).round(12) + 0.0
    array([[1.        , 0.50687933],
           [0.        , 0.25336527]])
    >>> decompose_precise(Scene.from_matrices(M=[[1]], C=[[2]], K=[[1]], x0=[1], v0=[0])) is None
    True
    """
    if 2 * scene.n > MAX_ORDER:
        return None
    split = rigid_split(scene)
    while bits <= max_bits:
        balls = _balls(scene, split, bits)
        if balls is not None:
            return _modes_of(scene, split, balls)
        bits *= 2
    return None


def _modes_of(scene: Scene, split: _Split | None, balls: _Balls) -> PreciseModes:
    from flint import ctx

    with ctx.workprec(balls.bits):
        rates = np.array([complex(r.real.mid(), r.imag.mid()) for r in balls.rates])
        radii = np.array([float(abs(r).rad()) for r in balls.rates])
        weights = np.array([[complex(balls.weights[i, k].real.mid(), balls.weights[i, k].imag.mid())
                             for k in range(len(rates))] for i in range(scene.n)])
    norm = float(np.max(np.abs(rates), initial=0.0))
    blocks = () if split is None else (_rigid_block(split),)
    return PreciseModes(rates, weights, np.ones(len(rates)), radii, blocks, norm,
                        np.zeros_like(weights, dtype=float), (), scene=scene, balls=[balls], split=split)


def _rigid_block(split: _Split) -> Block:
    """offset + slope·t as F e^{Tt} c with T = [[0, 1], [0, 0]], c = (0, 1): poles 0, 0."""
    F = np.array([[float(a), float(b)] for a, b in zip(split.slope, split.offset)], dtype=complex)
    return Block(np.array([[0, 1], [0, 0]], dtype=complex), F, np.array([0, 1], dtype=complex), 1.0)


def solve_precise(scene: Scene, *, reason: str) -> NumericSolution | None:
    """The scene solved by :func:`decompose_precise`, or None (see there).

    The result is a :class:`~laplace_springs.numeric_route.NumericSolution` (method
    ``"numeric"``) whose evaluation is certified to about 1e-17 of max |x|.

    Examples
    --------
    >>> from laplace_springs import Scene
    >>> scene = Scene.from_matrices(M=[[1, 0], [0, "1/1000000"]], K=[[2, -1], [-1, 2]],
    ...                             x0=[1, 0], v0=[0, 0])
    >>> sol = solve_precise(scene, reason="example")
    >>> values, errors = sol.evaluate([0.0, 1.0], return_error=True)
    >>> bool(errors.max() < 1e-15)
    True
    """
    modes = decompose_precise(scene)
    return None if modes is None else NumericSolution(scene, modes, reason)
