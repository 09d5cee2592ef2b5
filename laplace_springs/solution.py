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
stated and decided in :mod:`laplace_springs.policy`. Each route
(:mod:`laplace_springs.routes`) implements three hooks: a float64 pass with a running
error bound, an escalation for the times whose bound misses the target, and an
evaluation to any number of digits.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import Any, ClassVar

import numpy as np
import sympy as sp

from .exact.assembly import Piece
from .exact.jumps import InitialJump
from .exact.real_terms import Term
from .exact.resolvent import Resolvent
from .exact.screening import has_exact_form
from .limits import limits
from .model.errors import LimitError, SceneError
from .model.scene import Scene
from .model.symbols import TIME
from .model.units import attach_units, unit_note_text
from .numeric.first_order import massless_nodes, scene_entries
from .numeric.times import Times, as_times, check_dps
from .output.latex import matrix_latex
from .output.plots import plot_energy, plot_motion, plot_phase
from .output.text import formula_lines, summary_lines
from .planning.engines import Cost, Refusal
from .planning.execute import BUILDERS, DIGIT_HOSTS, EvaluationReport, Evaluator, execute_judged
from .planning.facts import scene_facts
from .planning.plan import Plan
from .planning.plan import plan as plan_request
from .planning.request import DEFAULT_REQUEST, Request, request_for
from .planning.standing import standing_covers, standing_seconds
from .policy import Verdict, check_target, reference_scale

__all__ = ["Solution", "Verification", "DEFAULT_SAMPLES", "t"]

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

    def __repr__(self) -> str:
        """``Verification(ok: ODE residual 2.1e-16, initial 0 (tolerance 1e-09))``.

        >>> Verification(2.1e-16, 0.0, 1e-9)
        Verification(ok: ODE residual 2.1e-16, initial 0 (tolerance 1e-09))
        >>> Verification(3e-5, 0.0, 1e-9)
        Verification(FAILED: ODE residual 3e-05, initial 0 (tolerance 1e-09))
        """
        verdict = "ok" if self.ok else "FAILED"
        return (f"Verification({verdict}: ODE residual {self.ode_residual:.2g}, initial "
                f"{self.initial_residual:.2g} (tolerance {self.tolerance:.2g}))")


class _SparseProduct:
    """A matrix of the scene (M, C, K, x0 or v0) as float64 coordinates of its nonzero
    entries: products cost O(nonzeros), so ``verify`` runs on scenes of any size."""

    def __init__(self, scene: Scene, name: str) -> None:
        entries = scene_entries(scene, name)
        self.n = scene.n
        self.rows = np.array([i for i, _ in entries], dtype=np.intp)
        self.cols = np.array([j for _, j in entries], dtype=np.intp)
        self.values = np.array([float(value) for value in entries.values()], dtype=float)

    def __call__(self, y: np.ndarray, absolute: bool = False) -> np.ndarray:
        values = np.abs(self.values) if absolute else self.values
        out = np.zeros((self.n, y.shape[1]))
        np.add.at(out, self.rows, values[:, None] * y[self.cols])
        return out

    def column(self) -> np.ndarray:
        out = np.zeros(self.n)
        out[self.rows] = self.values
        return out


def _check_order(derivative: object) -> int:
    if isinstance(derivative, bool) or not isinstance(derivative, (int, np.integer)) \
            or not 0 <= int(derivative) <= 2:
        raise ValueError(f"derivative must be 0, 1 or 2, got {derivative!r}")
    return int(derivative)


class Solution(ABC):
    """Motion x(t) of a scene: the interface every route honours.

    Build it with :func:`laplace_springs.solve`. The routes' classes
    (:class:`~laplace_springs.routes.exact.ExactSolution`,
    :class:`~laplace_springs.routes.modal.ModalSolution`,
    :class:`~laplace_springs.routes.certified.CertifiedSolution`) implement its hooks.

    Attributes
    ----------
    scene : Scene
    target : float
        The accuracy :meth:`evaluate` aims at (see :mod:`laplace_springs.policy`).
    """

    #: The route: "exact", "modal" or "certified".
    method: ClassVar[str] = ""

    def __init__(self, scene: Scene, *, reason: str | None, target: float | None = None) -> None:
        self.scene = scene
        self._reason = reason
        self.target = check_target(target)

    @property
    def reason(self) -> str:
        """Why this route was taken: the reason of the plan that chose it (made on first
        use where ``solve`` took the standing plan, :mod:`laplace_springs.planning.standing`:
        the plan ``solve`` makes first, for the default request)."""
        if self._reason is None:
            self._reason = plan_request(scene_facts(self.scene, self.requested), DEFAULT_REQUEST,
                                        method=self.requested, available=BUILDERS).reason
        return self._reason

    @reason.setter
    def reason(self, text: str) -> None:
        self._reason = text

    # -- the contract -----------------------------------------------------------------
    @property
    @abstractmethod
    def x(self) -> sp.ImmutableMatrix:
        """x(t) as a SymPy column matrix in :data:`laplace_springs.t`."""

    @property
    def escalation(self) -> str | None:
        """The first engine of the default plan that recomputes a time whose float64 bound
        misses the target ("refined", "ball", "mp", or a tighter float64 engine), or None."""
        chain = self.plan().chain
        return chain[1] if len(chain) > 1 else None

    @property
    @abstractmethod
    def poles(self) -> np.ndarray:
        """The poles λ of the motion (roots of Δ that occur), complex float64."""

    def evaluate(self, times: Any, *, dps: int | None = None, return_error: bool = False,
                 target: float | None = None, derivative: int = 0,
                 return_report: bool = False, units: bool | str = False,
                 progress: bool | None = None) -> Any:
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
        return_report : bool
            Also return an :class:`~laplace_springs.planning.execute.EvaluationReport`: the
            plan, and which engine produced each time.
        units : bool or str
            For a scene written with units: True returns values and bounds as pint
            Quantities in metres (m/s, m/s² for derivatives), a unit such as ``"cm"``
            converts to it. Times may carry units whatever this says (``"0.5 s"``).
        progress : bool, optional
            Show a progress bar on stderr (default: when the plan expects the evaluation to
            take more than ``Limits.progress_after_seconds``).

        Returns
        -------
        numpy.ndarray, or a tuple (values, bounds, report) of what was asked
            Values and bounds have shape (n, len(times)).

        Raises
        ------
        ValueError
            For NaN, infinite or negative times, a bad ``dps``, ``target`` or
            ``derivative``.
        LimitError
            When no engine of the package can bound a value within
            max(target, Limits.refusal_bound) of the scale, or the request is larger than
            ``Limits.max_evaluation_values`` (the message names the time and the way out).
        SceneError
            When the scene has symbols (give them values first).
        OverflowError
            When a value exceeds the float64 range (use ``dps``).

        Notes
        -----
        Every value satisfies the contract of :mod:`laplace_springs.policy`: its error is
        within ``target``·max(‖x(t)‖∞, S₀), or the returned bound says how large it may be.
        The planner (:mod:`laplace_springs.planning`) chooses the engines for this request;
        a time whose bound misses the target is recomputed by the next engine of the plan,
        a decision that looks at that time alone, so a value does not depend on the other
        times in the call (see :meth:`plan`).
        """
        self._require_numbers()
        T = as_times(times)
        order = derivative if derivative.__class__ is int and 0 <= derivative <= 2 \
            else _check_order(derivative)
        n = self.scene.n
        _check_size(len(T), n)
        goal = self.target if target is None else check_target(target)  # ours: checked
        if self._standing and order == 0 and dps is None and not return_report \
                and _quiet(progress, self.scene, len(T)) \
                and (found := self._standing_values(T, goal, return_error)) is not None:
            values, bounds = found
        else:
            values, bounds, report = self._planned_values(T, order, goal, dps, progress)
        if units:  # Quantities in the scene's units or the unit asked for
            values = attach_units(values, self.scene, order, units)
            if return_error:
                bounds = attach_units(bounds, self.scene, order, units)
        out = (values, bounds) if return_error else (values,)
        out = (*out, report) if return_report else out
        return out if len(out) > 1 else out[0]

    def _planned_values(self, T: Times, order: int, goal: float, dps: int | None,
                        progress: bool | None) -> tuple[np.ndarray, np.ndarray, EvaluationReport]:
        """Values, bounds and the report of :meth:`evaluate` from the plan of its request."""
        n = self.scene.n
        request = request_for(T, target=goal, dps=None if dps is None else check_dps(dps),
                              order=order)
        plan = self._plan(request)
        if dps is not None:
            values, bounds = self._digits_by(plan, T, order, request.dps or 0)
            report = EvaluationReport(plan, (plan.primary or "",) * len(T), np.zeros(len(T)))
        else:
            # an engine's overflow shows as an infinite bound, never a NumPy warning
            with np.errstate(all="ignore"):
                values, bounds, report, verdict = execute_judged(
                    plan, self._evaluator, T, n, order, goal, self._floor(order),
                    progress=progress)
                sizes = np.abs(values)
            _check_float_result(verdict, sizes, T, report, goal, order)
            bounds = _floored(bounds, sizes)
        return values, bounds, report

    #: True where ``solve`` took the standing plan: the solution's own engine is the primary
    #: of every float64 request of x (:mod:`laplace_springs.planning.standing`).
    _standing: bool = False

    def _standing_values(self, times: Times, target: float,
                         bounds: bool = True) -> tuple[np.ndarray, np.ndarray | None] | None:
        """x at ``times`` from the solution's own engine alone, when every bound is within
        target·S₀ (so within the target of every time's scale, and no time is pending) and
        every value within float64's range: what executing the plan gives then, without
        planning. None otherwise (the request is planned and executed in full).

        Without ``bounds`` (the caller returns none), the engine's bound over [0, last
        time] is asked first: where it meets the target the values alone are formed, the
        same numbers (their bounds None)."""
        if not standing_covers(len(times)):
            return None
        floor = self._floor(0)
        if not floor > 0:
            return None
        if not bounds and (covered := self._covered_values(times, target * floor)) is not None \
                and float(np.maximum.reduce(np.abs(covered), axis=None)) <= _HUGE:
            return covered, None
        # the primary, as executed (the standing engine's evaluation keeps NumPy quiet and
        # returns new float64 arrays)
        evaluator: Any = self._evaluator(self.method)
        values, found = evaluator(times, 0, target)
        sizes = np.abs(values)
        if not (float(np.maximum.reduce(found, axis=None)) / floor <= target
                and float(np.maximum.reduce(sizes, axis=None)) <= _HUGE):  # NaN fails both
            return None
        return values, _floored(found, sizes)

    def _covered_values(self, times: Times, most: float) -> np.ndarray | None:
        """x at ``times`` from the solution's own engine without bounds, where its bound
        over [0, last time] is known to be at most ``most`` without per-time work; None
        otherwise (and for engines that cannot tell)."""
        return None

    def plan(self, times: Any = None, *, target: float | None = None, dps: int | None = None,
             derivative: int = 0) -> Plan:
        """The plan :meth:`evaluate` would execute for these arguments (nothing is evaluated).

        Examples
        --------
        >>> import laplace_springs as ls
        >>> sol = ls.solve(ls.Scene.from_matrices(M=[[1]], C=[[2]], K=[[1]], x0=[1], v0=[0]))
        >>> sol.plan([0.5, 2]).chain[0] == sol.method
        True
        """
        T = as_times([] if times is None else times)
        request = request_for(T, target=check_target(self.target if target is None else target),
                              dps=None if dps is None else check_dps(dps),
                              order=_check_order(derivative))
        return self._plan(request if times is not None else DEFAULT_REQUEST)

    # -- planning and execution (the engines a solution can call) -------------------------
    #: "auto", an engine or a family: what ``solve`` was asked (kept for every request).
    requested: str = "auto"

    #: The arbitrary-precision engine this class evaluates with its own data ("mp" for
    #: exact terms, "ball" for certified poles), if any.
    _escalation_engine: ClassVar[str | None] = None
    #: False for solutions that are not planned (their own float64 pass and escalation).
    _planned: ClassVar[bool] = True

    def _own_engines(self) -> dict[str, Evaluator]:
        """Engines this solution evaluates with its own data: {name: evaluator}."""
        own: dict[str, Evaluator] = {self.method: lambda times, order, target: self._float(times, order)}
        if self._escalation_engine is not None:
            own[self._escalation_engine] = self._escalate
        return own

    #: Engines found unable to meet the target on this scene (their own bound missed it at
    #: the probe times when the solution was made): later plans leave them out.
    excluded: frozenset[str] = frozenset()

    def _plan(self, request: Request) -> Plan:
        if not self._planned:
            own = self._own_engines()
            return Plan(request, self.method, tuple(own), costs={name: Cost(0.0, 0.0) for name in own},
                        reason=self.reason)
        built, available = self._engine_sets
        return plan_request(scene_facts(self.scene, self.requested), request, method=self.requested,
                            built=built, available=available)

    @property
    def _engine_sets(self) -> tuple[frozenset[str], frozenset[str]]:
        """(the engines this solution holds, the engines its plans may use): made once, and
        again if :attr:`excluded` is replaced (``solve`` sets it after building)."""
        cached: Any = self.__dict__.get("_sets")
        if cached is None or cached[0] is not self.excluded:
            own = frozenset(self._own_engines())
            cached = self.__dict__["_sets"] = (self.excluded, own,
                                               (own | frozenset(BUILDERS)) - self.excluded)
        return cached[1], cached[2]

    def _evaluator(self, name: str) -> Evaluator | Refusal:
        """The evaluator of engine ``name`` for this scene, built once per solution."""
        cache = self.__dict__.setdefault("_evaluators", {})
        if name not in cache:
            own = self._own_engines()
            cache[name] = own[name] if name in own else BUILDERS[name](self)
        found: Evaluator | Refusal = cache[name]
        return found

    def _digits_by(self, plan: Plan, times: Times, order: int,
                   dps: int) -> tuple[np.ndarray, np.ndarray]:
        """``dps`` digits from the plan's arbitrary-precision engine."""
        for name in plan.chain:
            host = self if name == self._escalation_engine or not self._planned \
                else DIGIT_HOSTS[name](self)
            if not isinstance(host, Refusal):
                digits: tuple[np.ndarray, np.ndarray] = host._digits(times, order, dps)
                return digits
        raise LimitError(f"evaluate(..., dps={dps}): {plan.reason}")

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
        M, C, K = (_SparseProduct(self.scene, name) for name in ("M", "C", "K"))
        x0, v0 = (_SparseProduct(self.scene, name).column() for name in ("x0", "v0"))
        times = np.array([0.0, *(float(sp.Rational(str(s))) for s in samples)])
        x, v, a = (self.evaluate(times, derivative=order) for order in range(3))
        residual = np.max(np.abs(M(a) + C(v) + K(x)))
        size = np.max(M(np.abs(a), absolute=True) + C(np.abs(v), absolute=True)
                      + K(np.abs(x), absolute=True))
        massive = [i for i in range(self.scene.n) if i not in massless_nodes(self.scene)]
        start = np.max(np.abs(np.concatenate([x[:, 0] - x0, v[massive, 0] - v0[massive]])))
        data = np.max(np.abs(np.concatenate([x0, v0])))
        return Verification(float(residual / size) if size else float(residual),
                            float(start / data) if data else float(start), tolerance)

    def latex(self, *, form: str = "terms", resolvent: bool = False, sylvester: bool = False,
              standalone: bool = False, markdown: bool = False) -> str:
        """x(t) in LaTeX: the exact route's (see ``ExactSolution.latex``) where an exact form is
        affordable, else the rows of :attr:`x` with Float coefficients."""
        exact = self._exact_form
        if exact is not None and exact is not self:
            return exact.latex(form=form, resolvent=resolvent, sylvester=sylvester,
                               standalone=standalone, markdown=markdown)
        return matrix_latex(self.scene, self.x, standalone=standalone, markdown=markdown)

    def _repr_latex_(self) -> str:
        return "$$" + self.latex() + "$$"

    def __str__(self) -> str:
        """The title and x(t) with named rates, frequencies and coefficients (their values and
        exact definitions under "where"); beyond Limits.exact_form_max_coordinates coordinates, the
        modal summary instead (see :mod:`laplace_springs.output.text`)."""
        lines = [self.scene.title] if self.scene.title else []
        if not has_exact_form(self.scene):
            lines.append(f"{self.method} route: {self.reason}")
            lines += summary_lines(self.scene)
        else:
            lines += formula_lines(self.scene, list(self.x), self.conditions)
        note = unit_note_text(self.scene)
        return "\n".join([*lines, note] if note else lines)

    def __repr__(self) -> str:
        poles = self.poles
        slowest = float(-poles.real.max()) if len(poles) else 0.0
        return (f"<{type(self).__name__} of {self.scene!r}: {len(poles)} poles, slowest decay "
                f"rate {slowest:.3g}; method={self.method!r}: {self.reason}>")

    # -- the exact form, on every route (built on first use where affordable) ------------
    @property
    def exact(self) -> Any:
        """The exact solution of the scene (an ``ExactSolution``), built on first use.

        Raises
        ------
        ValueError
            When the scene is too large for an exact form (more than
            :attr:`~laplace_springs.limits.Limits.exact_form_max_coordinates` coordinates).
        """
        exact = self._exact_form
        if exact is None:
            raise ValueError(f"the exact form is built up to Limits.exact_form_max_coordinates = "
                             f"{limits().exact_form_max_coordinates} coordinates; this scene has "
                             f"{self.scene.n}: use x (Float coefficients) and evaluate()")
        return exact

    @property
    def resolvent(self) -> Resolvent:
        """Δ(λ), adj(λ) and X(λ) (see :mod:`laplace_springs.exact.resolvent`)."""
        return self.exact.motion.resolvent

    @property
    def pieces(self) -> tuple[Piece, ...]:
        """The exact motion's pieces, one per delay of the inputs (delay 0 first)."""
        return self.exact.motion.pieces

    @property
    def terms(self) -> tuple[tuple[Term, ...], ...]:
        """The real terms of each coordinate (of the piece switched on at t = 0)."""
        return self.exact.motion.terms

    @cached_property
    def steady_state(self) -> sp.ImmutableMatrix:
        """The part of x(t) with the input's poles: what the forcing sustains.

        Zero for a free motion; at exact resonance of an undamped system the secular
        t·sin term belongs here (its pole is the input's).
        """
        return self.exact.motion.part("steady")

    @cached_property
    def transient(self) -> sp.ImmutableMatrix:
        """The part of x(t) with the system's own poles only: x = transient + steady_state."""
        return self.exact.motion.part("transient")

    @property
    def initial_jump(self) -> InitialJump:
        """x(0⁺), x'(0⁺) and what jumped at t = 0 (see ``ExactMotion.initial_jump``)."""
        return self.exact.motion.initial_jump

    @property
    def g_denominator(self) -> sp.Poly:
        """The Δ(λ) of the g-basis: integer, content 1 (as the seed prints it)."""
        return self.exact.motion.g_denominator

    @property
    def g_coefficients(self) -> sp.ImmutableMatrix:
        """c_ik with x_i(t) = Σ_k c_ik g_k(t) (the seed's K_j and N_j)."""
        return self.exact.motion.g_coefficients

    @property
    def g_indices(self) -> tuple[int, ...]:
        """The k whose g_k occurs in some coordinate."""
        return self.exact.motion.g_indices

    @property
    def g_basis(self) -> dict[int, sp.Expr]:
        """g_k(t) = L⁻¹[λ^k/Δ(λ)] for the k in :attr:`g_indices`, exactly."""
        return self.exact.motion.g_basis

    def g_form(self) -> sp.ImmutableMatrix:
        """x(t) written as Σ c_ik g_k with g_k as undefined functions g_k(t)."""
        return self.exact.motion.g_form()

    def subs(self, values: Any) -> Solution:
        """The solution with parameters given values; only exact solutions have parameters.

        A numeric route's scene has none, so this is a SceneError naming what it has
        (see :meth:`laplace_springs.routes.exact.ExactSolution.subs`).
        """
        self.scene.subs(values)  # raises: a numeric scene has no parameters
        raise SceneError(f"the {self.method} route's scene has no parameters to substitute")

    @property
    def conditions(self) -> tuple:
        """Where the formula holds, when it is generic (e.g. "Δ(λ) has simple roots"); () if always."""
        return ()

    @property
    def definitions(self) -> dict:
        """Named quantity → definition for the names in :attr:`x` (empty for numeric scenes)."""
        return self.exact.motion.definitions

    def substituted(self) -> sp.ImmutableMatrix:
        """:attr:`x` with every named quantity replaced by its definition."""
        return self.exact.motion.substituted()

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

    @property
    def _exact_form(self) -> Solution | None:
        """The exact solution of the scene, where it is affordable (None otherwise)."""
        return None

    # -- shared helpers -----------------------------------------------------------------
    def _floor(self, order: int) -> float:
        """S₀·ρ^order: the contract's floor for the order-th derivative.

        Raises
        ------
        OverflowError
            When it is beyond the float64 range (a pole of 1e300 and x''): the contract's
            scale, and so every bound relative to it, cannot be formed.
        """
        floor = self._base_floor
        for _ in range(order):
            floor *= self._spectral_radius
        if not math.isfinite(floor):
            name = "x" + "'" * order
            raise OverflowError(
                f"{name}(t): the contract's scale S₀·ρ^{order} is beyond the float64 range "
                f"(S₀ = {self._base_floor:.3g}, the largest pole ρ = {self._spectral_radius:.3g}); "
                "no evaluation of this derivative can be judged against it")
        return floor

    @cached_property
    def _base_floor(self) -> float:
        s = self.scene
        x0 = max((abs(float(v)) for v in s.x0), default=0.0)
        massless = set(massless_nodes(s))
        v0 = max((abs(float(v)) for i, v in enumerate(s.v0) if i not in massless), default=0.0)
        return reference_scale(x0, v0, self._spectral_radius)

    def _require_numbers(self) -> None:
        # the facts know it, read once per scene (Scene.free_symbols walks every matrix:
        # 20 µs on a pair, on every call)
        if scene_facts(self.scene).symbolic:
            names = ", ".join(sorted(str(v) for v in self.scene.free_symbols))
            raise SceneError(f"evaluate needs numbers, but the scene has the parameters {names}; "
                             "build the scene with values for them")


def _quiet(progress: bool | None, scene: Scene, count: int) -> bool:
    """Whether an evaluation of ``count`` times on the standing plan shows no progress bar
    (as the executor decides from the plan's estimate)."""
    if progress is None:
        return standing_seconds(scene, count) <= limits().progress_after_seconds
    return not progress


def _floored(bounds: np.ndarray, sizes: np.ndarray) -> np.ndarray:
    """Bounds raised in place to Limits.min_relative_bound of the values' sizes, plus the
    smallest subnormal (a returned bound is never 0)."""
    bounds = np.maximum(bounds, limits().min_relative_bound * sizes, out=bounds)
    bounds += _TINY
    return bounds


def _check_size(count: int, n: int) -> None:
    """Refuse an evaluation larger than Limits.max_evaluation_values before any work."""
    most = limits().max_evaluation_values
    if count * max(n, 1) > most:
        raise LimitError(
            f"evaluate: {count:,} times x {n:,} coordinates = {count * n:,} values, more than "
            f"Limits.max_evaluation_values = {most:,}; evaluate the times in chunks of at most "
            f"{max(most // max(n, 1), 1):,}")


#: Values above this are refused as beyond float64 (a quarter of its largest number).
_HUGE = float(np.finfo(float).max) / 4


def _check_float_result(verdict: Verdict, sizes: np.ndarray, times: Times,
                        report: EvaluationReport, target: float, order: int = 0) -> None:
    """Raise rather than return a value beyond float64 (``sizes`` = |values|), or one no
    engine could bound within max(target, Limits.refusal_bound) of the scale (``verdict``:
    the executor's on these values)."""
    worst = report.relative_bounds
    refusal = max(target, limits().refusal_bound)
    if sizes.size and verdict.largest <= _HUGE and verdict.worst <= refusal:
        return  # every value within range, every bound within the refusal bound
    name = "x" + "'" * order
    with np.errstate(invalid="ignore"):
        huge = sizes > _HUGE   # an infinite value too (NaN is not)
    if huge.any():
        column = int(np.flatnonzero(huge.any(axis=0))[0])
        raise OverflowError(f"{name}(t) at t = {float(times.hi[column])!r} is beyond the float64 "
                            "range; evaluate(..., dps=30) gives it")
    missed = np.flatnonzero(~(worst <= refusal))
    if missed.size:
        column = int(missed[0])
        tried = ", ".join(report.plan.chain) or "none"
        bound = "no bound" if not np.isfinite(worst[column]) else f"a bound of {worst[column]:.1e}"
        raise LimitError(
            f"{name}(t) at t = {float(times.hi[column])!r}: the engines of the plan ({tried}) give "
            f"{bound} of the solution's scale, above max(target, Limits.refusal_bound) = "
            f"{max(target, limits().refusal_bound):g}"
            + (f" ({missed.size} times in all)" if missed.size > 1 else "")
            + f". {report.plan.reason}. Ways out: a coarser target (evaluate(..., target=)), "
            "dps= where the plan has an arbitrary-precision engine, or a smaller scene")
