"""Matrix products whose columns do not depend on the other columns of the call.

A value of x(t) must be the same float64 number whether t is evaluated alone or with other
times (the result contract). A BLAS product ``A @ B`` with one column per time does not
give that: OpenBLAS picks its kernels by the shape of B (a gemv for one column, edge
kernels for a remainder of columns, fused multiply-adds in some of them), so the rounding
of a column depends on how many columns share the call (measured: 37 of 50 columns of a
3 x 5 by 5 x 64 product differ in the last place from the same column alone).

These products pad the time axis with zero columns to a multiple of :data:`WIDTH` and
make every gemm of one product the same: A (its own layout, in the result's dtype) times
(k, WIDTH) columns, in one stacked matmul (NumPy calls the gemm per chunk in C). One
product over all the columns is not enough: OpenBLAS chooses between its small-matrix
kernels and its blocked ones by the size m·n·k (SkylakeX: at most 100³ takes the small
ones), and the blocked kernels add the partial sums of each block of k, so a 10 x 1000
matrix times 640 columns rounded every column differently from the same column in a
64-column product. A product large enough that a WIDTH-column gemm already takes the
blocked kernels (more than :data:`BLOCKED` multiply-adds) is one gemm over all the padded
columns: every column lies in a full tile of the same kernel. Measured on this machine's
OpenBLAS 0.3.31 (SkylakeX kernels) for shapes from 1 x 12 to 16,000 x 8, real, complex
and mixed, C and Fortran order, 1 to 20,000 columns, one thread and two: 0 of about
2,300 columns differ from the same column alone or among a few others
(``tests/numeric/test_reproducible.py`` checks the products and every engine). Cost: about
the flops of one product for many times; a lone time pays a WIDTH-column product
instead of a matrix-vector one (1000 x 1000: 0.9 ms against 0.27 ms).

Complex products are real products of the real and imaginary parts stacked (zgemm's
kernels on AVX2 machines round a column by the number of columns, dgemm's do not), and
never formed elementwise (NumPy's complex multiply fuses a·c − b·d in its vector loops
but not for a one-element outer product); ``numpy.einsum`` is not used: its loops change
with the shape, and so do its roundings.

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

__all__ = ["WIDTH", "BLOCKED", "columns_product", "rows_product"]

#: Columns per gemm: every gemm of this module has a multiple of this many, a small one
#: exactly this many (a multiple of OpenBLAS's column unrolling, 2 to 8 on x86-64).
WIDTH = 16
#: A product with more multiply-adds than this per gemm of :data:`WIDTH` columns is large:
#: OpenBLAS takes its blocked kernels for it whatever the number of columns (its
#: small-matrix kernels stop at 100³ on SkylakeX; twice that for a margin).
BLOCKED = 2_000_000


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
    if count == 0 or A.shape[1] == 0:
        return np.zeros((A.shape[0], count), dtype=dtype)
    if dtype.kind == "c":
        return _complex_product(A, B, dtype)
    return _real_product(A.astype(dtype, copy=False), B, dtype)


def _complex_product(A: np.ndarray, B: np.ndarray, dtype: np.dtype) -> np.ndarray:
    """A @ B for a complex result through one real product [Re A; Im A] @ [Re B, Im B]:
    OpenBLAS's zgemm on AVX2 machines (Haswell and Zen kernels, 0.3.31) rounds a column
    differently with 16 columns than with 592 for some shapes (100 x 100, 400 x 400,
    10 x 1000), where its dgemm rounds every column the same. The four real blocks are
    combined elementwise, (ArBr − AiBi) + i(ArBi + AiBr), a column from its own column."""
    count = B.shape[1]
    parts_A = [A.real, A.imag] if A.dtype.kind == "c" else [A]
    parts_B = [B.real, B.imag] if B.dtype.kind == "c" else [B]
    real = np.result_type(*parts_A, *parts_B)
    stacked = np.ascontiguousarray(np.concatenate(parts_A, axis=0), dtype=real)
    P = _real_product(stacked, np.concatenate(parts_B, axis=1), real)
    p = A.shape[0]
    blocks = [[P[i * p:(i + 1) * p, j * count:(j + 1) * count] for j in range(len(parts_B))]
              for i in range(len(parts_A))]
    out = np.empty((p, count), dtype=dtype)
    if len(parts_A) == 2 and len(parts_B) == 2:
        out.real = blocks[0][0] - blocks[1][1]
        out.imag = blocks[0][1] + blocks[1][0]
    elif len(parts_A) == 2:
        out.real, out.imag = blocks[0][0], blocks[1][0]
    else:
        out.real, out.imag = blocks[0][0], blocks[0][1]
    return out


def _real_product(A: np.ndarray, B: np.ndarray, dtype: np.dtype) -> np.ndarray:
    """:func:`columns_product` of a real A (its layout is A's own, the same for every
    call) and B, in ``dtype``."""
    count = B.shape[1]
    p, k = A.shape
    padded = -(-count // WIDTH) * WIDTH
    if padded == count and B.dtype == dtype and B.strides[1] == B.itemsize:
        wide = B
    else:
        wide = np.zeros((k, padded), dtype=dtype)
        wide[:, :count] = B
    if padded == WIDTH or A.size * WIDTH > BLOCKED:
        # one gemm; if large, blocked kernels with every column in a full tile
        return np.matmul(A, wide)[:, :count]
    # small: one gemm of WIDTH columns per chunk (small-matrix kernels; NumPy loops in C)
    stacked = wide.reshape(k, padded // WIDTH, WIDTH).transpose(1, 0, 2)
    out = np.matmul(A, stacked).transpose(1, 0, 2).reshape(p, padded)
    return out[:, :count]


def rows_product(X: np.ndarray, A: np.ndarray) -> np.ndarray:
    """X @ A with row j of the result independent of X's other rows (one row per time).

    >>> import numpy as np
    >>> X, A = np.arange(6.0).reshape(3, 2), np.eye(2)
    >>> rows_product(X, A).tolist()
    [[0.0, 1.0], [2.0, 3.0], [4.0, 5.0]]
    """
    return columns_product(np.asarray(A).T, np.asarray(X).T).T
