"""Matrix products whose columns do not depend on the other columns of the call.

A value of x(t) must be the same float64 number whether t is evaluated alone or with other
times (the result contract). A BLAS product ``A @ B`` with one column per time does not
give that: OpenBLAS picks its kernels by the shape of B (a gemv for one column, edge
kernels for a remainder of columns, fused multiply-adds in some of them), so the rounding
of a column depends on how many columns share the call (measured: 37 of 50 columns of a
3 x 5 by 5 x 64 product differ in the last place from the same column alone).

These products cut the time axis into chunks of exactly :data:`WIDTH` columns (the last
one zero-padded), so that every gemm has the same shape whatever the number of times; in
a fixed-shape gemm a column's rounding does not depend on its position or on the other
columns (measured on this machine's OpenBLAS for shapes from 3 x 5 to 1000 x 2000, real
and complex: 0 of 460 columns differ; ``tests/numeric/test_reproducible.py`` checks every
engine alone against random batches). Cost: the same flops as one product for many
times; a lone time pays a 64-column product instead of a matrix-vector one. A short
inner dimension (at most :data:`SHORT` terms) is summed term by term in index order with
elementwise outer products instead: the same IEEE operations for every entry whatever the
others (10⁵ times by a 6 x 6 matrix in 7 ms, against 18 ms in chunks and 108 ms for one
matmul; ``numpy.einsum`` is not used: its loops change with the shape, and so do its
roundings).

>>> import numpy as np
>>> rng = np.random.default_rng(0)
>>> A, B = rng.standard_normal((7, 9)), rng.standard_normal((9, 100))
>>> together = columns_product(A, B)
>>> alone = columns_product(A, B[:, [37]])
>>> bool(np.array_equal(together[:, 37], alone[:, 0]))
True
"""

from __future__ import annotations

import numpy as np

__all__ = ["WIDTH", "SHORT", "columns_product", "rows_product"]

#: Columns (or rows) per gemm: every product of this module has this many.
WIDTH = 64
#: Inner dimensions up to this are summed elementwise, term by term in index order.
SHORT = 16


def columns_product(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """A @ B with column j of the result independent of B's other columns.

    Parameters
    ----------
    A : numpy.ndarray
        (p, k), real or complex.
    B : numpy.ndarray
        (k, T): one column per time.

    Returns
    -------
    numpy.ndarray
        (p, T), the dtype of ``A @ B``.
    """
    A, B = np.asarray(A), np.asarray(B)
    dtype = np.result_type(A, B)
    count = B.shape[1]
    out = np.empty((A.shape[0], count), dtype=dtype)
    if count == 0:
        return out
    if A.shape[1] == 0:
        out[...] = 0
        return out
    if A.shape[1] <= SHORT:  # term by term in index order: one IEEE sequence per entry
        B = np.ascontiguousarray(B)
        np.multiply.outer(A[:, 0], B[0], out=out)
        for j in range(1, A.shape[1]):
            out += np.multiply.outer(A[:, j], B[j])
        return out
    chunk = np.zeros((B.shape[0], WIDTH), dtype=B.dtype)
    for start in range(0, count, WIDTH):
        stop = min(start + WIDTH, count)
        chunk[:, : stop - start] = B[:, start:stop]
        chunk[:, stop - start:] = 0
        out[:, start:stop] = (A @ chunk)[:, : stop - start]
    return out


def rows_product(X: np.ndarray, A: np.ndarray) -> np.ndarray:
    """X @ A with row j of the result independent of X's other rows (one row per time).

    >>> import numpy as np
    >>> X, A = np.arange(6.0).reshape(3, 2), np.eye(2)
    >>> rows_product(X, A).tolist()
    [[0.0, 1.0], [2.0, 3.0], [4.0, 5.0]]
    """
    return columns_product(np.asarray(A).T, np.asarray(X).T).T
