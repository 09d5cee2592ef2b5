"""A scene's entries as functions of its parameters, evaluated in double-double for many sets.

The numeric sweep path (:mod:`laplace_springs.sweeps.batched`) needs, for every parameter
set, the entries of M, C, K, x0 and v0 of ``scene.subs(set)`` to about 32 digits: its
refined eigenpairs leave residuals of that size, and the error bound is only as small as
the data are exact. :func:`dd_function` turns a SymPy expression (sums, products and
integer powers of the parameters and rational constants: every scene built from springs,
dashpots and masses) into a vectorised double-double evaluation that also returns a bound
on its own error; anything else (a square root of a parameter, say) is not compiled and
such scenes are swept one set at a time.

:func:`parameter_parts` gives each parameter value as the exact number the set means:
a float is its shortest decimal (``0.1`` is 1/10, as in :meth:`Scene.subs`), held as a
double-double hi + lo.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any

import numpy as np
import sympy as sp

from ..kernels.dd import UNIT_DD, U, dd_add, dd_div, dd_mul, from_exact
from ..model.scene import Scene

__all__ = ["DD", "dd_function", "parameter_parts", "SceneEntries", "scene_entries_of"]

#: A double-double array with an error bound: (hi, lo, err), each of shape (P,).
DD = tuple[np.ndarray, np.ndarray, np.ndarray]
Evaluator = Callable[[Sequence[DD]], DD]


def _constant(value: sp.Rational) -> Evaluator:
    hi, lo = from_exact(Fraction(int(value.p), int(value.q)))
    err = U * U * abs(hi)

    def evaluate(params: Sequence[DD]) -> DD:
        size = params[0][0].shape if params else ()
        return np.full(size, hi), np.full(size, lo), np.full(size, err)

    return evaluate


def _symbol(index: int) -> Evaluator:
    def evaluate(params: Sequence[DD]) -> DD:
        return params[index]

    return evaluate


def _add(parts: list[Evaluator]) -> Evaluator:
    def evaluate(params: Sequence[DD]) -> DD:
        hi, lo, err = parts[0](params)
        for part in parts[1:]:
            bh, bl, be = part(params)
            size = np.abs(hi) + np.abs(bh)
            hi, lo = dd_add(hi, lo, bh, bl)
            err = err + be + UNIT_DD * size
        return hi, lo, err

    return evaluate


def _mul(parts: list[Evaluator]) -> Evaluator:
    def evaluate(params: Sequence[DD]) -> DD:
        hi, lo, err = parts[0](params)
        for part in parts[1:]:
            bh, bl, be = part(params)
            err = np.abs(hi) * be + np.abs(bh) * err + err * be
            hi, lo = dd_mul(hi, lo, bh, bl)
            err = err + UNIT_DD * np.abs(hi)
        return hi, lo, err

    return evaluate


def _inverse(part: Evaluator) -> Evaluator:
    def evaluate(params: Sequence[DD]) -> DD:
        bh, bl, be = part(params)
        one = np.ones_like(bh)
        with np.errstate(divide="ignore", invalid="ignore"):
            hi, lo = dd_div(one, np.zeros_like(bh), bh, bl)
            margin = np.abs(bh) - 2 * be
            err = np.where(margin > 0, be / (np.abs(bh) * np.where(margin > 0, margin, 1.0)), np.inf)
        return hi, lo, err + UNIT_DD * np.abs(hi)

    return evaluate


def dd_function(expr: Any, symbols: Sequence[sp.Symbol]) -> Evaluator | None:
    """A vectorised double-double evaluation of ``expr`` in the parameters ``symbols``.

    The function takes one (hi, lo, err) triple per parameter (arrays of one shape) and
    returns (hi, lo, err) for the expression: err bounds |hi + lo − exact value| given the
    parameters' own errors (each operation's rounding counted as 2⁻¹⁰⁰ of its size).
    Returns None for anything but sums, products, integer powers and rationals.

    Examples
    --------
    >>> k, c = sp.symbols("k c")
    >>> f = dd_function(k / 3 + 2 * c, [k, c])
    >>> one = (np.array([1.0]), np.array([0.0]), np.array([0.0]))
    >>> hi, lo, err = f([one, one])
    >>> abs(Fraction(hi[0]) + Fraction(lo[0]) - Fraction(7, 3)) < Fraction(1, 10**30), bool(err[0] < 1e-29)
    (True, True)
    >>> dd_function(sp.sqrt(k), [k]) is None
    True
    """
    expr = sp.sympify(expr)
    index = {symbol: k for k, symbol in enumerate(symbols)}
    return _compile(expr, index)


def _compile(expr: sp.Expr, index: dict[sp.Symbol, int]) -> Evaluator | None:
    if expr.is_Rational:
        return _constant(expr)
    if expr.is_Symbol:
        return _symbol(index[expr]) if expr in index else None
    if expr.is_Add or expr.is_Mul:
        parts = [_compile(arg, index) for arg in expr.args]
        if any(part is None for part in parts):
            return None
        chosen = [part for part in parts if part is not None]
        return _add(chosen) if expr.is_Add else _mul(chosen)
    if expr.is_Pow and expr.exp.is_Integer and expr.exp != 0 and abs(int(expr.exp)) <= 64:
        base = _compile(expr.base, index)
        if base is None:
            return None
        power = _mul([base] * abs(int(expr.exp))) if abs(int(expr.exp)) > 1 else base
        return power if expr.exp > 0 else _inverse(power)
    return None


def parameter_parts(column: np.ndarray, given: Sequence[Any] | None = None) -> DD:
    """Parameter values as the exact numbers they mean, in double-double.

    A float stands for its shortest decimal (``repr``), as :func:`laplace_springs.model.numbers.to_exact`
    reads it; ``given`` (the values as the caller wrote them, where not floats) are
    converted exactly. Distinct values are converted once.

    Examples
    --------
    >>> hi, lo, err = parameter_parts(np.array([0.1, 0.1, 2.0]))
    >>> abs(Fraction(hi[0]) + Fraction(lo[0]) - Fraction(1, 10)) < Fraction(1, 10**33), float(lo[2])
    (True, 0.0)
    """
    hi = np.asarray(column, dtype=float)
    lo = np.zeros_like(hi)
    err = U * U * np.abs(hi)
    if given is not None:
        for k, value in enumerate(given):
            lo[k], exact = _correction(value, hi[k])
            if not exact:  # an irrational number: its float64 rounding
                err[k] = U * abs(hi[k])
    else:
        distinct, inverse = np.unique(hi, return_inverse=True)
        corrections = np.array([_correction(float(v), float(v))[0] for v in distinct])
        lo = corrections[inverse].reshape(hi.shape) if distinct.size else lo
    return hi, lo, err


def _correction(value: Any, rounded: float) -> tuple[float, bool]:
    """(exact value) − rounded as a float (a float's shortest decimal minus its binary
    value), and whether the value is a rational number (else the correction is 0)."""
    if not math.isfinite(rounded):
        return 0.0, True
    if isinstance(value, (float, np.floating)):
        exact = Fraction(repr(float(value)))
    elif isinstance(value, (int, np.integer)):
        exact = Fraction(int(value))
    elif isinstance(value, Fraction):
        exact = value
    elif isinstance(value, sp.Rational):
        exact = Fraction(int(value.p), int(value.q))
    else:
        return 0.0, False
    return float(exact - Fraction(rounded)), True


@dataclass(eq=False)
class SceneEntries:
    """The nonzero entries of M, C, K, x0, v0 (and the components' values) of a scene, as
    double-double functions of its parameters.

    Attributes
    ----------
    n : int
        Coordinates.
    pattern : dict
        Matrix name -> list of (i, j) positions of its structurally nonzero entries.
    expressions : dict
        Matrix name -> the SymPy expressions at those positions.
    components : list of tuple
        (kind, label, expression) of each spring and dashpot (also the pseudo-matrix
        ``"components"`` of :attr:`pattern` and :attr:`expressions`).
    compiled : bool
        Every entry of M, C, K, x0, v0 has a double-double evaluation (else the scene is
        swept set by set).
    """

    n: int
    symbols: tuple[sp.Symbol, ...]
    pattern: dict[str, list[tuple[int, int]]]
    expressions: dict[str, list[sp.Expr]]
    components: list[tuple[str, str, sp.Expr]]
    compiled: bool
    _functions: dict[str, Any] = field(default_factory=dict, repr=False)

    def __getstate__(self) -> dict[str, Any]:  # closures are rebuilt on arrival
        state = dict(self.__dict__)
        state["_functions"] = {}
        return state

    def compiles(self, name: str) -> bool:
        """Whether every entry of ``name`` has a double-double evaluation."""
        return all(f is not None for f in self._evaluators(name))

    def _evaluators(self, name: str) -> list[Evaluator | None]:
        if name not in self._functions:
            self._functions[name] = [dd_function(e, self.symbols) for e in self.expressions[name]]
        functions: list[Evaluator | None] = self._functions[name]
        return functions

    def evaluate(self, name: str, params: Sequence[DD], P: int) -> DD:
        """The entries of matrix ``name`` at the P parameter sets: (hi, lo, err), each (P, nnz)."""
        count = len(self.pattern[name])
        hi, lo, err = np.zeros((P, count)), np.zeros((P, count)), np.zeros((P, count))
        for k, function in enumerate(self._evaluators(name)):
            if function is None:
                raise ValueError(f"entry {k} of {name} has no double-double evaluation")
            h, low, e = function(params)
            hi[:, k], lo[:, k], err[:, k] = h, low, e
        return hi, lo, err

    def floats(self, name: str, rows: np.ndarray) -> np.ndarray:
        """The entries of ``name`` in float64 at the sets ``rows`` (P, parameters): (P, nnz)."""
        key = f"float:{name}"
        exprs = self.expressions[name]
        if key not in self._functions:
            self._functions[key] = sp.lambdify(list(self.symbols), list(exprs), modules="numpy")
        out = np.empty((rows.shape[0], len(exprs)))
        with np.errstate(all="ignore"):
            for k, value in enumerate(self._functions[key](*[rows[:, c] for c in range(rows.shape[1])])):
                out[:, k] = value
        return out


def scene_entries_of(scene: Scene) -> SceneEntries:
    """The :class:`SceneEntries` of a scene (its parameters in the order of ``scene.parameters``).

    Examples
    --------
    >>> scene = Scene.from_matrices(M=[[1, 0], [0, "m"]], K=[["k + 1", -1], [-1, 1]],
    ...                             x0=[1, 0], v0=[0, 0], parameters=["k", "m"])
    >>> entries = scene_entries_of(scene)
    >>> entries.pattern["K"], entries.compiled
    ([(0, 0), (0, 1), (1, 0), (1, 1)], True)
    >>> params = [parameter_parts(np.array([2.0])), parameter_parts(np.array([0.5]))]
    >>> entries.evaluate("K", params, 1)[0].tolist(), entries.evaluate("M", params, 1)[0].tolist()
    ([[3.0, -1.0, -1.0, 1.0]], [[1.0, 0.5]])
    """
    pattern: dict[str, list[tuple[int, int]]] = {}
    expressions: dict[str, list[sp.Expr]] = {}
    for name in ("M", "C", "K", "x0", "v0"):
        entries = getattr(scene, name).todok()
        keys = sorted(key for key, value in entries.items() if value != 0)
        pattern[name] = keys
        expressions[name] = [sp.sympify(entries[key]) for key in keys]
    symbols = tuple(scene.parameters)
    compiled = all(dd_function(e, symbols) is not None for exprs in expressions.values() for e in exprs)
    components = [(c.kind, c.label, sp.sympify(c.value)) for c in scene.components]
    pattern["components"] = [(k, 0) for k in range(len(components))]
    expressions["components"] = [value for _, _, value in components]
    return SceneEntries(scene.n, symbols, pattern, expressions, components, compiled)
