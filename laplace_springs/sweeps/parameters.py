"""The parameter sets of a sweep: read once, checked against each parameter's assumptions.

Values arrive as numbers or 1-D arrays per parameter (numbers, or text and exact
rationals read by the package's parser). Every set then stands for the exact values
:meth:`Scene.subs` would take: a float for its shortest decimal, text and rationals
exactly (:func:`~laplace_springs.sweeps.entries.parameter_parts`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import sympy as sp

from ..limits import limits
from ..model.errors import LimitError, SceneError
from ..model.numbers import shown, to_exact
from ..numeric.times import check_flat
from .entries import DD, parameter_parts

__all__ = ["ParameterSets", "parameter_sets", "check_flat"]


@dataclass(frozen=True, eq=False)
class ParameterSets:
    """P parameter sets.

    Attributes
    ----------
    names : tuple of str
        Parameter names, in the order of the scene's parameters.
    symbols : tuple of sympy.Symbol
    rows : numpy.ndarray
        (P, parameters) float64 values.
    given : dict
        Column -> the values as given, where some were not floats (text, rationals).
    """

    names: tuple[str, ...]
    symbols: tuple[sp.Symbol, ...]
    rows: np.ndarray
    given: dict[int, list[Any]]

    def __len__(self) -> int:
        return int(self.rows.shape[0])

    def subset(self, start: int, stop: int) -> ParameterSets:
        """Sets ``start`` to ``stop - 1``."""
        given = {c: values[start:stop] for c, values in self.given.items()}
        return ParameterSets(self.names, self.symbols, self.rows[start:stop], given)

    def take(self, index: np.ndarray) -> ParameterSets:
        """The sets at ``index``."""
        index = np.asarray(index, dtype=int)
        given = {c: [values[int(i)] for i in index] for c, values in self.given.items()}
        return ParameterSets(self.names, self.symbols, self.rows[index], given)

    def parts(self) -> list[DD]:
        """Each parameter as the exact values it means, in double-double (hi, lo, err)."""
        return [parameter_parts(self.rows[:, c], self.given.get(c))
                for c in range(self.rows.shape[1])]

    def values(self, b: int) -> dict[str, Any]:
        """Set ``b`` as ``Scene.subs`` takes it (floats, or the values as given)."""
        out: dict[str, Any] = {}
        for c, name in enumerate(self.names):
            out[name] = self.given[c][b] if c in self.given else float(self.rows[b, c])
        return out

    def describe(self, b: int) -> str:
        """``k = 1.5, c = 0.2`` for set ``b``."""
        return ", ".join(f"{name} = {value!r}" if isinstance(value, float) else f"{name} = {value}"
                         for name, value in self.values(b).items())


def _column(name: str, value: Any) -> tuple[np.ndarray, list[Any] | None]:
    """Float values of one parameter, and the values as given where they are not floats."""
    try:
        array = np.asarray(value)
    except (TypeError, ValueError):
        raise SceneError(f"sweep: values of {name!r} must be real numbers, got {shown(value)}") from None
    check_flat(array, f"sweep: values of {name!r}")
    if array.dtype.kind in "fiu" and not (array.dtype.kind in "iu" and np.any(np.abs(array) > 2**53)):
        floats = array.astype(float)
        _check_magnitudes(name, floats)
        return floats, None
    if array.dtype.kind == "b":
        raise SceneError(f"sweep: values of {name!r} must be real numbers, got booleans")
    if array.dtype.kind == "c":  # name the first value with an imaginary part, not value 0
        imaginary = np.flatnonzero(np.ravel(array).imag != 0)
        k = int(imaginary[0]) if imaginary.size else 0
        raise SceneError(f"sweep: value {k} of parameter {name!r}: expected a number, got "
                         f"{complex(np.ravel(array)[k])!r} (a complex value; a parameter is real)")
    flat = list(array.ravel()) if array.ndim else [array.item()]
    exact = []
    for k, item in enumerate(flat):
        if isinstance(item, (bool, np.bool_)):
            raise SceneError(f"sweep: values of {name!r} must be real numbers, got {item!r}")
        number = to_exact(item.item() if isinstance(item, np.generic) else item,
                          f"sweep: value {k} of parameter {name!r}")
        if number.free_symbols or not number.is_real:
            raise SceneError(f"sweep: value {k} of {name!r} must be a number, got {shown(item)}")
        exact.append(number)
    floats = np.array([float(v) for v in exact], dtype=float)
    return (floats if array.ndim else floats.reshape(())), exact


def _check_magnitudes(name: str, floats: np.ndarray) -> None:
    """Scene.subs' limit 1e-300 ≤ |value| ≤ 1e300 on finite nonzero float values (NaN and
    infinities get their own message from the sets' checks)."""
    size = np.abs(np.ravel(floats))
    with np.errstate(invalid="ignore"):
        outside = np.flatnonzero(np.isfinite(size) & (size != 0) & ((size < 1e-300) | (size > 1e300)))
    if outside.size:
        k = int(outside[0])
        raise SceneError(f"sweep: value {k} of parameter {name!r}: {float(np.ravel(floats)[k])!r} is "
                         "beyond the limit 1e-300 <= |value| <= 1e300 (MAX_MAGNITUDE) that float64 "
                         "evaluation can honour")


def parameter_sets(names: tuple[str, ...], symbols: tuple[sp.Symbol, ...],
                   values: Mapping[Any, Any]) -> ParameterSets:
    """Read and check the parameter sets of a sweep.

    Every parameter needs a value: a number (the same for every set) or a 1-D array; all
    arrays have one length P. Each value must meet its parameter's assumptions
    (positive, nonnegative, negative, real) as in :meth:`Scene.subs`.

    Examples
    --------
    >>> c, k = sp.symbols("c k", positive=True)
    >>> sets = parameter_sets(("c", "k"), (c, k), {"k": [1, 2], "c": "1/3"})
    >>> sets.rows.tolist(), sets.describe(1)
    ([[0.3333333333333333, 1.0], [0.3333333333333333, 2.0]], 'c = 1/3, k = 2.0')
    """
    if not isinstance(values, Mapping):
        raise SceneError(f"sweep: values must map parameter names to arrays, got {shown(values)}")
    by_name: dict[str, Any] = {}
    for key, value in values.items():
        name = key.name if isinstance(key, sp.Symbol) else key
        if not isinstance(name, str) or name not in names:
            raise SceneError(f"sweep: {shown(key)} is not a parameter of this scene; its "
                             f"parameters are {', '.join(names) or 'none'}")
        if name in by_name:
            raise SceneError(f"sweep: parameter {name!r} is given twice")
        by_name[name] = value
    missing = [name for name in names if name not in by_name]
    if missing:
        raise SceneError(f"sweep: no values for parameter(s) {', '.join(missing)}")
    columns = {name: _column(name, by_name[name]) for name in names}
    lengths = {name: a.size for name, (a, _) in columns.items() if a.ndim == 1}
    sizes = set(lengths.values())
    if len(sizes) > 1:
        listed = ", ".join(f"{name}: {size}" for name, size in lengths.items())
        raise SceneError(f"sweep: the value arrays must have one length (one entry per "
                         f"parameter set), got {listed}")
    P = sizes.pop() if sizes else 1
    if limits().sweep_max_sets < P:
        raise LimitError(f"sweep: {P:,} parameter sets, more than Limits.sweep_max_sets = "
                         f"{limits().sweep_max_sets:,}; sweep them in parts (out= streams each "
                         "part to a store)")
    if P == 0:
        raise SceneError("sweep: no parameter sets (the value arrays are empty)")
    rows = np.empty((P, len(names)))
    given: dict[int, list[Any]] = {}
    for k, (name, symbol) in enumerate(zip(names, symbols)):
        array, exact = columns[name]
        column = np.broadcast_to(array, (P,))
        _check_assumptions(name, symbol, column)
        rows[:, k] = column
        if exact is not None:
            given[k] = exact * P if len(exact) == 1 and P > 1 else exact
    return ParameterSets(names, symbols, rows, given)


def _check_assumptions(name: str, symbol: sp.Symbol, column: np.ndarray) -> None:
    bad = ~np.isfinite(column)
    assumptions = symbol.assumptions0
    what = "a finite number"
    with np.errstate(invalid="ignore"):
        if assumptions.get("positive"):
            bad |= ~(column > 0)
            what = "a positive number"
        elif assumptions.get("nonnegative"):
            bad |= ~(column >= 0)
            what = "a nonnegative number"
        elif assumptions.get("negative"):
            bad |= ~(column < 0)
            what = "a negative number"
    if bad.any():
        index = int(np.flatnonzero(bad)[0])
        raise SceneError(f"sweep: parameter {name!r} must be {what}, but set {index} has "
                         f"{name} = {float(column[index])!r}")
