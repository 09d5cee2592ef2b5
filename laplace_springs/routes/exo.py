"""Formula and periodic forces on scenes too large for exact partial fractions: the input's
own dynamics (an exosystem) joined to the scene, solved by the numeric engines.

Each forcing entry has the exact transform F(s) = Σ_τ e^{-sτ} R_τ(s) (and, for periodic
inputs, Σ_τ e^{-sτ} R_τ(s)/(1 − e^{-sT})) with rational R_τ = d + P/Q, deg P < deg Q
(:func:`~laplace_springs.model.forcing.input_transform`). P/Q is the impulse response of
w' = S w, f = cᵀw, w(0) = e_q with S the companion matrix of the monic Q and c the
coefficients of P; the constant d is an impulse (a jump d·M⁻¹e_i of the velocity). The
state w joins the scene as q massless nodes held by unit dashpots (rows C = I, K = −S)
that push on coordinate i through K[i, node] = −c: an unforced scene whose motion is the
forced one, served by the numeric engines of the planner with their own bounds.

Where the split of :mod:`laplace_springs.routes.exo_split` applies (rational entries,
blocks of degree ≤ 2, no resonance) a piece is instead a particular motion Πw plus a free
motion for the free-motion engines, which is faster and better conditioned; the augmented
scene serves the rest.

One piece is built per switching time τ (and per periodic part): the one of
τ = 0 carries the initial data, the others start from rest and are evaluated at t − τ
for t ≥ τ (periodic parts at t − τ − kT for every period k with τ + kT ≤ t), and the
values and bounds of the pieces are summed. Times are shifted exactly (rational τ and
T, the float time's exact value).

The contract's floor is S₀ plus the static displacement of the largest force met at a few
sample times, |f|·max|M⁻¹|/ρ², as for sampled forces.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from fractions import Fraction
from functools import cached_property
from typing import Any

import numpy as np
import sympy as sp

from ..kernels.precision import workdps
from ..limits import limits
from ..model.errors import FloatRangeError, LimitError, SceneError
from ..model.forcing import input_transform
from ..model.scene import Scene
from ..model.symbols import TIME
from ..numeric.first_order import massless_nodes, scene_arrays, scene_entries
from ..numeric.times import Times
from ..planning.execute import Evaluator
from ..solution import Solution, Verification
from .exo_split import SplitPiece, impulse_jump, split_piece

__all__ = ["ExoSolution", "solve_exo", "exo_refusal"]

_S = sp.Symbol("s")
#: Sample times at which the forces are read for the contract's floor.
_FORCE_SAMPLES = ("0", "0.37", "1.3", "4.1", "9.7")


@dataclass(frozen=True)
class _Input:
    """One rational part on one coordinate: impulse d, numerator c (deg < q), monic Q."""

    row: int
    impulse: sp.Expr
    numerator: tuple[sp.Expr, ...]   # c_0 .. c_{q-1}
    denominator: tuple[sp.Expr, ...]  # a_0 .. a_{q-1} of s^q + a_{q-1}s^{q-1} + ... + a_0


@dataclass(frozen=True)
class _Piece:
    """A piece switched on at ``delay`` (repeated every ``period`` if given)."""

    delay: Fraction
    period: Fraction | None
    impulsive: bool = False   # an impulse starts it (its velocity jumps at the switch)
    at_rest: bool = True      # it starts from rest (every piece but the initial data's)


def _rational_part(R: sp.Expr, row: int, entry: str) -> _Input:
    num, den = sp.fraction(sp.together(R))
    P, Q = sp.Poly(num, _S, domain="EX"), sp.Poly(den, _S, domain="EX")
    lead = Q.LC()
    P, Q = P.mul_ground(1 / lead), Q.mul_ground(1 / lead)
    quotient, remainder = sp.div(P, Q, _S)
    if quotient.degree() > 0:
        raise SceneError(f"{entry}: derivatives of impulses (DiracDelta') are not supported "
                         "by the numeric forced route")
    q = Q.degree()
    coefficients = list(reversed(remainder.all_coeffs())) if not remainder.is_zero else []
    coefficients += [sp.Integer(0)] * (q - len(coefficients))
    low = list(reversed(Q.all_coeffs()))[:q]
    return _Input(row, quotient.as_expr(), tuple(coefficients), tuple(low))


def _exact_fraction(value: sp.Expr, entry: str) -> Fraction:
    value = sp.nsimplify(value) if not value.is_Rational else value
    if not value.is_Rational:
        raise SceneError(f"{entry}: the switching time or period {value} must be a rational "
                         "number for the numeric forced route")
    return Fraction(int(value.p), int(value.q))


def _inputs(scene: Scene) -> dict[tuple[Fraction, Fraction | None], list[_Input]]:
    """(delay, period or None) -> the rational parts switched on there."""
    groups: dict[tuple[Fraction, Fraction | None], list[_Input]] = {(Fraction(0), None): []}
    for row, f in enumerate(scene.forcing or ()):
        if f == 0:
            continue
        entry = f"forcing[{row}]"
        transform = input_transform(f, entry, _S)
        if transform.conditions:
            raise SceneError(f"{entry}: symbolic switching times need the exact route")
        for tau, R in transform.parts:
            key: tuple[Fraction, Fraction | None] = (_exact_fraction(tau, entry), None)
            groups.setdefault(key, []).append(_rational_part(R, row, entry))
        if transform.periodic:
            period = _exact_fraction(transform.period, entry)
            for tau, R in transform.periodic:
                key = (_exact_fraction(tau, entry), period)
                groups.setdefault(key, []).append(_rational_part(R, row, entry))
    return groups


def _augmented(scene: Scene, inputs: list[_Input], start: bool, scale: sp.Expr) -> Scene:
    """The scene with the exosystems of ``inputs`` as massless nodes; the scene's own
    initial data when ``start``, else rest. The exosystem's state starts at ``scale``
    (a power of two near the static displacement of the forces) and pushes through
    −c/scale, so the engines' bounds, relative to the whole state, are relative to the
    displacements the forces cause."""
    n = scene.n
    size = n + sum(len(part.denominator) for part in inputs)
    M: dict[tuple[int, int], Any] = {}
    C: dict[tuple[int, int], Any] = {}
    K: dict[tuple[int, int], Any] = {}
    for name, target in (("M", M), ("C", C), ("K", K)):
        target.update(scene_entries(scene, name))
    x0 = [scene.x0[i] if start else 0 for i in range(n)] + [0] * (size - n)
    v0 = [scene.v0[i] if start else 0 for i in range(n)] + [0] * (size - n)
    impulses = [(part.row, part.impulse) for part in inputs if part.impulse != 0]
    if impulses:
        v0[:n] = [v + j for v, j in zip(v0[:n], _impulse_jump(scene, impulses))]
    node = n
    for part in inputs:
        q = len(part.denominator)
        for k in range(q):
            C[node + k, node + k] = sp.Integer(1)
            if k + 1 < q:   # w_k' = w_{k+1}
                K[node + k, node + k + 1] = sp.Integer(-1)
            K[node + q - 1, node + k] = K.get((node + q - 1, node + k), 0) + part.denominator[k]
            if part.numerator[k] != 0:
                K[part.row, node + k] = K.get((part.row, node + k), 0) - part.numerator[k] / scale
        if q:
            x0[node + q - 1] = scale
        node += q
    _balance(n, (M, C, K))
    def matrix(entries: dict[tuple[int, int], Any]) -> sp.SparseMatrix:
        return sp.SparseMatrix(size, size, {key: v for key, v in entries.items() if v != 0})
    return Scene.from_matrices(M=matrix(M), C=matrix(C), K=matrix(K), x0=x0, v0=v0,
                               title=scene.title)


def _balance(n: int, matrices: tuple[dict[tuple[int, int], Any], ...]) -> None:
    """Scale the scene's n equations (rows of M, C, K) by one power of two, in place, where
    their entries reach beyond 2^±900: the motion is the same, and springs of 1e300 on
    masses of 1e100 (2e300 in K) fit the joined scene's float64 range."""
    sizes = [abs(v) for matrix in matrices for (i, _), v in matrix.items() if i < n and v != 0]
    if not sizes:
        return
    top, bottom = (math.log2(float(v)) if v.is_Rational else math.log2(abs(complex(v)))
                   for v in (max(sizes), min(sizes)))
    if bottom >= -900 and top <= 900:
        return
    factor = sp.Integer(2) ** -int(round((top + bottom) / 2))
    for matrix in matrices:
        for key in [key for key in matrix if key[0] < n]:
            matrix[key] = matrix[key] * factor


def _impulse_jump(scene: Scene, impulses: list[tuple[int, Any]]) -> list[Any]:
    """The velocity jump M⁻¹·(impulses); a SceneError for an impulse on a massless node."""
    massless = set(massless_nodes(scene))
    for row, _ in impulses:
        if row in massless:
            raise SceneError(f"forcing[{row}]: an impulse on a massless node is not supported "
                             "by the numeric forced route")
    return impulse_jump(scene, impulses)


def _force_size(scene: Scene) -> float:
    """The largest |f_i(t)| met at a few sample times."""
    force = 0.0
    for f in scene.forcing or ():
        if f != 0:
            for sample in _FORCE_SAMPLES:
                try:
                    force = max(force, abs(complex(sp.N(f.subs(TIME, sp.Rational(sample))))))
                except TypeError:  # an impulse's DiracDelta(0) has no value
                    continue
    return force


def _state_scale(scene: Scene) -> sp.Expr:
    """A power of two near |f|/k, the static displacement of the forces (k the largest
    |K_ii|), for the exosystems' initial state."""
    _, _, K, _, _ = scene_arrays(scene)
    stiff = float(np.max(np.abs(np.diag(K)), initial=0.0))
    size = _force_size(scene) / stiff if stiff > 0 else 1.0
    if not (0 < size < np.inf):
        return sp.Integer(1)
    # within 2^±900: a scene entry (x0 of the state) of float64's range
    return sp.Integer(2) ** min(max(int(round(math.log2(size))), -900), 900)


def _piece_values(solution: Solution, times: list[Fraction], order: int,
                  target: float) -> tuple[np.ndarray, np.ndarray]:
    """A piece's values and bounds at ``times`` for ``target``; where its bound misses the
    piece's refusal bound, its plan's values for a coarse target (the sum's bound is judged
    by the caller), and NaN with an infinite bound where it has none."""
    for goal in (target, 0.5):
        try:
            found: tuple[np.ndarray, np.ndarray] = solution.evaluate(
                times, derivative=order, target=goal, return_error=True, progress=False)
            return found
        except LimitError:
            continue
    shape = (solution.scene.n, len(times))
    return np.full(shape, np.nan), np.full(shape, np.inf)


def exo_refusal(scene: Scene) -> str | None:
    """Why the numeric forced route cannot take ``scene`` (None when it can)."""
    if scene.free_symbols:
        return "the scene has symbols"
    if scene.sampled is not None:
        return "sampled forces take the sampled route"
    if not scene.is_forced:
        return "the scene is not forced"
    return None


def solve_exo(scene: Scene, solver: Callable[..., Solution], *, target: float | None = None,
              reason: str = "") -> ExoSolution:
    """Solve a forced numeric scene through the exosystems of its inputs; ``solver``
    (:func:`laplace_springs.solve`) solves each augmented, unforced scene.

    Examples
    --------
    x'' + 4x = cos(t) from rest: x = (cos t − cos 2t)/3.

    >>> import laplace_springs as ls
    >>> scene = ls.Scene.from_matrices(M=[[1]], K=[[4]], x0=[0], v0=[0], forcing=["cos(t)"])
    >>> sol = solve_exo(scene, ls.solve)
    >>> value = float(sol.evaluate([2.0])[0, 0])
    >>> bool(abs(value - (np.cos(2.0) - np.cos(4.0)) / 3) < 1e-14)
    True
    """
    why = exo_refusal(scene)
    if why is not None:
        raise SceneError(f"the numeric forced route cannot take this scene: {why}")
    pieces = []
    for (delay, period), inputs in sorted(_inputs(scene).items(),
                                          key=lambda item: (item[0][1] is not None, item[0][0])):
        start = delay == 0 and period is None
        if not inputs and not start:
            continue
        pieces.append((_Piece(delay, period, any(part.impulse != 0 for part in inputs),
                              not start), inputs))
    solved = [(piece, _solve_piece(scene, piece, inputs, solver, target))
              for piece, inputs in pieces]
    method = solved[0][1].method
    split = sum(isinstance(found, SplitPiece) for _, found in solved)
    text = reason or (f"the inputs' own dynamics, {len(solved)} piece"
                      f"{'s' if len(solved) != 1 else ''} ({split} split into a particular and a "
                      f"free motion, {len(solved) - split} joined to the scene); the first by "
                      f"the {method} engine")
    return ExoSolution(scene, solved, reason=text, target=target)


def _solve_piece(scene: Scene, piece: _Piece, inputs: list[_Input],
                 solver: Callable[..., Solution], target: float | None) -> Any:
    """The split into a particular and a free motion where it is exact
    (:mod:`laplace_springs.routes.exo_split`), else the augmented scene solved."""
    start = not piece.at_rest
    split = split_piece(scene, [(p.row, p.numerator, p.denominator) for p in inputs
                                if p.denominator],
                        [(p.row, p.impulse) for p in inputs if p.impulse != 0], start,
                        solver, target)
    if split is not None:
        return split
    try:
        augmented = _augmented(scene, inputs, start, _state_scale(scene))
    except SceneError as exc:  # its entries are the scene's and c/scale: a scale float64 misses
        raise FloatRangeError(f"the scene joined to its inputs' exosystems has an entry beyond "
                              f"float64's range: {exc}") from None
    return solver(augmented, target=target)


class ExoSolution(Solution):
    """Motion of a forced scene as the sum of its pieces (see the module notes): each a
    particular plus a free motion, or an augmented unforced scene. ``method`` is the first
    piece's engine + ``"+exo"``; ``x`` has no closed form here (use ``method='exact'`` on
    scenes small enough)."""

    _planned = False

    def __init__(self, scene: Scene, pieces: list[tuple[_Piece, Solution]], *, reason: str,
                 target: float | None = None) -> None:
        super().__init__(scene, reason=reason, target=target)
        self.pieces_solved = pieces

    @property
    def method(self) -> str:  # type: ignore[override]
        return f"{self.pieces_solved[0][1].method}+exo"

    @property
    def x(self) -> sp.ImmutableMatrix:
        raise SceneError("the numeric forced route gives values, not a closed form (the "
                         "solution's reason says why the exact route did not serve); "
                         "ls.solve(scene, method='exact') gives x(t) where that route can: "
                         "scenes small enough (Limits.max_exact_factor_degree) whose factors "
                         "have rational coefficients or degree <= 2")

    @property
    def poles(self) -> np.ndarray:
        return self.pieces_solved[0][1].poles

    @property
    def _spectral_radius(self) -> float:
        return float(self.pieces_solved[0][1]._spectral_radius)

    @cached_property
    def _base_floor(self) -> float:
        """S₀ plus the static displacement of the largest force met at a few times."""
        M = scene_arrays(self.scene)[0]
        force = _force_size(self.scene)
        rho = self._spectral_radius
        inverse = float(np.max(np.abs(np.linalg.pinv(M)))) if M.size else 0.0
        # in two quotients: ρ² and |f|·max|M⁻¹| alone may overflow (m = 1e-300, c = 1)
        return super()._base_floor + ((force / rho) * (inverse / rho) if rho > 1e-150 else 0.0)

    def _own_engines(self) -> dict[str, Evaluator]:
        return {self.method: self._sum}

    def _float(self, times: Times, order: int) -> tuple[np.ndarray, np.ndarray]:
        return self._sum(times, order, self.target)

    @cached_property
    def _start(self) -> tuple[np.ndarray, np.ndarray]:
        """x(0) and x'(0+) = v0 plus M⁻¹ times the impulses at t = 0 (exact, rounded once)."""
        v0 = [sp.Rational(v) for v in self.scene.v0]
        impulses = [(p.row, p.impulse) for p in _inputs(self.scene)[(Fraction(0), None)]
                    if p.impulse != 0]
        if impulses:
            v0 = [v + j for v, j in zip(v0, impulse_jump(self.scene, impulses))]
        return (np.array([float(v) for v in self.scene.x0]), np.array([float(v) for v in v0]))

    def _escalate(self, times: Times, order: int, target: float) -> tuple[np.ndarray, np.ndarray]:
        return self._sum(times, order, target)  # each piece escalates through its own plan

    def _sum(self, times: Times, order: int, target: float) -> tuple[np.ndarray, np.ndarray]:
        n = self.scene.n
        values = np.zeros((n, len(times)))
        bounds = np.zeros_like(values)
        exact = [Fraction(times.exact(i)) for i in range(len(times))]
        start = [i for i, t in enumerate(exact) if t == 0]
        if start and order < 2:  # x(0) = x0 and x'(0+) = v0 (+ impulses at 0): exactly
            data = self._start[order]
            values[:, start] = data[:, None]
            bounds[:, start] = (np.finfo(float).eps / 2 * np.abs(data))[:, None]
        for solution, columns, shifted in self._placements(exact, order, at_switch=True):
            part, part_bounds = _piece_values(solution, shifted, order, target)
            values[:, columns] += part[:n]
            bounds[:, columns] += part_bounds[:n]
        return values, bounds + np.finfo(float).eps * np.abs(values)

    def _placements(self, exact: list[Fraction], order: int,
                    at_switch: bool) -> Iterator[tuple[Any, list[int], list[Fraction]]]:
        """Per piece and switching time: the piece, the columns it reaches and their times
        after the switch. With ``at_switch``, a piece from rest leaves out the times at its
        switch where it is at rest (its velocity too, unless an impulse starts it), and
        t = 0 is left to the initial data for x and x'."""
        for piece, solution in self.pieces_solved:
            rest = at_switch and piece.at_rest and (
                order == 0 or (order == 1 and not piece.impulsive))
            for shift in _shifts(piece, max(exact, default=Fraction(0))):
                columns = [i for i, t in enumerate(exact)
                           if (t > shift or (t == shift and not rest))
                           and not (at_switch and t == 0 and order < 2)]
                if columns:
                    yield solution, columns, [exact[i] - shift for i in columns]

    def _digits(self, times: Times, order: int, dps: int) -> tuple[np.ndarray, np.ndarray]:
        """``dps`` digits: the pieces' own digits at the shifted times, summed."""
        n = self.scene.n
        values = np.zeros((n, len(times)), dtype=object)
        bounds = np.zeros((n, len(times)), dtype=object)
        exact = [Fraction(times.exact(i)) for i in range(len(times))]
        for solution, columns, shifted in self._placements(exact, order, at_switch=False):
            part, part_bounds = solution.evaluate(shifted, derivative=order, dps=dps,
                                                  return_error=True)
            with workdps(dps + 10):  # the sums with guard digits
                values[:, columns] = values[:, columns] + part[:n]
                bounds[:, columns] = bounds[:, columns] + part_bounds[:n]
        return values, bounds

    def verify(self, *, samples: Any = ("0.37", "1.3", "4.1"),
               tolerance: float | None = None) -> Verification:
        """Residual of M x'' + C x' + K x = f(t) at the sample times, relative to the terms'
        size, and of the initial data."""
        tolerance = 1e-9 if tolerance is None else float(tolerance)
        M, C, K, x0, v0 = scene_arrays(self.scene)
        times = np.array([0.0, *(float(sp.Rational(str(s))) for s in samples)])
        x, v, a = (self.evaluate(times, derivative=order) for order in range(3))
        force = np.zeros_like(x)
        for i, f in enumerate(self.scene.forcing or ()):
            if f != 0:
                force[i, 1:] = [float(f.subs(TIME, sp.Rational(str(s)))) for s in samples]
        residual = np.max(np.abs(M @ a[:, 1:] + C @ v[:, 1:] + K @ x[:, 1:] - force[:, 1:]))
        size = np.max(np.abs(M) @ np.abs(a) + np.abs(C) @ np.abs(v) + np.abs(K) @ np.abs(x)
                      + np.abs(force))
        massive = [i for i in range(self.scene.n) if i not in massless_nodes(self.scene)]
        v0 = self._start[1]  # x'(0+): v0 and the impulses at t = 0
        start = np.max(np.abs(np.concatenate([x[:, 0] - x0, v[massive, 0] - v0[massive]])))
        data = np.max(np.abs(np.concatenate([x0, v0])))
        return Verification(float(residual / size) if size else float(residual),
                            float(start / data) if data else float(start), tolerance)


def _shifts(piece: _Piece, last: Fraction) -> list[Fraction]:
    """The switching times of a piece up to the last time (every period for a periodic one)."""
    if piece.period is None:
        return [piece.delay]
    count = int((last - piece.delay) / piece.period) + 1 if last >= piece.delay else 0
    if count > limits().exo_max_periods:
        raise LimitError(f"a periodic force repeats {count:,} times before t = {float(last):g}, "
                         f"more than Limits.exo_max_periods = {limits().exo_max_periods:,} "
                         "for the numeric forced route (each period is one more evaluation)")
    return [piece.delay + k * piece.period for k in range(count)]
