"""The exact route: the motion from exact partial fractions, evaluated as a stable pole sum.

Float64 values come from the terms as a pole sum (:mod:`laplace_springs.numeric.terms`);
times whose bound misses the target are recomputed in mpmath from the exact terms
(escalation "mp"); ``dps`` evaluations likewise. :meth:`ExactSolution.verify` checks the
closed form symbolically.

A periodic input's response (:class:`~laplace_springs.exact.assembly.PeriodicResponse`)
is evaluated at the reduced times w = (t − τ) mod P, formed exactly (rational
arithmetic, or mpmath with the digits of t/P to spare for an irrational period) and
then rounded to a double-double: the one-period formula never sees a large t, so
float64 keeps its accuracy at t = 10⁶.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from fractions import Fraction
from typing import Any

import mpmath
import numpy as np
import sympy as sp

from ..exact.assembly import ExactMotion, PeriodicResponse, exact_motion
from ..exact.jumps import jump_residuals, laurent_at_infinity
from ..exact.root_sums import Condition
from ..exact.screening import has_exact_form
from ..kernels.dd import two_sum
from ..kernels.modulo import reduce_modulo
from ..kernels.precision import workdps
from ..limits import limits
from ..model.errors import SceneError
from ..model.forcing import input_transform
from ..model.numbers import generic_values
from ..model.scene import Scene
from ..model.symbols import TIME, lam
from ..numeric.mp_expr import mp_size, mp_value, numeric_value
from ..numeric.pole_sum import two_diff
from ..numeric.terms import NumericTerms, float_values, mp_values, numeric_terms
from ..numeric.times import Times
from ..output.latex import Output, solution_latex
from ..solution import DEFAULT_SAMPLES, Solution, Verification

__all__ = ["ExactSolution", "exact_solution_of"]

_EPS = float(np.finfo(float).eps)
#: Below this float64 sees 0 (its smallest subnormal is 4.9e-324; not a float literal:
#: 1e-330 is 0.0 in Python).
_UNSEEN = mpmath.mpf("1e-330")


class ExactSolution(Solution):
    """Exact motion x(t) of a scene, in real damped sine/cosine form.

    Holds an :class:`~laplace_springs.exact.assembly.ExactMotion`; :attr:`x`, the pieces,
    the seed's g-basis and the initial jump are exact. Float64 evaluation sums the terms
    as a stable pole sum (:mod:`laplace_springs.numeric.terms`); times whose bound misses
    the target are recomputed with mpmath ("mp").
    """

    method = "exact"
    _escalation_engine = "mp"

    def __init__(self, motion: ExactMotion, *, reason: str | None, target: float | None = None) -> None:
        super().__init__(motion.scene, reason=reason, target=target)
        self.motion = motion

    # -- exact data -------------------------------------------------------------------
    @property
    def x(self) -> sp.ImmutableMatrix:
        """x(t) as a SymPy column matrix; a response to an input delayed by τ carries
        Heaviside(t − τ), nothing else does (the solution holds for t ≥ 0)."""
        return self.motion.x

    @property
    def poles(self) -> np.ndarray:
        symbols = self.scene.free_symbols
        if symbols:  # float poles of a formula: name the way out, not mpmath's TypeError
            names = ", ".join(sorted(symbol.name for symbol in symbols))
            raise SceneError(f"poles need numbers, but the scene has the parameters {names}; "
                             "substitute values (sol.subs) or see ls.modes for them as formulas")
        nodes = [complex(z) for z in self._numeric(0)[0].poles.nodes] if self.pieces else []
        return np.array(nodes, dtype=complex)

    @property
    def _spectral_radius(self) -> float:
        return max((abs(complex(z)) for data in self._numeric(0) for z in data.poles.nodes),
                   default=0.0)

    @property
    def _exact_form(self) -> ExactSolution:
        return self

    @property
    def conditions(self) -> tuple[Condition, ...]:
        """Where :attr:`x` holds beyond finite parameters: each sum over the roots of a
        factor of Δ(λ) (symbolic coefficients, degree ≥ 3) needs those roots simple
        (disc_λ ≠ 0). Empty when :attr:`x` has no such sum (see
        :attr:`laplace_springs.exact.assembly.ExactMotion.conditions`)."""
        return self.motion.conditions

    def subs(self, values: Any) -> ExactSolution:
        """The exact solution of the scene with some parameters given values, solved again.

        Solving again (rather than substituting into :attr:`x`) keeps degenerate values
        exact: at critical damping the generic formula is 0/0, the new one is (1 + t)e^{-t}.

        Parameters
        ----------
        values : mapping
            Parameter (Symbol or name) -> value, as in :meth:`Scene.subs`.

        Examples
        --------
        >>> scene = Scene.from_matrices(M=[[1]], C=[["c"]], K=[[1]], x0=[1], v0=[0],
        ...                             parameters=["c"])
        >>> sol = ExactSolution(exact_motion(scene), reason="example")
        >>> sol.subs({"c": 2}).x[0]
        t*exp(-t) + exp(-t)
        """
        scene = self.scene.subs(values)
        return ExactSolution(exact_motion(scene), reason=f"{self.reason}; parameters given values",
                             target=self.target)

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
        output: Output = "document" if standalone else "markdown" if markdown else "fragment"
        return solution_latex(self.motion, form=form, resolvent=resolvent, sylvester=sylvester,
                              output=output)

    def __repr__(self) -> str:
        body = ", ".join(f"{name}(t) = {expr}" for name, expr in zip(self.scene.names, self.x))
        return f"ExactSolution({body})"

    # -- evaluation ---------------------------------------------------------------------
    def _motion_of(self, order: int) -> ExactMotion:
        motion = self.motion
        for _ in range(order):
            motion = motion.derivative()
        return motion

    def _numeric(self, order: int, dps: int = 40) -> tuple[NumericTerms, ...]:
        key = (order, dps)
        cache = self.__dict__.setdefault("_numeric_cache", {})
        if key not in cache:
            motion = self._motion_of(order)
            cache[key] = tuple(numeric_terms(piece.terms, dps=dps) for piece in motion.pieces)
        return cache[key]

    def _periodic_numeric(self, order: int, dps: int = 40
                          ) -> tuple[PeriodicResponse, tuple[NumericTerms, ...], NumericTerms] | None:
        """The periodic response's one-period sums and its terms in t, as pole sums."""
        if self.motion.periodic is None:
            return None
        key = ("periodic", order, dps)
        cache = self.__dict__.setdefault("_numeric_cache", {})
        if key not in cache:
            periodic = self._motion_of(order).periodic
            assert periodic is not None
            sums = tuple(numeric_terms(rows, dps=dps) for rows in periodic.sums)
            rest = numeric_terms(tuple(r + t for r, t in zip(periodic.resonant, periodic.tail)), dps=dps)
            cache[key] = (periodic, sums, rest)
        return cache[key]

    def _shifted(self, times: Times, delay: sp.Expr) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Columns with t ≥ delay and t − delay there as a double-double.

        Times within 2⁻⁴⁸ (relative) of the delay are compared and shifted exactly
        (:func:`_exact_shift`): the double-doubles of t and τ each hold 2⁻¹⁰⁶ of their
        size, which t = "0.3" + 1e-29 against τ = 3/10 would turn into an error of 1e-13
        in t − τ (and so in x ≈ (t − τ)²/2, beyond its bound), and a time 1e-34 before τ
        into one after it."""
        if delay == 0:
            return np.arange(len(times)), times.hi, times.lo
        with workdps(40):
            tau = mp_value(delay, 40)
            tau_hi = float(tau)
            tau_lo = float(tau - tau_hi)
        after = (times.hi > tau_hi) | ((times.hi == tau_hi) & (times.lo >= tau_lo))
        hi, lo = two_diff(times.hi, tau_hi, tau_lo)
        hi, lo = two_sum(hi, lo + times.lo)
        with np.errstate(invalid="ignore"):
            near = np.abs(times.hi - tau_hi) <= 2.0**-48 * np.maximum(np.abs(times.hi), abs(tau_hi))
        for j in np.flatnonzero(near).tolist():
            hi[j], lo[j], after[j] = _exact_shift(times, j, delay)
        on = np.flatnonzero(after)
        return on, hi[on], lo[on]

    def _start(self, times: Times, order: int) -> tuple[np.ndarray, list[sp.Expr]] | None:
        """The columns at t = 0 exactly and x^(order)(0⁺) there, exact (orders 0 and 1:
        the state after any jump; order 2: :meth:`_acceleration_start`), or None. Pole
        sums at 0 cancel to the initial data only up to their rounding, which no relative
        bound can cover where that state is 0 (a scene forced from rest)."""
        if order > 2:
            return None
        columns = np.flatnonzero((times.hi == 0) & (times.lo == 0))
        if not columns.size:
            return None
        if order == 2:
            return columns, self._acceleration_start()
        jump = self.initial_jump
        return columns, list(jump.x_plus if order == 0 else jump.v_plus)

    def _acceleration_start(self) -> list[sp.Expr]:
        """x''(0⁺), exact: the λ⁻³ coefficient at λ = ∞ of the transform switched on at
        t = 0 (free response and inputs from t = 0) plus that of the periodic inputs' first
        pieces (their response from rest starts with x = x' = 0 but x'' = M⁻¹f(0⁺)). Its
        pole sums cancel at 0 like x's: x''(0) = 0 of a scene at rest under t·cos(3t)
        was refused, or served only beside a time of 1e-300."""
        cache = self.__dict__.setdefault("_piece_starts", {})
        if "acceleration" not in cache:
            motion = self.motion
            first = motion.pieces[0]
            R = motion.resolvent
            numerators, denominator = ((list(R.numerators), R.determinant) if first.denominator is None
                                       else (list(first.numerators), first.denominator))
            start = [laurent_at_infinity(N, denominator, 3)[1][2] for N in numerators]
            if motion.periodic is not None and self.scene.forcing is not None:
                load = [sp.Add(*(part for tau, part in T.periodic if tau == 0))
                        for T in (input_transform(f, f"forcing[{j}]", lam)
                                  for j, f in enumerate(self.scene.forcing))]
                for i in range(self.scene.n):
                    N, D = sp.fraction(sp.cancel(sp.Add(*(R.adjugate[i, j] * load[j]
                                                         for j in range(self.scene.n)))
                                                 / R.determinant.as_expr()))
                    if N != 0:
                        start[i] += laurent_at_infinity(sp.Poly(N, lam), sp.Poly(D, lam), 3)[1][2]
            cache["acceleration"] = start
        found: list[sp.Expr] = cache["acceleration"]
        return found

    def _piece_start(self, piece: Any, order: int) -> list[float] | None:
        """x^(order) of a delayed piece just after it switches on (orders 0, 1 and 2; from
        its transform at λ = ∞, exact, rounded once), or None: its pole sum at t − τ = 0
        cancels to that state only up to its rounding, which no relative bound covers
        where the motion is 0 there (a scene at rest until a delayed input)."""
        if order > 2 or piece.delay == 0 or not piece.numerators or piece.denominator is None:
            return None
        cache = self.__dict__.setdefault("_piece_starts", {})
        key = (piece.delay, order)
        if key not in cache:
            expansions = [laurent_at_infinity(N, piece.denominator, 3) for N in piece.numerators]
            impulsive = any(not q.is_zero for q, _ in expansions)
            cache[key] = None if impulsive else [
                float(mp_value(a[order], 20)) if a[order] != 0 else 0.0 for _, a in expansions]
        found: list[float] | None = cache[key]
        return found

    def _float(self, times: Times, order: int) -> tuple[np.ndarray, np.ndarray]:
        values, bounds = self._float_sums(times, order)
        start = self._start(times, order)
        if start is not None:
            columns, exact = start
            for i, value in enumerate(exact):
                rounded = float(mp_value(value, 20)) if value != 0 else 0.0
                values[i, columns] = rounded
                bounds[i, columns] = abs(rounded) * _EPS
        return values, bounds

    def _float_sums(self, times: Times, order: int) -> tuple[np.ndarray, np.ndarray]:
        n = self.scene.n
        values, bounds = np.zeros((n, len(times))), np.zeros((n, len(times)))
        for piece, data in zip(self.pieces, self._numeric(order)):
            on, hi, lo = self._shifted(times, piece.delay)
            if on.size:
                part, bound = float_values(data, n, hi, lo)
                _at_switch_on(part, bound, hi, lo, self._piece_start(piece, order))
                values[:, on] += part
                bounds[:, on] += bound
        periodic = self._periodic_numeric(order)
        if periodic is not None:
            response, sums, rest = periodic
            for tau, data in zip(response.delays, sums):
                hi, lo = _reduced_float(times, tau, response.period)
                part, bound = float_values(data, n, hi, lo)
                values += part
                bounds += bound
            part, bound = float_values(rest, n, times.hi, times.lo)
            values += part
            bounds += bound
        return values, bounds

    def _mp(self, times: Times, order: int, digits: int, floor: float,
            enough: mpmath.mpf = 0) -> tuple[list, list]:
        """mpmath values and bounds (n lists of mpf) good to ``digits`` of max(|x|, floor),
        or to ``enough`` absolutely (a time whose values and bounds are all below it is
        not refined further: float64 sees 0 there).

        The parts (pieces, a periodic response's sums at the reduced times, its tail) are
        each good to ``digits`` of their own size; where they cancel (a period of 1e-40:
        sums of 1e33 that add up to 0.05) the evaluation is redone with the digits lost."""
        total, bounds, sizes = self._mp_parts(times, order, digits, floor)
        start = self._start(times, order)
        exact_columns = set() if start is None else set(start[0].tolist())
        # t = 0 is set exactly below: its cancellation does not count
        work = {j: digits for j in range(len(times)) if j not in exact_columns}
        while True:
            redo: dict[int, list[int]] = {}
            for j, done in work.items():
                more = self._more_digits(total, bounds, sizes, j, (digits, done), floor, enough)
                if more:
                    redo.setdefault(more, []).append(j)
            if not redo:
                break
            for more, redone in redo.items():
                again, bound, size = self._mp_parts(times.subset(np.array(redone)), order, more, floor)
                for k, j in enumerate(redone):
                    work[j] = more
                    for i in range(self.scene.n):
                        total[i][j], bounds[i][j], sizes[i][j] = again[i][k], bound[i][k], size[i][k]
        if start is not None:  # the exact state after the jump, to the digits asked
            columns, exact = start
            for i, value in enumerate(exact):
                held = mp_value(value, digits + 5) if value != 0 else mpmath.mpf(0)
                with workdps(digits + 5):
                    for j in columns:
                        total[i][j] = held
                        bounds[i][j] = abs(held) * mpmath.mpf(10) ** (-digits - 3)
        return total, bounds

    @staticmethod
    def _more_digits(total: list, bounds: list, sizes: list, j: int, digits: tuple[int, int],
                     floor: float, enough: mpmath.mpf) -> int:
        """The digits to evaluate column ``j`` at again (0: it stands): the parts are each
        good to ``done`` digits of their own size; where they cancel to x(t) (a period of
        1e-40: sums of 1e33 that add up to 0.05; a periodic response at t = 1e-300: parts
        of order 1 that add up to 1e-300) the column needs the digits lost besides. The sum
        seen at ``done`` digits may itself be rounding, so at least twice the digits are
        taken until it stands (or until its values and bounds are below ``enough``).
        Column by column: a time's digits are its own."""
        asked, done = digits
        with workdps(30):
            if max(*(abs(row[j]) for row in total), *(row[j] for row in bounds)) < enough:
                return 0
            scale = max([mpmath.mpf(floor), *(abs(row[j]) for row in total)])
            largest = max((row[j] for row in sizes), default=mpmath.mpf(0))
            # parts that cancel to exactly 0 (no floor): every digit may be lost
            lost = largest / scale if scale > 0 else (mpmath.inf if largest > 0 else 0)
        top = limits().max_dps
        if lost <= 10 or done >= top:
            return 0
        need = top if lost == mpmath.inf else asked + int(mpmath.log10(lost)) + 5
        return 0 if need <= done else min(max(need, 2 * done), top)

    def _mp_parts(self, times: Times, order: int, digits: int,
                  floor: float) -> tuple[list, list, list]:
        """:meth:`_mp` once: values, bounds (each part's, plus the rounding of their sum)
        and the sum of the parts' sizes."""
        n = self.scene.n
        work = digits + 20
        with workdps(work):
            total = [[mpmath.mpf(0)] * len(times) for _ in range(n)]
            bounds = [[mpmath.mpf(0)] * len(times) for _ in range(n)]
            sizes = [[mpmath.mpf(0)] * len(times) for _ in range(n)]
            stamps = [times.mpf(j) for j in range(len(times))]
        for piece, data in zip(self.pieces, self._numeric(order)):
            if piece.delay == 0:
                on, shifted = list(range(len(times))), stamps
            else:
                moved = [_mp_shift(times, j, piece.delay, work) for j in range(len(times))]
                on = [j for j, v in enumerate(moved) if v >= 0]
                shifted = [moved[j] for j in on]
            if not on:
                continue
            part, bound, _ = mp_values(data, n, shifted, digits, [floor] * len(on))
            with workdps(work):
                for k, j in enumerate(on):
                    for i in range(n):
                        total[i][j] += part[i][k]
                        bounds[i][j] += bound[i][k]
                        sizes[i][j] += abs(part[i][k])
        periodic = self._periodic_numeric(order)
        if periodic is not None:
            response, sums, rest = periodic
            runs = [(data, _reduced_mp(times, tau, response.period, work))
                    for tau, data in zip(response.delays, sums)] + [(rest, stamps)]
            for data, at in runs:
                part, bound, _ = mp_values(data, n, at, digits, [floor] * len(at))
                with workdps(work):
                    for j in range(len(times)):
                        for i in range(n):
                            total[i][j] += part[i][j]
                            bounds[i][j] += bound[i][j]
                            sizes[i][j] += abs(part[i][j])
        with workdps(work):  # the rounding of the sums of the parts
            unit = mpmath.mpf(10) ** (1 - work)
            bounds = [[b + s * unit for b, s in zip(rb, rs)] for rb, rs in zip(bounds, sizes)]
        return total, bounds, sizes

    def _escalate(self, times: Times, order: int, target: float) -> tuple[np.ndarray, np.ndarray]:
        digits = max(limits().escalation_digits, math.ceil(-math.log10(target)) + 5)
        total, bounds = self._mp(times, order, digits, self._floor(order), enough=_UNSEEN)
        values = np.array([[float(v) for v in row] for row in total])
        errors = np.array([[float(b) for b in row] for row in bounds])
        return values, errors + np.abs(values) * _EPS

    def _digits(self, times: Times, order: int, dps: int) -> tuple[np.ndarray, np.ndarray]:
        total, bounds = self._mp(times, order, dps + 2, self._floor(order))
        values = np.empty((self.scene.n, len(times)), dtype=object)
        errors = np.empty((self.scene.n, len(times)), dtype=object)
        with workdps(dps):
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
        # a periodic response's floor((t - τ)/P) is constant between switching times:
        # held as a symbol while differentiating, given its value at each sample time
        held = {f: sp.Dummy(f"floor{k}") for k, f in enumerate(sorted(x.atoms(sp.floor), key=str))}
        x = x.xreplace(held)
        v = x.diff(TIME)
        force = sp.Matrix(s.forcing) if s.forcing is not None and s.is_forced else sp.zeros(s.n, 1)
        force = force.replace(sp.Heaviside, lambda arg, *_: sp.Heaviside(arg, 1))  # t = 0⁺
        residual = (s.M * v.diff(TIME) + s.C * v + s.K * x - force).xreplace(generic)
        residual = residual.replace(sp.DiracDelta, lambda *args: sp.S.Zero)  # 0 off the delays
        jump = self.initial_jump
        x, v = (m.replace(sp.DiracDelta, lambda *a: sp.S.Zero) for m in (x, v))
        x, v = (_at_time(m, held, 0) for m in (x, v))
        start = jump_residuals(s, x.subs(TIME, 0) - s.x0, v.subs(TIME, 0) - s.v0,
                               jump.impulses, load=self.motion.impulsive_load())
        start = [sp.sympify(e).xreplace(generic) for e in start]
        periodic = self.motion.periodic
        times = _sample_times(samples, [piece.delay for piece in self.pieces],
                              None if periodic is None else (periodic.delays, periodic.period))
        sizes = [*s.x0, *s.v0, *(f.subs(TIME, tv) for f in force.xreplace(generic) for tv in times)]
        scale = max(1.0, _size([e.replace(sp.DiracDelta, lambda *a: 0) for e in sizes], generic, 20))
        ode = _size([_at_time(e, held, tv).subs(TIME, tv) for e in residual for tv in times], {}, dps)
        return Verification(ode / scale, _size(start, generic, dps) / scale, tolerance)


def _exact_shift(times: Times, j: int, delay: sp.Expr) -> tuple[float, float, bool]:
    """t_j − τ as a double-double (rounded once) and whether t_j ≥ τ, from exact values:
    rational arithmetic for a rational τ, else mpmath with the digits the difference
    cancels (t is rational, so t ≠ τ for an irrational τ)."""
    exact = _exact_number(delay)
    if exact is not None:
        v = times.exact(j) - exact
        hi = float(v)
        return hi, float(v - Fraction(hi)), v >= 0
    moved = _mp_shift(times, j, delay, 40)
    with workdps(40):
        hi = float(moved)
        return hi, float(moved - hi), bool(moved >= 0)


def _mp_shift(times: Times, j: int, delay: sp.Expr, digits: int) -> mpmath.mpf:
    """t_j − τ to ``digits`` significant digits (rounded at that precision): exactly
    formed for a rational τ, else at the digits the difference cancels besides."""
    exact = _exact_number(delay)
    if exact is not None:
        v = times.exact(j) - exact
        with workdps(digits):
            return mpmath.mpf(v.numerator) / v.denominator
    work = digits + 10
    while True:
        with workdps(work):
            tv = times.mpf(j)
            tau = mp_value(delay, work)
            v = tv - tau
            size = max(abs(tv), abs(tau))
            lost = int(mpmath.log10(size / abs(v))) + 1 if v != 0 and size > 0 else work
        if work >= digits + lost + 10 or work >= limits().max_dps:
            with workdps(digits):
                return +v
        work = min(digits + lost + 20, limits().max_dps)


def _exact_number(value: sp.Expr) -> Fraction | None:
    return Fraction(int(value.p), int(value.q)) if isinstance(value, sp.Rational) else None


def _reduced_exact(times: Times, tau: sp.Expr, period: sp.Expr) -> list[Fraction] | None:
    """(t − τ) mod P exactly for rational τ and P (None otherwise)."""
    d, P = _exact_number(tau), _exact_number(period)
    if d is None or P is None:
        return None
    out = []
    for j in range(len(times)):
        v = times.exact(j) - d
        out.append(v - P * math.floor(v / P))
    return out


def _reduced_mp(times: Times, tau: sp.Expr, period: sp.Expr, dps: int) -> list[mpmath.mpf]:
    """(t − τ) mod P in [0, P) as mpf good to ``dps`` digits (relative to P)."""
    exact = _reduced_exact(times, tau, period)
    with workdps(dps):
        if exact is not None:
            return [mpmath.mpf(w.numerator) / w.denominator for w in exact]
    largest = max((abs(float(times.exact(j))) for j in range(len(times))), default=0.0)
    work = dps + 10 + max(0, math.ceil(math.log10(max(largest, 1.0) / float(period))))
    with workdps(work):
        P, d = mp_value(period, work), mp_value(tau, work)
        out = []
        for j in range(len(times)):
            v = times.mpf(j) - d
            out.append(v - P * mpmath.floor(v / P))
    with workdps(dps):
        return [+w for w in out]


def _at_switch_on(part: np.ndarray, bound: np.ndarray, hi: np.ndarray, lo: np.ndarray,
                  start: list[float] | None) -> None:
    """Where the shifted time is exactly 0, a piece's values become its exact state just
    after it switches on (rounded once), in place."""
    if start is None:
        return
    columns = np.flatnonzero((hi == 0) & (lo == 0))
    if columns.size:
        exact = np.array(start)[:, None]
        part[:, columns] = exact
        bound[:, columns] = np.abs(exact) * _EPS


def _reduced_float(times: Times, tau: sp.Expr, period: sp.Expr) -> tuple[np.ndarray, np.ndarray]:
    """(t − τ) mod P as double-doubles hi + lo: vectorised in double-double for float times
    and rational τ, P (:func:`~laplace_springs.kernels.modulo.reduce_modulo`), formed exactly
    before rounding for the rest."""
    d, P = _exact_number(tau), _exact_number(period)
    if d is not None and P is not None and not times.lo.any():
        hi, lo, done = reduce_modulo(times.hi, d, P)
        rest = np.flatnonzero(~done)
        if rest.size:
            hi[rest], lo[rest] = _pairs(_reduced_exact(times.subset(rest), tau, period) or [])
        return hi, lo
    exact = _reduced_exact(times, tau, period)
    if exact is None:
        with workdps(40):
            values = _reduced_mp(times, tau, period, 40)
            hi = np.array([float(w) for w in values])
            lo = np.array([float(w - h) for w, h in zip(values, hi)])
        return hi, lo
    return _pairs(exact)


def _pairs(exact: list[Fraction]) -> tuple[np.ndarray, np.ndarray]:
    """Exact rationals as double-doubles: hi correctly rounded, lo the rounded remainder."""
    hi = np.array([float(w) for w in exact])
    lo = np.array([float(w - Fraction(h)) for w, h in zip(exact, hi)])
    return hi, lo


def _at_time(expr: Any, held: dict, time: Any) -> Any:
    """``expr`` with the held floor((t − τ)/P) symbols given their values at ``time``."""
    return expr.xreplace({symbol: f.subs(TIME, time) for f, symbol in held.items()}) if held else expr


def _sample_times(samples: Sequence[Any], delays: Sequence[sp.Expr],
                  periodic: tuple[Sequence[sp.Expr], sp.Expr] | None = None) -> list[sp.Expr]:
    """t = 0 and the samples, moved off the switching times of delayed inputs (and of
    periodic ones: τ + kP)."""

    def switching(value: sp.Expr) -> bool:
        if any(value == d for d in delays):
            return True
        return periodic is not None and any(sp.simplify((value - tau) / periodic[1]).is_integer
                                            for tau in periodic[0])

    times: list[sp.Expr] = [sp.S.Zero]
    for tv in samples:
        value = sp.Rational(str(tv))
        while switching(value):
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
            size = float(mp_size(expr, dps, caches))
        except (TypeError, ValueError):
            size = float(abs(numeric_value(expr, dps)))
        out = max(out, size)
    return out




def exact_solution_of(scene: Scene, *, method: str, target: float) -> ExactSolution | None:
    """The exact solution of a scene solved on another route, where it is affordable
    (up to :attr:`~laplace_springs.limits.Limits.exact_form_max_coordinates` coordinates)."""
    if not has_exact_form(scene):
        return None
    return ExactSolution(exact_motion(scene), reason=f"exact form of a {method} solution",
                         target=target)
