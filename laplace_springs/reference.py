"""An independent high-precision route: the matrix exponential of the first-order system.

Nothing here inverts a transform or uses the partial-fraction engine: x(t) comes from
mpmath's ``expm`` of y' = [[0, I], [-M⁻¹K, -M⁻¹C]] y at a chosen precision. Tests and
the benchmark compare the toolkit's answers with it.
"""

from __future__ import annotations

from typing import Sequence

import mpmath
import numpy as np
import sympy as sp

__all__ = ["reference_motion", "relative_error", "first_order_matrix_mp"]


def _mp_matrix(matrix: sp.MatrixBase) -> mpmath.matrix:
    out = mpmath.matrix(*matrix.shape)
    for i in range(matrix.rows):
        for j in range(matrix.cols):
            out[i, j] = _to_mpf(matrix[i, j])
    return out


def first_order_matrix_mp(scene) -> mpmath.matrix:
    """Z = [[0, I], [-M⁻¹K, -M⁻¹C]] at the current mpmath precision (numeric scenes)."""
    n = scene.n
    Minv = mpmath.inverse(_mp_matrix(scene.M))
    A, B = Minv * _mp_matrix(scene.K), Minv * _mp_matrix(scene.C)
    Z = mpmath.zeros(2 * n, 2 * n)
    for i in range(n):
        Z[i, n + i] = 1
        for j in range(n):
            Z[n + i, j], Z[n + i, n + j] = -A[i, j], -B[i, j]
    return Z


def reference_motion(scene, times: Sequence, dps: int = 40) -> np.ndarray:
    """x(t) of a numeric, unforced scene at ``times`` from a ``dps``-digit matrix exponential.

    Parameters
    ----------
    scene : Scene
        A scene with numeric entries and positive definite M.
    times : sequence
        Times (floats are read by their shortest decimal form; strings as decimals).
    dps : int
        Working precision in decimal digits.

    Returns
    -------
    numpy.ndarray
        Object array of mpmath numbers, shape (n, len(times)).

    Examples
    --------
    >>> from laplace_springs import Scene
    >>> scene = Scene.from_matrices(M=[[1]], K=[[1]], x0=[1], v0=[0])
    >>> x = reference_motion(scene, [1], dps=30)
    >>> mpmath.nstr(x[0, 0], 15)
    '0.54030230586814'
    """
    n = scene.n
    with mpmath.workdps(dps):
        Z = first_order_matrix_mp(scene)
        y0 = mpmath.matrix([*_mp_matrix(scene.x0), *_mp_matrix(scene.v0)])
        out = np.empty((n, len(times)), dtype=object)
        for col, tv in enumerate(times):
            y = mpmath.expm(Z * _to_mpf(tv)) * y0
            for i in range(n):
                out[i, col] = +y[i]
        return out


def _to_mpf(value) -> mpmath.mpf:
    """A number as an mpf at the current precision (floats by their shortest decimal)."""
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float):
        return mpmath.mpf(repr(value))
    if isinstance(value, sp.Basic):
        return mpmath.mpf(sp.Float(sp.N(value, mpmath.mp.dps + 5), mpmath.mp.dps + 5)._mpf_)
    return mpmath.mpf(value)


def relative_error(values, reference) -> float:
    """max |values - reference| / max |reference|, computed with 60-digit mpmath.

    Examples
    --------
    >>> relative_error([1.0, 2.0], [1, 2.000000001]) < 1e-9
    True
    """
    with mpmath.workdps(60):
        ref = [_to_mpf(r) for r in np.ravel(reference)]
        diff = max(abs(_to_mpf(v) - r) for v, r in zip(np.ravel(values), ref))
        scale = max(abs(r) for r in ref)
        return float(diff / scale) if scale else float(diff)
