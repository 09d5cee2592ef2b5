"""Interoperability: the exact transfer matrix G(s), poles and zeros, python-control and SciPy.

The Laplace transform of M x'' + C x' + K x = f with zero initial data is
(s²M + sC + K) X(s) = F(s), so the transfer matrix from the forces to the positions is

    G(s) = (s²M + sC + K)⁻¹ = adj(s) / Δ(s),

with Δ the determinant of the resolvent (:mod:`laplace_springs.exact.resolvent`).
:func:`transfer_function` gives it exactly in ``ls.s``; G(iω) is the frequency response H
of :func:`laplace_springs.analysis.frequency.frequency_response`. :func:`poles_and_zeros`
gives the roots of Δ and of one entry's numerator as numbers (certified roots for rational
scenes). :func:`from_state_space` builds a scene from state-space matrices of the
second-order shape.

The state-space form and the conversions to python-control and SciPy live in
:mod:`laplace_springs.model.state_space`, beside the scene (they need only its matrices, and the
``Scene`` methods call them): :func:`~laplace_springs.model.state_space.state_space`,
:func:`~laplace_springs.model.state_space.initial_state`,
:func:`~laplace_springs.model.state_space.to_control`,
:func:`~laplace_springs.model.state_space.to_scipy`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import sympy as sp
from flint import fmpq, fmpq_poly

from ..exact.resolvent import resolvent
from ..kernels.precision import flint_workprec
from ..limits import limits
from ..model.errors import SceneError
from ..model.numbers import declare_parameters, shown, to_exact
from ..model.scene import Scene
from ..model.symbols import S, lam

__all__ = ["transfer_function", "poles_and_zeros", "from_state_space"]

#: Working precision (bits) of the certified roots; their midpoints are rounded to float64.
_ROOT_BITS = 128


def transfer_function(scene: Scene) -> sp.ImmutableMatrix:
    """The exact transfer matrix G(s) = (s²M + sC + K)⁻¹ from forces to positions.

    Parameters
    ----------
    scene : Scene
        Numbers or symbolic parameters; massless nodes are allowed (G is then a proper
        rational matrix of lower degree). Initial data and forcing play no role.

    Returns
    -------
    sympy.ImmutableMatrix
        n x n, entry ``G[i, j]`` the transform of coordinate i's response to a unit
        impulse on coordinate j: a rational function of :data:`laplace_springs.s` in
        lowest terms (numerator and denominator expanded, common factors cancelled).

    Examples
    --------
    A single mass, spring and dashpot, symbolically:

    >>> from laplace_springs.model.scene import Scene
    >>> scene = Scene.from_matrices(M=[["m"]], C=[["c"]], K=[["k"]], x0=[0], v0=[0],
    ...                             parameters=["m", "c", "k"])
    >>> transfer_function(scene)[0, 0]
    1/(c*s + k + m*s**2)

    The seed's Example 2 (x'' + x'/5 + A x = f):

    >>> scene = Scene.from_normalized(A=[[3, -1], [-2, 2]], B=[["0.2", 0], [0, "0.2"]],
    ...                               x0=[1, 0], v0=[0, 0])
    >>> transfer_function(scene)[1, 0]
    50/(25*s**4 + 10*s**3 + 126*s**2 + 25*s + 100)
    """
    R = resolvent(scene)
    at = {lam: S}
    delta = R.determinant.as_expr().xreplace(at)
    return sp.ImmutableMatrix(R.adjugate.applyfunc(lambda entry: sp.cancel(entry.xreplace(at) / delta)))


def _roots(poly: sp.Poly) -> np.ndarray:
    """Complex roots of an exact numeric polynomial, repeated by multiplicity.

    Rational coefficients: python-flint's certified ``complex_roots`` at 128 bits, the
    midpoints rounded to float64. Other exact coefficients (√2, π): ``numpy.roots``.
    """
    if poly.is_zero or poly.degree() <= 0:
        return np.zeros(0, dtype=complex)
    coefficients = poly.all_coeffs()
    if all(c.is_Rational for c in coefficients):
        exact = fmpq_poly([fmpq(int(c.p), int(c.q)) for c in reversed(coefficients)])
        with flint_workprec(_ROOT_BITS):
            pairs: list[Any] = list(exact.complex_roots())  # (root ball, multiplicity)
            found = [(complex(pair[0]), int(pair[1])) for pair in pairs]
        return np.array([root for root, m in found for _ in range(m)], dtype=complex)
    return np.roots(np.array([complex(c) for c in coefficients])).astype(complex)


def _check_index(index: int, n: int, what: str) -> None:
    if isinstance(index, bool) or not isinstance(index, (int, np.integer)) or not 0 <= index < n:
        raise ValueError(f"{what} {index!r} is out of range for a scene with {n} coordinates (0-based)")


def poles_and_zeros(scene: Scene, *, force: int = 0, output: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Poles of the scene and zeros of one entry G[output, force], as complex numbers.

    The poles are the roots of Δ(s) = det(s²M + sC + K), each repeated by its
    multiplicity: the eigenvalues of the state matrix A of
    :func:`~laplace_springs.model.state_space.state_space`. The zeros are the roots of
    adj(s)[output, force], the numerator of G[output, force] over Δ. A zero that lies
    on a pole marks a mode this input-output pair does not see (it cancels in G).

    Parameters
    ----------
    scene : Scene
        Numeric entries.
    force : int
        The coordinate the input force acts on (0-based).
    output : int
        The coordinate whose position is the output (0-based).

    Returns
    -------
    poles, zeros : numpy.ndarray of complex
        Sorted by real part (to 12 digits), then imaginary part. No zeros when the numerator is a
        constant or when G[output, force] is identically zero.

    Raises
    ------
    SceneError
        When M, C or K have symbols.
    ValueError
        For a coordinate out of range.

    Examples
    --------
    Two masses on springs 1 (wall - m1 - m2): a force on m1 moving m1 has the zeros ±i,
    the natural frequency of m2 on its own spring.

    >>> from laplace_springs.model.scene import Scene
    >>> scene = Scene.from_matrices(M=[[1, 0], [0, 1]], K=[[2, -1], [-1, 1]], x0=[0, 0], v0=[0, 0])
    >>> poles, zeros = poles_and_zeros(scene)
    >>> np.round(np.abs(poles.imag), 6).tolist(), zeros.round(12).tolist()
    ([1.618034, 0.618034, 0.618034, 1.618034], [-1j, 1j])
    """
    symbols = scene.M.free_symbols | scene.C.free_symbols | scene.K.free_symbols
    if symbols:
        names = ", ".join(sorted(symbol.name for symbol in symbols))
        raise SceneError(f"poles and zeros need numbers, but M, C, K have the parameters {names}; "
                         "give them values with scene.subs(...)")
    _check_index(force, scene.n, "force")
    _check_index(output, scene.n, "output")
    R = resolvent(scene)
    poles = _roots(R.determinant)
    zeros = _roots(sp.Poly(R.adjugate[output, force], lam))
    return _sorted(poles), _sorted(zeros)


def _sorted(values: np.ndarray) -> np.ndarray:
    """By real part, then imaginary part; real parts equal to 12 digits count as equal
    (a conjugate pair computed in floats keeps its order, −i before +i)."""
    if values.size == 0:
        return values
    scale = float(np.max(np.abs(values))) or 1.0
    order = np.lexsort((values.imag, np.round(values.real / scale, 12)))
    return values[order]


# ----------------------------------------------------------------------------
# Back from a state-space form
# ----------------------------------------------------------------------------


def _rows(value: Any, name: str) -> list[list[Any]]:
    """Nested rows of a matrix-like value (lists, a numpy array, a SymPy matrix), or a
    SceneError naming the matrix and what is wrong with its shape."""
    expected = f"{name} must be a matrix: rows of entries (nested lists, a 2-D array or a SymPy matrix)"
    if isinstance(value, (str, bytes, Mapping)) or not (hasattr(value, "__iter__") or hasattr(value, "tolist")):
        raise SceneError(f"{expected}, got {shown(value)}")
    rows = value.tolist() if hasattr(value, "tolist") else list(value)
    if not isinstance(rows, list):
        raise SceneError(f"{expected}, got {shown(value)}")
    for index, row in enumerate(rows):
        if isinstance(row, (str, bytes)) or not isinstance(row, (list, tuple, Sequence)):
            raise SceneError(f"{expected}; row {index} is {shown(row)}, not a row of entries "
                             f"(a flat list is a vector: write [[...], [...]])")
    if len({len(row) for row in rows}) > 1:
        lengths = [len(row) for row in rows]
        raise SceneError(f"{name} has rows of different lengths: {shown(lengths)}")
    return [list(row) for row in rows]


def _exact(value: Any, name: str, shape: tuple[int, int], parameters: Mapping[str, sp.Symbol]
           ) -> sp.Matrix:
    rows = _rows(value, name)
    found = (len(rows), len(rows[0]) if rows else 0)
    if found != shape:
        raise SceneError(f"{name} must be {shape[0]} x {shape[1]}, got {found[0]} x {found[1]}")
    return sp.Matrix(shape[0], shape[1], [to_exact(entry, f"{name}[{i},{j}]", parameters=parameters)
                                          for i, row in enumerate(rows) for j, entry in enumerate(row)])


def _same(value: sp.Expr, target: sp.Expr) -> bool:
    difference = value - target
    return bool(difference == 0 or (difference.free_symbols and sp.simplify(difference) == 0))


def _check_block(matrix: sp.Matrix, name: str, target: sp.Matrix, what: str, offset: tuple[int, int]
                 ) -> None:
    for i in range(target.rows):
        for j in range(target.cols):
            if not _same(matrix[i, j], target[i, j]):
                raise SceneError(
                    f"{name}[{i + offset[0]},{j + offset[1]}] = {matrix[i, j]}, expected {target[i, j]}: "
                    f"{what}; a general first-order system has no spring-mass form here")


def from_state_space(A: Any, B: Any = None, C: Any = None, D: Any = None, *,
                     x0: Any = None, v0: Any = None, names: Sequence[str] | None = None,
                     title: str = "", parameters: Any = None) -> Scene:
    """A scene from state-space matrices of the shape of :func:`~laplace_springs.model.state_space.state_space`.

    ``A`` must read [[0, I], [−K', −C']] (state (x, x')). Without ``B`` the scene has
    M = I, K = K', C = C' (the normalised form x'' + C'x' + K'x = 0); with
    ``B = [[0], [M⁻¹]]`` it has that M, K = M K' and C = M C', so that
    ``from_state_space(*state_space(scene))`` gives back the scene's matrices.
    ``C`` must be [I, 0] (the positions) and ``D`` zero, when given.

    Parameters
    ----------
    A : matrix-like, 2n x 2n
    B : matrix-like, 2n x n, optional
    C : matrix-like, n x 2n, optional
    D : matrix-like, n x n, optional
        Entries as in :meth:`Scene.from_matrices`: numbers, text, SymPy expressions
        (a float is its shortest decimal, 0.2 is 1/5).
    x0, v0 : vector-like, optional
        Initial positions and velocities (zero by default).
    names, title, parameters
        As in :meth:`Scene.from_matrices`.

    Returns
    -------
    Scene

    Raises
    ------
    SceneError
        When a matrix is not of the second-order shape (the message names the first entry
        that is not), has the wrong size, or the scene it gives is invalid.

    Examples
    --------
    >>> scene = from_state_space([[0, 0, 1, 0], [0, 0, 0, 1], [-3, 1, "-0.2", 0], [2, -2, 0, "-0.2"]],
    ...                          x0=[1, 0], v0=[0, 0])
    >>> scene.K.tolist(), scene.C.tolist()
    ([[3, -1], [-2, 2]], [[1/5, 0], [0, 1/5]])
    >>> from_state_space([[0, 1], [1, 0]], [[1], [1]])
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: B[0,0] = 1, expected 0: inputs must be forces on the masses, B = [[0], [M^-1]]; a general first-order system has no spring-mass form here
    """
    given = getattr(A, "shape", None) or ((len(A),) if isinstance(A, Sequence) else ())
    if given and int(given[0]) > 2 * limits().max_matrix_input_size:  # before reading any entry
        raise SceneError(f"A has {int(given[0]):,} rows; at most {2 * limits().max_matrix_input_size} "
                         "square is read entry by entry (Limits.max_matrix_input_size)")
    rows = _rows(A, "A")
    size = len(rows)
    if size == 0 or size % 2 or any(len(row) != size for row in rows):
        raise SceneError(f"A must be square with an even size 2n (state (x, x')), got {size} rows")
    if size > 2 * limits().max_matrix_input_size:
        raise SceneError(f"A is {size} x {size}; at most {2 * limits().max_matrix_input_size} square is read "
                         "entry by entry")
    n = size // 2
    declared = declare_parameters(parameters, A, B, C, D, x0, v0)
    exact_A = _exact(rows, "A", (size, size), declared)
    identity, zero = sp.eye(n), sp.zeros(n, n)
    shape = "A must read [[0, I], [-K', -C']] for the state (x, x')"
    _check_block(exact_A[:n, :n], "A", zero, shape, (0, 0))
    _check_block(exact_A[:n, n:], "A", identity, shape, (0, n))
    mass = identity
    if B is not None:
        exact_B = _exact(B, "B", (size, n), declared)
        _check_block(exact_B[:n, :], "B", zero, "inputs must be forces on the masses, B = [[0], [M^-1]]",
                     (0, 0))
        lower = exact_B[n:, :]
        if lower.det() == 0:
            raise SceneError("the lower block of B (M^-1) is singular: inputs must be one force per mass")
        mass = lower.inv().applyfunc(sp.cancel)
    if C is not None:
        _check_block(_exact(C, "C", (n, size), declared), "C", identity.row_join(zero),
                     "outputs must be the positions, C = [I, 0]", (0, 0))
    if D is not None:
        _check_block(_exact(D, "D", (n, n), declared), "D", zero, "D must be zero", (0, 0))
    stiffness = (mass * -exact_A[n:, :n]).applyfunc(sp.cancel)
    damping = (mass * -exact_A[n:, n:]).applyfunc(sp.cancel)
    return Scene.from_matrices(M=mass, C=damping, K=stiffness, x0=[0] * n if x0 is None else x0,
                               v0=[0] * n if v0 is None else v0, names=names, title=title,
                               parameters=declared)
