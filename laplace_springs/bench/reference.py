"""An independent high-precision route: the matrix exponential of the first-order system.

Nothing here inverts a transform, finds a root or uses an eigen-decomposition: x(t)
comes from the matrix exponential of the exact first-order system y' = Z y, by mpmath's
``expm`` or python-flint's certified arb ``exp``, at a chosen precision. Tests and the
benchmark compare every route with it: the exact route (partial fractions), the modal
route (float64 eigenvectors) and the certified route (roots of the characteristic
polynomial) share no algorithm with it, and it shares no code with them: its first-order
matrix is built here, column by column, by applying the equations of motion to each
unit state (:func:`reference_system`), not by the package's block formulas
(:mod:`laplace_springs.kernels.first_order`).
"""

from __future__ import annotations

from collections.abc import Sequence

import mpmath
import numpy as np
import sympy as sp
from flint import arb, arb_mat, fmpq, fmpq_mat, fmpz

from ..kernels.precision import flint_workprec, workdps, workprec
from ..model.errors import SceneError
from ..model.numbers import to_exact

__all__ = ["reference_motion", "reference_motion_arb", "reference_forced_motion",
           "relative_error", "first_order_matrix_mp", "reference_system"]


def reference_system(scene) -> tuple[sp.Matrix, sp.Matrix]:
    """Exact Z and y(0) with y' = Z y, whose first n entries are x, built independently.

    The state is y = (x, v) with the velocities v of the massive coordinates (those with
    a nonzero row or column of M). Column k of Z is the derivative of the k-th unit state:
    x' is v on the massive coordinates; on the massless ones it solves their rows of
    C x' + K x = 0; then M v' = −(C x' + K x) on the massive rows. Each step is a linear
    solve of the scene's own matrices (SymPy, exact).

    >>> from laplace_springs import Scene
    >>> Z, y0 = reference_system(Scene.from_matrices(M=[[2]], C=[[1]], K=[[8]], x0=[1], v0=[3]))
    >>> Z.tolist(), y0.T.tolist()
    ([[0, 1], [-4, -1/2]], [[1, 3]])
    """
    M, C, K = (sp.Matrix(m) for m in (scene.M, scene.C, scene.K))
    n = scene.n
    massive = [i for i in range(n) if any(M[i, j] != 0 or M[j, i] != 0 for j in range(n))]
    light = [i for i in range(n) if i not in massive]
    size = n + len(massive)
    columns = []
    for k in range(size):
        state = [1 if j == k else 0 for j in range(size)]
        x = sp.Matrix(state[:n])
        xdot = sp.zeros(n, 1)
        for slot, i in enumerate(massive):
            xdot[i] = state[n + slot]
        if light:  # rows of the massless nodes: C x' + K x = 0, unknowns x'_light
            rhs = -(K * x + C * xdot).extract(light, [0])
            xdot_light = C.extract(light, light).LUsolve(rhs)
            for slot, i in enumerate(light):
                xdot[i] = xdot_light[slot]
        force = -(K * x + C * xdot).extract(massive, [0])
        vdot = M.extract(massive, massive).LUsolve(force) if massive else sp.zeros(0, 1)
        columns.append(list(xdot) + list(vdot))
    Z = sp.Matrix(size, size, lambda i, j: columns[j][i])
    y0 = sp.Matrix([*scene.x0, *(scene.v0[i] for i in massive)])
    return Z, y0


def _mp_matrix(matrix: sp.MatrixBase) -> mpmath.matrix:
    out = mpmath.matrix(*matrix.shape)
    for i in range(matrix.rows):
        for j in range(matrix.cols):
            out[i, j] = _to_mpf(matrix[i, j])
    return out


def first_order_matrix_mp(scene) -> mpmath.matrix:
    """Z of :func:`reference_system` at the current mpmath precision (numeric scenes)."""
    return _mp_matrix(reference_system(scene)[0])


def _expm_motion(Z: sp.MatrixBase, y0: sp.MatrixBase, n: int, times: Sequence,
                 dps: int) -> np.ndarray:
    """The first n entries of exp(Z t)·y0 by mpmath at ``dps`` digits, one column per time."""
    with workdps(dps):
        Z, y0 = _mp_matrix(Z), _mp_matrix(y0)
        out = np.empty((n, len(times)), dtype=object)
        for col, tv in enumerate(times):
            y = mpmath.expm(Z * _to_mpf(tv)) * y0
            for i in range(n):
                out[i, col] = +y[i]
        return out


def reference_motion(scene, times: Sequence, dps: int = 40) -> np.ndarray:
    """x(t) of a numeric, unforced scene at ``times`` from a ``dps``-digit matrix exponential.

    Parameters
    ----------
    scene : Scene
        A scene with numeric entries and invertible M, or massless nodes held by
        dashpots (see :func:`reference_system`).
    times : sequence
        Times (floats by their exact binary value; strings as exact decimals).
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
    Z, y0 = reference_system(scene)
    return _expm_motion(Z, y0, scene.n, times, dps)


def _to_mpf(value) -> mpmath.mpf:
    """A number as an mpf at the current precision: floats by their exact binary value (a
    float time or value is the number it holds), exact numbers rounded once."""
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float):
        return mpmath.mpf(value)
    if isinstance(value, sp.Rational):
        return mpmath.mpf(int(value.p)) / int(value.q)
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
    with workdps(60):
        ref = [_to_mpf(r) for r in np.ravel(reference)]
        diff = max(abs(_to_mpf(v) - r) for v, r in zip(np.ravel(values), ref))
        scale = max(abs(r) for r in ref)
        return float(diff / scale) if scale else float(diff)


# ----------------------------------------------------------------------------- arb route


def _arb_time(value):
    """A time as an arb ball: floats and mpmath numbers exactly, strings as decimals."""
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, (int, float)):
        return arb(value)
    if isinstance(value, mpmath.mpf):
        sign, man, exp, _ = value._mpf_
        return arb(fmpz(-man if sign else man)) * arb(2) ** int(exp)
    if isinstance(value, sp.Rational):
        return arb(fmpq(int(value.p), int(value.q)))
    return arb(str(value))


def _exact_rational_matrix(matrix: sp.MatrixBase):
    """The matrix as a flint fmpq_mat if every entry is rational, else None."""
    if not all(isinstance(e, sp.Rational) for e in matrix):
        return None
    return fmpq_mat(matrix.rows, matrix.cols, [fmpq(int(e.p), int(e.q)) for e in matrix])


def _arb_entry(value: sp.Expr, digits: int) -> arb:
    """An exact number as an arb ball: rationals exactly, others (such as √2) as a
    ``digits``-digit decimal widened by 10^(1 - digits) of its size, so the ball holds
    the exact value."""
    if isinstance(value, sp.Rational):
        return arb(fmpq(int(value.p), int(value.q)))
    ball = arb(str(sp.N(value, digits)))
    return ball + arb(0, (abs(ball).upper() * arb(10) ** (1 - digits)).upper())


def _arb_matrix(matrix: sp.MatrixBase, digits: int) -> arb_mat:
    """An exact numeric matrix as balls that contain its entries (rational ones exactly)."""
    rational = _exact_rational_matrix(matrix)
    if rational is not None:
        return arb_mat(rational)
    entries = [_arb_entry(e, digits) for e in matrix]
    return arb_mat(matrix.rows, matrix.cols, entries)


def _arb_to_mpf(value) -> mpmath.mpf:
    man, exp = value.mid().man_exp()
    return mpmath.mpf((int(man), int(exp)))


def _arb_motion(scene, times: Sequence, digits: int) -> tuple[list[list[arb]], float]:
    """Balls of x(t) (one row per coordinate) and the largest radius relative to max |x|,
    at the current precision."""
    Z, y0 = reference_system(scene)
    n = scene.n
    Z, y0 = _arb_matrix(Z, digits + 20), _arb_matrix(y0, digits + 20)
    columns = [(Z * _arb_time(tv)).exp() * y0 for tv in times]
    balls = [[y[i, 0] for y in columns] for i in range(n)]
    scale = max(abs(float(b.mid())) for row in balls for b in row)
    radius = max(float(b.rad()) for row in balls for b in row)
    if not all(b.is_finite() for row in balls for b in row):
        return balls, float("inf")
    return balls, radius / scale if scale else radius


def reference_motion_arb(scene, times: Sequence, digits: int = 60,
                         *, max_bits: int = 16384) -> np.ndarray:
    """x(t) from python-flint's certified arb matrix exponential of the first-order system.

    An independent route (no transform, no partial fractions, not mpmath's expm):
    exp(Z t)·[x0; v0] with Z = [[0, I], [-M⁻¹K, -M⁻¹C]] in ball arithmetic. The working
    precision is doubled until every ball's radius is below 10^-digits relative to
    max |x| over all coordinates and times, so the returned midpoints are certified to
    that many digits in that norm.

    Parameters
    ----------
    scene : Scene
        A numeric scene with invertible M, or massless nodes held by dashpots (see
        :func:`reference_system`); rational entries are used exactly.
    times : sequence
        Times: floats and mpmath numbers are read exactly (their binary value), strings
        as decimal numbers.
    digits : int
        Certified decimal digits, relative to max |x|.
    max_bits : int
        Give up (``ArithmeticError``) beyond this working precision.

    Returns
    -------
    numpy.ndarray
        Object array of mpmath numbers, shape (n, len(times)).

    Examples
    --------
    >>> from laplace_springs import Scene
    >>> scene = Scene.from_matrices(M=[[1]], C=[[2]], K=[[1]], x0=[1], v0=[0])
    >>> x = reference_motion_arb(scene, [1.0], digits=30)
    >>> mpmath.nstr(x[0, 0], 20)   # (1 + t) e^{-t} at t = 1
    '0.73575888234288464319'
    """
    bits = int(digits * 3.33) + 64
    while bits <= max_bits:
        with flint_workprec(bits):
            balls, relative_radius = _arb_motion(scene, times, digits)
        if relative_radius < 10.0 ** -digits:
            out = np.empty((scene.n, len(times)), dtype=object)
            with workprec(bits):
                for i, row in enumerate(balls):
                    for col, ball in enumerate(row):
                        out[i, col] = _arb_to_mpf(ball)
            return out
        bits *= 2
    raise ArithmeticError(f"reference_motion_arb: {digits} digits not reached at {max_bits} bits")




def reference_forced_motion(scene, S, w0, G, times: Sequence, dps: int = 40) -> np.ndarray:
    """x(t) of a scene driven by f(t) = G w(t), w' = S w, w(0) = w0 (an exosystem).

    The augmented first-order system [[Z, B G], [0, S]] with B = [[0], [M⁻¹]] is
    exponentiated by mpmath at ``dps`` digits. Harmonic, polynomial and exponential
    inputs are exosystem outputs: cos ωt is the first state of S = [[0, -ω], [ω, 0]],
    w0 = (1, 0); a constant force has S = [[0]]. No Laplace transform is involved, so
    this checks the forced closed forms independently. The scene's own ``forcing`` is
    ignored.

    Examples
    --------
    x'' + x = cos(2t), x(0) = x'(0) = 0 has x = (cos t - cos 2t)/3:

    >>> from laplace_springs import Scene
    >>> scene = Scene.from_matrices(M=[[1]], K=[[1]], x0=[0], v0=[0])
    >>> x = reference_forced_motion(scene, [[0, -2], [2, 0]], [1, 0], [[1, 0]], [1], dps=30)
    >>> mpmath.nstr(x[0, 0], 12), mpmath.nstr((mpmath.cos(1) - mpmath.cos(2)) / 3, 12)
    ('0.318816380805', '0.318816380805')
    """
    n = scene.n
    Z, y0 = reference_system(scene)
    if Z.rows != 2 * n:
        raise SceneError("reference_forced_motion needs an invertible M (no massless nodes)")
    S, G, w0 = (_exact(rows, name) for rows, name in ((S, "S"), (G, "G"), ([w0], "w0")))
    load = sp.Matrix.vstack(sp.zeros(n, S.rows), sp.Matrix(scene.M).inv() * G)
    big = sp.Matrix.vstack(sp.Matrix.hstack(Z, load),
                           sp.Matrix.hstack(sp.zeros(S.rows, 2 * n), S))
    return _expm_motion(big, sp.Matrix.vstack(y0, w0.T), n, times, dps)


def _exact(rows, name: str) -> sp.Matrix:
    """Nested rows of numbers or decimal strings as an exact matrix (never sympified text)."""
    return sp.Matrix([[to_exact(v, f"{name}[{i},{j}]") for j, v in enumerate(row)]
                      for i, row in enumerate(rows)])
