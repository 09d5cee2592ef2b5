"""The exact state-space form of a scene, and its python-control and SciPy systems.

With the state y = (x, x'), the forces on the masses as inputs u and the positions as
outputs, ``M x'' + C x' + K x = u`` reads

    y' = A y + B u,    x = C_out y + D u,

    A = [[0, I], [−M⁻¹K, −M⁻¹C]],   B = [[0], [M⁻¹]],   C_out = [I, 0],   D = 0,

and y(0) = (x0, v0) (:func:`initial_state`). :func:`state_space` gives the four matrices
exactly (rational numbers, or rational functions of the scene's parameters); its transfer
matrix C_out (sI − A)⁻¹ B is (s²M + sC + K)⁻¹. A scene with massless nodes has a singular
M and only a descriptor form E y' = A y + B u, which is not supported here.

:func:`to_control` and :func:`to_scipy` round the exact matrices entry by entry to float64
and build a ``control.StateSpace`` or a ``scipy.signal.StateSpace``; both packages are
optional (``pip install 'laplace_springs[control]'``).
:func:`laplace_springs.analysis.interop.from_state_space` goes the other way for matrices of
the second-order shape above. This module reads only the scene's matrices and does not import
the scene module, so that ``Scene`` methods can call it.

Examples
--------
>>> from laplace_springs.model.scene import Scene
>>> scene = Scene.from_matrices(M=[[2]], C=[[1]], K=[[8]], x0=[1], v0=[0])
>>> A, B, C, D = state_space(scene)
>>> A
Matrix([
[ 0,    1],
[-4, -1/2]])
>>> B.T, C, D
(Matrix([[0, 1/2]]), Matrix([[1, 0]]), Matrix([[0]]))
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np
import sympy as sp

from ..kernels.first_order import massless_nodes
from .errors import SceneError
from .names import describe_coordinate

if TYPE_CHECKING:
    import control
    import scipy.signal

__all__ = ["SceneMatrices", "state_space", "initial_state", "to_control", "to_scipy"]


class SceneMatrices(Protocol):
    """What these functions read of a :class:`~laplace_springs.model.scene.Scene`.

    (This module does not import the scene module, so that ``Scene`` methods can call it.)
    """

    @property
    def M(self) -> Any: ...
    @property
    def C(self) -> Any: ...
    @property
    def K(self) -> Any: ...
    @property
    def x0(self) -> Any: ...
    @property
    def v0(self) -> Any: ...
    @property
    def names(self) -> tuple[str, ...]: ...
    @property
    def mass_names(self) -> tuple[str, ...]: ...
    @property
    def n(self) -> int: ...

    def normalized(self) -> tuple[Any, Any]: ...

_INSTALL = "pip install 'laplace_springs[control]'"
#: Massless coordinates named in an error message (the rest are counted).
_LISTED = 10

Entries = dict[tuple[int, int], sp.Expr]


def _matrix(rows: int, cols: int, entries: Mapping[tuple[int, int], sp.Expr], like: Any) -> Any:
    """An exact matrix stored as ``like`` (the scene's M) is: dense, or sparse of its class."""
    if isinstance(like, sp.ImmutableSparseMatrix):
        build = getattr(type(like), "from_entries", None)  # ExactSparseMatrix: fast for large scenes
        if build is not None:
            return build(rows, cols, entries)
        return sp.ImmutableSparseMatrix(rows, cols, dict(entries))
    flat: list[Any] = [sp.S.Zero] * (rows * cols)
    for (i, j), value in entries.items():
        flat[i * cols + j] = value
    return sp.ImmutableMatrix(rows, cols, flat)


def _massless(scene: SceneMatrices) -> list[int]:
    """Coordinates whose row and column of M are zero."""
    return massless_nodes(scene.M.todok(), scene.n)


def _descriptor_error(scene: SceneMatrices, detail: str) -> SceneError:
    return SceneError(f"state_space: {detail}; M is singular, so the scene has only a descriptor "
                      "form E y' = A y + B u, which is not supported (give every coordinate a mass)")


def _mass_inverse(scene: SceneMatrices) -> Entries:
    """The nonzero entries of M⁻¹ (M invertible: checked by the caller)."""
    entries = scene.M.todok()
    if all(i == j for i, j in entries):
        return {(i, i): 1 / value for (i, _), value in entries.items()}
    inverse = scene.M.inv()
    if scene.M.free_symbols:
        inverse = inverse.applyfunc(sp.cancel)
    return {key: value for key, value in inverse.todok().items() if value != 0}


def state_space(scene: SceneMatrices) -> tuple[Any, Any, Any, Any]:
    """The exact state-space matrices (A, B, C, D) of a scene.

    State y = (x, x') (positions, then velocities), inputs the forces on the n
    coordinates, outputs the n positions:

        A = [[0, I], [−M⁻¹K, −M⁻¹C]],  B = [[0], [M⁻¹]],  C = [I, 0],  D = 0.

    The scene's initial data and forcing are not part of the matrices: y(0) is
    :func:`initial_state`, and ``scene.forcing`` is the input u(t).

    Parameters
    ----------
    scene : Scene
        Every coordinate has a mass (M invertible); entries may be symbolic.

    Returns
    -------
    A, B, C, D : sympy.ImmutableMatrix
        Of shapes 2n x 2n, 2n x n, n x 2n and n x n, exact. Scenes stored sparse (more
        than ``Limits.dense_storage_max_coordinates`` coordinates) give sparse matrices of the
        class of their M (:class:`~laplace_springs.model.scene.ExactSparseMatrix`).

    Raises
    ------
    SceneError
        When M is singular (massless nodes): the message names the massless coordinates.

    Examples
    --------
    A mass m on a spring k with a dashpot c, all symbolic:

    >>> from laplace_springs.model.scene import Scene
    >>> scene = Scene.from_matrices(M=[["m"]], C=[["c"]], K=[["k"]], x0=[0], v0=[0],
    ...                             parameters=["m", "c", "k"])
    >>> state_space(scene)[0]
    Matrix([
    [   0,    1],
    [-k/m, -c/m]])
    >>> state_space(Scene.from_matrices(M=[[1, 0], [0, 0]], C=[[0, 0], [0, 1]],
    ...                                 K=[[2, -1], [-1, 1]], x0=[0, 0], v0=[0, 0]))
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: state_space: coordinate x2 has zero mass (massless node); M is singular, so the scene has only a descriptor form E y' = A y + B u, which is not supported (give every coordinate a mass)
    """
    n = scene.n
    massless = _massless(scene)
    if massless:
        names = [describe_coordinate(i, names=scene.names, mass_names=scene.mass_names) for i in massless]
        listed = ", ".join(names[:_LISTED]) + (f", ... ({len(names)} in all)" if len(names) > _LISTED else "")
        plural = "s" if len(names) > 1 else ""
        verb = "have" if len(names) > 1 else "has"
        raise _descriptor_error(scene, f"{listed} {verb} zero mass (massless node{plural})")
    try:
        stiffness, damping = scene.normalized()
    except SceneError as error:
        raise _descriptor_error(scene, str(error)) from error
    A: Entries = {(i, n + i): sp.S.One for i in range(n)}
    for (i, j), value in stiffness.todok().items():
        A[(n + i, j)] = -value
    for (i, j), value in damping.todok().items():
        A[(n + i, n + j)] = -value
    B = {(n + i, j): value for (i, j), value in _mass_inverse(scene).items()}
    C = {(i, i): sp.S.One for i in range(n)}
    like = scene.M
    return (_matrix(2 * n, 2 * n, A, like), _matrix(2 * n, n, B, like), _matrix(n, 2 * n, C, like),
            _matrix(n, n, {}, like))


def initial_state(scene: SceneMatrices) -> sp.ImmutableMatrix:
    """The initial state y(0) = (x0, v0) of :func:`state_space`, a 2n x 1 exact column.

    Examples
    --------
    >>> from laplace_springs.model.scene import Scene
    >>> initial_state(Scene.from_matrices(M=[[1]], K=[[4]], x0=["1/2"], v0=[3])).T
    Matrix([[1/2, 3]])
    """
    return sp.ImmutableMatrix.vstack(scene.x0, scene.v0)


def _float_arrays(scene: SceneMatrices, caller: str) -> tuple[np.ndarray, ...]:
    """The state-space matrices rounded entry by entry to float64 (numeric scenes only)."""
    symbols = scene.M.free_symbols | scene.C.free_symbols | scene.K.free_symbols
    if symbols:
        names = sorted(symbol.name for symbol in symbols)
        example = ", ".join(f"{name!r}: ..." for name in names)
        raise SceneError(f"{caller} needs numbers, but M, C, K have the parameters {', '.join(names)}; "
                         f"give them values first: scene.subs({{{example}}})")
    arrays = []
    for name, matrix in zip("ABCD", state_space(scene)):
        array = np.zeros(matrix.shape)
        for (i, j), value in matrix.todok().items():
            array[i, j] = float(value)
        if not np.all(np.isfinite(array)):
            raise SceneError(f"{caller}: an entry of {name} is beyond the float64 range")
        arrays.append(array)
    return tuple(arrays)


def to_control(scene: SceneMatrices) -> control.StateSpace:
    """The scene as a python-control ``StateSpace`` (float64, continuous time).

    The matrices are those of :func:`state_space`, each exact entry rounded to the
    nearest float64. Signals are named after the coordinates: inputs ``f_x1``, ...,
    outputs ``x1``, ..., states ``x1``, ..., ``x1_dot``, .... The free motion is
    ``control.initial_response(sys, T, X0)`` with ``X0`` the float values of
    :func:`initial_state`.

    Raises
    ------
    ImportError
        Without python-control (``pip install 'laplace_springs[control]'``).
    SceneError
        For symbolic M, C or K (the message names the parameters; use ``scene.subs``),
        or massless nodes (see :func:`state_space`).

    Examples
    --------
    >>> from laplace_springs.model.scene import Scene
    >>> sys = to_control(Scene.from_matrices(M=[[1]], C=[["0.2"]], K=[[4]], x0=[1], v0=[0]))
    >>> sys.A.tolist(), sys.input_labels, sys.state_labels
    ([[0.0, 1.0], [-4.0, -0.2]], ['f_x1'], ['x1', 'x1_dot'])
    """
    try:
        import control
    except ImportError as error:
        raise ImportError("to_control needs python-control, an optional dependency of "
                          f"laplace_springs: {_INSTALL}") from error
    A, B, C, D = _float_arrays(scene, "to_control")
    names = list(scene.names)
    return control.StateSpace(A, B, C, D, inputs=[f"f_{name}" for name in names], outputs=names,
                              states=names + [f"{name}_dot" for name in names])


def to_scipy(scene: SceneMatrices) -> scipy.signal.StateSpace:
    """The scene as a ``scipy.signal.StateSpace`` (float64, continuous time).

    The matrices are those of :func:`state_space`, each exact entry rounded to the
    nearest float64; ``scipy.signal.lsim(sys, U, T, X0=...)`` simulates it.

    Raises
    ------
    ImportError
        Without SciPy (``pip install 'laplace_springs[control]'``).
    SceneError
        For symbolic M, C or K, or massless nodes.

    Examples
    --------
    >>> from laplace_springs.model.scene import Scene
    >>> sys = to_scipy(Scene.from_matrices(M=[[1]], C=[["0.2"]], K=[[4]], x0=[1], v0=[0]))
    >>> sys.A.tolist(), sys.B.tolist()
    ([[0.0, 1.0], [-4.0, -0.2]], [[0.0], [1.0]])
    """
    try:
        import scipy.signal
    except ImportError as error:
        raise ImportError(f"to_scipy needs SciPy, an optional dependency of laplace_springs: {_INSTALL}"
                          ) from error
    return scipy.signal.StateSpace(*_float_arrays(scene, "to_scipy"))
