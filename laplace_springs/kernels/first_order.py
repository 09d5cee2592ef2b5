"""The first-order system of M x'' + C x' + K x = 0, and the massless nodes: one copy each.

With every mass nonzero (M invertible) the state is y = (x, x') and

    Z = [[0, I], [−M⁻¹K, −M⁻¹C]].

Massless nodes z (row and column of M zero) carry no velocity of their own: their
equations C_zz x_z' = −(K x)_z − C_zm x_m' make x_z' a function of the state, so the state is
y = (x, x_m') with the massive velocities m only (Maxwell elements, nodes held by a
dashpot), and

    x_m' = v_m,   x_z' = P x + Q v_m,   v_m' = −M_mm⁻¹(K_m x + C_mz P x) − M_mm⁻¹(C_mm + C_mz Q) v_m

with P = −C_zz⁻¹K_z and Q = −C_zz⁻¹C_zm. Their initial velocities play no role, as in the
transform X(λ). The same code serves exact SymPy matrices (the certified and exact routes,
state space, the seed's [[0, I], [−A, −B]]) and float64 arrays (the general modal route),
through a two-function backend: ``take(A, rows, cols)`` and ``solve(A, B)`` (A⁻¹B).

>>> import sympy as sp
>>> Z, y0, massive = first_order(sp.Matrix([[2]]), sp.Matrix([[1]]), sp.Matrix([[8]]),
...                              sp.Matrix([1]), sp.Matrix([3]))
>>> Z, list(y0), massive
(Matrix([
[ 0,    1],
[-4, -1/2]]), [1, 3], [0])
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from typing import Any

import numpy as np
import sympy as sp

__all__ = ["massless_nodes", "first_order", "SYMPY", "FLOAT", "Backend"]


def massless_nodes(entries: Iterable[tuple[int, int]], n: int) -> list[int]:
    """The coordinates whose row and column of M hold no nonzero entry.

    ``entries`` are the (row, column) positions of M's nonzero entries.

    >>> massless_nodes([(0, 0), (2, 2)], 3)
    [1]
    """
    touched = {index for key in entries for index in key}
    return [i for i in range(n) if i not in touched]


class Backend:
    """Matrix operations of one number field: exact SymPy, or float64 NumPy."""

    def __init__(self, take: Callable[[Any, Sequence[int], Sequence[int]], Any],
                 solve: Callable[[Any, Any], Any], zeros: Callable[[int, int], Any],
                 stack: Callable[[list[list[Any]]], Any], column: Callable[[Sequence[Any]], Any]):
        self.take, self.solve, self.zeros, self.stack, self.column = take, solve, zeros, stack, column


def _sympy_solve(A: Any, B: Any) -> Any:
    if A.rows == 0:
        return sp.zeros(0, B.cols)
    return A.inv() * B  # SymPy raises ValueError "Matrix det == 0; not invertible."


def _sympy_stack(blocks: list[list[Any]]) -> Any:
    rows = [sp.Matrix.hstack(*row) for row in blocks]
    return sp.Matrix.vstack(*rows)


def _float_stack(blocks: list[list[Any]]) -> Any:
    return np.block(blocks)


#: Exact SymPy matrices.
SYMPY = Backend(take=lambda A, r, c: sp.Matrix(A).extract(list(r), list(c)), solve=_sympy_solve,
                zeros=sp.zeros, stack=_sympy_stack, column=lambda values: sp.Matrix(list(values)))
#: float64 NumPy arrays.
FLOAT = Backend(take=lambda A, r, c: np.asarray(A)[np.ix_(list(r), list(c))],
                solve=lambda A, B: np.linalg.solve(A, B) if len(A) else np.zeros((0, B.shape[1])),
                zeros=lambda r, c: np.zeros((r, c)), stack=_float_stack,
                column=lambda values: np.array(list(values), dtype=float))


def first_order(M: Any, C: Any, K: Any, x0: Sequence[Any], v0: Sequence[Any],
                backend: Backend = SYMPY,
                massless: Sequence[int] | None = None) -> tuple[Any, Any, list[int]]:
    """y' = Z y, y(0) = y0 whose first n entries are x (see the module notes).

    Parameters
    ----------
    M, C, K : matrices of ``backend``
    x0, v0 : sequences
    backend : Backend
        :data:`SYMPY` (exact) or :data:`FLOAT` (float64).
    massless : sequence of int, optional
        The massless nodes (found from M's nonzero entries when omitted).

    Returns
    -------
    Z, y0, massive
        The matrix, the initial state, and the coordinates whose velocities are the state
        entries n, n + 1, ...

    Raises
    ------
    ValueError or numpy.linalg.LinAlgError
        When the mass block on the massive nodes, or the dashpot block on the massless
        ones, is singular (the callers say what that means for them).
    """
    n = len(x0)
    if massless is None:
        massless = massless_nodes(_positions(M, backend), n)
    z = list(massless)
    m = [i for i in range(n) if i not in z]
    everything = list(range(n))
    take, solve = backend.take, backend.solve
    P = -solve(take(C, z, z), take(K, z, everything))     # x_z' = P x + Q v_m
    Q = -solve(take(C, z, z), take(C, z, m))
    Cmz = take(C, m, z)
    Avel = -solve(take(M, m, m), take(K, m, everything) + Cmz @ P)
    Bvel = -solve(take(M, m, m), take(C, m, m) + Cmz @ Q)
    top = backend.zeros(n, n + len(m))
    for row, i in enumerate(m):
        top[i, n + row] = 1
    for row, i in enumerate(z):
        for j in range(n):
            top[i, j] = P[row, j]
        for j in range(len(m)):
            top[i, n + j] = Q[row, j]
    Z = backend.stack([[top], [backend.stack([[Avel, Bvel]])]]) if m else top
    y0 = backend.column([*x0, *(v0[i] for i in m)])
    return Z, y0, m


def _positions(M: Any, backend: Backend) -> list[tuple[int, int]]:
    if backend is FLOAT:
        return [(int(i), int(j)) for i, j in zip(*np.nonzero(np.asarray(M)))]
    return [key for key, value in sp.Matrix(M).todok().items() if value != 0]
