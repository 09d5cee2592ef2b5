"""A forced piece split into a particular motion and a free one, where that is exact.

For inputs f = H w, w' = S w (the exosystems of :mod:`laplace_springs.routes.exo`), the
particular motion x_p = Π w solves M Π S² + C Π S + K Π = H (a Sylvester equation, the
regulator equation of control theory), uniquely when no eigenvalue of S is a pole of the
scene (no resonance). With rational M, C, K, S and H it is solved exactly (python-flint,
per exosystem block: n·q unknowns). Then x = x_h + Π w, where x_h is the *free* motion of
the scene from x0 − Π w(0), v0 − Π S w(0) (exact rationals): any free-motion engine of the
planner serves it (the krylov, classical, Chebyshev or tiny engines on large or small
scenes) with its own bound, and w(t) comes from one scalar scene per block of degree ≤ 2
(w = (h, h') with h'' + a₁h' + a₀h = 0: the tiny engine's closed forms, phases in
double-double). The derivatives are x_p^{(r)} = (Π S^r) w, formed exactly.

The bound of a value is the free part's bound, plus |Π S^r|·(the bound of w), plus the
rounding of Π S^r to float64 and of the products and sums (u per term).

Where the split does not apply (irrational entries, an exosystem of degree above 2,
resonance: the Sylvester equation is singular, or x0 − Π w(0) has numbers beyond
Limits.max_digits), :func:`split_piece` returns None and the caller joins the exosystems
to the scene instead.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from fractions import Fraction
from typing import Any

import mpmath
import numpy as np
import sympy as sp
from flint import fmpq, fmpq_mat

from ..kernels.precision import workdps
from ..limits import limits
from ..model.errors import SceneError
from ..model.scene import Scene
from ..numeric.first_order import rational_entries
from ..solution import Solution

__all__ = ["SplitPiece", "split_piece", "impulse_jump"]

_U = 2.0**-53


def _fmpq(value: Any) -> Any:
    """An exact SymPy number as fmpq, or None when it is not rational."""
    value = sp.sympify(value)
    if not value.is_Rational:
        return None
    return fmpq(int(value.p), int(value.q))


def _rational(value: Any) -> sp.Rational:
    return sp.Rational(int(value.p), int(value.q))


class SplitPiece:
    """x = x_h + Π w for one piece (see the module notes): ``free`` is the solution of the
    free motion, ``blocks`` the scalar exosystem solutions with their Π S^r (r = 0, 1, 2)
    exactly (fmpq_mat), ``rounded`` the same as float64."""

    def __init__(self, free: Solution, blocks: list[tuple[Solution, list[Any]]]) -> None:
        self.free = free
        self.blocks = blocks
        self.rounded = [[_float(P) for P in weights] for _, weights in blocks]

    @property
    def method(self) -> str:
        return self.free.method

    @property
    def poles(self) -> np.ndarray:
        return self.free.poles

    @property
    def _spectral_radius(self) -> float:
        return float(self.free._spectral_radius)

    def evaluate(self, times: Sequence[Fraction], *, derivative: int, target: float | None = None,
                 return_error: bool = True, dps: int | None = None,
                 progress: bool | None = False) -> tuple[np.ndarray, np.ndarray]:
        """Values and bounds of x^(derivative) at the (exact) times (mpmath numbers with
        ``dps``)."""
        if dps is not None:
            return self._digits(times, derivative, dps)
        # beyond Limits.exo_fine_max_coordinates the free part recomputes a time with
        # another engine only when its bound misses ten times the target (the certified
        # engine costs seconds to build there); the sum's bound says what was reached
        large = self.free.scene.n > limits().exo_fine_max_coordinates
        looser = None if target is None else min(10 * target, 0.5) if large else target
        values, bounds = self.free.evaluate(list(times), derivative=derivative, target=looser,
                                            return_error=True, progress=False)
        rounding = np.zeros_like(values)
        for (exo, _), weights in zip(self.blocks, self.rounded):
            w, w_bounds = exo.evaluate(list(times), derivative=0, target=target,
                                       return_error=True, progress=False)
            dw, dw_bounds = exo.evaluate(list(times), derivative=1, target=target,
                                         return_error=True, progress=False)
            P = weights[derivative]
            state = np.vstack([w[:1], dw[:1]])[:P.shape[1]]
            state_bounds = np.vstack([w_bounds[:1], dw_bounds[:1]])[:state.shape[0]]
            part = P @ state
            values = values + part
            size = np.abs(P) @ np.abs(state)
            bounds = bounds + np.abs(P) @ state_bounds
            rounding += size
        total = np.abs(values)
        return values, bounds + 4 * _U * (rounding + total)

    def _digits(self, times: Sequence[Fraction], derivative: int,
                dps: int) -> tuple[np.ndarray, np.ndarray]:
        values, bounds = self.free.evaluate(list(times), derivative=derivative, dps=dps,
                                            return_error=True)
        with workdps(dps + 10):  # the sums at the digits asked, with guard digits
            self._add_digits(values, bounds, times, derivative, dps)
        return values, bounds

    def _add_digits(self, values: np.ndarray, bounds: np.ndarray, times: Sequence[Fraction],
                    derivative: int, dps: int) -> None:
        for exo, weights in self.blocks:
            w, w_bounds = exo.evaluate(list(times), derivative=0, dps=dps, return_error=True)
            dw, dw_bounds = exo.evaluate(list(times), derivative=1, dps=dps, return_error=True)
            P = weights[derivative]
            rows = [w[0], dw[0]][:P.ncols()]
            errors = [w_bounds[0], dw_bounds[0]][:P.ncols()]
            for i in range(P.nrows()):
                for k in range(P.ncols()):
                    weight = mpmath.mpf(int(P[i, k].p)) / int(P[i, k].q)
                    for col in range(len(times)):
                        values[i, col] += weight * rows[k][col]
                        bounds[i, col] += abs(weight) * errors[k][col]


def split_piece(scene: Scene, blocks: list[tuple[int, tuple[Any, ...], tuple[Any, ...]]],
                impulses: list[tuple[int, Any]], start: bool,
                solver: Callable[..., Solution], target: float | None) -> SplitPiece | None:
    """The split of one piece, or None where it does not apply (see the module notes).

    ``blocks``: (row, numerator c_0..c_{q-1}, denominator a_0..a_{q-1}) per input part;
    ``impulses``: (row, d); ``start``: the piece carries the scene's initial data.
    """
    M, C, K = (rational_entries(scene, name) for name in ("M", "C", "K"))
    if M is None or C is None or K is None:
        return None
    n = scene.n
    x0 = [_fmpq(v) if start else fmpq(0) for v in scene.x0]
    v0 = [_fmpq(v) if start else fmpq(0) for v in scene.v0]
    if any(v is None for v in x0 + v0):
        return None
    if impulses:
        jump = _impulse_jump(M, n, impulses)
        if jump is None:
            return None
        v0 = [a + b for a, b in zip(v0, jump)]
    solved: list[tuple[Scene, list[Any]]] = []
    for row, numerator, denominator in blocks:
        c = [_fmpq(v) for v in numerator]
        a = [_fmpq(v) for v in denominator]
        q = len(a)
        if q == 0 or q > 2 or any(v is None for v in c + a):
            return None
        S = _companion(a)
        Pi = _regulator(M, C, K, n, S, row, c)
        if Pi is None:
            return None
        w0 = fmpq_mat(q, 1, [0] * (q - 1) + [1])
        start_x, start_v = Pi * w0, Pi * (S * w0)
        x0 = [x0[i] - start_x[i, 0] for i in range(n)]
        v0 = [v0[i] - start_v[i, 0] for i in range(n)]
        weights = [Pi, Pi * S, Pi * S * S]
        solved.append((_exo_scene(a), weights))
    try:
        free = Scene.from_matrices(M=scene.M, C=scene.C, K=scene.K,
                                   x0=[_rational(v) for v in x0],
                                   v0=[_rational(v) for v in v0], title=scene.title)
    except SceneError:
        # the free part's data x0 − Π w(0) is exact, and Π's entries are rational functions
        # of the scene's: masses and a dashpot of 1e-300 give numbers of 1,200 digits,
        # beyond Limits.max_digits; the caller joins the exosystems to the scene instead
        return None
    # the free part cancels the particular one where the motion starts from rest: on
    # small scenes its engine is chosen for a tenth of the target (times whose bound
    # misses the target itself escalate); on larger ones that would choose the certified
    # engine (4.5 s to build at 50 masses), and the target itself chooses
    goal = target if target is not None else limits().target
    finer = goal / 10 if n <= limits().exo_fine_max_coordinates else goal
    return SplitPiece(solver(free, target=finer),
                      [(solver(exo, target=target), weights) for exo, weights in solved])


def _companion(a: list[Any]) -> Any:
    """S with w' = S w for h^(q) + a_{q-1}h^(q-1) + ... + a_0 h = 0, w = (h, h', ...)."""
    q = len(a)
    S = fmpq_mat(q, q)
    for k in range(q - 1):
        S[k, k + 1] = 1
    for k in range(q):
        S[q - 1, k] = -a[k]
    return S


def _regulator(M: dict, C: dict, K: dict, n: int, S: Any, row: int, c: list[Any]) -> Any:
    """Π (n x q) with M Π S² + C Π S + K Π = e_row cᵀ, exactly; None when singular."""
    q = S.nrows()
    S2 = S * S
    system = fmpq_mat(n * q, n * q)
    for j in range(q):          # column j of the equation
        for col in range(q):    # column col of Π
            weights = ((M, S2[col, j]), (C, S[col, j]), (K, fmpq(1) if col == j else fmpq(0)))
            for entries, weight in weights:
                if weight == 0:
                    continue
                for (i, k), value in entries.items():
                    system[j * n + i, col * n + k] += weight * value
    right = fmpq_mat(n * q, 1)
    for j in range(q):
        right[j * n + row, 0] = c[j]
    try:
        solution = system.solve(right)
    except ZeroDivisionError:  # singular: a pole of the input is a pole of the scene
        return None
    Pi = fmpq_mat(n, q)
    for col in range(q):
        for i in range(n):
            Pi[i, col] = solution[col * n + i, 0]
    return Pi


def _impulse_jump(M: dict, n: int, impulses: list[tuple[int, Any]]) -> list[Any] | None:
    """M⁻¹ times the impulses (the velocity jump), exactly; None for a singular M."""
    matrix = fmpq_mat(n, n)
    for (i, j), value in M.items():
        matrix[i, j] = value
    right = fmpq_mat(n, 1)
    for row, d in impulses:
        value = _fmpq(d)
        if value is None:
            return None
        right[row, 0] += value
    try:
        solved = matrix.solve(right)
    except ZeroDivisionError:
        return None
    return [solved[i, 0] for i in range(n)]


def impulse_jump(scene: Scene, impulses: list[tuple[int, Any]]) -> list[sp.Rational]:
    """The velocity jump M⁻¹·(impulses), exactly (SymPy rationals)."""
    M = rational_entries(scene, "M")
    jump = None if M is None else _impulse_jump(M, scene.n, impulses)
    if jump is None:
        column = scene.M.LUsolve(sp.Matrix([sum((d for row, d in impulses if row == i),
                                                sp.Integer(0)) for i in range(scene.n)]))
        return list(column)
    return [_rational(v) for v in jump]


def _exo_scene(a: list[Any]) -> Scene:
    """h with h'' + a₁h' + a₀h = 0, h(0) = 0, h'(0) = 1 (q = 2), or h' + a₀h = 0,
    h(0) = 1 written as h'' + a₀h' = 0, h'(0) = −a₀ (q = 1)."""
    if len(a) == 2:
        return Scene.from_matrices(M=[[1]], C=[[_rational(a[1])]], K=[[_rational(a[0])]],
                                   x0=[0], v0=[1])
    return Scene.from_matrices(M=[[1]], C=[[_rational(a[0])]], K=[[0]], x0=[1],
                               v0=[-_rational(a[0])])


def _float(matrix: Any) -> np.ndarray:
    return np.array([[float(matrix[i, j]) for j in range(matrix.ncols())]
                     for i in range(matrix.nrows())])
