"""(K − ω²M + iωC)⁻¹ B where float64 cannot resolve it: exactly, or in certified balls.

:mod:`laplace_springs.analysis.frequency` solves the pencils in float64 with
double-double refinement; refinement does not converge where the pencil is singular at
float64 precision (condition number beyond about 1e15): near ω = 0 on a scene with a
rigid-body mode (cond ≈ ‖K‖/ω²), or at an undamped natural frequency rounded to float64.
In exact arithmetic the pencil is singular only where ω is exactly a natural frequency of
an undamped mode, or ω = 0 with K singular; anywhere else the response exists, and this
module finds it:

* rational M, C and K (every scene written with integers, decimals or fractions): the
  real 2n x 2n system [[A, −D], [D, A]] [X_re; X_im] = [B_re; B_im], A = K − ω²M, D = ωC,
  solved over the rationals by python-flint (ω and B, float64 numbers, are exact dyadic
  rationals), each entry then correctly rounded to float64;
* irrational entries (√2, π): the pencil as complex balls (python-flint acb) enclosing the
  exact entries at 64, 128, 256, ... bits, solved with certified enclosures until every
  entry's radius is below 2⁻⁶⁰ of the largest |entry| (normwise a few units of float64
  rounding, as the float route), up to :data:`MAX_BITS`.

A pencil that is exactly singular is a SceneError; a response beyond the float64 range a
LimitError, both naming ω.
"""

from __future__ import annotations

import math
from fractions import Fraction
from typing import Any

import numpy as np
import sympy as sp
from flint import acb, acb_mat, arb, fmpq, fmpq_mat

from ..kernels.precision import flint_workprec
from ..model.errors import LimitError, SceneError
from ..numeric.mp_expr import numeric_value

__all__ = ["ExactPencil", "singular_message", "MAX_BITS"]

#: Largest working precision of the ball route. Balls of p bits resolve a pencil P of
#: condition number well below 2^(p − 60); one whose inverse is within the float64 range
#: has cond(P) = ‖P‖‖P⁻¹‖ ≤ n·‖P‖·1e308 ≈ 2^(1100 + log2 ‖P‖), so 4,096 bits serve every
#: such pencil with ‖P‖ (entries, ω²) below about 2^2900. Past it, SymPy decides whether P
#: is singular (a SceneError) and a nonsingular one is a LimitError.
MAX_BITS = 4096
#: The ball route stops once every radius is below this fraction of the largest |entry|.
_RADIUS = 2.0**-60


def singular_message(caller: str, w: float) -> str:
    """What an exactly singular pencil at ω means."""
    if w == 0:
        return (f"{caller}: omega = 0.0: K is singular, a rigid-body mode (the scene is free to "
                "drift: a static force moves it without bound); ask for omega > 0")
    return (f"{caller}: omega = {w!r}: K - omega^2 M + i omega C is singular: omega is a natural "
            "frequency of an undamped mode (resonance: the response grows without bound, no "
            "steady state)")


class ExactPencil:
    """The pencil K − ω²M + iωC of a scene with numeric entries, solved without rounding.

    Parameters
    ----------
    M, C, K : sympy.Matrix
        n x n, numeric (float_matrix has accepted them).

    Examples
    --------
    A free mass with a dashpot c = 1/10, at ω = 1e-12: H = 1/(−ω² + iω/10) =
    (−ω² − iω/10)/(ω⁴ + ω²/100), about −100 − 1e13 i:

    >>> import sympy as sp
    >>> pencil = ExactPencil(sp.Matrix([[1]]), sp.Matrix([[sp.Rational(1, 10)]]), sp.Matrix([[0]]))
    >>> H = pencil.solve(1e-12, np.eye(1, dtype=complex), "frequency_response")
    >>> complex(H[0, 0])
    (-100-10000000000000j)
    """

    def __init__(self, M: sp.MatrixBase, C: sp.MatrixBase, K: sp.MatrixBase) -> None:
        self.n = int(M.rows)
        self._exprs = (M, C, K)
        self._rational = _rational_matrices(self._exprs)

    def solve(self, w: float, B: np.ndarray, caller: str) -> np.ndarray:
        """(K − ω²M + iωC)⁻¹ B (n x m complex float64) at the float64 frequency ``w``."""
        if self._rational is not None:
            return self._solve_rational(w, B, caller)
        return self._solve_balls(w, B, caller)

    def _solve_rational(self, w: float, B: np.ndarray, caller: str) -> np.ndarray:
        n, m = self.n, B.shape[1]
        assert self._rational is not None
        M, C, K = self._rational
        q = fmpq(*Fraction(w).as_integer_ratio())
        A = K - M * (q * q)
        D = C * q
        big = fmpq_mat(2 * n, 2 * n, [(A[i % n, j % n] if (i < n) == (j < n) else
                                       (-D[i, j - n] if i < n else D[i - n, j]))
                                      for i in range(2 * n) for j in range(2 * n)])
        rhs = fmpq_mat(2 * n, m, [_fmpq(float(part[i % n, j]))
                                  for part in (B.real, B.imag) for i in range(n) for j in range(m)])
        try:
            X = big.solve(rhs)
        except ZeroDivisionError:
            raise SceneError(singular_message(caller, w)) from None
        exact = [[(Fraction(int(X[i, j].p), int(X[i, j].q)), Fraction(int(X[i + n, j].p), int(X[i + n, j].q)))
                  for j in range(m)] for i in range(n)]
        largest = max((max(abs(re), abs(im)) for row in exact for re, im in row), default=Fraction(0))
        _check_range(largest, w, caller)
        out = np.empty((n, m), dtype=complex)
        for i, row in enumerate(exact):
            for j, (re, im) in enumerate(row):
                out[i, j] = complex(re.numerator / re.denominator, im.numerator / im.denominator)
        return out

    def _solve_balls(self, w: float, B: np.ndarray, caller: str) -> np.ndarray:
        n, m = self.n, B.shape[1]
        bits = 64
        while bits <= MAX_BITS:
            with flint_workprec(bits + 20):
                M, C, K = (_balls(matrix, bits) for matrix in self._exprs)
                x = arb(_fmpq(w))
                pencil = acb_mat(n, n, [acb(K[i][j] - x * x * M[i][j], x * C[i][j])
                                        for i in range(n) for j in range(n)])
                rhs = acb_mat(n, m, [acb(_fmpq(float(B[i, j].real)), _fmpq(float(B[i, j].imag)))
                                     for i in range(n) for j in range(m)])
                try:
                    X = pencil.solve(rhs)
                except ZeroDivisionError:  # not proved nonsingular at this precision
                    bits *= 2
                    continue
                entries = [[X[i, j] for j in range(m)] for i in range(n)]
                largest = max((max(abs(float(z.real.mid())), abs(float(z.imag.mid())))
                               for row in entries for z in row), default=0.0)
                radius = max((max(float(z.real.rad()), float(z.imag.rad()))
                              for row in entries for z in row), default=0.0)
                if radius <= _RADIUS * largest or (largest == 0 and radius == 0):
                    mids = [[(_mid_fraction(z.real), _mid_fraction(z.imag))
                             for z in row] for row in entries]
                    top = max((max(abs(re), abs(im)) for row in mids for re, im in row),
                              default=Fraction(0))
                    _check_range(top, w, caller)
                    return np.array([[complex(float(re), float(im)) for re, im in row] for row in mids],
                                    dtype=complex)
            bits *= 2
        raise self._unresolved(w, caller)

    def _unresolved(self, w: float, caller: str) -> SceneError | LimitError:
        """Why the balls did not resolve the pencil at MAX_BITS: it is singular (det(P) = 0,
        decided by SymPy), or its inverse is beyond the float64 range."""
        M, C, K = self._exprs
        q = sp.Rational(*Fraction(w).as_integer_ratio())
        det = sp.Matrix(K - q**2 * M + sp.I * q * C).det(method="berkowitz")
        zero = sp.expand(det).equals(0)
        if zero:
            return SceneError(singular_message(caller, w))
        if zero is None:
            return SceneError(f"{caller}: omega = {w!r}: K - omega^2 M + i omega C is singular to "
                              f"{MAX_BITS} bits (a natural frequency of an undamped mode, or 0 on a "
                              "scene with a rigid-body mode), or its inverse is far beyond the "
                              "float64 range")
        return LimitError(f"{caller}: at omega = {w!r} the response is not resolved in "
                          f"{MAX_BITS}-bit balls: the pencil is nonsingular, with a condition "
                          "number beyond about 1e1200, so |H| is beyond the float64 range "
                          "(about 1e-308 to 1e308) or its entries are")


def _fmpq(value: float) -> fmpq:
    return fmpq(*Fraction(value).as_integer_ratio())


def _mid_fraction(x: arb) -> Fraction:
    """The midpoint of a ball, exactly (an arb midpoint is a dyadic number)."""
    mantissa, exponent = x.mid().man_exp()
    return Fraction(int(mantissa)) * Fraction(2) ** int(exponent)


def _check_range(largest: Fraction, w: float, caller: str) -> None:
    """A LimitError when the largest |entry| of a nonzero response is outside float64."""
    if largest == 0:
        return
    if largest >= Fraction(np.finfo(float).max) or largest < Fraction(np.finfo(float).tiny):
        exponent = math.floor(math.log10(largest.numerator) - math.log10(largest.denominator))
        raise LimitError(f"{caller}: at omega = {w!r} the response is beyond the float64 range "
                         f"(|H| about 1e{exponent:+d}); float64 values exist only between about "
                         "1e-308 and 1e308")


def _rational_matrices(exprs: tuple[sp.MatrixBase, ...]) -> tuple[fmpq_mat, ...] | None:
    """M, C and K as python-flint rational matrices, or None where an entry is irrational."""
    out = []
    for matrix in exprs:
        n, m = matrix.shape
        values: list[Any] = [fmpq(0)] * (n * m)
        for (i, j), entry in matrix.todok().items():
            if not entry.is_Rational:
                return None
            values[i * m + j] = fmpq(int(entry.p), int(entry.q))
        out.append(fmpq_mat(n, m, values))
    return tuple(out)


def _balls(matrix: sp.MatrixBase, bits: int) -> list[list[arb]]:
    """The entries of a numeric matrix as balls enclosing them, at the working precision:
    a rational exactly (rounded by arb, which widens the ball), another number from
    SymPy's value to about ``bits`` + 50 bits, widened by 2^-(bits + 20) of its size."""
    n, m = matrix.shape
    dps = int(bits * 0.302) + 15
    out = [[arb(0)] * m for _ in range(n)]
    for (i, j), entry in matrix.todok().items():
        if entry.is_Rational:
            out[i][j] = arb(fmpq(int(entry.p), int(entry.q)))
        else:
            mid = arb(str(numeric_value(entry, dps)))
            out[i][j] = mid + arb(0, (abs(mid) * arb(2) ** -(bits + 20)).upper())
    return out
