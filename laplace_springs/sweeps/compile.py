"""A symbolic scene compiled once for many parameter sets.

The motion of a scene is x(t) = Σ_roots residues of X(λ) e^{λt} with
X_i(λ) = N_i(λ)/D(λ): D(λ) = Δ(λ)·D_f(λ) is the determinant det(λ²M + λC + K) times the
common denominator of the forcing's Laplace transform, and N_i(λ) the matching
numerator (the resolvent's adjugate applied to the initial data and the forces). The
coefficients of D and of every N_i are exact expressions in the scene's parameters;
:func:`compile_scene` builds them once (SymPy) and turns them into NumPy functions
(``sympy.lambdify`` of SymPy objects, never of text), together with the same
polynomials with every term's coefficient replaced by its absolute value, evaluated at
the absolute values of the parameters: a bound on the rounding of each coefficient.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import sympy as sp

from ..exact.resolvent import resolvent
from ..limits import limits
from ..model.errors import SceneError
from ..model.forcing import input_transform
from ..model.numbers import shown
from ..model.scene import Scene
from ..model.symbols import lam
from .parameters import parameter_sets

__all__ = ["CompiledScene", "compile_scene", "compile_refusal", "compiled_or_reason", "parameter_rows"]



def _absolute(expr: sp.Expr, symbols: Sequence[sp.Symbol]) -> sp.Expr | None:
    """The polynomial ``expr`` with absolute coefficients (None when not a polynomial)."""
    if not symbols:
        return sp.Abs(expr)
    try:
        poly = sp.Poly(expr, *symbols)
    except sp.PolynomialError:
        return None
    if not all(c.is_number and c.is_real for c in poly.coeffs()):
        return None
    return sp.Add(*(abs(c) * sp.Mul(*(s**e for s, e in zip(symbols, monom)))
                    for monom, c in poly.terms()))


def _lambdified(exprs: Sequence[sp.Expr], symbols: Sequence[sp.Symbol]) -> Callable[..., list[Any]]:
    return sp.lambdify(list(symbols), list(exprs), modules="numpy")


@dataclass(eq=False)
class CompiledScene:
    """A scene's transform X_i(λ) = N_i(λ)/D(λ) as coefficient functions of its parameters.

    Attributes
    ----------
    scene : Scene
        The symbolic scene.
    symbols : tuple of sympy.Symbol
        Its parameters, in the order of :attr:`names`.
    names : tuple of str
        Parameter names (sorted, as ``scene.parameters``).
    denominator : list of sympy.Expr
        Coefficients of D(λ), highest power first.
    numerators : list of list of sympy.Expr
        Coefficients of each N_i(λ), highest first, padded to ``len(denominator) - 1``.
    """

    scene: Scene
    symbols: tuple[sp.Symbol, ...]
    names: tuple[str, ...]
    denominator: list[sp.Expr]
    numerators: list[list[sp.Expr]]
    initial: list[sp.Expr]
    _functions: dict[str, Any] = field(default_factory=dict, repr=False)

    @property
    def degree(self) -> int:
        """Degree of D(λ): the number of roots."""
        return len(self.denominator) - 1

    def __getstate__(self) -> dict[str, Any]:  # lambdified functions are rebuilt on arrival
        state = dict(self.__dict__)
        state["_functions"] = {}
        return state

    def _function(self, key: str) -> Any:
        if key not in self._functions:
            flat = list(self.denominator) + [c for row in self.numerators for c in row]
            if key == "values":
                self._functions[key] = _lambdified(flat, self.symbols)
            elif key == "bounds":
                absolute = [_absolute(c, self.symbols) for c in flat]
                plain = [sp.S.Zero if a is None else a for a in absolute]
                self._functions[key] = (_lambdified(plain, self.symbols),
                                        np.array([a is None for a in absolute]))
            else:
                self._functions[key] = _lambdified(self.initial, self.symbols)
        return self._functions[key]

    def coefficients(self, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Coefficients at the parameter sets ``rows`` (shape (P, parameters)).

        Returns
        -------
        den, num : ndarray
            D's coefficients (P, N+1) and the numerators' (P, n, N), highest first.
        den_abs, num_abs : ndarray
            The same polynomials with absolute coefficients at absolute parameters
            (bounds on every term; the value itself where that is not a polynomial).
        """
        P = rows.shape[0]
        columns = [rows[:, k] for k in range(rows.shape[1])]
        values = _stack(self._function("values")(*columns), P)
        function, not_polynomial = self._function("bounds")
        bounds = _stack(function(*[np.abs(c) for c in columns]), P)
        bounds[:, not_polynomial] = np.abs(values[:, not_polynomial])
        N = self.degree
        n = len(self.numerators)
        return (values[:, :N + 1], values[:, N + 1:].reshape(P, n, N),
                bounds[:, :N + 1], bounds[:, N + 1:].reshape(P, n, N))

    def coefficients_extended(self, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        """D's and the numerators' coefficients evaluated in ``numpy.longdouble``.

        Only when every coefficient is a polynomial in the parameters with rational
        coefficients (the rationals are passed in as extended-precision values, not as
        float64 constants); None otherwise. Their rounding errors are then bounded by
        :meth:`rounding_counts` units of ``numpy.longdouble``'s unit roundoff.

        Examples
        --------
        >>> import laplace_springs as ls
        >>> scene = ls.Scene.from_matrices(M=[[1]], C=[["c/3"]], K=[["k"]], x0=[1], v0=[0],
        ...                                parameters=["c", "k"])
        >>> den, num = compile_scene(scene).coefficients_extended(np.array([[1.0, 2.0]]))
        >>> den.dtype == np.longdouble, float(den[0, 1] * 3)
        (True, 1.0)
        """
        if "extended" not in self._functions:
            flat = list(self.denominator) + [c for row in self.numerators for c in row]
            constants = sorted({r for c in flat for r in sp.sympify(c).atoms(sp.Rational)
                                if not r.is_Integer}, key=lambda r: (r.p, r.q))
            dummies = [sp.Dummy(f"r{k}") for k in range(len(constants))]
            swapped = [sp.sympify(c).xreplace(dict(zip(constants, dummies))) for c in flat]
            names = list(self.symbols) + dummies
            usable = all(e.is_polynomial(*names) and all(a.is_Integer for a in e.atoms(sp.Number))
                         for e in swapped)
            self._functions["extended"] = (_lambdified(swapped, names), [
                np.longdouble(r.p) / np.longdouble(r.q) for r in constants]) if usable else None
        entry = self._functions["extended"]
        if entry is None:
            return None
        function, values = entry
        P = rows.shape[0]
        columns = [rows[:, k].astype(np.longdouble) for k in range(rows.shape[1])]
        out = np.empty((P, len(self.denominator) + len(self.numerators) * self.degree),
                       dtype=np.longdouble)
        for k, value in enumerate(function(*columns, *values)):
            out[:, k] = value
        N, n = self.degree, len(self.numerators)
        return out[:, :N + 1], out[:, N + 1:].reshape(P, n, N)

    def rounding_counts(self) -> tuple[np.ndarray, np.ndarray]:
        """Roundings in evaluating each coefficient (an upper count, from its expression).

        An exact integer costs none; any other coefficient at most ``count_ops + 1``, so
        ``counts · 2⁻⁵³ · bound`` bounds its rounding error (to first order).

        Examples
        --------
        >>> import laplace_springs as ls
        >>> scene = ls.Scene.from_matrices(M=[[1]], C=[["c"]], K=[["k"]], x0=[1], v0=[0],
        ...                                parameters=["c", "k"])
        >>> [a.tolist() for a in compile_scene(scene).rounding_counts()]
        [[0.0, 1.0, 1.0], [[0.0, 1.0]]]
        """
        if "counts" not in self._functions:
            def count(c: sp.Expr) -> float:
                return 0.0 if c.is_Integer else float(sp.count_ops(c) + 1)
            self._functions["counts"] = (
                np.array([count(c) for c in self.denominator]),
                np.array([[count(c) for c in row] for row in self.numerators]).reshape(
                    len(self.numerators), self.degree))
        return self._functions["counts"]

    def parameter_degrees(self) -> tuple[np.ndarray, np.ndarray]:
        """Total degree of each coefficient in the parameters (``count_ops + 1`` where a
        coefficient is not a polynomial in them).

        A parameter set's float64 values differ from the exact values they stand for (a
        float's shortest decimal, an exact rational rounded) by at most u relative, so a
        coefficient of degree d moves by at most d·u times its absolute bound: part of
        the coefficient error the kernels propagate.

        Examples
        --------
        >>> import laplace_springs as ls
        >>> scene = ls.Scene.from_matrices(M=[[1]], C=[["c"]], K=[["k*c"]], x0=[1], v0=[0],
        ...                                parameters=["c", "k"])
        >>> [a.tolist() for a in compile_scene(scene).parameter_degrees()]
        [[0.0, 1.0, 2.0], [[0.0, 1.0]]]
        """
        if "degrees" not in self._functions:
            def degree(c: sp.Expr) -> float:
                expr = sp.sympify(c)
                if not (expr.free_symbols & set(self.symbols)):
                    return 0.0
                try:
                    return float(sp.Poly(expr, *self.symbols).total_degree())
                except sp.PolynomialError:
                    return float(sp.count_ops(expr) + 1)
            self._functions["degrees"] = (
                np.array([degree(c) for c in self.denominator]),
                np.array([[degree(c) for c in row] for row in self.numerators]).reshape(
                    len(self.numerators), self.degree))
        return self._functions["degrees"]

    def initial_size(self, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """‖x0‖∞ and ‖v0‖∞ of each parameter set."""
        P = rows.shape[0]
        values = _stack(self._function("initial")(*[rows[:, k] for k in range(rows.shape[1])]), P)
        n = len(self.numerators)
        return np.max(np.abs(values[:, :n]), axis=1), np.max(np.abs(values[:, n:]), axis=1)


def _stack(values: list[Any], P: int) -> np.ndarray:
    out = np.empty((P, len(values)))
    for k, value in enumerate(values):
        out[:, k] = value  # constants broadcast
    return out


def _forcing_parts(scene: Scene) -> tuple[list[sp.Expr], sp.Expr] | str:
    """Numerators of the forces' transforms over one common denominator, and it (or why
    the forces cannot be compiled: a period or a delay)."""
    assert scene.forcing is not None
    fractions = []
    for j, entry in enumerate(scene.forcing):
        if entry == 0:
            fractions.append((sp.S.Zero, sp.S.One))
            continue
        transform = input_transform(entry, f"forcing[{j}]", lam)
        if transform.period is not None:
            return f"forcing[{j}] = {shown(entry)} is periodic"
        parts = transform.parts
        if any(tau != 0 for tau, _ in parts):
            return f"forcing[{j}] = {shown(entry)} has a delayed part (Heaviside or DiracDelta at t > 0)"
        total = sp.Add(*(R for _, R in parts))
        fractions.append(sp.fraction(sp.cancel(sp.together(total))))
    common = functools.reduce(sp.lcm, [den for _, den in fractions], sp.S.One)
    numerators = [sp.expand(num * sp.cancel(common / den)) for num, den in fractions]
    return numerators, sp.expand(common)


def compile_refusal(scene: Scene) -> str | None:
    """Why the scene cannot be compiled, found without compiling it (or None).

    Examples
    --------
    >>> import laplace_springs as ls
    >>> scene = ls.Scene.from_matrices(M=[[1]], K=[["k"]], x0=[0], v0=[0], parameters=["k"],
    ...                                forcing=[ls.square_wave(1, 2)])
    >>> compile_refusal(scene)
    'forcing[0] = ... is periodic'
    """
    if scene.sampled is not None:
        return "the scene has sampled forces"
    if scene.n > limits().sweep_max_coordinates:
        return (f"the scene has {scene.n} coordinates, more than "
                f"Limits.sweep_max_coordinates = {limits().sweep_max_coordinates} (its symbolic "
                "adjugate would be too large)")
    if scene.is_forced:
        found = _forcing_parts(scene)
        if isinstance(found, str):
            return found
    return None


def compiled_or_reason(scene: Scene) -> CompiledScene | str:
    """The :class:`CompiledScene`, or why the scene cannot be compiled."""
    why = compile_refusal(scene)
    if why is not None:
        return why
    R = resolvent(scene)
    denominator = R.determinant.as_expr()
    numerators = [N.as_expr() for N in R.numerators]
    if scene.is_forced:
        found = _forcing_parts(scene)
        assert not isinstance(found, str)
        forces, common = found
        adjugate = R.adjugate
        numerators = [sp.expand(N * common + sum((adjugate[i, j] * forces[j]
                                                  for j in range(scene.n)), sp.S.Zero))
                      for i, N in enumerate(numerators)]
        denominator = sp.expand(denominator * common)
    D = sp.Poly(denominator, lam)
    N = D.degree()
    if N < 1:
        return "det(λ²M + λC + K) does not depend on λ; the scene has no dynamics"
    rows = []
    for i, numerator in enumerate(numerators):
        poly = sp.Poly(numerator, lam)
        if not poly.is_zero and poly.degree() >= N:
            return (f"coordinate {scene.names[i]} has an impulsive part at t = 0 (its transform "
                    "is not a proper fraction)")
        coeffs = [] if poly.is_zero else poly.all_coeffs()
        rows.append([sp.S.Zero] * (N - len(coeffs)) + coeffs)
    symbols = tuple(scene.parameters)
    initial = list(scene.x0) + list(scene.v0)
    return CompiledScene(scene, symbols, tuple(s.name for s in symbols), D.all_coeffs(), rows,
                         initial)


def compile_scene(scene: Scene) -> CompiledScene:
    """Compile a scene with declared parameters for :func:`laplace_springs.sweeps.sweep`.

    Parameters
    ----------
    scene : Scene
        At most :attr:`~laplace_springs.limits.Limits.sweep_max_coordinates` coordinates;
        forces (if any) without delays or periods, no sampled forces.

    Returns
    -------
    CompiledScene

    Raises
    ------
    SceneError
        For a scene too large, a delayed or periodic force, or a motion with an impulsive
        part (a transform that is not a proper fraction).

    Examples
    --------
    >>> import laplace_springs as ls
    >>> scene = ls.Scene.from_matrices(M=[[1]], C=[["c"]], K=[["k"]], x0=[1], v0=[0],
    ...                                parameters=["c", "k"])
    >>> compiled = compile_scene(scene)
    >>> compiled.names, compiled.denominator, compiled.numerators
    (('c', 'k'), [1, c, k], [[1, c]])
    """
    found = compiled_or_reason(scene)
    if isinstance(found, str):
        raise SceneError(f"sweep: cannot compile the scene: {found}; sweep it with "
                         "ls.sweep, which solves such scenes set by set")
    return found


def parameter_rows(compiled: CompiledScene, values: Mapping[Any, Any]) -> np.ndarray:
    """The parameter sets as a float array (P, parameters), checked.

    Every parameter of the scene needs a value: a number (the same for every set) or a
    1-D array; all arrays have the same length P (see
    :func:`~laplace_springs.sweeps.parameters.parameter_sets`).
    """
    return parameter_sets(compiled.names, compiled.symbols, values).rows
