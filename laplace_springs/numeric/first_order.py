"""A scene's numbers for the numeric routes: float arrays, the exact first-order system,
and the exact split of rigid-body motion.

Every numeric route starts here, from the scene's exact data:

* :func:`scene_arrays` gives M, C, K, x0, v0 as float64 (or a :class:`SceneError` that
  names the symbolic or out-of-range entry);
* :func:`first_order_system` gives the exact y' = Z y, y(0) = y0 whose first n entries are
  x, with massless nodes held by dashpots reduced (their velocities follow from their
  equations);
* :func:`rigid_split` separates the rigid-body motion (K r = C r = 0) exactly, so that the
  rest of the motion has no zero eigenvalue.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import numpy as np
import sympy as sp
from flint import fmpq, fmpq_mat, fmpz_mat

from ..kernels.first_order import SYMPY, first_order
from ..kernels.first_order import massless_nodes as kernel_massless
from ..limits import limits
from ..model.errors import SceneError
from ..model.scene import Scene

__all__ = ["scene_entries", "rational_entries", "rational_matrices", "scene_cache", "check_numeric_size", "symbolic_entries", "float_matrix", "scene_arrays",
           "massless_nodes", "first_order_system", "RigidSplit", "rigid_split", "is_rational",
           "has_first_order_form"]



_ENTRIES: dict[int, tuple[dict[str, Any], Any]] = {}


def scene_entries(scene: Scene, name: str) -> dict[tuple[int, int], Any]:
    """The nonzero entries of ``scene.M`` (``"M"``, ``"C"``, ``"K"``, ``"x0"``, ``"v0"``) as a
    dict, read once per scene: ``todok`` of a large sparse matrix costs milliseconds, and the
    route checks read every matrix several times. Do not modify the returned dict.

    >>> scene_entries(Scene.from_matrices(M=[[2]], K=[[8]], x0=[1], v0=[0]), "K")
    {(0, 0): 8}
    """
    table = scene_cache(scene)
    if name not in table:
        table[name] = getattr(scene, name).todok()
    return table[name]


def rational_entries(scene: Scene, name: str) -> dict[tuple[int, int], Any] | None:
    """The nonzero entries of ``scene.M`` (``"M"``, ``"C"``, ``"K"``, ``"x0"``, ``"v0"``) as
    flint ``fmpq``, or None when one is not a rational number. Read once per scene, from the
    matrix's integer or rational domain representation when it has one (no SymPy objects:
    a 10,000-mass chain takes milliseconds). Do not modify the returned dict.

    >>> rational_entries(Scene.from_matrices(M=[[2]], K=[["8/3"]], x0=[1], v0=[0]), "K")
    {(0, 0): 8/3}
    """
    return rational_matrices(scene, (name,))[0]


def rational_matrices(scene: Scene, names: tuple[str, ...]) -> list[dict[tuple[int, int], Any] | None]:
    """:func:`rational_entries` of several of the scene's matrices (one look-up of its
    table).

    >>> rational_matrices(Scene.from_matrices(M=[[2]], K=[["8/3"]], x0=[1], v0=[0]), ("M", "K"))
    [{(0, 0): 2}, {(0, 0): 8/3}]
    """
    table = scene_cache(scene)
    out = []
    for name in names:
        key = _RATIONAL_KEYS.get(name) or "rational " + name
        found = table.get(key, table)  # the table itself: not read yet (None is an answer)
        if found is table:
            found = table[key] = _read_rational(scene, name)
        out.append(found)
    return out


_RATIONAL_KEYS = {name: "rational " + name for name in ("M", "C", "K", "x0", "v0")}


def _read_rational(scene: Scene, name: str) -> dict[tuple[int, int], Any] | None:
    matrix = getattr(scene, name)
    rep = getattr(matrix, "_rep", None)
    domain = getattr(rep, "domain", None)
    if rep is not None and domain is not None and (domain.is_ZZ or domain.is_QQ):
        try:
            rows = rep.to_sdm()
            # SymPy's flint ground types hold fmpq (QQ) or fmpz (ZZ) already
            return {(i, j): value if value.__class__ is fmpq else fmpq(value)
                    for i, row in rows.items() for j, value in row.items() if value}
        except (AttributeError, TypeError, ValueError):  # pragma: no cover - another SymPy layout
            pass
    out = {}
    for key, entry in scene_entries(scene, name).items():
        if not entry.is_Rational:
            return None
        out[key] = fmpq(int(entry.p), int(entry.q))
    return out


def scene_cache(scene: Scene) -> dict[str, Any]:
    """A dict kept as long as the scene lives, for facts read from it once (entries, checks).

    >>> scene = Scene.from_matrices(M=[[1]], K=[[1]], x0=[1], v0=[0])
    >>> scene_cache(scene) is scene_cache(scene)
    True
    """
    key = id(scene)
    found = _ENTRIES.get(key)
    if found is None:  # the table, and a reference whose callback drops it with the scene
        found = _ENTRIES[key] = ({}, weakref.ref(scene, _dropper(key)))
    return found[0]


def _dropper(key: int) -> Any:
    """The callback that drops the table of the scene ``key`` when the scene is collected."""
    def drop(_: Any) -> None:
        _ENTRIES.pop(key, None)
    return drop


def symbolic_entries(scene: Scene) -> list[str]:
    """``"K[1,1] = k"`` for every entry of M, C, K, x0, v0 that has a free symbol.

    Examples
    --------
    >>> symbolic_entries(Scene.from_matrices(M=[[1]], K=[["k"]], x0=["d"], v0=[0],
    ...                                      parameters=["k", "d"]))
    ['K[0,0] = k', 'x0[0] = d']
    """
    found = []
    for name in ("M", "C", "K", "x0", "v0"):
        for (i, j), entry in sorted(scene_entries(scene, name).items()):  # nonzero entries
            if entry.free_symbols:
                label = f"{name}[{i}]" if name in ("x0", "v0") else f"{name}[{i},{j}]"
                found.append(f"{label} = {entry}")
    return found


def check_numeric_size(scene: Scene) -> None:
    """A SceneError, at once, for a scene beyond :attr:`~laplace_springs.limits.Limits.general_modal_max_coordinates`.

    Examples
    --------
    >>> check_numeric_size(Scene.from_matrices(M=[[1]], K=[[1]], x0=[1], v0=[0]))  # fine
    """
    if scene.n > limits().general_modal_max_coordinates:
        raise SceneError(
            f"the numeric routes hold a scene as dense float64 matrices and decompose its 2n x 2n "
            f"first-order matrix; this scene has n = {scene.n:,} coordinates, more than "
            f"Limits.general_modal_max_coordinates = {limits().general_modal_max_coordinates:,} (800 take about 30 s on one "
            f"core, and the time grows like n³). Solve a scene of at most "
            f"{limits().general_modal_max_coordinates:,} coordinates (a coarser model). Undamped and "
            "classically damped scenes take the symmetric modal route, and Rayleigh-damped ones "
            "(C = aK + bM, diagonal M) the Chebyshev route, without dense 2n x 2n matrices")


def float_matrix(matrix: sp.MatrixBase, name: str) -> np.ndarray:
    """An exact numeric matrix as float64, or a SceneError naming the first bad entry.

    Reads the nonzero entries only (``todok``), so a sparse matrix converts in time
    proportional to them; the result is dense, and a matrix of more than
    (2·Limits.general_modal_max_coordinates)² entries is refused before it is allocated.

    Examples
    --------
    >>> float_matrix(sp.Matrix([[1, sp.Rational(1, 4)]]), "K")
    array([[1.  , 0.25]])
    >>> float_matrix(sp.Matrix([[sp.Symbol("k")]]), "K")
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: K[0,0] = k is symbolic; give numbers for a numeric evaluation
    """
    rows, cols = matrix.shape
    if rows * cols > (2 * limits().general_modal_max_coordinates) ** 2:
        raise SceneError(f"{name} is {rows:,} x {cols:,}: more entries than a dense float64 array of "
                         f"the numeric routes holds ((2·Limits.general_modal_max_coordinates)², "
                         f"Limits.general_modal_max_coordinates = {limits().general_modal_max_coordinates:,})")
    out = np.zeros(matrix.shape)
    for (i, j), entry in sorted(matrix.todok().items()):
        if entry.free_symbols:
            raise SceneError(f"{name}[{i},{j}] = {entry} is symbolic; give numbers for a "
                             "numeric evaluation")
        try:
            out[i, j] = float(entry)
        except (TypeError, OverflowError, ValueError):
            raise SceneError(f"{name}[{i},{j}] = {entry} has no float64 value") from None
        if not np.isfinite(out[i, j]):
            raise SceneError(f"{name}[{i},{j}] = {entry} is beyond the float64 range")
    return out


def scene_arrays(scene: Scene) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(M, C, K, x0, v0) of a numeric scene as float64 arrays (x0, v0 flat).

    Examples
    --------
    >>> M, C, K, x0, v0 = scene_arrays(Scene.from_matrices(M=[[2]], K=[[8]], x0=[1], v0=[0]))
    >>> M, K, x0
    (array([[2.]]), array([[8.]]), array([1.]))
    """
    check_numeric_size(scene)
    M, C, K = (float_matrix(getattr(scene, name), name) for name in ("M", "C", "K"))
    x0, v0 = (float_matrix(getattr(scene, name).T, name).ravel() for name in ("x0", "v0"))
    return M, C, K, x0, v0


def massless_nodes(scene: Scene) -> list[int]:
    """Indices whose row and column of M are zero (massless nodes)."""
    exact = rational_entries(scene, "M")
    return kernel_massless(scene_entries(scene, "M") if exact is None else exact, scene.n)


def is_rational(scene: Scene) -> bool:
    """Whether every entry of M, C, K, x0 and v0 is a rational number."""
    return all(rational_entries(scene, name) is not None for name in ("M", "C", "K", "x0", "v0"))


def first_order_system(scene: Scene) -> tuple[sp.Matrix, sp.Matrix, list[int]]:
    """Exact y' = Z y, y(0) = y0 whose first n entries are x, for a numeric scene.

    With invertible M this is Z = [[0, I], [-M⁻¹K, -M⁻¹C]], y = [x; x'].
    Massless nodes (indices z whose row and column of M are zero) are reduced: their
    velocity follows from their equations, C_zz x_z' = -(K x)_z - C_zm x_m', so the
    state is y = [x; x_m'] with the massive velocities m only (Maxwell elements and other
    nodes held by a dashpot). Their given v0 entries play no role, as in X(λ).

    Returns
    -------
    Z, y0 : sympy.Matrix
        Exact.
    massive : list of int
        The coordinates whose velocities are state entries n, n + 1, ...

    Raises
    ------
    SceneError
        For massless nodes without an invertible dashpot block C_zz, or a singular mass
        block on the other nodes.

    Examples
    --------
    >>> Z, y0, massive = first_order_system(Scene.from_matrices(M=[[2]], C=[[1]], K=[[8]],
    ...                                                         x0=[1], v0=[3]))
    >>> Z, y0.T, massive
    (Matrix([
    [ 0,    1],
    [-4, -1/2]]), Matrix([[1, 3]]), [0])
    """
    z = massless_nodes(scene)
    try:
        M, C, K = (sp.Matrix(a) for a in (scene.M, scene.C, scene.K))
        Z, y0, m = first_order(M, C, K, list(scene.x0), list(scene.v0), SYMPY, massless=z)
    except ValueError:  # SymPy: "Matrix det == 0; not invertible."
        raise SceneError("the first-order form needs an invertible mass block and, for "
                         f"massless nodes {z}, an invertible dashpot block on them") from None
    return Z, y0, m


@dataclass(frozen=True, eq=False)
class RigidSplit:
    """x(t) = lift·q(t) + offset + slope·t, where q moves as M q'' + C q' + K q = 0,
    q(0) = q0, q'(0) = dq0 and has no rigid-body motion (K and C share no null vector).

    Every matrix is exact (python-flint ``fmpq_mat``); :meth:`arrays` and
    :meth:`rounding` give the float64 data of the inner system and the size of each
    entry's rounding.
    """

    M: Any
    C: Any
    K: Any
    q0: Any
    dq0: Any
    lift: Any
    offset: Any
    slope: Any

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(M, C, K, q0, dq0) of the inner system as float64 (vectors flat)."""
        M, C, K, q0, dq0 = (_float_array(m) for m in (self.M, self.C, self.K, self.q0, self.dq0))
        return M, C, K, q0.ravel(), dq0.ravel()

    def rounding(self) -> tuple[np.ndarray, ...]:
        """|float(a) − a| for every entry of (M, C, K, q0, dq0), exactly."""
        out = [_rounding_array(m) for m in (self.M, self.C, self.K, self.q0, self.dq0)]
        return out[0], out[1], out[2], out[3].ravel(), out[4].ravel()


def _fmpq_mat(matrix: sp.MatrixBase) -> Any:
    """An exact rational SymPy matrix as an fmpq_mat (read from its nonzero entries)."""
    out = fmpq_mat(matrix.rows, matrix.cols)
    for (i, j), entry in matrix.todok().items():
        value = sp.Rational(entry)
        out[i, j] = fmpq(int(value.p), int(value.q))
    return out


def _float_array(matrix: Any) -> np.ndarray:
    return np.array([[float(matrix[i, j]) for j in range(matrix.ncols())]
                     for i in range(matrix.nrows())], dtype=float).reshape(matrix.nrows(), matrix.ncols())


def _rounding_array(matrix: Any) -> np.ndarray:
    out = np.zeros((matrix.nrows(), matrix.ncols()))
    for i in range(matrix.nrows()):
        for j in range(matrix.ncols()):
            entry = matrix[i, j]
            if entry != 0:
                exact = Fraction(int(entry.p), int(entry.q))
                out[i, j] = abs(float(exact - Fraction(float(exact))))
    return out


def _nullspace(*blocks: Any) -> Any:
    """An exact basis (columns, fmpq_mat) of {y : [blocks]·y = 0}, by flint's integer nullspace."""
    rows: list[list[int]] = []
    for block in blocks:
        for i in range(block.nrows()):
            row = [block[i, j] for j in range(block.ncols())]
            scale = math.lcm(*[int(e.q) for e in row if e != 0])
            rows.append([int(e * scale) for e in row])
    basis, rank = fmpz_mat(rows).nullspace()
    cols = blocks[0].ncols()
    return fmpq_mat(cols, rank, [basis[i, j] for i in range(cols) for j in range(rank)])


def rigid_split(scene: Scene) -> RigidSplit | None:
    """Split off the rigid-body motion (K r = C r = 0) exactly; None if there is none.

    With N the left null vectors of K and C, Nᵀ M x(t) = Nᵀ M (x0 + v0 t) fixes the rigid
    part, and the rest moves in the complement Q = ker(Nᵀ M) as the smaller system
    (QᵀMQ, QᵀCQ, QᵀKQ). Also None for massless nodes, symbolic or irrational entries,
    or when the complement's mass matrix is singular. Exact rational arithmetic in
    python-flint throughout (a 200-mass free-free chain splits in a fraction of a second).

    Examples
    --------
    Two free masses joined by a spring: the centre of mass drifts at the mean velocity.

    >>> split = rigid_split(Scene.from_matrices(M=[[1, 0], [0, 1]], K=[[1, -1], [-1, 1]],
    ...                                         x0=[1, 0], v0=[0, 2]))
    >>> split.offset.transpose(), split.slope.transpose(), split.M
    ([1/2, 1/2], [1, 1], [2])
    """
    if not is_rational(scene) or massless_nodes(scene):
        return None
    check_numeric_size(scene)  # before the dense n x n matrices below
    M, C, K = (_fmpq_mat(getattr(scene, name)) for name in ("M", "C", "K"))
    right = _nullspace(K, C)
    if right.ncols() == 0:  # the common case: no rigid motion
        return None
    left = _nullspace(K.transpose(), C.transpose())
    if left.ncols() != right.ncols():
        return None
    weighted = left.transpose() * M
    fixed = weighted * right
    lift = _nullspace(weighted)
    if fixed.det() == 0 or lift.ncols() == 0:
        return None
    inner_mass = lift.transpose() * M * lift
    if inner_mass.det() == 0:
        return None
    solve = fixed.inv() * weighted
    x0, v0 = _fmpq_mat(scene.x0), _fmpq_mat(scene.v0)
    offset, slope = right * solve * x0, right * solve * v0
    normal = lift.transpose() * lift
    q0 = normal.solve(lift.transpose() * (x0 - offset))
    dq0 = normal.solve(lift.transpose() * (v0 - slope))
    if lift * q0 != x0 - offset or lift * dq0 != v0 - slope:
        return None
    return RigidSplit(inner_mass, lift.transpose() * C * lift, lift.transpose() * K * lift,
                      q0, dq0, lift, offset, slope)


def has_first_order_form(scene: Scene) -> bool:
    """Whether y' = Z y exists: the massive block of M invertible and, for massless nodes,
    the dashpot block on them invertible (numeric entries; exact tests).

    Examples
    --------
    >>> has_first_order_form(Scene.from_matrices(M=[[1, 0], [0, 0]], K=[[2, -1], [-1, 1]],
    ...                                          x0=[0, 0], v0=[0, 0]))
    False
    """
    exact = [rational_entries(scene, name) for name in ("M", "C", "K")]
    if any(entries is None for entries in exact) and any(
            not e.is_Rational and e.free_symbols for name in ("M", "C", "K")
            for e in scene_entries(scene, name).values()):
        return False
    z = massless_nodes(scene)
    if not z and all(i == j for i, j in (exact[0] if exact[0] is not None
                                         else scene_entries(scene, "M"))):
        return True  # a diagonal M with every mass nonzero
    m = [i for i in range(scene.n) if i not in z]
    return _invertible(scene.M.extract(m, m)) and (not z or _invertible(scene.C.extract(z, z)))


def _invertible(matrix: sp.MatrixBase) -> bool:
    if matrix.rows == 0:
        return True
    if matrix.is_diagonal():
        return all(matrix[i, i] != 0 for i in range(matrix.rows))
    if all(e.is_Rational for e in matrix):

        return fmpq_mat(matrix.rows, matrix.cols, [fmpq(int(e.p), int(e.q)) for e in matrix]).det() != 0
    return bool(matrix.det() != 0)
