"""The :class:`Scene`: an exact linear system ``M x'' + C x' + K x = 0`` with initial data.

A scene is built from matrices (:meth:`Scene.from_matrices`), from the seed's
normalised form ``x'' + B x' + A x = 0`` (:meth:`Scene.from_normalized`), or from
masses, springs and dashpots (:meth:`Scene.from_components`). Every entry passes
through :func:`laplace_springs.model.numbers.to_exact`, so ``0.2`` is stored as ``1/5``
and identifiers become SymPy Symbols: ``positive=True`` in ``M``, ``C``, ``K`` and
component values (they are physical parameters), ``real=True`` in ``x0``, ``v0``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import sympy
from sympy.polys.matrices import DomainMatrix

from .errors import SceneError
from .forcing import forcing_vector
from .numbers import declare_parameters, generic_values, shown, to_exact
from .symbols import TIME

__all__ = ["SUPPORTS", "Component", "Scene"]

#: Names of fixed supports a spring or dashpot may connect to (case-insensitive).
SUPPORTS = frozenset({"wall", "ceiling", "ground", "floor", "support", "air"})
LAYOUTS = ("horizontal", "vertical")

Parameters = Mapping[str, sympy.Symbol]
_NON_FINITE = (sympy.nan, sympy.zoo, sympy.oo, -sympy.oo)


@dataclass(frozen=True)
class Component:
    """A spring or dashpot between two nodes (mass names or fixed supports).

    Attributes
    ----------
    kind : str
        ``"spring"`` (value is a stiffness) or ``"dashpot"`` (value is a damping constant).
    label : str
        The component's name, e.g. ``"k1"`` or ``"mu2"``.
    a, b : str
        The nodes it connects: mass names, or a support name in lower case.
    value : sympy.Expr
        The exact stiffness or damping constant.
    """

    kind: str
    label: str
    a: str
    b: str
    value: sympy.Expr


# ----------------------------------------------------------------------------
# Entry conversion
# ----------------------------------------------------------------------------


def _rows_of(value: Any, name: str) -> list[list[Any]]:
    """The rows of a matrix given as nested sequences, a numpy array or a SymPy matrix."""
    if isinstance(value, sympy.MatrixBase) or hasattr(value, "tolist"):
        value = value.tolist()
    if isinstance(value, (str, bytes)) or not isinstance(value, Sequence):
        raise SceneError(f"{name}: expected a matrix (a list of rows), got {shown(value)}")
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


def _exact_matrix(value: Any, name: str, parameters: Parameters) -> sympy.ImmutableMatrix:
    """An exact square matrix; each entry converted with the entry name ``name[i,j]``."""
    rows = _rows_of(value, name)
    if not rows or len(rows) != len(rows[0]):
        columns = len(rows[0]) if rows else 0
        raise SceneError(f"{name} must be a non-empty square matrix, got shape {len(rows)}x{columns}")
    entries = [
        [to_exact(entry, f"{name}[{i},{j}]", parameters=parameters) for j, entry in enumerate(row)]
        for i, row in enumerate(rows)
    ]
    return sympy.ImmutableMatrix(entries)


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


def _exact_vector(value: Any, name: str, size: int, parameters: Parameters) -> sympy.ImmutableMatrix:
    """An exact ``size`` x 1 column; entries named ``name[i]``."""
    entries = _flat_entries(value, name)
    if len(entries) != size:
        raise SceneError(f"{name} has {len(entries)} entries, expected {size} (one per coordinate)")
    return sympy.ImmutableMatrix(
        [to_exact(entry, f"{name}[{i}]", parameters=parameters) for i, entry in enumerate(entries)]
    )


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


def _check_finite(name: str, matrix: sympy.MatrixBase) -> None:
    for index, entry in enumerate(matrix):
        if not isinstance(entry, sympy.Expr) or entry.has(*_NON_FINITE):
            i, j = divmod(index, matrix.cols)
            raise SceneError(f"{name}[{i},{j}] must be a finite number, got {entry!r}")


def _check_time_free(scene: Scene) -> None:
    """M, C, K, x0 and v0 are constants: the time ``t`` may appear only in ``forcing``."""
    for field in ("M", "C", "K", "x0", "v0"):
        matrix = getattr(scene, field)
        for index, entry in enumerate(matrix):
            if entry.has(TIME):
                i, j = divmod(index, matrix.cols)
                where = f"{field}[{i},{j}]" if field in ("M", "C", "K") else f"{field}[{index}]"
                raise SceneError(f"{where}: the time t may appear only in forcing, got {entry}")


def _check_diagonal_masses(M: sympy.MatrixBase) -> None:
    """The diagonal of M (the masses) is nonnegative; a zero is a massless node."""
    for i in range(M.rows):
        mass = M[i, i]
        if mass.is_nonnegative is False:
            raise SceneError(
                f"mass M[{i},{i}] must be positive, got {mass}; 0 is allowed for a massless node"
            )


def _check_numeric_mass_matrix(M: sympy.MatrixBase) -> None:
    """Symmetric M: positive semi-definite (exact LDLᵀ with diagonal pivoting)."""
    if not M.is_symmetric():
        return  # only the pencil's regularity is required (checked by the caller)
    _check_diagonal_masses(M)
    work = sympy.Matrix(M)
    rest = list(range(M.rows))
    while rest:
        k = max(rest, key=lambda i: work[i, i])
        pivot = work[k, k]
        if pivot < 0 or (pivot == 0 and any(work[i, j] != 0 for i in rest for j in rest)):
            raise SceneError(
                f"M must be symmetric positive semi-definite, but it is indefinite "
                f"(a pivot {pivot} remains in its LDLᵀ factorisation) for M = {M.tolist()}"
            )
        if pivot == 0:
            return
        rest.remove(k)
        for i in rest:
            factor = work[i, k] / pivot
            for j in rest:
                work[i, j] -= factor * work[k, j]


def _pencil_is_regular(M: sympy.MatrixBase, C: sympy.MatrixBase, K: sympy.MatrixBase) -> bool:
    """Whether det(λ²M + λC + K) is not identically zero.

    Δ has degree ≤ 2n, so it vanishes identically iff it vanishes at 2n + 1 rational
    points; symbols get fixed generic values first, and only if all those points give
    zero is the symbolic determinant formed.
    """
    symbols = sorted(M.free_symbols | C.free_symbols | K.free_symbols, key=lambda s: s.name)
    generic = generic_values(symbols)
    for point in range(2 * M.rows + 1):
        value = sympy.Rational(3 + 2 * point, 7)
        pencil = (value**2 * M + value * C + K).xreplace(generic)
        if DomainMatrix.from_Matrix(sympy.Matrix(pencil)).det() != 0:
            return True
        if symbols:
            break
    if not symbols:
        return False
    lam = sympy.Dummy("lambda")
    return sympy.cancel(sympy.Matrix(lam**2 * M + lam * C + K).det(method="berkowitz")) != 0


def _singular_pencil_message(M: sympy.MatrixBase, C: sympy.MatrixBase, K: sympy.MatrixBase) -> str:
    """Why Δ ≡ 0: name a motion that meets no mass, dashpot or spring, when there is one."""
    text = (
        "the pencil λ²M + λC + K is singular: det(λ²M + λC + K) is identically zero, so the "
        "motion is not determined by the equations"
    )
    null = sympy.Matrix.vstack(sympy.Matrix(M), sympy.Matrix(C), sympy.Matrix(K)).nullspace()
    if not null:
        return text
    vector = null[0] / next(entry for entry in null[0] if entry != 0)
    coordinates = [i for i, entry in enumerate(vector) if entry != 0]
    if len(coordinates) == 1:
        return f"{text}; coordinate {coordinates[0]} has no mass and no spring or dashpot acting on it"
    return (
        f"{text}; the motion along {list(vector)} (coordinates {coordinates}) meets no mass, "
        "dashpot or spring"
    )


def _check_mass_matrix(M: sympy.MatrixBase, C: sympy.MatrixBase, K: sympy.MatrixBase) -> None:
    """M: nonnegative masses / positive semi-definite; if singular, a regular pencil."""
    if M.is_diagonal():
        _check_diagonal_masses(M)
        singular = any(M[i, i].is_zero is not False for i in range(M.rows))
    elif not M.free_symbols:
        _check_numeric_mass_matrix(M)
        singular = M.det() == 0
    else:
        singular = sympy.cancel(M.det()) == 0
    if singular and not _pencil_is_regular(M, C, K):
        raise SceneError(_singular_pencil_message(M, C, K))


def _check_names(names: tuple[str, ...], n: int) -> None:
    if len(names) != n:
        raise SceneError(f"names has {len(names)} entries, expected {n} (one per coordinate)")
    if not all(isinstance(name, str) and name for name in names):
        raise SceneError(f"names must be non-empty strings, got {names!r}")
    if len(set(names)) != n:
        raise SceneError(f"names must be distinct, got {names!r}")


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


def _parse_masses(masses: Mapping[str, Any] | Iterable[Sequence[Any]],
                  parameters: Parameters) -> dict[str, sympy.Expr]:
    parsed: dict[str, sympy.Expr] = {}
    for name, value in _pairs(masses, "masses", 1):
        if not isinstance(name, str) or not name:
            raise SceneError(f"mass names must be non-empty strings, got {shown(name)}")
        if name.lower() in SUPPORTS:
            raise SceneError(f"mass name {name!r} is reserved for a fixed support")
        if name in parsed:
            raise SceneError(f"mass {name!r} is given twice")
        mass = to_exact(value, f"mass {name!r}", parameters=parameters)
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
        if node.lower() in SUPPORTS:
            return node.lower()
    known = ", ".join(masses)
    supports = ", ".join(sorted(SUPPORTS))
    raise SceneError(f"{kind} {label!r}: unknown node {shown(node)}; known masses: {known}; supports: {supports}")


def _component(kind: str, label: Any, spec: Any, masses: Mapping[str, sympy.Expr],
               parameters: Parameters) -> Component:
    if not isinstance(label, str) or not label:
        raise SceneError(f"{kind} labels must be non-empty strings, got {shown(label)}")
    if isinstance(spec, str) or not isinstance(spec, Sequence) or len(spec) != 3:
        raise SceneError(f"{kind} {label!r}: expected (node_a, node_b, value), got {shown(spec)}")
    a, b = (_node(node, label, kind, masses) for node in spec[:2])
    if a == b:
        raise SceneError(f"{kind} {label!r} connects {a!r} to itself")
    if a in SUPPORTS and b in SUPPORTS:
        raise SceneError(f"{kind} {label!r} connects two supports ({a!r}, {b!r}); it would carry no motion")
    value = to_exact(spec[2], f"{kind} {label!r}", parameters=parameters)
    if value.is_negative:
        quantity = "stiffness" if kind == "spring" else "damping"
        raise SceneError(f"{kind} {label!r}: {quantity} must be nonnegative, got {value}")
    return Component(kind, label, a, b, value)


def _parse_components(
    springs: Any, dashpots: Any, masses: Mapping[str, sympy.Expr], parameters: Parameters
) -> tuple[Component, ...]:
    components: list[Component] = []
    for kind, items in (("spring", springs), ("dashpot", dashpots)):
        for label, spec in _pairs(items, f"{kind}s", 3):
            if any(existing.label == label for existing in components):
                raise SceneError(f"component label {label!r} is used twice")
            components.append(_component(kind, label, spec, masses, parameters))
    return tuple(components)


def _assemble(components: Iterable[Component], kind: str, index: Mapping[str, int]) -> sympy.ImmutableMatrix:
    """Stiffness (springs) or damping (dashpots) matrix of the components of ``kind``."""
    matrix = sympy.zeros(len(index), len(index))
    for component in components:
        if component.kind != kind:
            continue
        ends = [index[node] for node in (component.a, component.b) if node in index]
        for i in ends:
            matrix[i, i] += component.value
        if len(ends) == 2:
            i, j = ends
            matrix[i, j] -= component.value
            matrix[j, i] -= component.value
    return sympy.ImmutableMatrix(matrix)


def _initial_by_mass(value: Any, name: str, mass_names: Sequence[str]) -> Any:
    """A mapping mass name -> value becomes a list in coordinate order (missing: 0)."""
    if value is None:
        return [0] * len(mass_names)
    if not isinstance(value, Mapping):
        return value
    unknown = [key for key in value if key not in mass_names]
    if unknown:
        raise SceneError(f"{name}: unknown mass {unknown[0]!r}; masses are {', '.join(mass_names)}")
    return [value.get(mass, 0) for mass in mass_names]


# ----------------------------------------------------------------------------
# Scene
# ----------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class Scene:
    """An exact linear system ``M x'' + C x' + K x = 0``, ``x(0) = x0``, ``x'(0) = v0``.

    Build one with :meth:`from_matrices`, :meth:`from_normalized` or
    :meth:`from_components`; the constructor itself expects exact
    ``sympy.ImmutableMatrix`` data and checks shapes and masses.

    Attributes
    ----------
    M, C, K : sympy.ImmutableMatrix
        Mass, damping and stiffness matrices, n x n, exact. ``C`` and ``K`` are
        zero matrices when there is no damping or no stiffness.
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

    def __post_init__(self) -> None:
        for field in ("M", "C", "K", "x0", "v0"):
            if not isinstance(getattr(self, field), sympy.ImmutableMatrix):
                raise SceneError(
                    f"{field} must be a sympy.ImmutableMatrix; use Scene.from_matrices to convert"
                )
        n = self.M.rows
        if n == 0 or self.M.cols != n:
            raise SceneError(f"M must be a non-empty square matrix, got shape {self.M.rows}x{self.M.cols}")
        for field in ("C", "K"):
            _check_shape(field, getattr(self, field).shape, (n, n), "M")
        for field in ("x0", "v0"):
            _check_column(field, getattr(self, field).shape, n)
        for field in ("M", "C", "K", "x0", "v0"):
            _check_finite(field, getattr(self, field))
        _check_mass_matrix(self.M, self.C, self.K)
        if isinstance(self.names, str):
            raise SceneError(f"names must be a sequence of strings, got {self.names!r}")
        object.__setattr__(self, "names", tuple(self.names))
        _check_names(self.names, n)
        if self.layout not in LAYOUTS:
            raise SceneError(f"layout must be one of {', '.join(LAYOUTS)}, got {self.layout!r}")
        if self.mass_names and len(self.mass_names) != n:
            raise SceneError(f"mass_names has {len(self.mass_names)} entries, expected {n}")
        _check_time_free(self)
        if self.forcing is not None:
            _check_column("forcing", self.forcing.shape, n)
        declared = declare_parameters(self.parameters, self.M, self.C, self.K, self.x0, self.v0,
                                      self.forcing)
        object.__setattr__(self, "parameters", tuple(declared[name] for name in sorted(declared)))

    def __repr__(self) -> str:
        title = f" {self.title!r}:" if self.title else ""
        damping = "damped" if self.is_damped else "undamped"
        plural = "s" if self.n != 1 else ""
        driven = ", forced" if self.is_forced else ""
        return f"<Scene{title} {self.n} coordinate{plural}, {damping}{driven}>"

    # -- properties ---------------------------------------------------------
    @property
    def n(self) -> int:
        """Number of coordinates (degrees of freedom)."""
        return self.M.rows

    @property
    def is_damped(self) -> bool:
        """Whether ``C`` has a nonzero entry."""
        return any(entry != 0 for entry in self.C)

    @property
    def is_forced(self) -> bool:
        """Whether an external force acts (``forcing`` has a nonzero entry)."""
        return self.forcing is not None and any(entry != 0 for entry in self.forcing)

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
    def normalized(self) -> tuple[sympy.ImmutableMatrix, sympy.ImmutableMatrix]:
        """The seed's normalised matrices ``(A, B) = (M^-1 K, M^-1 C)``, exact.

        Returns
        -------
        A, B : sympy.ImmutableMatrix
            So that the system reads ``x'' + B x' + A x = 0``.

        Examples
        --------
        >>> scene = Scene.from_matrices(M=[[1, 0], [0, 2]], C=[[0.2, 0], [0, 0.4]],
        ...                             K=[[2, -1], [-1, 1]], x0=[1, 0], v0=[0, 0])
        >>> A, B = scene.normalized()
        >>> A.tolist(), B.tolist()
        ([[2, -1], [-1/2, 1/2]], [[1/5, 0], [0, 1/5]])
        """
        if self.M.det() == 0:
            raise SceneError("the normalised form x'' + B x' + A x = 0 needs an invertible M; "
                             "this scene has massless nodes (M is singular)")
        if self.M.is_diagonal():
            inverse = sympy.diag(*[1 / self.M[i, i] for i in range(self.n)])
        else:
            inverse = self.M.inv()
        simplify = sympy.cancel if self.M.free_symbols else (lambda entry: entry)
        A = (inverse * self.K).applyfunc(simplify)
        B = (inverse * self.C).applyfunc(simplify)
        return sympy.ImmutableMatrix(A), sympy.ImmutableMatrix(B)

    def with_initial(self, *, x0: Any = None, v0: Any = None) -> Scene:
        """A new scene with other initial data; ``None`` keeps the current value.

        ``x0`` and ``v0`` are vectors, or mappings from mass names (coordinate
        names for a scene built from matrices) to values, missing ones 0.

        Examples
        --------
        >>> scene = Scene.from_matrices(M=[[1]], K=[[4]], x0=[1], v0=[0])
        >>> scene.with_initial(v0=[0.5]).v0
        Matrix([[1/2]])
        >>> scene.with_initial(x0={"x1": "1/3"}).x0
        Matrix([[1/3]])
        """
        keys = self.mass_names or self.names
        declared = declare_parameters(self.parameters, x0, v0)
        changes = {}
        for name, value in (("x0", x0), ("v0", v0)):
            if value is not None:
                changes[name] = _exact_vector(_initial_by_mass(value, name, keys), name, self.n, declared)
        return dataclasses.replace(self, **changes)

    def with_forcing(self, forcing: Any) -> Scene:
        """A new scene with other external forces (``None`` removes them).

        ``forcing`` is a sequence with one entry per coordinate, or a mapping from mass
        names or coordinate names to entries, missing ones 0. Entries are text in ``t``,
        numbers or SymPy expressions
        (see :func:`laplace_springs.model.forcing.parse_forcing`).

        Examples
        --------
        >>> scene = Scene.from_matrices(M=[[1]], K=[[4]], x0=[0], v0=[0])
        >>> scene.with_forcing(["cos(3*t)"]).forcing
        Matrix([[cos(3*t)]])
        """
        keys = self.mass_names or self.names
        if isinstance(forcing, Mapping) and set(forcing) <= set(self.names):
            keys = self.names  # coordinate names x1..xn work for every scene
        values = None if forcing is None else _initial_by_mass(forcing, "forcing", keys)
        declared = declare_parameters(self.parameters, forcing)
        return dataclasses.replace(self, forcing=forcing_vector(values, self.n, declared))

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

        def apply(matrix: sympy.ImmutableMatrix) -> sympy.ImmutableMatrix:
            return sympy.ImmutableMatrix(matrix.xreplace(mapping))

        components = tuple(dataclasses.replace(component, value=component.value.xreplace(mapping))
                           for component in self.components)
        for component in components:
            if component.value.is_negative:
                raise SceneError(f"subs: {component.kind} {component.label!r} becomes {component.value}")
        return dataclasses.replace(
            self, M=apply(self.M), C=apply(self.C), K=apply(self.K), x0=apply(self.x0),
            v0=apply(self.v0), forcing=None if self.forcing is None else apply(self.forcing),
            components=components, parameters=tuple(remaining))

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
            symbol = by_name[name]
            exact = to_exact(value, f"parameter {name!r}", parameters=by_name)
            for assumption in ("positive", "nonnegative", "real", "negative"):
                if symbol.assumptions0.get(assumption) and exact.is_extended_real is not None \
                        and getattr(exact, f"is_{assumption}") is False:
                    raise SceneError(f"parameter {name!r} is {assumption}, got {exact}")
            mapping[symbol] = exact
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
    ) -> Scene:
        """A scene from mass, damping and stiffness matrices.

        Parameters
        ----------
        M : matrix-like
            Mass matrix, n x n: nested lists/tuples, a numpy array or a SymPy matrix.
            Entries are numbers or text (see :func:`laplace_springs.model.numbers.to_exact`).
        C, K : matrix-like, optional
            Damping and stiffness matrices; zero when omitted. Need not be symmetric.
        x0, v0 : vector-like
            Initial displacements and velocities: flat, one column or one row.
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

        Returns
        -------
        Scene

        Raises
        ------
        SceneError
            For a non-square or empty ``M``, mismatched shapes, a wrong vector length,
            non-finite or non-numeric entries, an undeclared name, a number beyond the
            limits of :mod:`laplace_springs.model.numbers`, a negative mass, an indefinite symmetric
            ``M``, or a singular pencil (det(λ²M + λC + K) identically zero). A zero mass
            is allowed: it is a massless node (see :attr:`Solution.initial_jump`).

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
        laplace_springs.model.errors.SceneError: the pencil λ²M + λC + K is singular: ...; coordinate 1 has no mass and no spring or dashpot acting on it
        """
        declared = declare_parameters(parameters, M, C, K, x0, v0, forcing)
        mass = _exact_matrix(M, "M", declared)
        n = mass.rows
        damping = _optional_matrix(C, "C", mass, "M", declared)
        stiffness = _optional_matrix(K, "K", mass, "M", declared)
        return cls(
            M=mass,
            C=damping,
            K=stiffness,
            x0=_exact_vector(x0, "x0", n, declared),
            v0=_exact_vector(v0, "v0", n, declared),
            names=_default_names(n) if names is None else tuple(names),
            title=title,
            layout=layout,
            forcing=forcing_vector(forcing, n, declared),
            parameters=tuple(declared.values()),
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
    ) -> Scene:
        """A scene from the seed's normalised form ``x'' + B x' + A x = f(t)``.

        The scene has ``M = I``, ``K = A`` and ``C = B``. ``A`` need not be
        symmetric (the seed's Example 1 has ``A = [[3, -1], [-2, 2]]``). ``forcing``
        is then a force per unit mass, as in :meth:`from_matrices`.

        Examples
        --------
        >>> scene = Scene.from_normalized(A=[[3, -1], [-2, 2]], x0=[1, 0], v0=[0, 1])
        >>> scene.M.tolist(), scene.K.tolist()
        ([[1, 0], [0, 1]], [[3, -1], [-2, 2]])
        """
        declared = declare_parameters(parameters, A, B, x0, v0, forcing)
        stiffness = _exact_matrix(A, "A", declared)
        n = stiffness.rows
        damping = _optional_matrix(B, "B", stiffness, "A", declared)
        return cls.from_matrices(
            M=sympy.eye(n), C=damping, K=stiffness, x0=x0, v0=v0, names=names, title=title,
            layout=layout, forcing=forcing, parameters=declared,
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
    ) -> Scene:
        """A scene assembled from masses, springs and dashpots.

        Parameters
        ----------
        masses : mapping of str to number, or sequence of (name, value)
            The masses, in coordinate order.
        springs, dashpots : mapping or sequence, optional
            ``{label: (node_a, node_b, value)}``, or rows ``(label, node_a, node_b, value)``.
            A node is a mass name or a fixed support, one of :data:`SUPPORTS`
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

        Returns
        -------
        Scene
            With ``components`` and ``mass_names`` set, coordinates named ``x1..xn``.

        Raises
        ------
        SceneError
            For an unknown node, a component from a node to itself or between two
            supports, a negative stiffness or damping, a duplicate label or mass
            name, a negative mass, or a singular pencil (a massless node with no spring
            or dashpot). A mass of 0 is a massless node.

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
        declared = declare_parameters(parameters, masses, springs, dashpots, x0, v0, forcing)
        mass_values = _parse_masses(masses, declared)
        components = _parse_components(springs, dashpots, mass_values, declared)
        mass_names = tuple(mass_values)
        index = {name: i for i, name in enumerate(mass_names)}
        n = len(mass_names)
        return cls(
            M=sympy.ImmutableMatrix(sympy.diag(*mass_values.values())),
            C=_assemble(components, "dashpot", index),
            K=_assemble(components, "spring", index),
            x0=_exact_vector(_initial_by_mass(x0, "x0", mass_names), "x0", n, declared),
            v0=_exact_vector(_initial_by_mass(v0, "v0", mass_names), "v0", n, declared),
            names=_default_names(n),
            title=title,
            layout=layout,
            components=components,
            mass_names=mass_names,
            forcing=None if forcing is None else forcing_vector(
                _initial_by_mass(forcing, "forcing", mass_names), n, declared),
            parameters=tuple(declared.values()),
        )


def _optional_matrix(
    value: Any, name: str, reference: sympy.ImmutableMatrix, reference_name: str, parameters: Parameters
) -> sympy.ImmutableMatrix:
    """``value`` as an exact matrix of the shape of ``reference``; zeros when ``None``."""
    if value is None:
        return sympy.ImmutableMatrix(sympy.zeros(*reference.shape))
    rows = _rows_of(value, name)
    _check_shape(name, (len(rows), len(rows[0]) if rows else 0), reference.shape, reference_name)
    return _exact_matrix(rows, name, parameters)
