"""Shared independent references for the tests.

`reference_motion` integrates nothing and inverts no transform: it applies mpmath's
matrix exponential of the first-order system y' = [[0, I], [-M⁻¹K, -M⁻¹C]] y at high
precision, the route the acceptance references use too.
"""

from __future__ import annotations

import mpmath
import numpy as np
import pytest
import sympy as sp


def _mp_matrix(matrix: sp.MatrixBase) -> mpmath.matrix:
    out = mpmath.matrix(*matrix.shape)
    for i in range(matrix.rows):
        for j in range(matrix.cols):
            value = sp.Rational(matrix[i, j])
            out[i, j] = mpmath.mpf(int(value.p)) / int(value.q)
    return out


def reference_motion(scene, times, dps: int = 40) -> np.ndarray:
    """x(t) of a numeric scene at ``times`` from a ``dps``-digit matrix exponential."""
    n = scene.n
    with mpmath.workdps(dps):
        Minv = mpmath.inverse(_mp_matrix(scene.M))
        A, B = Minv * _mp_matrix(scene.K), Minv * _mp_matrix(scene.C)
        Z = mpmath.zeros(2 * n, 2 * n)
        for i in range(n):
            Z[i, n + i] = 1
            for j in range(n):
                Z[n + i, j], Z[n + i, n + j] = -A[i, j], -B[i, j]
        y0 = mpmath.matrix([*_mp_matrix(scene.x0), *_mp_matrix(scene.v0)])
        out = np.empty((n, len(times)), dtype=object)
        for col, tv in enumerate(times):
            y = mpmath.expm(Z * mpmath.mpf(str(tv))) * y0
            for i in range(n):
                out[i, col] = y[i]
        return out


def _to_mpf(value) -> mpmath.mpf:
    if isinstance(value, sp.Basic):
        return mpmath.mpf(sp.Float(value, 60)._mpf_)
    return mpmath.mpf(value)


def relative_error(values, reference) -> float:
    """max |values - reference| / max |reference|, computed with 60-digit mpmath."""
    with mpmath.workdps(60):
        diff = max(abs(_to_mpf(v) - r) for v, r in zip(np.ravel(values), np.ravel(reference)))
        scale = max(abs(r) for r in np.ravel(reference))
        return float(diff / scale)


@pytest.fixture
def reference():
    return reference_motion
