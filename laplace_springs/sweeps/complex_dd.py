"""Complex double-double arrays and sparse products for the batched sweep engine.

A complex double-double is four float64 arrays (re_hi, re_lo, im_hi, im_lo) of one
shape; the operations are those of :mod:`laplace_springs.kernels.dd` applied to the real
and imaginary parts. :class:`RowGroups` holds the nonzero positions of a sparse matrix
(the same for every parameter set) grouped by row, so that a product with a stack of
matrices is a gather, elementwise double-double products and a pairwise sum per row.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..kernels.dd import dd_add, dd_mul, dd_mul_float, fast_two_sum, split, two_prod, two_sum

__all__ = ["CDD", "cdd", "cdd_add", "cdd_mul", "cdd_mul_float", "cdd_product", "cdd_scale",
           "cdd_float", "RowGroups",
           "row_groups"]

#: (re_hi, re_lo, im_hi, im_lo)
CDD = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]


def cdd(value: np.ndarray, low: np.ndarray | None = None) -> CDD:
    """A complex float array (plus an optional complex low part) as a complex double-double
    (the parts are not renormalised: hi + lo is the value)."""
    low = np.zeros_like(value) if low is None else low
    return value.real.copy(), low.real.copy(), value.imag.copy(), low.imag.copy()


def cdd_float(a: CDD) -> np.ndarray:
    """The complex double-double rounded to complex float64."""
    return (a[0] + a[1]) + 1j * (a[2] + a[3])


def cdd_add(a: CDD, b: CDD) -> CDD:
    """a + b."""
    rh, rl = dd_add(a[0], a[1], b[0], b[1])
    ih, il = dd_add(a[2], a[3], b[2], b[3])
    return rh, rl, ih, il


def cdd_mul(a: CDD, b: CDD) -> CDD:
    """a·b: (ar br − ai bi) + i(ar bi + ai br), each product and sum in double-double."""
    p1 = dd_mul(a[0], a[1], b[0], b[1])
    p2 = dd_mul(a[2], a[3], b[2], b[3])
    p3 = dd_mul(a[0], a[1], b[2], b[3])
    p4 = dd_mul(a[2], a[3], b[0], b[1])
    rh, rl = dd_add(p1[0], p1[1], -p2[0], -p2[1])
    ih, il = dd_add(p3[0], p3[1], p4[0], p4[1])
    return rh, rl, ih, il


def cdd_mul_float(a: CDD, b: np.ndarray) -> CDD:
    """a·b for a complex float64 b (each product exact to 2u² relative)."""
    p1 = dd_mul_float(a[0], a[1], b.real)
    p2 = dd_mul_float(a[2], a[3], b.imag)
    p3 = dd_mul_float(a[0], a[1], b.imag)
    p4 = dd_mul_float(a[2], a[3], b.real)
    rh, rl = dd_add(p1[0], p1[1], -p2[0], -p2[1])
    ih, il = dd_add(p3[0], p3[1], p4[0], p4[1])
    return rh, rl, ih, il


def cdd_product(a: np.ndarray, b: np.ndarray) -> CDD:
    """a·b for complex float64 a, b, exactly up to the final two-sums (error ≤ u²|a||b|)."""
    p1, e1 = two_prod(a.real, b.real)
    p2, e2 = two_prod(a.imag, b.imag)
    p3, e3 = two_prod(a.real, b.imag)
    p4, e4 = two_prod(a.imag, b.real)
    rh, r = two_sum(p1, -p2)
    ih, i = two_sum(p3, p4)
    return (*fast_two_sum(rh, r + (e1 - e2)), *fast_two_sum(ih, i + (e3 + e4)))


def cdd_scale(a: CDD, hi: np.ndarray, lo: np.ndarray) -> CDD:
    """a·(hi + lo) for a real double-double hi + lo."""
    rh, rl = dd_mul(a[0], a[1], hi, lo)
    ih, il = dd_mul(a[2], a[3], hi, lo)
    return rh, rl, ih, il


@dataclass(frozen=True)
class RowGroups:
    """The nonzero positions of an n x n sparse matrix, as an (n, width) table of entry
    indices per row (padded with ``count``, the index of an extra zero entry).

    Examples
    --------
    >>> groups = row_groups([(0, 0), (0, 1), (1, 1)], 2)
    >>> groups.table.tolist(), groups.width
    ([[0, 1], [2, 3]], 2)
    """

    n: int
    rows: np.ndarray
    cols: np.ndarray
    table: np.ndarray

    @property
    def count(self) -> int:
        return int(self.rows.size)

    @property
    def width(self) -> int:
        return int(self.table.shape[1])

    def product(self, values: tuple[np.ndarray, np.ndarray], x: np.ndarray) -> CDD:
        """A·x in double-double for the stack of matrices with entries ``values`` (hi, lo),
        each (P, count), and a complex float64 x of shape (P, n, m): shape (P, n, m).

        Each product a_ij·x_jk is formed exactly (Dekker's two-product, the splits made
        once per entry and per x), each row's sum with Knuth's two-sum; the result's error
        is below 2⁻¹⁰⁰·(width + 2)·Σ_j |a_ij||x_jk| plus |a_lo||x| rounding.
        """
        hi, lo = values
        P = hi.shape[0]
        m = x.shape[2]
        pad = np.zeros((P, 1))
        ah, al = (np.concatenate([part, pad], axis=1)[:, :, None] for part in split(hi))
        a, a_lo = (np.concatenate([part, pad], axis=1)[:, :, None] for part in (hi, lo))
        zero = np.zeros((P, 1, m))
        out: list[np.ndarray] = []
        for part in (np.ascontiguousarray(x.real), np.ascontiguousarray(x.imag)):
            xh, xl = split(part)
            g, gh, gl = (np.concatenate([v[:, self.cols, :], zero], axis=1) for v in (part, xh, xl))
            p = a * g
            e = (((ah * gh - p) + ah * gl + al * gh) + al * gl) + a_lo * g
            p, e = p[:, self.table, :], e[:, self.table, :]  # (P, n, width, m)
            total, error = p[:, :, 0], e[:, :, 0]
            for slot in range(1, self.width):
                total, rounding = two_sum(total, p[:, :, slot])
                error = error + (rounding + e[:, :, slot])
            out.extend(fast_two_sum(total, error))
        return out[0], out[1], out[2], out[3]

    def floats(self, values: np.ndarray, x: np.ndarray) -> np.ndarray:
        """A·x in float64 (complex x (P, n, m), entries ``values`` (P, count))."""
        P = values.shape[0]
        out = np.zeros((P, self.n, x.shape[2]), dtype=x.dtype)
        for slot in range(self.width):
            index = self.table[:, slot]
            real = index < self.count
            rows = np.flatnonzero(real)
            entries = index[real]
            out[:, rows, :] += values[:, entries, None] * x[:, self.cols[entries], :]
        return out

    def magnitude(self, values: np.ndarray, x: np.ndarray) -> np.ndarray:
        """|A|·x for nonnegative float x (P, n, m) and |entries| ``values`` (P, count)."""
        P = values.shape[0]
        out = np.zeros((P, self.n, x.shape[2]))
        for slot in range(self.width):  # one entry per row at a time: no repeated rows
            index = self.table[:, slot]
            real = index < self.count
            rows = np.flatnonzero(real)
            entries = index[real]
            out[:, rows, :] += values[:, entries, None] * x[:, self.cols[entries], :]
        return out


def row_groups(pattern: list[tuple[int, int]], n: int) -> RowGroups:
    """The :class:`RowGroups` of a sparsity pattern (width a power of two)."""
    rows = np.array([i for i, _ in pattern], dtype=np.intp)
    cols = np.array([j for _, j in pattern], dtype=np.intp)
    count = rows.size
    lengths = np.bincount(rows, minlength=n) if count else np.zeros(n, dtype=int)
    longest = int(lengths.max(initial=0))
    width = 1 << max(int(np.ceil(np.log2(longest))) if longest > 1 else 0, 0)
    table = np.full((n, max(width, 1)), count, dtype=np.intp)
    fill = np.zeros(n, dtype=int)
    for k, i in enumerate(rows.tolist()):
        table[i, fill[i]] = k
        fill[i] += 1
    return RowGroups(n, rows, cols, table)

