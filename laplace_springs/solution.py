"""The result contract: one :class:`Solution` interface for every route.

Whatever :func:`laplace_springs.solve` returns answers the same questions the same way:

* :attr:`Solution.x`: x(t) as a SymPy column matrix in :data:`laplace_springs.t`;
* :meth:`Solution.evaluate`: float64 values with an error bound, or mpmath values to
  ``dps`` digits with their bound, for x or its derivatives;
* :meth:`Solution.verify`: the residuals of M x'' + C x' + K x = f and of the initial
  data;
* :attr:`Solution.method` (``"exact"``, ``"modal"`` or ``"certified"``),
  :attr:`Solution.reason`, :attr:`Solution.escalation`;
* :meth:`Solution.latex` and the plots.

The accuracy promised, and when an evaluation escalates to a more precise route, is
stated and decided in :mod:`laplace_springs.policy`. Each route implements three hooks:
a float64 pass with a running error bound, an escalation for the times whose bound
misses the target, and an evaluation to any number of digits.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import Any, ClassVar

import mpmath
import numpy as np
import sympy as sp

from .exact.algebraic import numeric_value
from .exact.assembly import ExactMotion, Piece, exact_motion
from .exact.jumps import InitialJump, jump_residuals
from .exact.real_terms import Term
from .exact.resolvent import Resolvent
from .model.errors import SceneError
from .model.numbers import generic_values
from .model.scene import Scene
from .model.symbols import TIME
from .numeric.certified import (
    CertifiedPoles,
    certified_digits,
    certified_poles,
    certified_values,
    closed_form,
)
from .numeric.first_order import massless_nodes, scene_arrays
from .numeric.modal import ModalMotion
from .numeric.mp_expr import mp_value
from .numeric.pole_sum import derivative_sum, two_diff
from .numeric.terms import NumericTerms, float_values, mp_values, numeric_terms
from .numeric.times import Times, as_times, check_dps
from .output.latex import matrix_latex, solution_latex
from .output.plots import plot_energy, plot_motion, plot_phase
from .policy import (
    CERTIFIED_MAX_ORDER,
    ESCALATION_DIGITS,
    EXACT_FALLBACK_MAX_COORDINATES,
    EXACT_FORM_MAX_COORDINATES,
    check_target,
    escalate_columns,
    reference_scale,
)

__all__ = ["Solution", "ExactSolution", "ModalSolution", "CertifiedSolution", "Verification",
           "DEFAULT_SAMPLES", "t"]

#: Time, the variable of every solution (the results hold for t ≥ 0).
t = TIME

#: Sample times (besides t = 0) at which :meth:`Solution.verify` checks the equations.
DEFAULT_SAMPLES: tuple[str, ...] = ("0.37", "1.3", "4.1")

_TINY = float(np.finfo(float).smallest_subnormal)
_EPS = float(np.finfo(float).eps)


@dataclass(frozen=True)
class Verification:
    """Outcome of :meth:`Solution.verify`: residuals relative to the solution's size.

    Attributes
    ----------
    ode_residual : float
        max |M x'' + C x' + K x − f| over the sample times, relative to the size of the
        terms.
    initial_residual : float
        The mismatch of the initial data (or of the jump conditions at t = 0 for massless
        nodes), relative to the data's size.
    tolerance : float
        What the route checks against.
    """

    ode_residual: float
    initial_residual: float
    tolerance: float

    @property
    def ok(self) -> bool:
        """True when both residuals are within the tolerance."""
        return self.ode_residual <= self.tolerance and self.initial_residual <= self.tolerance

    def __bool__(self) -> bool:
        return self.ok


def _check_order(derivative: object) -> int:
    if isinstance(derivative, bool) or not isinstance(derivative, (int, np.integer)) \
            or not 0 <= int(derivative) <= 2:
        raise ValueError(f"derivative must be 0, 1 or 2, got {derivative!r}")
    return int(derivative)


class Solution(ABC):
    """Motion x(t) of a scene: the interface every route honours.

    Build it with :func:`laplace_springs.solve`. Subclasses: :class:`ExactSolution`,
    :class:`ModalSolution`, :class:`CertifiedSolution`.

    Attributes
    ----------
    scene : Scene
    reason : str
        Why this route was taken.
    target : float
        The accuracy :meth:`evaluate` aims at (see :mod:`laplace_springs.policy`).
    """

    #: The route: "exact", "modal" or "certified".
    method: ClassVar[str] = ""

    def __init__(self, scene: Scene, *, reason: str, target: float | None = None) -> None:
        self.scene = scene
        self.reason = reason
        self.target = check_target(target)

    # -- the contract -----------------------------------------------------------------
    @property
    @abstractmethod
    def x(self) -> sp.ImmutableMatrix:
        """x(t) as a SymPy column matrix in :data:`laplace_springs.t`."""

    @property
    @abstractmethod
    def escalation(self) -> str | None:
        """Where times whose float64 bound misses the target go: "mp", "certified" or None."""

    @property
    @abstractmethod
    def poles(self) -> np.ndarray:
        """The poles λ of the motion (roots of Δ that occur), complex float64."""

    def evaluate(self, times: Any, *, dps: int | None = None, return_error: bool = False,
                 target: float | None = None, derivative: int = 0) -> Any:
        """x(t) (or a derivative) at the given times.

        Parameters
        ----------
        times : array_like
            Times t ≥ 0 (a scalar is one time). A float is the number it holds (0.1 is
            0.1000000000000000055…); a string such as ``"0.1"``, a Fraction or a SymPy
            rational is used exactly.
        dps : int, optional
            Decimal digits. Without it the result is float64; with it, an object array of
            mpmath numbers good to ``dps`` digits of max(‖x(t)‖∞, S₀).
        return_error : bool
            Also return bounds on the error of every entry (float64 without ``dps``,
            mpmath numbers with it).
        target : float, optional
            Relative accuracy for float64 values (default: the solution's ``target``,
            :data:`laplace_springs.policy.TARGET`). Times whose bound misses it are
            recomputed by the escalation route.
        derivative : {0, 1, 2}
            Evaluate x, x' or x''.

        Returns
        -------
        numpy.ndarray, or (numpy.ndarray, numpy.ndarray)
            Shape (n, len(times)).

        Raises
        ------
        ValueError
            For NaN, infinite or negative times, a bad ``dps``, ``target`` or
            ``derivative``.
        SceneError
            When the scene has symbols (give them values first).
        OverflowError
            When a value exceeds the float64 range (use ``dps``).

        Notes
        -----
        Every value satisfies the contract of :mod:`laplace_springs.policy`: its error is
        within ``target``·max(‖x(t)‖∞, S₀), or the returned bound says how large it may be.
        The decision to escalate a time looks at that time alone, so a value does not
        depend on the other times in the call.
        """
        self._require_numbers()
        T = as_times(times)
        order = _check_order(derivative)
        if dps is not None:
            values, bounds = self._digits(T, order, check_dps(dps))
            return (values, bounds) if return_error else values
        goal = check_target(self.target if target is None else target)
        values, bounds = self._float(T, order)
        mask = escalate_columns(values, bounds, self._floor(order), goal)
        if mask.any() and self.escalation is not None:
            columns = np.flatnonzero(mask)
            better, better_bounds = self._escalate(T.subset(columns), order, goal)
            values[:, columns], bounds[:, columns] = better, better_bounds
        _check_float_result(values, bounds, T)
        bounds = bounds + _TINY
        return (values, bounds) if return_error else values

    def verify(self, *, samples: Sequence[Any] = DEFAULT_SAMPLES,
               tolerance: float | None = None) -> Verification:
        """Check that the motion satisfies the equations and the initial data.

        x, x' and x'' are evaluated at t = 0 and the sample times (float64, every value
        within its bound); the residual M x'' + C x' + K x − f is taken relative to
        max(|M||x''| + |C||x'| + |K||x| + |f|) and the initial mismatch relative to the
        data. The velocities of massless nodes are not compared with v0: their constraint
        sets them. :class:`ExactSolution` checks its closed form symbolically instead.

        Returns
        -------
        Verification
            Truthy when both residuals are within ``tolerance`` (default 1e-9).
        """
        tolerance = 1e-9 if tolerance is None else float(tolerance)
        M, C, K, x0, v0 = scene_arrays(self.scene)
        times = np.array([0.0, *(float(sp.Rational(str(s))) for s in samples)])
        x, v, a = (self.evaluate(times, derivative=order) for order in range(3))
        residual = np.max(np.abs(M @ a + C @ v + K @ x))
        size = np.max(np.abs(M) @ np.abs(a) + np.abs(C) @ np.abs(v) + np.abs(K) @ np.abs(x))
        massive = [i for i in range(self.scene.n) if i not in massless_nodes(self.scene)]
        start = np.max(np.abs(np.concatenate([x[:, 0] - x0, v[massive, 0] - v0[massive]])))
        data = np.max(np.abs(np.concatenate([x0, v0])))
        return Verification(float(residual / size) if size else float(residual),
                            float(start / data) if data else float(start), tolerance)

    def latex(self, *, form: str = "terms", resolvent: bool = False, sylvester: bool = False,
              standalone: bool = False, markdown: bool = False) -> str:
        """x(t) in LaTeX (see :meth:`ExactSolution.latex`); Float coefficients for large scenes."""
        exact = self._exact_solution
        if exact is not None:
            return exact.latex(form=form, resolvent=resolvent, sylvester=sylvester,
                               standalone=standalone, markdown=markdown)
        return matrix_latex(self.scene, self.x, standalone=standalone, markdown=markdown)

    def _repr_latex_(self) -> str:
        return "$$" + self.latex() + "$$"

    def __repr__(self) -> str:
        poles = self.poles
        slowest = float(-poles.real.max()) if len(poles) else 0.0
        return (f"<{type(self).__name__} of {self.scene!r}: {len(poles)} poles, slowest decay "
                f"rate {slowest:.3g}; method={self.method!r}: {self.reason}>")

    # -- plots (need matplotlib) --------------------------------------------------------
    def plot(self, ax: Any = None, **kw: Any) -> Any:
        """The seed's "Mass Position vs. Time" plot; see :func:`laplace_springs.output.plots.plot_motion`."""
        return plot_motion(self, ax, **kw)

    def plot_phase(self, ax: Any = None, **kw: Any) -> Any:
        """Phase portraits x_i' against x_i; see :func:`laplace_springs.output.plots.plot_phase`."""
        return plot_phase(self, ax, **kw)

    def plot_energy(self, ax: Any = None, **kw: Any) -> Any:
        """Kinetic, potential, dissipated energy; see :func:`laplace_springs.output.plots.plot_energy`."""
        return plot_energy(self, ax, **kw)

    # -- the hooks each route implements ------------------------------------------------
    @abstractmethod
    def _float(self, times: Times, order: int) -> tuple[np.ndarray, np.ndarray]:
        """float64 values and error bounds (inf where unreliable), shape (n, len(times))."""

    @abstractmethod
    def _escalate(self, times: Times, order: int, target: float) -> tuple[np.ndarray, np.ndarray]:
        """float64 values and bounds from the escalation route, for the given times."""

    @abstractmethod
    def _digits(self, times: Times, order: int, dps: int) -> tuple[np.ndarray, np.ndarray]:
        """mpmath values to ``dps`` digits and their bounds (object arrays)."""

    @property
    @abstractmethod
    def _spectral_radius(self) -> float:
        """max |λ| over the poles."""

    @cached_property
    def _exact_solution(self) -> ExactSolution | None:
        """The exact solution of the scene, where it is affordable (None otherwise)."""
        if self.scene.n > EXACT_FORM_MAX_COORDINATES:
            return None
        return ExactSolution(exact_motion(self.scene), reason="exact form of a " + self.method
                             + " solution", target=self.target)

    # -- shared helpers -----------------------------------------------------------------
    def _floor(self, order: int) -> float:
        """S₀·ρ^order: the contract's floor for the order-th derivative."""
        return self._base_floor * self._spectral_radius**order

    @cached_property
    def _base_floor(self) -> float:
        s = self.scene
        x0 = max((abs(float(v)) for v in s.x0), default=0.0)
        v0 = max((abs(float(v)) for i, v in enumerate(s.v0) if i not in massless_nodes(s)),
                 default=0.0)
        return reference_scale(x0, v0, self._spectral_radius)

    def _require_numbers(self) -> None:
        if self.scene.free_symbols:
            names = ", ".join(sorted(str(v) for v in self.scene.free_symbols))
            raise SceneError(f"evaluate needs numbers, but the scene has the parameters {names}; "
                             "build the scene with values for them")


def _check_float_result(values: np.ndarray, bounds: np.ndarray, times: Times) -> None:
    """Raise rather than return a value that is not finite or a bound that is not."""
    with np.errstate(invalid="ignore"):
        huge = ~np.isfinite(values) | (np.abs(values) > np.finfo(float).max / 4)
    if huge.any():
        column = int(np.flatnonzero(huge.any(axis=0))[0])
        raise OverflowError(f"x(t) at t = {times.hi[column]!r} is beyond the float64 range "
                            "(or not finite); evaluate(..., dps=30) gives it")
    if not np.all(np.isfinite(bounds)):
        column = int(np.flatnonzero(~np.all(np.isfinite(bounds), axis=0))[0])
        raise ArithmeticError(f"no route could bound the error of x(t) at t = {times.hi[column]!r}; "
                              "evaluate(..., dps=30) computes it to 30 digits")


# ---------------------------------------------------------------------------- exact route


class ExactSolution(Solution):
    """Exact motion x(t) of a scene, in real damped sine/cosine form.

    Holds an :class:`~laplace_springs.exact.assembly.ExactMotion`; :attr:`x`, the pieces,
    the seed's g-basis and the initial jump are exact. Float64 evaluation sums the terms
    as a stable pole sum (:mod:`laplace_springs.numeric.terms`); times whose bound misses
    the target are recomputed with mpmath ("mp").
    """

    method = "exact"

    def __init__(self, motion: ExactMotion, *, reason: str, target: float | None = None) -> None:
        super().__init__(motion.scene, reason=reason, target=target)
        self.motion = motion

    @property
    def escalation(self) -> str:
        return "mp"

    # -- exact data -------------------------------------------------------------------
    @property
    def x(self) -> sp.ImmutableMatrix:
        """x(t) as a SymPy column matrix; a response to an input delayed by τ carries
        Heaviside(t − τ), nothing else does (the solution holds for t ≥ 0)."""
        return self.motion.x

    @property
    def resolvent(self) -> Resolvent:
        """Δ(λ), adj(λ) and X(λ) (see :mod:`laplace_springs.exact.resolvent`)."""
        return self.motion.resolvent

    @property
    def terms(self) -> tuple[tuple[Term, ...], ...]:
        """The real terms of each coordinate (of the piece switched on at t = 0)."""
        return self.motion.terms

    @property
    def pieces(self) -> tuple[Piece, ...]:
        """The motion's pieces, one per delay of the inputs (delay 0 first)."""
        return self.motion.pieces

    @cached_property
    def steady_state(self) -> sp.ImmutableMatrix:
        """The part of x(t) with the input's poles: what the forcing sustains.

        Zero for a free motion; at exact resonance of an undamped system the secular
        t·sin term belongs here (its pole is the input's).
        """
        return self.motion.part("steady")

    @cached_property
    def transient(self) -> sp.ImmutableMatrix:
        """The part of x(t) with the system's own poles only: x = transient + steady_state."""
        return self.motion.part("transient")

    @property
    def initial_jump(self) -> InitialJump:
        """x(0⁺), x'(0⁺) and what jumped at t = 0 (see :attr:`ExactMotion.initial_jump`)."""
        return self.motion.initial_jump

    @property
    def g_denominator(self) -> sp.Poly:
        """The Δ(λ) of the g-basis: integer, content 1 (as the seed prints it)."""
        return self.motion.g_denominator

    @property
    def g_coefficients(self) -> sp.ImmutableMatrix:
        """c_ik with x_i(t) = Σ_k c_ik g_k(t) (the seed's K_j and N_j)."""
        return self.motion.g_coefficients

    @property
    def g_indices(self) -> tuple[int, ...]:
        """The k whose g_k occurs in some coordinate."""
        return self.motion.g_indices

    @property
    def g_basis(self) -> dict[int, sp.Expr]:
        """g_k(t) = L⁻¹[λ^k/Δ(λ)] for the k in :attr:`g_indices`, exactly."""
        return self.motion.g_basis

    def g_form(self) -> sp.ImmutableMatrix:
        """x(t) written as Σ c_ik g_k with g_k as undefined functions g_k(t)."""
        return self.motion.g_form()

    @property
    def definitions(self) -> dict:
        """Named quantity → definition for the names in :attr:`x` (empty for numeric scenes)."""
        return self.motion.definitions

    def substituted(self) -> sp.ImmutableMatrix:
        """:attr:`x` with every named quantity replaced by its definition."""
        return self.motion.substituted()

    @property
    def poles(self) -> np.ndarray:
        nodes = [complex(z) for z in self._numeric(0)[0].poles.nodes] if self.pieces else []
        return np.array(nodes, dtype=complex)

    @property
    def _spectral_radius(self) -> float:
        return max((abs(complex(z)) for data in self._numeric(0) for z in data.poles.nodes),
                   default=0.0)

    @cached_property
    def _exact_solution(self) -> ExactSolution:
        return self

    def latex(self, *, form: str = "terms", resolvent: bool = False, sylvester: bool = False,
              standalone: bool = False, markdown: bool = False) -> str:
        """x(t) in LaTeX the way the seed writes it, with every named quantity defined.

        Parameters
        ----------
        form : {"terms", "g"}
            Damped sines and cosines, or x_i = Σ c_ik g_k(t) with the g_k written out.
        resolvent : bool
            Also Δ(λ), R(λ) = (λ²I + λB + A)⁻¹ and X(λ).
        sylvester : bool
            Also Sylvester's matrices and cos(√A t), sin(√A t)/√A (undamped numeric scenes).
        standalone : bool
            A complete ``article`` document (compiles with pdflatex).
        markdown : bool
            A Markdown snippet: each block between ``$$`` lines.

        Returns
        -------
        str
            See :mod:`laplace_springs.output.latex` for the conventions (no imaginary unit,
            algebraic numbers as named constants, θ(t − τ) for switched inputs).
        """
        output = "document" if standalone else "markdown" if markdown else "fragment"
        return solution_latex(self.motion, form=form, resolvent=resolvent, sylvester=sylvester,
                              output=output)

    def __repr__(self) -> str:
        body = ", ".join(f"{name}(t) = {expr}" for name, expr in zip(self.scene.names, self.x))
        return f"ExactSolution({body})"

    # -- evaluation ---------------------------------------------------------------------
    def _numeric(self, order: int, dps: int = 40) -> tuple[NumericTerms, ...]:
        key = (order, dps)
        cache = self.__dict__.setdefault("_numeric_cache", {})
        if key not in cache:
            motion = self.motion
            for _ in range(order):
                motion = motion.derivative()
            cache[key] = tuple(numeric_terms(piece.terms, dps=dps) for piece in motion.pieces)
        return cache[key]

    def _shifted(self, times: Times, delay: sp.Expr) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Columns with t ≥ delay and t − delay there as a double-double."""
        if delay == 0:
            return np.arange(len(times)), times.hi, times.lo
        with mpmath.workdps(40):
            tau = mp_value(delay, 40)
            tau_hi = float(tau)
            tau_lo = float(tau - tau_hi)
        on = np.flatnonzero((times.hi > tau_hi) | ((times.hi == tau_hi) & (times.lo >= tau_lo)))
        hi, lo = two_diff(times.hi[on], tau_hi, tau_lo)
        return on, hi, lo + times.lo[on]

    def _float(self, times: Times, order: int) -> tuple[np.ndarray, np.ndarray]:
        n = self.scene.n
        values, bounds = np.zeros((n, len(times))), np.zeros((n, len(times)))
        for piece, data in zip(self.pieces, self._numeric(order)):
            on, hi, lo = self._shifted(times, piece.delay)
            if on.size:
                part, bound = float_values(data, n, hi, lo)
                values[:, on] += part
                bounds[:, on] += bound
        return values, bounds

    def _mp(self, times: Times, order: int, digits: int, floor: float) -> tuple[list, list]:
        """mpmath values and bounds (n lists of mpf) good to ``digits``."""
        n = self.scene.n
        work = digits + 20
        with mpmath.workdps(work):
            total = [[mpmath.mpf(0)] * len(times) for _ in range(n)]
            bounds = [[mpmath.mpf(0)] * len(times) for _ in range(n)]
            stamps = [times.mpf(j) for j in range(len(times))]
        for piece, data in zip(self.pieces, self._numeric(order)):
            with mpmath.workdps(work):
                tau = mp_value(piece.delay, work) if piece.delay != 0 else mpmath.mpf(0)
                on = [j for j, tv in enumerate(stamps) if tv >= tau]
                shifted = [stamps[j] - tau for j in on]
            if not on:
                continue
            part, bound, _ = mp_values(data, n, shifted, digits, [floor] * len(on))
            with mpmath.workdps(work):
                for k, j in enumerate(on):
                    for i in range(n):
                        total[i][j] += part[i][k]
                        bounds[i][j] += bound[i][k]
        return total, bounds

    def _escalate(self, times: Times, order: int, target: float) -> tuple[np.ndarray, np.ndarray]:
        digits = max(ESCALATION_DIGITS, math.ceil(-math.log10(target)) + 5)
        total, bounds = self._mp(times, order, digits, self._floor(order))
        values = np.array([[float(v) for v in row] for row in total])
        errors = np.array([[float(b) for b in row] for row in bounds])
        return values, errors + np.abs(values) * _EPS

    def _digits(self, times: Times, order: int, dps: int) -> tuple[np.ndarray, np.ndarray]:
        total, bounds = self._mp(times, order, dps + 2, self._floor(order))
        values = np.empty((self.scene.n, len(times)), dtype=object)
        errors = np.empty((self.scene.n, len(times)), dtype=object)
        with mpmath.workdps(dps):
            for i, row in enumerate(total):
                for j, v in enumerate(row):
                    values[i, j] = +v
                    errors[i, j] = bounds[i][j] + abs(v) * mpmath.mpf(10) ** (-dps)
        return values, errors

    # -- verification -------------------------------------------------------------------
    def verify(self, *, samples: Sequence[Any] = DEFAULT_SAMPLES,
               tolerance: float | None = None) -> Verification:
        """Check at high precision that :attr:`x` satisfies the equations and initial data.

        The exact expression is differentiated symbolically and M x'' + C x' + K x − f is
        evaluated at the sample times (also at t = 0⁺, where a massless node's constraint
        must already hold) with enough digits for ``tolerance`` (default 1e-30, at 40
        digits). At the start the jump conditions of
        :func:`laplace_springs.exact.jumps.jump_residuals` are checked: M(x(0⁺) − x0) = 0
        and M(x'(0⁺) − v0) + C(x(0⁺) − x0) = 0 (plus impulse terms), which for an
        invertible M is x(0) = x0, x'(0) = v0. Symbolic parameters are given fixed
        generic values first (the residual is an identity in them).
        """
        tolerance = 1e-30 if tolerance is None else float(tolerance)
        dps = max(40, math.ceil(-math.log10(max(tolerance, 1e-4000))) + 10)
        s = self.scene
        generic = generic_values(s.free_symbols)
        x = sp.Matrix(self.x)
        v = x.diff(TIME)
        force = sp.Matrix(s.forcing) if s.forcing is not None and s.is_forced else sp.zeros(s.n, 1)
        force = force.replace(sp.Heaviside, lambda arg, *_: sp.Heaviside(arg, 1))  # t = 0⁺
        residual = (s.M * v.diff(TIME) + s.C * v + s.K * x - force).xreplace(generic)
        residual = residual.replace(sp.DiracDelta, lambda *args: sp.S.Zero)  # 0 off the delays
        jump = self.initial_jump
        x, v = (m.replace(sp.DiracDelta, lambda *a: sp.S.Zero) for m in (x, v))
        start = jump_residuals(s, x.subs(TIME, 0) - s.x0, v.subs(TIME, 0) - s.v0,
                               jump.impulses, load=self.motion.impulsive_load())
        start = [sp.sympify(e).xreplace(generic) for e in start]
        times = _sample_times(samples, [piece.delay for piece in self.pieces])
        sizes = [*s.x0, *s.v0, *(f.subs(TIME, tv) for f in force.xreplace(generic) for tv in times)]
        scale = max(1.0, _size([e.replace(sp.DiracDelta, lambda *a: 0) for e in sizes], generic, 20))
        ode = _size([e.subs(TIME, tv) for e in residual for tv in times], {}, dps)
        return Verification(ode / scale, _size(start, generic, dps) / scale, tolerance)


def _sample_times(samples: Sequence[Any], delays: Sequence[sp.Expr]) -> list[sp.Expr]:
    """t = 0 and the samples, moved off the switching times of delayed inputs."""
    times: list[sp.Expr] = [sp.S.Zero]
    for tv in samples:
        value = sp.Rational(str(tv))
        while any(value == d for d in delays):
            value += sp.Rational(1, 7)
        times.append(value)
    return times


def _size(exprs: Sequence[Any], values: dict, dps: int) -> float:
    """max |e| over the expressions, at ``dps`` digits (complex values allowed)."""
    caches: dict = {}
    out = 0.0
    for e in exprs:
        expr = sp.sympify(e).xreplace(values)
        try:
            size = float(abs(mp_value(expr, dps, caches)))
        except (TypeError, ValueError):
            size = float(abs(numeric_value(expr, dps)))
        out = max(out, size)
    return out


# ---------------------------------------------------------------------------- modal route


class ModalSolution(Solution):
    """Motion x(t) of a numeric scene from a conditioned float64 eigen-decomposition.

    Holds a :class:`~laplace_springs.numeric.modal.ModalMotion`. Times whose float64 bound
    misses the target go to the certified route where the scene allows it (rational
    entries, 2n ≤ :data:`~laplace_springs.policy.CERTIFIED_MAX_ORDER`), else to the exact
    route's mpmath evaluation (up to
    :data:`~laplace_springs.policy.EXACT_FALLBACK_MAX_COORDINATES` coordinates).
    """

    method = "modal"

    def __init__(self, scene: Scene, motion: ModalMotion, *, reason: str,
                 target: float | None = None, certified: CertifiedPoles | None = None) -> None:
        super().__init__(scene, reason=reason, target=target)
        self.motion = motion
        self._given_certified = certified

    @property
    def modes(self) -> Any:
        """The float64 modes and blocks (:class:`~laplace_springs.numeric.modal.Modes`)."""
        return self.motion.modes

    @property
    def poles(self) -> np.ndarray:
        return self.motion.poles()

    @property
    def _spectral_radius(self) -> float:
        return float(np.max(np.abs(self.poles), initial=0.0))

    @cached_property
    def x(self) -> sp.ImmutableMatrix:
        """x(t): the exact closed form up to EXACT_FORM_MAX_COORDINATES coordinates (built on
        first use), else terms t^p e^{αt}(a cos βt + b sin βt) with Float coefficients."""
        exact = self._exact_solution
        return exact.x if exact is not None else self.motion.closed_form()

    @cached_property
    def _certified(self) -> CertifiedPoles | None:
        if self._given_certified is not None:
            return self._given_certified
        if 2 * self.scene.n > CERTIFIED_MAX_ORDER:
            return None
        return certified_poles(self.scene)

    @cached_property
    def _exact_fallback(self) -> ExactSolution | None:
        if self.scene.n > EXACT_FALLBACK_MAX_COORDINATES:
            return None
        return self._exact_solution

    @property
    def escalation(self) -> str | None:
        if self._certified is not None:
            return "certified"
        return "mp" if self.scene.n <= EXACT_FALLBACK_MAX_COORDINATES else None

    def _float(self, times: Times, order: int) -> tuple[np.ndarray, np.ndarray]:
        values = self.motion.values(times.hi, order)
        bounds = self.motion.bound(times.hi, order)
        if times.lo.any():  # a decimal time: the float evaluated at hi, off by lo·x'
            slope = np.abs(self.motion.values(times.hi, order + 1))
            bounds = bounds + 2 * np.abs(times.lo)[None, :] * slope
        return values, bounds

    def _escalate(self, times: Times, order: int, target: float) -> tuple[np.ndarray, np.ndarray]:
        if self._certified is not None:
            return certified_values(self._certified, times, order, target, self._floor(order))
        exact = self._exact_fallback
        if exact is not None:
            return exact._escalate(times, order, target)
        return self._float(times, order)

    def _digits(self, times: Times, order: int, dps: int) -> tuple[np.ndarray, np.ndarray]:
        if self._certified is not None:
            return certified_digits(self._certified, times, order, dps, self._floor(order))
        exact = self._exact_fallback
        if exact is not None:
            return exact._digits(times, order, dps)
        raise ValueError("evaluate(..., dps=) needs the certified or the exact route, and this "
                         f"scene suits neither ({self.scene.n} coordinates, entries "
                         "not all rational or too large for them)")


# ---------------------------------------------------------------------------- certified route


class CertifiedSolution(Solution):
    """Motion x(t) from certified poles and residues (ball arithmetic).

    Holds :class:`~laplace_springs.numeric.certified.CertifiedPoles`. Float64 values come
    from the stable pole-sum kernels; times whose bound misses the target are evaluated
    in ball arithmetic, whose radius certifies the bound.
    """

    method = "certified"

    def __init__(self, scene: Scene, poles: CertifiedPoles, *, reason: str,
                 target: float | None = None) -> None:
        super().__init__(scene, reason=reason, target=target)
        self.certified = poles

    @property
    def escalation(self) -> str:
        return "certified"

    @cached_property
    def poles(self) -> np.ndarray:
        nodes = self._fast(0).poles.nodes
        return np.array([complex(z) for z in nodes], dtype=complex)

    @property
    def _spectral_radius(self) -> float:
        return self.certified.spectral_radius()

    @cached_property
    def x(self) -> sp.ImmutableMatrix:
        """x(t): the exact closed form up to EXACT_FORM_MAX_COORDINATES coordinates (built on
        first use), else real terms with Float coefficients from the certified poles."""
        exact = self._exact_solution
        return exact.x if exact is not None else sp.ImmutableMatrix(closed_form(self.certified))

    def _fast(self, order: int) -> NumericTerms:
        cache = self.__dict__.setdefault("_fast_cache", {})
        if order not in cache:
            form = self.certified.pole_sum(40)
            cache[order] = NumericTerms((), derivative_sum(form, order) if order else form, 40)
        return cache[order]

    def _float(self, times: Times, order: int) -> tuple[np.ndarray, np.ndarray]:
        return float_values(self._fast(order), self.scene.n, times.hi, times.lo)

    def _escalate(self, times: Times, order: int, target: float) -> tuple[np.ndarray, np.ndarray]:
        return certified_values(self.certified, times, order, target, self._floor(order))

    def _digits(self, times: Times, order: int, dps: int) -> tuple[np.ndarray, np.ndarray]:
        return certified_digits(self.certified, times, order, dps, self._floor(order))
