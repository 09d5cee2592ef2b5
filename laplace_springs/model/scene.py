"""The :class:`Scene`: an exact linear system ``M x'' + C x' + K x = 0`` with initial data.

A scene is built from matrices (:meth:`Scene.from_matrices`), from the seed's
normalised form ``x'' + B x' + A x = 0`` (:meth:`Scene.from_normalized`), or from
masses, springs and dashpots (:meth:`Scene.from_components`). Every entry passes
through :func:`laplace_springs.model.numbers.to_exact`, so ``0.2`` is stored as ``1/5``
and identifiers become SymPy Symbols: ``positive=True`` in ``M``, ``C``, ``K`` and
component values (they are physical parameters), ``real=True`` in ``x0``, ``v0``.

Sizes. A scene has at most :attr:`~laplace_springs.limits.Limits.max_coordinates` coordinates and
:attr:`~laplace_springs.limits.Limits.max_components` springs and dashpots, and a matrix given entry by entry (nested
lists or an array) is at most :attr:`~laplace_springs.limits.Limits.max_matrix_input_size` square; each limit is
checked before any entry is converted, and a violation is a :class:`SceneError` naming
the entry and the limit. Up to :attr:`~laplace_springs.limits.Limits.dense_storage_max_coordinates` coordinates ``M``,
``C`` and ``K`` are dense ``sympy.ImmutableMatrix``; larger scenes hold them as
:class:`ExactSparseMatrix` (a ``sympy.ImmutableSparseMatrix``) and every check costs time
proportional to their nonzero entries, so a 10,000-mass chain is built in seconds.
"""

from __future__ import annotations

import contextlib
import dataclasses
import heapq
import importlib
import sys
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import numpy
import sympy
from sympy.core.basic import Basic
from sympy.core.containers import Dict, Tuple
from sympy.matrices.immutable import ImmutableRepMatrix
from sympy.polys.domains import GF
from sympy.polys.matrices import DomainMatrix

from ..limits import limits
from . import state_space as _state_space
from .components import Component
from .equations import read_equations
from .errors import SceneError
from .forcing import forcing_vector
from .names import describe_coordinate, in_coordinate_order
from .numbers import TRANSCENDENTAL, declare_parameters, generic_values, shown, to_exact
from .sampled import Sampled, sampled_entries
from .supports import (
    SUPPORTS,
    is_support,
    parse_support_motion,
    support_motion_latex,
    support_motion_words,
    support_name,
    with_support_forcing,
)
from .symbols import TIME
from .units import SceneUnits, parameter_value, read_scene_units, updated_entries

__all__ = [
    "ExactSparseMatrix",
    "Scene",
]

# SUPPORTS (from .supports): the words naming supports; wall_left, ground2 ... name supports too.
LAYOUTS = ("horizontal", "vertical")

#: Draws a scene's diagram for notebooks: ``renderer(scene, "png" | "svg")`` returns PNG
#: bytes, SVG text or None. model/ does not import output/, so
#: laplace_springs.output.drawing registers it when it is imported (and the first display
#: of a scene imports that module by name, since ``import laplace_springs`` loads nothing).
_DISPLAY_HOOKS: dict[str, Callable[[Any, str], bytes | str | None]] = {}
#: The module that registers the diagram renderer.
_RENDERER_MODULE = "laplace_springs.output.drawing"


def register_diagram_renderer(renderer: Callable[[Any, str], bytes | str | None] | None) -> None:
    """Set the function behind ``Scene._repr_png_`` and ``Scene._repr_svg_`` (None: no diagram).

    Examples
    --------
    >>> from laplace_springs.output.drawing import scene_image   # registers itself
    >>> register_diagram_renderer(None)
    >>> print(Scene.from_matrices(M=[[1]], K=[[1]], x0=[1], v0=[0])._repr_png_())
    None
    >>> register_diagram_renderer(scene_image)
    """
    _DISPLAY_HOOKS.pop("diagram", None)
    if renderer is not None:
        _DISPLAY_HOOKS["diagram"] = renderer


def _diagram(scene: Any, fmt: str) -> bytes | str | None:
    if "diagram" not in _DISPLAY_HOOKS and _RENDERER_MODULE not in sys.modules:
        importlib.import_module(_RENDERER_MODULE)  # registers itself
    renderer = _DISPLAY_HOOKS.get("diagram")
    return renderer(scene, fmt) if renderer is not None else None


#: Draws a scene on matplotlib axes for ``Scene.draw``; registered by output.drawing.
_DRAWERS: dict[str, Callable[..., Any]] = {}


def register_scene_drawer(drawer: Callable[..., Any]) -> None:
    """Set the function behind ``Scene.draw`` (``laplace_springs.draw_scene``)."""
    _DRAWERS["draw"] = drawer


def _drawer() -> Callable[..., Any]:
    if "draw" not in _DRAWERS:
        importlib.import_module(_RENDERER_MODULE)  # registers itself
    return _DRAWERS["draw"]


Parameters = Mapping[str, sympy.Symbol]
Entries = dict[tuple[int, int], sympy.Expr]
_NON_FINITE = (sympy.nan, sympy.zoo, sympy.oo, -sympy.oo)
#: Points λ at which a large scene's pencil is tried for regularity (see _pencil_is_regular).
_SPARSE_PENCIL_POINTS = 3
#: Largest n for the float64 eigenvalue test that accepts a clearly positive definite M.
_FLOAT_CHECK_MAX = 2_000
#: Listed names in error messages (the rest are counted).
_LISTED = 10


class ExactSparseMatrix(sympy.ImmutableSparseMatrix):
    """The ``sympy.ImmutableSparseMatrix`` of a large scene's ``M``, ``C`` and ``K``.

    The same matrix as SymPy's, built in time proportional to its nonzero entries: SymPy
    orders a sparse matrix's entries by a general sort key (about 80 µs per entry); here
    they are ordered by (row, column). Results of operations on it are of this class too.

    Examples
    --------
    >>> K = ExactSparseMatrix.from_dok(3, 3, {(0, 0): 2, (0, 1): -1, (1, 0): -1})
    >>> K == sympy.Matrix([[2, -1, 0], [-1, 0, 0], [0, 0, 0]]), K.todok()[(0, 1)]
    (True, -1)
    """

    @classmethod
    def _fromrep(cls, rep: Any) -> ExactSparseMatrix:
        return cls._with_entries(rep, rep.to_sympy().to_dok())

    @classmethod
    def from_entries(cls, rows: int, cols: int,
                     entries: Mapping[tuple[int, int], sympy.Expr]) -> ExactSparseMatrix:
        """The matrix with these entries (SymPy expressions; zeros are left out)."""
        nonzero = {key: value for key, value in entries.items() if value is not sympy.S.Zero}
        return cls._with_entries(cls._smat_to_DomainMatrix(rows, cols, nonzero), nonzero)

    @classmethod
    def _with_entries(cls, rep: Any, entries: Mapping[tuple[int, int], sympy.Expr]) -> ExactSparseMatrix:
        """The object of ``rep`` (a DomainMatrix), whose nonzero entries are ``entries``."""
        rows, cols = rep.shape
        if len(entries) != rep.nnz():
            entries = rep.to_sympy().to_dok()  # some given entry was a zero after all
        integer: dict[int, sympy.Integer] = {}
        items = []
        new = Basic.__new__
        for (i, j), value in sorted(entries.items(), key=_position):
            row = integer.get(i) or integer.setdefault(i, sympy.Integer(i))
            column = integer.get(j) or integer.setdefault(j, sympy.Integer(j))
            items.append(new(Tuple, new(Tuple, row, column), value))
        table = new(Dict, *items)
        table.elements = frozenset(items)
        table._dict = dict(items)
        obj = new(cls, sympy.Integer(rows), sympy.Integer(cols), table)
        obj._rows, obj._cols, obj._rep = rows, cols, rep
        return obj


def _position(item: tuple[tuple[int, int], Any]) -> tuple[int, int]:
    return item[0]


def _from_entries(rows: int, cols: int, entries: Mapping[tuple[int, int], Any]) -> Any:
    """The exact matrix with these entries (zeros are left out), stored as a scene of
    ``rows`` coordinates stores it."""
    if rows > limits().dense_storage_max_coordinates:
        return ExactSparseMatrix.from_entries(rows, cols, entries)
    flat: list[Any] = [sympy.S.Zero] * (rows * cols)
    for (i, j), value in entries.items():
        flat[i * cols + j] = value
    return sympy.ImmutableMatrix(rows, cols, flat)


def _stored(matrix: Any, n: int) -> Any:
    """``matrix`` in a scene's storage: dense up to Limits.dense_storage_max_coordinates, else sparse."""
    if n > limits().dense_storage_max_coordinates:
        if isinstance(matrix, ExactSparseMatrix):
            return matrix
        return ExactSparseMatrix.from_entries(matrix.rows, matrix.cols, matrix.todok())
    return matrix if isinstance(matrix, sympy.ImmutableMatrix) else sympy.ImmutableMatrix(matrix)


def _listed(names: Iterable[str]) -> str:
    """Names for an error message: the first few, then how many in all."""
    names = list(names)
    if len(names) <= _LISTED:
        return ", ".join(names)
    return f"{', '.join(names[:_LISTED])}, ... ({len(names):,} in all)"


# ----------------------------------------------------------------------------
# Entry conversion
# ----------------------------------------------------------------------------


class _Converter:
    """:func:`to_exact` with the declared parameters, remembering the values of repeated
    plain entries (text, int, float, Fraction): a scene file repeats "1" and "0" thousands
    of times. Only successful conversions are remembered, so every error still names its
    entry."""

    _PLAIN = (str, int, float, Fraction)

    def __init__(self, parameters: Parameters) -> None:
        self.parameters = parameters
        self.known: dict[tuple[type, Any], sympy.Expr] = {}

    def __call__(self, value: Any, entry: str) -> sympy.Expr:
        kind = type(value)
        if kind not in self._PLAIN:
            return to_exact(value, entry, parameters=self.parameters)
        key = (kind, value)
        known = self.known.get(key)
        if known is None:
            known = self.known[key] = to_exact(value, entry, parameters=self.parameters)
        return known


def _check_size(name: str, n: int, limit: int, what: str, hint: str) -> None:
    if n > limit:
        raise SceneError(f"{name}: {n:,} {what}, more than the limit {limit:,}{hint}")


def _check_coordinates(name: str, n: int) -> None:
    _check_size(name, n, limits().max_coordinates, "coordinates", " (Limits.max_coordinates)")


def _rows_of(value: Any, name: str) -> list[list[Any]]:
    """The rows of a matrix given as nested sequences or a numpy array."""
    shape = getattr(value, "shape", None)
    if isinstance(shape, tuple) and shape:
        _check_dense_input(name, int(shape[0]))
    if hasattr(value, "tolist"):
        value = value.tolist()
    if isinstance(value, (str, bytes)) or not isinstance(value, Sequence):
        raise SceneError(f"{name}: expected a matrix (a list of rows), got {shown(value)}")
    _check_dense_input(name, len(value))
    rows = [list(row) if isinstance(row, Sequence) and not isinstance(row, str) else row for row in value]
    for index, row in enumerate(rows):
        if not isinstance(row, list):
            raise SceneError(
                f"{name}: expected a matrix (a list of rows), but row {index} is {shown(row)}"
            )
        if len(row) != len(rows[0]):
            raise SceneError(
                f"{name}: row {index} has {len(row)} entries but row 0 has {len(rows[0])}"
            )
    return rows


def _check_dense_input(name: str, n: int) -> None:
    _check_size(name, n, limits().max_matrix_input_size, "rows given entry by entry",
                " (Limits.max_matrix_input_size); describe a larger scene by its masses, springs and "
                "dashpots (Scene.from_components, or [masses] in a scene file), or give a SymPy "
                "sparse matrix")


def _matrix_shape(value: Any, name: str) -> tuple[int, int]:
    """The shape of a matrix input, read without converting its entries."""
    if isinstance(value, sympy.MatrixBase):
        return value.shape
    rows = _rows_of(value, name)
    return len(rows), len(rows[0]) if rows else 0


def _exact_matrix(value: Any, name: str, convert: _Converter) -> Any:
    """An exact square matrix; each entry converted with the entry name ``name[i,j]``.

    A SymPy matrix is read from its nonzero entries; nested sequences and arrays entry by
    entry (at most Limits.max_matrix_input_size rows).
    """
    if isinstance(value, sympy.MatrixBase):
        rows, cols = value.shape
        _check_coordinates(name, rows)
        given = sorted(value.todok().items(), key=_position)
    else:
        table = _rows_of(value, name)
        rows, cols = len(table), len(table[0]) if table else 0
        given = [((i, j), entry) for i, row in enumerate(table) for j, entry in enumerate(row)]
    if not rows or rows != cols:
        raise SceneError(f"{name} must be a non-empty square matrix, got shape {rows}x{cols}")
    entries: Entries = {}
    for (i, j), entry in given:
        exact = convert(entry, f"{name}[{i},{j}]")
        if exact is not sympy.S.Zero:
            entries[(i, j)] = exact
    return _from_entries(rows, cols, entries)


def _flat_entries(value: Any, name: str) -> list[Any]:
    """The entries of a vector given flat, as a column or as a row."""
    if isinstance(value, sympy.MatrixBase) or hasattr(value, "tolist"):
        value = value.tolist()
    if isinstance(value, (str, bytes)) or not isinstance(value, Sequence):
        raise SceneError(f"{name}: expected a vector (a list of numbers), got {shown(value)}")
    nested = [isinstance(item, Sequence) and not isinstance(item, str) for item in value]
    if not any(nested):
        return list(value)
    if all(nested) and all(len(item) == 1 for item in value):  # column [[a], [b]]
        return [item[0] for item in value]
    if len(value) == 1:  # row [[a, b]]
        return list(value[0])
    raise SceneError(f"{name}: expected a vector (flat, one column or one row), got {shown(value)}")


def _exact_vector(value: Any, name: str, size: int, convert: _Converter) -> sympy.ImmutableMatrix:
    """An exact ``size`` x 1 column; entries named ``name[i]``."""
    entries = _flat_entries(value, name)
    if len(entries) != size:
        raise SceneError(f"{name} has {len(entries)} entries, expected {size} (one per coordinate)")
    return sympy.ImmutableMatrix([convert(entry, f"{name}[{i}]") for i, entry in enumerate(entries)])


# ----------------------------------------------------------------------------
# Validation
# ----------------------------------------------------------------------------


def _check_shape(name: str, shape: tuple[int, int], expected: tuple[int, int], reference: str) -> None:
    if shape != expected:
        raise SceneError(
            f"{name} has shape {shape[0]}x{shape[1]} but {reference} has shape {expected[0]}x{expected[1]}"
        )


def _check_column(name: str, shape: tuple[int, int], n: int) -> None:
    if shape != (n, 1):
        raise SceneError(f"{name} must be a {n}x1 column (one entry per coordinate), "
                         f"got shape {shape[0]}x{shape[1]}")


def _first(entries: Entries, bad: Callable[[Any], bool]) -> tuple[tuple[int, int], Any] | None:
    """The first entry (in row-major order) for which ``bad`` holds, or None."""
    found = [key for key, entry in entries.items() if bad(entry)]
    return (min(found), entries[min(found)]) if found else None


def _not_finite(entry: Any) -> bool:
    if isinstance(entry, sympy.Rational):
        return False
    return not isinstance(entry, sympy.Expr) or entry.has(*_NON_FINITE)


def _has_time(entry: Any) -> bool:
    """Whether ``entry`` holds the time: ls.t, or any Symbol named t (a Symbol named t is
    time wherever it appears, whatever its assumptions)."""
    return not isinstance(entry, sympy.Rational) and (
        entry.has(TIME) or any(symbol.name == "t" for symbol in entry.free_symbols))


def _check_finite(name: str, entries: Entries) -> None:
    first = _first(entries, _not_finite)
    if first is not None:
        (i, j), entry = first
        raise SceneError(f"{name}[{i},{j}] must be a finite number, got {shown(entry)}")


def _check_time_free(entries: Mapping[str, Entries]) -> None:
    """M, C, K, x0 and v0 are constants: the time ``t`` may appear only in ``forcing``."""
    for field in ("M", "C", "K", "x0", "v0"):
        first = _first(entries[field], _has_time)
        if first is not None:
            (i, j), entry = first
            where = f"{field}[{i},{j}]" if field in ("M", "C", "K") else f"{field}[{i}]"
            raise SceneError(f"{where}: the time t may appear only in forcing, got {entry}")


def _is_diagonal(entries: Entries) -> bool:
    return all(i == j for i, j in entries)


def _check_diagonal_masses(entries: Entries) -> None:
    """The diagonal of M (the masses) is nonnegative; a zero is a massless node."""
    for i in sorted(i for i, j in entries if i == j):
        mass = entries[(i, i)]
        if mass.is_nonnegative is False:
            raise SceneError(
                f"mass M[{i},{i}] must be positive, got {mass}; 0 is allowed for a massless node"
            )


def _asymmetry(entries: Entries) -> tuple[tuple[int, int], sympy.Expr, sympy.Expr] | None:
    """The first pair of entries with M[i,j] != M[j,i], or None for a symmetric matrix."""
    for (i, j), value in entries.items():
        other = entries.get((j, i), sympy.S.Zero)
        if value != other and (value.is_Rational and other.is_Rational
                               or sympy.simplify(value - other) != 0):
            return (i, j), value, other
    return None


def _is_symmetric(entries: Entries) -> bool:
    return _asymmetry(entries) is None


def _check_symmetric_mass(entries: Entries) -> None:
    """M is symmetric: the kinetic energy ½ẋᵀMẋ sees only its symmetric part."""
    found = _asymmetry(entries)
    if found is None:
        return
    (i, j), value, other = found
    raise SceneError(
        f"M must be symmetric (the kinetic energy ½ẋᵀMẋ sees only its symmetric part), but "
        f"M[{i},{j}] = {value} but M[{j},{i}] = {other}; C and K may be non-symmetric "
        f"(gyroscopic and circulatory forces), and the seed's non-symmetric A = M⁻¹K "
        f"belongs in Scene.from_normalized(A=..., B=...), which takes M = I")


def _clearly_positive_definite(n: int, entries: Entries) -> bool:
    """Whether float64 eigenvalues prove a numeric symmetric M positive definite.

    |λ(M) − λ(float(M))| is at most the rounding of the entries plus the backward error
    of the symmetric eigensolver, both below 1e-12·‖M‖_F for n ≤ 2,000; a smallest
    computed eigenvalue above 1e-10·‖M‖_F leaves a wide margin. Otherwise (nearly
    singular, indefinite, large) the exact factorisation decides.
    """
    if n > _FLOAT_CHECK_MAX:
        return False
    dense = numpy.zeros((n, n))
    for (i, j), value in entries.items():
        dense[i, j] = float(value)
    if not numpy.all(numpy.isfinite(dense)):
        return False
    size = float(numpy.linalg.norm(dense))
    return bool(numpy.isfinite(size) and numpy.linalg.eigvalsh(dense)[0] > 1e-10 * size)


def _check_numeric_mass_matrix(M: sympy.MatrixBase, entries: Entries) -> None:
    """Symmetric M: positive semi-definite (exact LDLᵀ with diagonal pivoting).

    The factorisation works on the nonzero entries, rows as dictionaries: its cost
    follows the fill-in (none for a diagonal or banded M).
    """
    _check_diagonal_masses(entries)
    if _clearly_positive_definite(M.rows, entries):
        return
    exact: Callable[[sympy.Expr], Any]
    if all(value.is_Rational for value in entries.values()):
        exact = _fraction  # the same values, faster arithmetic
    else:
        exact = _same
    rows: dict[int, dict[int, Any]] = {i: {} for i in range(M.rows)}
    for (i, j), value in entries.items():
        rows[i][j] = exact(value)
    diagonal = {i: row.get(i, 0) for i, row in rows.items()}
    heap = [(-value, i) for i, value in diagonal.items()]
    heapq.heapify(heap)
    while rows:
        negative, k = heapq.heappop(heap)
        if k not in rows or diagonal[k] != -negative:
            continue  # an outdated entry
        pivot = diagonal[k]
        if pivot < 0 or (pivot == 0 and any(rows.values())):
            where = f"M = {M.tolist()}" if M.rows <= 8 else f"the {M.rows}x{M.rows} M"
            raise SceneError(
                f"M must be symmetric positive semi-definite, but it is indefinite "
                f"(a pivot {pivot} remains in its LDLᵀ factorisation) for {where}"
            )
        if pivot == 0:
            return
        row = rows.pop(k)
        others = [(j, value) for j, value in row.items() if j != k]
        for i, below in others:
            target = rows[i]
            target.pop(k, None)
            factor = below / pivot
            for j, value in others:
                updated = target.get(j, 0) - factor * value
                if updated == 0:
                    target.pop(j, None)
                else:
                    target[j] = updated
            diagonal[i] = target.get(i, 0)
            heapq.heappush(heap, (-diagonal[i], i))


def _fraction(value: sympy.Expr) -> Fraction:
    return Fraction(int(value.p), int(value.q))


def _same(value: sympy.Expr) -> sympy.Expr:
    return value


def _full_rank(n: int, entries: Mapping[tuple[int, int], sympy.Expr],
               generic: Mapping[sympy.Symbol, sympy.Rational]) -> bool:
    """Whether the n x n matrix of these entries, symbols at ``generic``, is nonsingular.

    Sparse elimination modulo two primes near 2⁶¹ (:data:`_PRIMES`), without the growth
    of exact fractions: full rank modulo a prime proves full rank over the rationals; a
    deficit modulo both is taken as singular (wrong only if both primes divide the
    determinant's numerator). Entries that are not rational are settled by exact
    elimination.
    """
    rows: dict[int, dict[int, sympy.Expr]] = {}
    for (i, j), given in entries.items():
        value = given.xreplace(generic) if given.free_symbols else given
        if value != 0:
            rows.setdefault(i, {})[j] = value
    if len(rows) < n:
        return False  # a zero row
    ranks = [_rank_modulo(prime, n, rows) for prime in _PRIMES]
    if None not in ranks:
        return n in ranks
    return bool(DomainMatrix.from_dict_sympy(n, n, rows).rank() == n)


#: The primes of :func:`_rank_modulo`: 2⁶¹ − 1 and the largest prime below 2⁶⁰.
_PRIMES = (2**61 - 1, int(sympy.prevprime(2**60)))


def _rank_modulo(prime: int, n: int, rows: Mapping[int, Mapping[int, sympy.Expr]]) -> int | None:
    """The rank of a rational matrix's image modulo ``prime`` (at most its rank over ℚ);
    None when an entry is not rational or has a denominator divisible by the prime."""
    field = GF(prime)
    reduced: dict[int, dict[int, Any]] = {}
    for i, row in rows.items():
        target = reduced[i] = {}
        for j, value in row.items():
            if not value.is_Rational or value.q % prime == 0:
                return None
            target[j] = field(int(value.p) * pow(int(value.q), -1, prime))
    return int(DomainMatrix(reduced, (n, n), field).rank())


def _pencil_points(n: int, sparse: bool) -> list[sympy.Rational]:
    count = min(2 * n + 1, _SPARSE_PENCIL_POINTS) if sparse else 2 * n + 1
    return [sympy.Rational(3 + 2 * point, 7) for point in range(count)]


def _pencil_at(value: sympy.Rational, M: Any, C: Any, K: Any) -> Entries:
    """The nonzero entries of λ²M + λC + K at λ = ``value``."""
    terms: dict[tuple[int, int], list[sympy.Expr]] = {}
    for scale, matrix in ((value**2, M), (value, C), (sympy.S.One, K)):
        for key, entry in matrix.todok().items():
            terms.setdefault(key, []).append(scale * entry)
    return {key: sympy.Add(*parts) for key, parts in terms.items()}


def _determinant(matrix: sympy.Matrix) -> Any:
    """det(matrix) of numbers in SymPy's polynomial domains: entries with algebraic numbers
    (sqrt(2)) in their number field, where the expression domain EX would simplify every
    elimination step (a 4 x 4 pencil with sqrt(2): 0.13 s in EX, 4 ms in QQ<sqrt(2)>)."""
    found = DomainMatrix.from_Matrix(matrix)
    if found.domain.is_EX:
        with contextlib.suppress(sympy.PolynomialError, sympy.CoercionFailed,
                                 NotImplementedError):
            found = DomainMatrix.from_Matrix(matrix, extension=True)
    return found.det()


def _pencil_is_regular(M: sympy.MatrixBase, C: sympy.MatrixBase, K: sympy.MatrixBase) -> bool:
    """Whether det(λ²M + λC + K) is not identically zero.

    Δ has degree ≤ 2n, so it vanishes identically iff it vanishes at 2n + 1 rational
    points; symbols get fixed generic values first, and only if all those points give
    zero is the symbolic determinant formed. A scene of more than
    Limits.dense_storage_max_coordinates coordinates is tried at three points by sparse exact
    elimination, and its pencil taken as singular if all three give zero.
    """
    symbols = sorted(M.free_symbols | C.free_symbols | K.free_symbols, key=lambda s: s.name)
    generic = generic_values(symbols)
    # π, e taken as unknowns too: Δ(λ, π) ≠ 0 at a point proves Δ ≢ 0, and then
    # Δ(λ) ≢ 0 (π is transcendental); EX would simplify every elimination step
    constants = [c for c in TRANSCENDENTAL if any(m.has(c) for m in (M, C, K))]
    generic.update({c: sympy.Rational(101 + 17 * i, 83 + 5 * i) for i, c in enumerate(constants)})
    sparse = M.rows > limits().dense_storage_max_coordinates
    for value in _pencil_points(M.rows, sparse):
        if sparse:
            if _full_rank(M.rows, _pencil_at(value, M, C, K), generic):
                return True
            continue
        pencil = (value**2 * M + value * C + K).xreplace(generic)
        if _determinant(sympy.Matrix(pencil)) != 0:
            return True
        if symbols or constants:
            break
    if not (symbols or constants) or sparse:
        return False
    lam = sympy.Dummy("lambda")
    return sympy.cancel(sympy.Matrix(lam**2 * M + lam * C + K).det(method="berkowitz")) != 0


def _common_null_vector(M: Any, C: Any, K: Any) -> list[sympy.Expr] | None:
    """A nonzero v with Mv = Cv = Kv = 0, or None.

    Scenes of more than Limits.dense_storage_max_coordinates coordinates: only for a diagonal M,
    whose null vectors live on the massless coordinates z (the columns z of C and K are
    searched, symbols at generic values); None otherwise.
    """
    if M.rows <= limits().dense_storage_max_coordinates:
        null = sympy.Matrix.vstack(sympy.Matrix(M), sympy.Matrix(C), sympy.Matrix(K)).nullspace()
        return list(null[0]) if null else None
    masses = M.todok()
    if not _is_diagonal(masses):
        return None
    massless = [i for i in range(M.rows) if (i, i) not in masses]
    if not massless:
        return None
    column = {j: position for position, j in enumerate(massless)}
    generic = generic_values(C.free_symbols | K.free_symbols)
    rows: dict[tuple[str, int], dict[int, sympy.Expr]] = {}
    for name, matrix in (("C", C), ("K", K)):
        for (i, j), value in matrix.todok().items():
            if j in column:
                rows.setdefault((name, i), {})[column[j]] = value.xreplace(generic)
    table = dict(enumerate(rows.values()))
    basis = DomainMatrix.from_dict_sympy(max(len(table), 1), len(massless), table).nullspace()
    if basis.shape[0] == 0:
        return None
    vector = [sympy.S.Zero] * M.rows
    for position, value in enumerate(basis.to_Matrix().row(0)):
        vector[massless[position]] = value
    return vector


def _singular_pencil_message(M: sympy.MatrixBase, C: sympy.MatrixBase, K: sympy.MatrixBase,
                             label: Callable[[int], str]) -> str:
    """Why Δ ≡ 0: name a motion that meets no mass, dashpot or spring, when there is one
    (coordinates named by ``label``, as the user named them)."""
    text = (
        "the pencil λ²M + λC + K is singular: det(λ²M + λC + K) is identically zero, so the "
        "motion is not determined by the equations"
    )
    null = _common_null_vector(M, C, K)
    if null is None:
        if M.rows > limits().dense_storage_max_coordinates:
            points = ", ".join(str(point) for point in _pencil_points(M.rows, True))
            return (f"{text} (it vanishes at λ = {points}, where a scene of more than "
                    f"Limits.dense_storage_max_coordinates = {limits().dense_storage_max_coordinates} coordinates "
                    "is tried)")
        return text
    pivot = next(entry for entry in null if entry != 0)
    vector = [entry / pivot for entry in null]
    coordinates = [i for i, entry in enumerate(vector) if entry != 0]
    if len(coordinates) == 1:
        return f"{text}; {label(coordinates[0])} has zero mass and no spring or dashpot acting on it"
    named = ", ".join(label(i) for i in coordinates[:_LISTED])
    named += f", ... ({len(coordinates):,} in all)" if len(coordinates) > _LISTED else ""
    if len(vector) > 8:
        return (f"{text}; the motion {shown([vector[i] for i in coordinates])} of {named} "
                "(the others at rest) meets no mass, dashpot or spring")
    return f"{text}; the motion along {vector} ({named}) meets no mass, dashpot or spring"


def _check_mass_matrix(M: sympy.MatrixBase, C: sympy.MatrixBase, K: sympy.MatrixBase,
                       entries: Entries, label: Callable[[int], str]) -> None:
    """M (nonzero ``entries``): nonnegative masses / positive semi-definite; if singular, a
    regular pencil."""
    if _is_diagonal(entries):
        _check_diagonal_masses(entries)
        zero = sympy.S.Zero
        singular = any(entries.get((i, i), zero).is_zero is not False for i in range(M.rows))
    else:
        _check_symmetric_mass(entries)
        if not M.free_symbols:
            _check_numeric_mass_matrix(M, entries)
        if M.rows > limits().dense_storage_max_coordinates:
            singular = not _full_rank(M.rows, entries, generic_values(M.free_symbols))
        elif not M.free_symbols:
            singular = M.det() == 0
        else:
            singular = sympy.cancel(M.det()) == 0
    if singular and not _pencil_is_regular(M, C, K):
        raise SceneError(_singular_pencil_message(M, C, K, label))


def _check_names(names: tuple[str, ...], n: int) -> None:
    if len(names) != n:
        raise SceneError(f"names has {len(names)} entries, expected {n} (one per coordinate)")
    if not all(isinstance(name, str) and name for name in names):
        raise SceneError(f"names must be non-empty strings, got {shown(names)}")
    if len(set(names)) != n:
        raise SceneError(f"names must be distinct, got {shown(names)}")


def _default_names(n: int) -> tuple[str, ...]:
    return tuple(f"x{i + 1}" for i in range(n))


# ----------------------------------------------------------------------------
# Components
# ----------------------------------------------------------------------------


def _pairs(items: Mapping[str, Any] | Iterable[Sequence[Any]], what: str,
           width: int) -> list[tuple[str, Any]]:
    """``(label, rest)`` pairs from a mapping ``label -> rest`` or rows ``(label, *rest)``."""
    if isinstance(items, Mapping):
        return list(items.items())
    if isinstance(items, (str, bytes)) or not isinstance(items, Iterable):
        raise SceneError(f"{what}: expected a table (label -> ...) or a list of rows, got {shown(items)}")
    pairs = []
    for row in items:
        if isinstance(row, str) or not isinstance(row, Sequence) or len(row) != width + 1:
            raise SceneError(f"{what}: expected rows of {width + 1} items (label, ...), got {shown(row)}")
        pairs.append((row[0], row[1] if width == 1 else tuple(row[1:])))
    return pairs


def _check_counts(masses: Any, springs: Any, dashpots: Any) -> None:
    """Limits.max_coordinates and Limits.max_components, for inputs whose length is known, before any work."""
    if isinstance(masses, (Mapping, Sequence)):
        _check_size("masses", len(masses), limits().max_coordinates, "masses", " (Limits.max_coordinates)")
    sizes = [len(items) for items in (springs, dashpots) if isinstance(items, (Mapping, Sequence))]
    _check_components(sum(sizes))


def _check_components(count: int) -> None:
    _check_size("springs and dashpots", count, limits().max_components, "components", " (Limits.max_components)")


def _parse_masses(masses: Mapping[str, Any] | Iterable[Sequence[Any]],
                  convert: _Converter) -> dict[str, sympy.Expr]:
    parsed: dict[str, sympy.Expr] = {}
    pairs = _pairs(masses, "masses", 1)
    _check_size("masses", len(pairs), limits().max_coordinates, "masses", " (Limits.max_coordinates)")
    for name, value in pairs:
        if not isinstance(name, str) or not name:
            raise SceneError(f"mass names must be non-empty strings, got {shown(name)}")
        if is_support(name):
            raise SceneError(f"mass name {name!r} is reserved for a fixed support")
        if name in parsed:
            raise SceneError(f"mass {name!r} is given twice")
        mass = convert(value, f"mass {name!r}")
        if mass.is_nonnegative is False:
            raise SceneError(f"mass {name!r} must be positive, got {mass}; 0 is allowed for a massless node")
        parsed[name] = mass
    if not parsed:
        raise SceneError("a scene needs at least one mass")
    return parsed


def _node(node: Any, label: str, kind: str, masses: Mapping[str, sympy.Expr]) -> str:
    """A mass name as given, or a support name in lower case."""
    if isinstance(node, str):
        if node in masses:
            return node
        if is_support(node):
            return str(support_name(node))
    known = _listed(masses)
    supports = ", ".join(sorted(SUPPORTS)) + " (or one of them and _, - or a digit: wall_left)"
    raise SceneError(f"{kind} {label!r}: unknown node {shown(node)}; known masses: {known}; supports: {supports}")


def _component(kind: str, label: Any, spec: Any, masses: Mapping[str, sympy.Expr],
               convert: _Converter) -> Component:
    if not isinstance(label, str) or not label:
        raise SceneError(f"{kind} labels must be non-empty strings, got {shown(label)}")
    if isinstance(spec, str) or not isinstance(spec, Sequence) or len(spec) != 3:
        raise SceneError(f"{kind} {label!r}: expected (node_a, node_b, value), got {shown(spec)}")
    a, b = (_node(node, label, kind, masses) for node in spec[:2])
    if a == b:
        raise SceneError(f"{kind} {label!r} connects {a!r} to itself")
    if is_support(a) and is_support(b):
        raise SceneError(f"{kind} {label!r} connects two supports ({a!r}, {b!r}); it would carry no motion")
    value = convert(spec[2], f"{kind} {label!r}")
    if value.is_negative:
        quantity = "stiffness" if kind == "spring" else "damping"
        raise SceneError(f"{kind} {label!r}: {quantity} must be nonnegative, got {value}")
    return Component(kind, label, a, b, value)


def _parse_components(
    springs: Any, dashpots: Any, masses: Mapping[str, sympy.Expr], convert: _Converter
) -> tuple[Component, ...]:
    components: list[Component] = []
    labels: set[Any] = set()
    given = [(kind, _pairs(items, f"{kind}s", 3)) for kind, items in (("spring", springs), ("dashpot", dashpots))]
    _check_components(sum(len(pairs) for _, pairs in given))
    for kind, pairs in given:
        for label, spec in pairs:
            if _hashable(label) and label in labels:
                raise SceneError(f"component label {label!r} is used twice")
            component = _component(kind, label, spec, masses, convert)
            labels.add(component.label)
            components.append(component)
    return tuple(components)


def _hashable(value: Any) -> bool:
    try:
        hash(value)
    except TypeError:
        return False
    return True


def _assemble(components: Iterable[Component], kind: str, index: Mapping[str, int]) -> Any:
    """Stiffness (springs) or damping (dashpots) matrix of the components of ``kind``.

    A component ``k`` between coordinates i and j adds ``k`` to entries (i, i) and (j, j)
    and ``-k`` to (i, j) and (j, i); to a support, ``k`` to (i, i) only. The terms of each
    entry are summed once, so many components on one entry cost linear time.
    """
    terms: dict[tuple[int, int], list[sympy.Expr]] = {}
    for component in components:
        if component.kind != kind:
            continue
        ends = [index[node] for node in (component.a, component.b) if node in index]
        for i in ends:
            terms.setdefault((i, i), []).append(component.value)
        if len(ends) == 2:
            i, j = ends
            terms.setdefault((i, j), []).append(-component.value)
            terms.setdefault((j, i), []).append(-component.value)
    entries = {key: parts[0] if len(parts) == 1 else sympy.Add(*parts) for key, parts in terms.items()}
    return _from_entries(len(index), len(index), entries)  # zero sums are left out there


def _resolved(mapping: dict[sympy.Symbol, sympy.Expr]) -> dict[sympy.Symbol, sympy.Expr]:
    """Values that name other substituted parameters, with those put in (``c = 2*sqrt(k)``)."""
    for _ in range(len(mapping) + 1):
        cyclic = sorted(symbol.name for symbol, value in mapping.items() if value.has(*mapping))
        if not cyclic:
            return mapping
        mapping = {symbol: value.xreplace(mapping) for symbol, value in mapping.items()}
    raise SceneError(f"subs: the values of {', '.join(cyclic)} refer to each other in a cycle")


def _initial_by_mass(value: Any, name: str, names: Sequence[str],
                     mass_names: Sequence[str] = ()) -> Any:
    """A mapping mass or coordinate name -> value becomes a list in coordinate order
    (missing: 0), names resolved by :func:`~laplace_springs.model.names.coordinate_index`
    (a mass name first)."""
    if value is None:
        return [0] * len(names)
    if not isinstance(value, Mapping):
        return value
    return in_coordinate_order(value, name, names=names, mass_names=mass_names)


# ----------------------------------------------------------------------------
# Scene
# ----------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class Scene:
    """An exact linear system ``M x'' + C x' + K x = 0``, ``x(0) = x0``, ``x'(0) = v0``.

    Build one with :meth:`from_matrices`, :meth:`from_normalized` or
    :meth:`from_components`; the constructor itself expects exact
    ``sympy.ImmutableMatrix`` (or ``ImmutableSparseMatrix``) data, checks shapes and
    masses, and stores ``M``, ``C``, ``K`` as the scene's size calls for.

    Attributes
    ----------
    M, C, K : sympy.ImmutableMatrix or ExactSparseMatrix
        Mass, damping and stiffness matrices, n x n, exact. ``C`` and ``K`` are
        zero matrices when there is no damping or no stiffness. Dense
        ``sympy.ImmutableMatrix`` up to :attr:`~laplace_springs.limits.Limits.dense_storage_max_coordinates`
        coordinates, :class:`ExactSparseMatrix` (a ``sympy.ImmutableSparseMatrix``)
        beyond; the constructor converts to the storage the size calls for. Read their
        nonzero entries with ``.todok()``: it costs time in proportion to them.
    x0, v0 : sympy.ImmutableMatrix
        Initial displacements and velocities, n x 1.
    names : tuple of str
        Coordinate names, by default ``("x1", ..., "xn")``.
    title : str
        A short title.
    layout : str
        ``"horizontal"`` or ``"vertical"``, for drawings.
    components : tuple of Component
        The springs and dashpots, when built from components; else empty.
    mass_names : tuple of str
        The mass names, when built from components; else empty.
    forcing : sympy.ImmutableMatrix or None
        External forces f(t), one exact expression in :data:`laplace_springs.t` per
        coordinate (n x 1), or ``None`` for a free (unforced) motion. See
        :mod:`laplace_springs.model.forcing` for what an input may contain.
    parameters : tuple of sympy.Symbol
        The declared parameters, sorted by name: those declared when the scene was
        built (``parameters=[...]``, a ``[parameters]`` table) and every Symbol in its
        data. See :meth:`subs` to give them values.
    support_motion : tuple of (str, sympy.Expr)
        The moving supports and their displacements u(t) (``support_motion`` of
        :meth:`from_components`); their equivalent force is part of ``forcing``. See
        :mod:`laplace_springs.model.supports`.
    sampled : tuple of (Sampled or None), or None
        Measured force histories (:func:`laplace_springs.model.sampled.sampled`), one
        entry per coordinate, added to ``forcing``; None when there are none. Given as
        forcing entries; they are data, not SymPy expressions.
    units : SceneUnits or None
        For a scene written with units (``"0.5 kg"``, ``"2.5 N/cm"``, pint Quantities):
        the record of the units its author wrote; its numbers are exact SI. None for a
        scene of bare numbers. See :mod:`laplace_springs.model.units`.

    Examples
    --------
    The seed's Example 1 (ceiling - k1 - m1 - k2 - m2):

    >>> scene = Scene.from_components(
    ...     masses={"m1": 1, "m2": "1/2"},
    ...     springs={"k1": ("ceiling", "m1", 2), "k2": ("m1", "m2", 1)},
    ...     x0=[1, 0], v0=[0, 1], title="Example 1", layout="vertical")
    >>> scene
    <Scene 'Example 1': 2 coordinates, undamped>
    >>> scene.K
    Matrix([
    [ 3, -1],
    [-1,  1]])
    >>> A, B = scene.normalized()
    >>> A
    Matrix([
    [ 3, -1],
    [-2,  2]])
    """

    M: sympy.ImmutableMatrix
    C: sympy.ImmutableMatrix
    K: sympy.ImmutableMatrix
    x0: sympy.ImmutableMatrix
    v0: sympy.ImmutableMatrix
    names: tuple[str, ...]
    title: str = ""
    layout: str = "horizontal"
    components: tuple[Component, ...] = ()
    mass_names: tuple[str, ...] = ()
    forcing: sympy.ImmutableMatrix | None = None
    parameters: tuple[sympy.Symbol, ...] = ()
    support_motion: tuple[tuple[str, sympy.Expr], ...] = ()
    sampled: tuple[Sampled | None, ...] | None = None
    units: SceneUnits | None = None

    def __post_init__(self) -> None:
        for field in ("M", "C", "K", "x0", "v0"):
            if not isinstance(getattr(self, field), ImmutableRepMatrix):
                raise SceneError(
                    f"{field} must be a sympy.ImmutableMatrix (or ImmutableSparseMatrix); "
                    "use Scene.from_matrices to convert"
                )
        n = self.M.rows
        if n == 0 or self.M.cols != n:
            raise SceneError(f"M must be a non-empty square matrix, got shape {self.M.rows}x{self.M.cols}")
        _check_coordinates("M", n)
        _check_components(len(self.components))
        for field in ("C", "K"):
            _check_shape(field, getattr(self, field).shape, (n, n), "M")
        for field in ("x0", "v0"):
            _check_column(field, getattr(self, field).shape, n)
        for field in ("M", "C", "K"):
            object.__setattr__(self, field, _stored(getattr(self, field), n))
        for field in ("x0", "v0"):
            if not isinstance(getattr(self, field), sympy.ImmutableMatrix):
                object.__setattr__(self, field, sympy.ImmutableMatrix(getattr(self, field)))
        entries = {field: getattr(self, field).todok() for field in ("M", "C", "K", "x0", "v0")}
        for field in ("M", "C", "K", "x0", "v0"):
            _check_finite(field, entries[field])
        _check_time_free(entries)
        _check_mass_matrix(self.M, self.C, self.K, entries["M"], self._coordinate_label)
        if isinstance(self.names, str):
            raise SceneError(f"names must be a sequence of strings, got {self.names!r}")
        object.__setattr__(self, "names", tuple(self.names))
        _check_names(self.names, n)
        if self.layout not in LAYOUTS:
            raise SceneError(f"layout must be one of {', '.join(LAYOUTS)}, got {shown(self.layout)}")
        if not isinstance(self.title, str):
            raise SceneError(f"title must be a string, got {shown(self.title)}")
        if self.mass_names and len(self.mass_names) != n:
            raise SceneError(f"mass_names has {len(self.mass_names)} entries, expected {n}")
        if self.forcing is not None:
            _check_column("forcing", self.forcing.shape, n)
        if self.sampled is not None:  # measured force histories, apart from the formulas
            if len(self.sampled) != n or not all(s is None or isinstance(s, Sampled) for s in self.sampled):
                raise SceneError(f"sampled must hold {n} entries, each a Sampled or None")
            object.__setattr__(self, "sampled", tuple(self.sampled) if any(self.sampled) else None)
        declared = declare_parameters(self.parameters, self.M, self.C, self.K, self.x0, self.v0,
                                      self.forcing)
        object.__setattr__(self, "parameters", tuple(declared[name] for name in sorted(declared)))

    def _coordinate_label(self, index: int) -> str:
        """Coordinate ``index`` as the user named it (for messages; safe before the names
        are checked)."""
        names = self.names if isinstance(self.names, (tuple, list)) else ()
        masses = self.mass_names if isinstance(self.mass_names, (tuple, list)) else ()
        return describe_coordinate(index, names=[str(name) for name in names],
                                   mass_names=[str(name) for name in masses])

    def _repr_latex_(self) -> str | None:
        """The equations M x'' + C x' + K x = f(t) with their matrices (Jupyter shows it).

        Only for scenes of at most 12 coordinates; larger ones show their ``repr``.

        Examples
        --------
        >>> print(Scene.from_matrices(M=[[2]], K=[[8]], x0=[1], v0=[0])._repr_latex_())
        $\\left[\\begin{matrix}2\\end{matrix}\\right] \\ddot{x} + \\left[\\begin{matrix}8\\end{matrix}\\right] x = 0,\\quad x(0) = \\left[\\begin{matrix}1\\end{matrix}\\right],\\ \\dot{x}(0) = \\left[\\begin{matrix}0\\end{matrix}\\right]$
        """
        if self.n > 12:
            return None
        parts = [f"{sympy.latex(sympy.Matrix(self.M))} \\ddot{{x}}"]
        if self.is_damped:
            parts.append(f"{sympy.latex(sympy.Matrix(self.C))} \\dot{{x}}")
        if any(entry != 0 for entry in self.K.values()):
            parts.append(f"{sympy.latex(sympy.Matrix(self.K))} x")
        right = sympy.latex(sympy.Matrix(self.forcing)) if self.forcing is not None and self.is_forced else "0"
        if self.sampled is not None:  # a measured history is shown by its size, not its samples
            column = self.forcing if self.forcing is not None else sympy.zeros(self.n, 1)
            right = "\\left[\\begin{matrix}" + " \\\\ ".join(
                sympy.latex(column[i]) if s is None else (
                    ("" if column[i] == 0 else sympy.latex(column[i]) + " + ")
                    + f"\\text{{sampled ({s.kind}, {s.times.size} samples)}}")
                for i, s in enumerate(self.sampled)) + "\\end{matrix}\\right]"
        start = (f"x(0) = {sympy.latex(sympy.Matrix(self.x0))},\\ "
                 f"\\dot{{x}}(0) = {sympy.latex(sympy.Matrix(self.v0))}")
        moving = support_motion_latex(self)
        start += f",\\quad {moving}" if moving else ""
        return f"${' + '.join(parts)} = {right},\\quad {start}$"

    def draw(self, ax: Any = None, **options: Any) -> Any:
        """The scene's diagram: :func:`laplace_springs.draw_scene` (needs matplotlib)."""
        return _drawer()(self, ax, **options)

    def _repr_png_(self) -> bytes | None:
        """The scene's diagram as PNG bytes (Jupyter shows it); None without matplotlib or a
        drawable layout (see :func:`laplace_springs.draw_scene`)."""
        out = _diagram(self, "png")
        return out if isinstance(out, bytes) else None

    def _repr_svg_(self) -> str | None:
        """The scene's diagram as SVG text; None without matplotlib or a drawable layout."""
        out = _diagram(self, "svg")
        return out if isinstance(out, str) else None

    def __repr__(self) -> str:
        title = f" {self.title!r}:" if self.title else ""
        damping = "damped" if self.is_damped else "undamped"
        plural = "s" if self.n != 1 else ""
        driven = ", forced" if self.is_forced else ""
        driven += " (sampled)" if self.sampled is not None else ""
        return f"<Scene{title} {self.n} coordinate{plural}, {damping}{driven}{support_motion_words(self)}>"

    # -- properties ---------------------------------------------------------
    @property
    def n(self) -> int:
        """Number of coordinates (degrees of freedom)."""
        return self.M.rows

    @property
    def is_damped(self) -> bool:
        """Whether ``C`` has a nonzero entry."""
        return any(entry != 0 for entry in self.C.todok().values())

    @property
    def is_forced(self) -> bool:
        """Whether an external force acts (``forcing`` has a nonzero entry)."""
        return self.sampled is not None or (
            self.forcing is not None and any(entry != 0 for entry in self.forcing))

    @property
    def free_symbols(self) -> frozenset[sympy.Symbol]:
        """The Symbols in ``M``, ``C``, ``K``, ``x0`` and ``v0``.

        Examples
        --------
        >>> scene = Scene.from_matrices(M=[[1]], K=[["k"]], x0=["d"], v0=[0], parameters=["k", "d"])
        >>> sorted(symbol.name for symbol in scene.free_symbols)
        ['d', 'k']
        """
        symbols: set[sympy.Symbol] = set()
        for matrix in (self.M, self.C, self.K, self.x0, self.v0):
            symbols |= matrix.free_symbols
        if self.forcing is not None:
            symbols |= self.forcing.free_symbols - {TIME}
        return frozenset(symbols)

    # -- derived data -------------------------------------------------------
    def state_space(self) -> tuple[Any, Any, Any, Any]:
        """Exact (A, B, C, D): state (x, x'), forces on the masses in, positions out.

        See :func:`laplace_springs.model.state_space.state_space`.

        Examples
        --------
        >>> A, B, C, D = Scene.from_matrices(M=[[2]], K=[[8]], x0=[1], v0=[0]).state_space()
        >>> A, B.T
        (Matrix([
        [ 0, 1],
        [-4, 0]]), Matrix([[0, 1/2]]))
        """
        return _state_space.state_space(self)

    def to_control(self) -> Any:
        """The scene as a python-control ``StateSpace`` (float64); needs the ``control`` extra."""
        return _state_space.to_control(self)

    def to_scipy(self) -> Any:
        """The scene as a ``scipy.signal.StateSpace`` (float64); needs SciPy."""
        return _state_space.to_scipy(self)

    def normalized(self) -> tuple[sympy.ImmutableMatrix, sympy.ImmutableMatrix]:
        """The seed's normalised matrices ``(A, B) = (M^-1 K, M^-1 C)``, exact.

        Returns
        -------
        A, B : sympy.ImmutableMatrix
            So that the system reads ``x'' + B x' + A x = 0``
            (:class:`ExactSparseMatrix` for a scene stored sparse, which needs a diagonal M).

        Examples
        --------
        >>> scene = Scene.from_matrices(M=[[1, 0], [0, 2]], C=[[0.2, 0], [0, 0.4]],
        ...                             K=[[2, -1], [-1, 1]], x0=[1, 0], v0=[0, 0])
        >>> A, B = scene.normalized()
        >>> A.tolist(), B.tolist()
        ([[2, -1], [-1/2, 1/2]], [[1/5, 0], [0, 1/5]])
        """
        entries = self.M.todok()
        if self.n > limits().dense_storage_max_coordinates:
            return self._sparse_normalized(entries)
        if self.M.det() == 0:
            raise SceneError("the normalised form x'' + B x' + A x = 0 needs an invertible M; "
                             "this scene has massless nodes (M is singular)")
        if _is_diagonal(entries):
            inverse = sympy.diag(*[1 / self.M[i, i] for i in range(self.n)])
        else:
            inverse = self.M.inv()
        simplify = sympy.cancel if self.M.free_symbols else (lambda entry: entry)
        A = (inverse * self.K).applyfunc(simplify)
        B = (inverse * self.C).applyfunc(simplify)
        return sympy.ImmutableMatrix(A), sympy.ImmutableMatrix(B)

    def _sparse_normalized(self, entries: Entries) -> tuple[Any, Any]:
        """(M⁻¹K, M⁻¹C) of a large scene with a diagonal M, row by row."""
        masses = {i: value for (i, j), value in entries.items() if i == j}
        if not _is_diagonal(entries) or len(masses) < self.n \
                or any(mass.is_zero is not False for mass in masses.values()):
            raise SceneError(
                f"the normalised form of a scene of {self.n} coordinates (more than "
                f"Limits.dense_storage_max_coordinates = {limits().dense_storage_max_coordinates}) needs a diagonal "
                "M with nonzero masses; this scene's M is not diagonal or has massless nodes")
        simplify = sympy.cancel if self.M.free_symbols else _same

        def scaled(matrix: Any) -> Any:
            rows = {key: simplify(value / masses[key[0]]) for key, value in matrix.todok().items()}
            return _from_entries(self.n, self.n, rows)

        return scaled(self.K), scaled(self.C)

    def with_initial(self, *, x0: Any = None, v0: Any = None) -> Scene:
        """A new scene with other initial data; ``None`` keeps the current value.

        ``x0`` and ``v0`` are vectors, or mappings from mass or coordinate names to
        values, missing ones 0 (a mass name first: see :mod:`laplace_springs.model.names`).

        Examples
        --------
        >>> scene = Scene.from_matrices(M=[[1]], K=[[4]], x0=[1], v0=[0])
        >>> scene.with_initial(v0=[0.5]).v0
        Matrix([[1/2]])
        >>> scene.with_initial(x0={"x1": "1/3"}).x0
        Matrix([[1/3]])
        """
        declared = declare_parameters(self.parameters, x0, v0)
        given = updated_entries(self.units, {"x0": x0, "v0": v0}, declared)  # in the scene's units
        x0, v0 = given["x0"], given["v0"]
        changes = {}
        for name, value in (("x0", x0), ("v0", v0)):
            if value is not None:
                changes[name] = _exact_vector(_initial_by_mass(value, name, self.names, self.mass_names),
                                              name, self.n, _Converter(declared))
        return dataclasses.replace(self, **changes)

    def with_forcing(self, forcing: Any) -> Scene:
        """A new scene with other external forces (``None`` removes them).

        ``forcing`` is a sequence with one entry per coordinate, or a mapping from mass
        names or coordinate names to entries, missing ones 0 (a mass name first: masses
        named ``x2``, ``x1`` in that order take ``{"x1": f}`` on the second mass). Entries are text in ``t``,
        numbers or SymPy expressions
        (see :func:`laplace_springs.model.forcing.parse_forcing`). The equivalent force
        of moving supports (``support_motion``) stays.

        Examples
        --------
        >>> scene = Scene.from_matrices(M=[[1]], K=[[4]], x0=[0], v0=[0])
        >>> scene.with_forcing(["cos(3*t)"]).forcing
        Matrix([[cos(3*t)]])
        """
        values = None if forcing is None else _initial_by_mass(forcing, "forcing", self.names,
                                                               self.mass_names)
        declared = declare_parameters(self.parameters, forcing)
        values = updated_entries(self.units, {"forcing": values}, declared)["forcing"]
        external = forcing_vector(values, self.n, declared)  # moving supports keep driving:
        return dataclasses.replace(self, forcing=with_support_forcing(
            external, self.components, self.mass_names, self.support_motion),
            sampled=sampled_entries(values))

    def subs(self, values: Mapping[Any, Any]) -> Scene:
        """A new scene with some parameters given values.

        Parameters
        ----------
        values : mapping
            Parameter (a Symbol or its name) -> value: a number, text (which may name
            the other parameters) or a SymPy expression.

        Returns
        -------
        Scene
            Checked like any scene: a value that makes a mass negative or the pencil
            singular is a SceneError.

        Examples
        --------
        >>> scene = Scene.from_matrices(M=[[1]], C=[["c"]], K=[[1]], x0=[1], v0=[0],
        ...                             parameters=["c"])
        >>> scene.parameters
        (c,)
        >>> critical = scene.subs({"c": 2})
        >>> critical.C, critical.parameters
        (Matrix([[2]]), ())
        >>> scene.subs({"k": 2})
        Traceback (most recent call last):
        ...
        laplace_springs.model.errors.SceneError: subs: 'k' is not a parameter of this scene; its parameters are c
        """
        mapping = self._substitution(values)
        remaining = [symbol for symbol in self.parameters if symbol not in mapping]

        def apply(matrix: Any) -> Any:
            if isinstance(matrix, ExactSparseMatrix):
                replaced = {key: value.xreplace(mapping) for key, value in matrix.todok().items()}
                return _from_entries(matrix.rows, matrix.cols, replaced)
            return sympy.ImmutableMatrix(matrix.xreplace(mapping))

        components = tuple(dataclasses.replace(component, value=component.value.xreplace(mapping))
                           for component in self.components)
        for component in components:
            if component.value.is_negative:
                raise SceneError(f"subs: {component.kind} {component.label!r} becomes {component.value}")
        return dataclasses.replace(
            self, M=apply(self.M), C=apply(self.C), K=apply(self.K), x0=apply(self.x0),
            v0=apply(self.v0), forcing=None if self.forcing is None else apply(self.forcing),
            components=components, parameters=tuple(remaining),
            support_motion=tuple((name, u.xreplace(mapping)) for name, u in self.support_motion))

    def _substitution(self, values: Mapping[Any, Any]) -> dict[sympy.Symbol, sympy.Expr]:
        """Symbol -> exact value, each checked against its parameter's assumptions."""
        if not isinstance(values, Mapping):
            raise SceneError(f"subs: expected a mapping parameter -> value, got {shown(values)}")
        by_name = {symbol.name: symbol for symbol in self.parameters}
        known = ", ".join(by_name) or "none"
        mapping: dict[sympy.Symbol, sympy.Expr] = {}
        for key, value in values.items():
            name = key.name if isinstance(key, sympy.Symbol) else key
            if not isinstance(name, str) or name not in by_name:
                raise SceneError(f"subs: {shown(name)} is not a parameter of this scene; "
                                 f"its parameters are {known}")
            given = parameter_value(value, name, self.units, by_name)  # with a unit: in SI
            mapping[by_name[name]] = to_exact(given, f"parameter {name!r}", parameters=by_name)
        mapping = _resolved(mapping)
        for symbol, exact in mapping.items():
            for assumption in ("positive", "nonnegative", "real", "negative"):
                if symbol.assumptions0.get(assumption) and exact.is_extended_real is not None \
                        and getattr(exact, f"is_{assumption}") is False:
                    raise SceneError(f"parameter {symbol.name!r} is {assumption}, got {exact}")
        return mapping

    # -- builders -----------------------------------------------------------
    @classmethod
    def from_matrices(
        cls,
        *,
        M: Any,
        C: Any = None,
        K: Any = None,
        x0: Any,
        v0: Any,
        names: Sequence[str] | None = None,
        title: str = "",
        layout: str = "horizontal",
        forcing: Any = None,
        parameters: Any = None,
        units: Any = None,
    ) -> Scene:
        """A scene from mass, damping and stiffness matrices.

        Parameters
        ----------
        M : matrix-like
            Mass matrix, n x n: nested lists/tuples or a numpy array (at most
            :attr:`~laplace_springs.limits.Limits.max_matrix_input_size` rows: every entry is read), or a SymPy matrix
            (dense or sparse, at most :attr:`~laplace_springs.limits.Limits.max_coordinates` rows: its nonzero entries
            are read). Entries are numbers or text (see
            :func:`laplace_springs.model.numbers.to_exact`).
        C, K : matrix-like, optional
            Damping and stiffness matrices; zero when omitted. Need not be symmetric.
        x0, v0 : vector-like or mapping
            Initial displacements and velocities: flat, one column or one row, or a mapping
            coordinate name -> value (missing ones 0).
        names : sequence of str, optional
            Coordinate names; ``("x1", ..., "xn")`` by default.
        title : str, optional
        layout : {"horizontal", "vertical"}, optional
        forcing : sequence, optional
            External forces, one entry per coordinate: text in ``t`` such as
            ``"10*cos(20*t)"`` or ``"Heaviside(t - 1)"`` (parsed, never evaluated),
            numbers (constant forces) or SymPy expressions. An entry whose Laplace
            transform is not rational times delays is a SceneError. See
            :mod:`laplace_springs.model.forcing`.
        parameters : sequence or mapping, optional
            The names text entries may use as symbolic parameters: ``["k", "c"]``
            (positive), or ``{"a": "real", "k": "stiffness"}`` (an assumption word or a
            description; see :func:`laplace_springs.model.numbers.declare_parameters`).
            A SymPy Symbol in an entry is declared by being there. Any other name in
            text is a SceneError.
        units : None or "SI", optional
            Entries may carry units (``"2 kg"``, ``"250 N/m"``, ``"5 cm"``, pint
            Quantities: M a mass, C a damping, K a stiffness, x0 a length, v0 a velocity,
            forcing a force); they are converted to exact SI and the scene keeps a record
            of them (:mod:`laplace_springs.model.units`). Then every nonzero entry needs
            a unit, unless ``units="SI"`` declares bare numbers to be SI.

        Returns
        -------
        Scene

        Raises
        ------
        SceneError
            For a non-square or empty ``M``, mismatched shapes, a wrong vector length,
            non-finite or non-numeric entries, an undeclared name, a number beyond the
            limits of :mod:`laplace_springs.model.numbers`, a size beyond
            :attr:`~laplace_springs.limits.Limits.max_matrix_input_size` or :attr:`~laplace_springs.limits.Limits.max_coordinates` (before any entry
            is read), a negative mass, an indefinite symmetric ``M``, or a singular
            pencil (det(λ²M + λC + K) identically zero). A zero mass is allowed: it is a
            massless node (see :attr:`Solution.initial_jump`).

        Examples
        --------
        >>> scene = Scene.from_matrices(M=[[1, 0], [0, "1/2"]], C=[["0.2", 0], [0, "0.1"]],
        ...                             K=[[3, -1], [-1, 1]], x0=[1, 0], v0=[0, 0])
        >>> scene.C
        Matrix([
        [1/5,    0],
        [  0, 1/10]])
        >>> Scene.from_matrices(M=[[1]], K=[["k"]], x0=[1], v0=[0], parameters=["k"]).K
        Matrix([[k]])
        >>> Scene.from_matrices(M=[[1, 0], [0, 0]], x0=[0, 0], v0=[0, 0])
        Traceback (most recent call last):
        ...
        laplace_springs.model.errors.SceneError: the pencil λ²M + λC + K is singular: ...; coordinate x2 has zero mass and no spring or dashpot acting on it
        """
        shape = _matrix_shape(M, "M")  # sizes first: nothing is converted beyond the limits
        _check_coordinates("M", shape[0])
        declared = declare_parameters(parameters, M, C, K, x0, v0, forcing)
        given, record = read_scene_units("matrices", {"M": M, "C": C, "K": K, "x0": x0, "v0": v0,
                                                      "forcing": forcing}, declared, units)
        M, C, K, x0, v0, forcing = (given[name] for name in ("M", "C", "K", "x0", "v0", "forcing"))
        convert = _Converter(declared)
        mass = _exact_matrix(M, "M", convert)
        n = mass.rows
        damping = _optional_matrix(C, "C", mass, "M", convert)
        stiffness = _optional_matrix(K, "K", mass, "M", convert)
        if isinstance(names, (str, bytes, Mapping)) or not (names is None or isinstance(names, Iterable)):
            raise SceneError(f"names must be a sequence of strings, got {shown(names)}")
        coordinates = _default_names(n) if names is None else tuple(names)
        x0, v0, forcing = (_initial_by_mass(value, entry, coordinates) if isinstance(value, Mapping)
                           else value for value, entry in ((x0, "x0"), (v0, "v0"), (forcing, "forcing")))
        return cls(
            M=mass,
            C=damping,
            K=stiffness,
            x0=_exact_vector(x0, "x0", n, convert),
            v0=_exact_vector(v0, "v0", n, convert),
            names=coordinates,
            title=title,
            layout=layout,
            forcing=forcing_vector(forcing, n, declared),
            sampled=sampled_entries(forcing),
            parameters=tuple(declared.values()),
            units=record,
        )

    @classmethod
    def from_normalized(
        cls,
        *,
        A: Any,
        B: Any = None,
        x0: Any,
        v0: Any,
        names: Sequence[str] | None = None,
        title: str = "",
        layout: str = "horizontal",
        forcing: Any = None,
        parameters: Any = None,
        units: Any = None,
    ) -> Scene:
        """A scene from the seed's normalised form ``x'' + B x' + A x = f(t)``.

        The scene has ``M = I``, ``K = A`` and ``C = B``. ``A`` need not be
        symmetric (the seed's Example 1 has ``A = [[3, -1], [-2, 2]]``). ``forcing``
        is then a force per unit mass, as in :meth:`from_matrices`. With units, ``A`` is a
        stiffness per mass (``"3 1/s**2"``, ``"3 N/(m*kg)"``), ``B`` a damping per mass
        (``"0.2 1/s"``) and ``forcing`` an acceleration.

        Examples
        --------
        >>> scene = Scene.from_normalized(A=[[3, -1], [-2, 2]], x0=[1, 0], v0=[0, 1])
        >>> scene.M.tolist(), scene.K.tolist()
        ([[1, 0], [0, 1]], [[3, -1], [-2, 2]])
        """
        shape = _matrix_shape(A, "A")
        _check_coordinates("A", shape[0])
        declared = declare_parameters(parameters, A, B, x0, v0, forcing)
        given, record = read_scene_units("normalized", {"A": A, "B": B, "x0": x0, "v0": v0,
                                                        "forcing": forcing}, declared, units)
        A, B, x0, v0, forcing = (given[name] for name in ("A", "B", "x0", "v0", "forcing"))
        convert = _Converter(declared)
        stiffness = _exact_matrix(A, "A", convert)
        n = stiffness.rows
        damping = _optional_matrix(B, "B", stiffness, "A", convert)
        identity = _from_entries(n, n, {(i, i): sympy.S.One for i in range(n)})
        return cls.from_matrices(
            M=identity, C=damping, K=stiffness, x0=x0, v0=v0, names=names, title=title,
            layout=layout, forcing=forcing, parameters=declared, units=record,
        )

    @classmethod
    def from_components(
        cls,
        *,
        masses: Mapping[str, Any] | Iterable[Sequence[Any]],
        springs: Mapping[str, Sequence[Any]] | Iterable[Sequence[Any]] = (),
        dashpots: Mapping[str, Sequence[Any]] | Iterable[Sequence[Any]] = (),
        x0: Any = None,
        v0: Any = None,
        title: str = "",
        layout: str = "horizontal",
        forcing: Any = None,
        parameters: Any = None,
        support_motion: Mapping[str, Any] | None = None,
        units: Any = None,
    ) -> Scene:
        """A scene assembled from masses, springs and dashpots.

        Parameters
        ----------
        masses : mapping of str to number, or sequence of (name, value)
            The masses, in coordinate order.
        springs, dashpots : mapping or sequence, optional
            ``{label: (node_a, node_b, value)}``, or rows ``(label, node_a, node_b, value)``.
            A node is a mass name or a fixed support, one of :data:`~laplace_springs.model.supports.SUPPORTS`
            (case-insensitive). A spring ``k`` between masses i and j adds ``k`` to
            ``K[i,i]`` and ``K[j,j]`` and ``-k`` to ``K[i,j]`` and ``K[j,i]``; to a
            support it adds ``k`` to ``K[i,i]`` only. Dashpots fill ``C`` alike.
        x0, v0 : sequence, or mapping mass name -> value, optional
            Initial data; missing entries are 0.
        forcing : sequence, or mapping mass name -> force, optional
            External forces on the masses (see :meth:`from_matrices`); missing ones 0.
        parameters : sequence or mapping, optional
            Declared parameters, as in :meth:`from_matrices`.
        title : str, optional
        layout : {"horizontal", "vertical"}, optional
        support_motion : mapping support name -> displacement u(t), optional
            Moving supports (base excitation), ``{"ground": "sin(3*t)/100"}``: a spring k
            from mass i to the support pulls with k (u − x_i), a dashpot c with
            c (u' − x_i'), so ``forcing`` gains k u + c u'. ``wall_left``, ``wall_right``,
            ``ground2`` ... are distinct supports. See :mod:`laplace_springs.model.supports`.
        units : None or "SI", optional
            Values may carry units: masses ``"0.5 kg"`` or ``"500 g"``, springs
            ``"250 N/m"`` or ``"2.5 N/cm"``, dashpots ``"1.4 N*s/m"`` or ``"1.4 kg/s"``,
            x0 ``"5 cm"``, v0 ``"2 m/s"``, forces ``"10*cos(3*t) N"`` (t in seconds),
            support motions ``"sin(3*t) cm"``, or pint Quantities; as in
            :meth:`from_matrices`.

        Returns
        -------
        Scene
            With ``components`` and ``mass_names`` set, coordinates named ``x1..xn``.

        Raises
        ------
        SceneError
            For an unknown node, a component from a node to itself or between two
            supports, a negative stiffness or damping, a duplicate label or mass
            name, a negative mass, a singular pencil (a massless node with no spring
            or dashpot), more than :attr:`~laplace_springs.limits.Limits.max_coordinates` masses or more than
            :attr:`~laplace_springs.limits.Limits.max_components` springs and dashpots (before any value is read). A
            mass of 0 is a massless node.

        Examples
        --------
        The seed's Example 5: three spring-dashpot pairs, wall - m1 - m2 - wall.

        >>> scene = Scene.from_components(
        ...     masses={"m1": 1, "m2": 0.8},
        ...     springs={"k1": ("wall", "m1", 400), "k2": ("m1", "m2", 379), "k3": ("m2", "wall", 100)},
        ...     dashpots={"mu1": ("wall", "m1", 0.5), "mu2": ("m1", "m2", 1.4), "mu3": ("m2", "wall", 0.9)},
        ...     x0={"m1": 0.05, "m2": 0.07}, v0=[3, 2])
        >>> scene.C.tolist(), scene.K.tolist()
        ([[19/10, -7/5], [-7/5, 23/10]], [[779, -379], [-379, 479]])
        """
        _check_counts(masses, springs, dashpots)
        declared = declare_parameters(parameters, masses, springs, dashpots, x0, v0, forcing,
                                      support_motion)
        given, record = read_scene_units("components", {
            "masses": masses, "springs": springs, "dashpots": dashpots, "x0": x0, "v0": v0,
            "forcing": forcing, "support_motion": support_motion}, declared, units)
        masses, springs, dashpots, x0, v0, forcing, support_motion = (given[name] for name in (
            "masses", "springs", "dashpots", "x0", "v0", "forcing", "support_motion"))
        convert = _Converter(declared)
        mass_values = _parse_masses(masses, convert)
        components = _parse_components(springs, dashpots, mass_values, convert)
        motion = parse_support_motion(support_motion, components, declared)
        mass_names = tuple(mass_values)
        index = {name: i for i, name in enumerate(mass_names)}
        n = len(mass_names)
        names = _default_names(n)
        diagonal = {(i, i): mass for i, mass in enumerate(mass_values.values()) if mass != 0}
        return cls(
            M=_from_entries(n, n, diagonal),
            C=_assemble(components, "dashpot", index),
            K=_assemble(components, "spring", index),
            x0=_exact_vector(_initial_by_mass(x0, "x0", names, mass_names), "x0", n, convert),
            v0=_exact_vector(_initial_by_mass(v0, "v0", names, mass_names), "v0", n, convert),
            names=names,
            title=title,
            layout=layout,
            components=components,
            mass_names=mass_names,
            forcing=with_support_forcing(None if forcing is None else forcing_vector(
                _initial_by_mass(forcing, "forcing", names, mass_names), n, declared),
                components, mass_names, motion),
            parameters=tuple(declared.values()),
            support_motion=motion,
            sampled=sampled_entries(_initial_by_mass(forcing, "forcing", names, mass_names)),
            units=record,
        )

    @classmethod
    def from_equations(
        cls,
        equations: Any,
        *,
        parameters: Any = None,
        coordinates: Sequence[str] | None = None,
        x0: Any = None,
        v0: Any = None,
        title: str = "",
        layout: str = "horizontal",
    ) -> Scene:
        """A scene from its equations of motion, as text or SymPy ``Eq`` objects.

        Reads primes (``x1'' + 3*x1 - x2 = 0``, ``x1'(0) = 2``), SymPy's notation
        (``Derivative(x1(t), t, 2)``, ``x1(t).diff(t)``, ``Eq`` objects) and Mathematica's
        (``m1*x''[t] + k*x[t] == 0``, ``x[0] == d1``), with initial conditions, values
        (``k1 = 400``) and forces on the right-hand side; the text is parsed, never
        evaluated. See :mod:`laplace_springs.model.equations` for the notations and what
        is refused.

        Parameters
        ----------
        equations : str, sympy.Eq, or a sequence of them
            The equations of motion and (optionally) the initial conditions.
        parameters : sequence or mapping, optional
            Names the text may use as symbols, as in :meth:`from_matrices`.
        coordinates : sequence of str, optional
            The unknown functions in column order.
        x0, v0 : sequence or mapping, optional
            Initial data not given as equations.
        title : str, optional
        layout : {"horizontal", "vertical"}, optional

        Returns
        -------
        Scene
            Rows of M, C, K are the equations (each sign-normalised so that its own
            leading coefficient is positive), columns the coordinates; equations whose M
            is not symmetric but invertible are solved for the accelerations first (M⁻¹
            times both sides: M = I).

        Raises
        ------
        SceneError
            For a term not linear in the unknowns (``x1**2``, ``sin(x1)``), a coefficient
            depending on t, a third derivative, a coordinate without an equation, a
            missing or repeated initial condition, and every error of :meth:`from_matrices`.

        Examples
        --------
        >>> scene = Scene.from_equations('''
        ...     x1'' + 3*x1 - x2 = 0
        ...     x2'' - 2*x1 + 2*x2 = 0
        ...     x1(0) = 1/20; x1'(0) = 2; x2(0) = 0; x2'(0) = 0''')
        >>> scene.K, scene.x0.T
        (Matrix([
        [ 3, -1],
        [-2,  2]]), Matrix([[1/20, 0]]))
        """
        system = read_equations(equations, parameters=parameters, coordinates=coordinates,
                                x0=x0, v0=v0)
        return cls.from_matrices(**system.matrices(), title=title, layout=layout)


def _optional_matrix(value: Any, name: str, reference: Any, reference_name: str,
                     convert: _Converter) -> Any:
    """``value`` as an exact matrix of the shape of ``reference``; zeros when ``None``."""
    if value is None:
        return _from_entries(reference.rows, reference.cols, {})
    _check_shape(name, _matrix_shape(value, name), reference.shape, reference_name)
    return _exact_matrix(value, name, convert)
