"""Assemble x(t) from the resolvent: solve(), the Solution object and its g-basis.

Each coordinate X_i(λ) = N_i(λ)/Δ(λ) is inverted by the shared partial-fraction engine
(the denominator is factored once). The seed's basis g_k(t) = L⁻¹[λ^k/Δ(λ)] and the
coefficients c_ik with x_i(t) = Σ_k c_ik g_k(t) are available beside the closed form.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING, Sequence

import mpmath
import numpy as np
import sympy as sp

from .algebraic import numeric_value
from .errors import SceneError
from .evaluate import NumericTerms, _mp_time, evaluate_float, evaluate_mp, numeric_terms
from .forcing import input_transform
from .jumps import InitialJump, initial_jump, jump_residuals
from .mp_expr import mp_value
from .numbers import TIME
from .partial_fractions import decompose
from .real_terms import Term, group_terms, naming_scope, solution_terms, terms_expr
from .resolvent import Resolvent, lam, resolvent

if TYPE_CHECKING:
    from .scene import Scene

__all__ = ["t", "Piece", "Solution", "Verification", "solve"]

#: Time, the variable of every solution (the results hold for t ≥ 0).
t = TIME

_METHODS = ("auto", "exact", "numeric")

#: Largest number of coordinates "auto" solves exactly when the numeric route could
#: serve (an unforced, numeric scene): above it Δ has degree > 16 and the exact route
#: takes seconds (8 masses: 2-8 s) while the numeric route takes milliseconds.
EXACT_LIMIT = 8


def _terms_of(decompositions) -> tuple[tuple[Term, ...], ...]:
    """Real terms per coordinate, named quantities numbered once for the whole solution."""
    return solution_terms(decompositions)


@dataclass(frozen=True)
class Piece:
    """One part of the motion: terms in the shifted time t − τ, switched on at t = τ.

    The free response and every input starting at t = 0 form the piece with delay 0;
    an input delayed by τ (a step or impulse at τ, a window's end) adds a piece with
    that delay.

    Attributes
    ----------
    delay : sympy.Expr
        τ ≥ 0.
    terms : tuple of tuple of Term
        Per coordinate, real terms in the variable t − τ.
    steady : tuple of tuple of bool
        Per term: whether its pole is a pole of the input (steady-state part) rather
        than of the system alone (transient part).
    impulses : tuple of tuple of sympy.Expr
        Per coordinate, coefficients c_j of DiracDelta(t − τ, j) in x: only an impulsive
        input on a massless node puts them there. Empty when there are none.
    numerators, denominator : sympy.Poly
        The piece's transform X_τ(λ) = numerators/denominator (forced scenes).
    """

    delay: sp.Expr
    terms: tuple[tuple[Term, ...], ...]
    steady: tuple[tuple[bool, ...], ...]
    impulses: tuple[tuple[sp.Expr, ...], ...] = ()
    numerators: tuple[sp.Poly, ...] = ()
    denominator: sp.Poly | None = None

    def expr(self, row: int, part: str = "all") -> sp.Expr:
        """Coordinate ``row`` of this piece in :data:`t` (Heaviside-switched if τ > 0)."""
        chosen = [term for term, steady in zip(self.terms[row], self.steady[row])
                  if part == "all" or steady == (part == "steady")]
        shifted = t - self.delay
        deltas = sp.Add(*(c * (sp.DiracDelta(shifted) if j == 0 else sp.DiracDelta(shifted, j))
                          for j, c in enumerate(self.impulses[row] if self.impulses else ())
                          if c != 0)) if part != "steady" else sp.S.Zero
        if self.delay == 0:
            return terms_expr(chosen, t) + deltas
        body = terms_expr(chosen, shifted)
        return (sp.Heaviside(shifted) * body if body != 0 else sp.S.Zero) + deltas


@dataclass(frozen=True)
class Verification:
    """Outcome of :meth:`Solution.verify`: residuals relative to the solution's size."""

    ode_residual: float
    initial_residual: float
    tolerance: float

    @property
    def ok(self) -> bool:
        """True when both residuals are within the tolerance."""
        return self.ode_residual <= self.tolerance and self.initial_residual <= self.tolerance

    def __bool__(self) -> bool:
        return self.ok


@dataclass(frozen=True, eq=False)
class Solution:
    """Exact motion x(t) of a scene, in real damped sine/cosine form.

    Build it with :func:`solve`. ``terms[i]`` holds the structured real terms of
    coordinate i; :attr:`x` is the same as a SymPy column matrix in :data:`t`.
    """

    scene: Scene
    resolvent: Resolvent
    terms: tuple[tuple[Term, ...], ...]
    pieces: tuple[Piece, ...] = ()

    def __post_init__(self) -> None:
        if not self.pieces:  # a free motion: one piece, nothing steady
            flags = tuple((False,) * len(row) for row in self.terms)
            object.__setattr__(self, "pieces", (Piece(sp.S.Zero, self.terms, flags),))

    @cached_property
    def x(self) -> sp.ImmutableMatrix:
        """x(t) as a SymPy column matrix in the symbol :data:`laplace_springs.t`.

        A response to an input delayed by τ carries the factor Heaviside(t − τ); nothing
        else does (the whole solution holds for t ≥ 0).
        """
        return self._part("all")

    @cached_property
    def steady_state(self) -> sp.ImmutableMatrix:
        """The part of x(t) with the input's poles: what the forcing sustains.

        For a damped system driven by a harmonic force this is the steady oscillation
        left once the transient has died out. At exact resonance of an undamped
        system the secular t·sin term belongs here (its pole is the input's).
        Zero for a free motion.
        """
        return self._part("steady")

    @cached_property
    def transient(self) -> sp.ImmutableMatrix:
        """The part of x(t) with the system's own poles only: x = transient + steady_state."""
        return self._part("transient")

    def _part(self, part: str) -> sp.ImmutableMatrix:
        return sp.ImmutableMatrix([sp.Add(*(piece.expr(i, part) for piece in self.pieces))
                                   for i in range(self.scene.n)])

    #: Which route produced the solution (a :class:`NumericSolution` says "numeric").
    method = "exact"

    @property
    def reason(self) -> str:
        """Why this route: the exact one is the default wherever it is affordable."""
        return "exact partial fractions (the default where affordable)"

    @cached_property
    def modes(self):
        """The scene's modes (see :func:`laplace_springs.modes.modes`)."""
        from .modes import modes

        return modes(self.scene)

    @cached_property
    def _numeric(self) -> tuple[NumericTerms, ...]:
        return tuple(numeric_terms(piece.terms, dps=40) for piece in self.pieces)

    def evaluate(self, times, *, dps: int | None = None, return_error: bool = False):
        """Evaluate x(t) at the given times.

        Parameters
        ----------
        times : array_like
            Times t ≥ 0 (a scalar is treated as one time).
        dps : int, optional
            Decimal digits. Without it the result is float64; with it, an object array
            of mpmath numbers accurate to about that many digits.
        return_error : bool, optional
            Also return an array of estimated absolute error bounds (float64 only).

        Returns
        -------
        numpy.ndarray, or (numpy.ndarray, numpy.ndarray)
            Shape (n, len(times)); with ``return_error`` the error bounds as well.

        Notes
        -----
        Float64 evaluation is stable by construction (near-equal poles are summed in a
        divided-difference basis, phases carried in double-double) and points whose
        error estimate is still too large are recomputed with mpmath inside the call;
        see :mod:`laplace_springs.evaluate`.
        """
        if dps is not None:
            if return_error:
                raise ValueError("return_error is available for float64 evaluation only")
            return self._evaluate_mp(list(np.atleast_1d(times)), dps)
        times = np.atleast_1d(np.asarray(times, dtype=float))
        n = self.scene.n
        values, error = np.zeros((n, times.size)), np.zeros((n, times.size))
        for piece, data in zip(self.pieces, self._numeric):
            tau = float(piece.delay)
            on = times >= tau if tau else np.ones(times.size, dtype=bool)
            if not on.any():
                continue
            part, bound = evaluate_float(data, n, times[on], return_error=True,
                                         delay=piece.delay if tau else None)
            values[:, on] += part
            error[:, on] += bound
        return (values, error) if return_error else values

    def _evaluate_mp(self, times: list, dps: int) -> np.ndarray:
        n = self.scene.n
        out = np.empty((n, len(times)), dtype=object)
        with mpmath.workdps(dps + 20):
            ts = [_mp_time(v) for v in times]
            out[:] = mpmath.mpf(0)
        for piece in self.pieces:
            with mpmath.workdps(dps + 20):
                tau = mpmath.mpf(sp.Float(piece.delay, dps + 20)._mpf_) if piece.delay else 0
                on = [col for col, tv in enumerate(ts) if tv >= tau]
                shifted = [ts[col] - tau for col in on]
            if not on:
                continue
            data = numeric_terms(piece.terms, dps=dps + 15)
            part = evaluate_mp(data, n, shifted, dps)
            with mpmath.workdps(dps):
                for k, col in enumerate(on):
                    for i in range(n):
                        out[i, col] = out[i, col] + part[i, k]
        return out

    @cached_property
    def g_denominator(self) -> sp.Poly:
        """The Δ(λ) of the g-basis: integer, content 1 (as the seed prints it)."""
        return self.resolvent.integer_characteristic_polynomial

    @cached_property
    def g_coefficients(self) -> sp.ImmutableMatrix:
        """c_ik with x_i(t) = Σ_k c_ik g_k(t), k = 0..2n-1 (the seed's K_j and N_j).

        Columns k ≥ deg Δ are zero (deg Δ < 2n when M is singular: massless nodes).
        """
        R = self.resolvent
        scale = sp.cancel(self.g_denominator.as_expr() / R.determinant.as_expr())
        n2 = 2 * self.scene.n
        rows = []
        for N in R.numerators:
            coeffs = list(reversed(N.all_coeffs())) if not N.is_zero else []
            coeffs += [0] * (n2 - len(coeffs))
            rows.append([sp.factor_terms(sp.expand(scale * c)) for c in coeffs[:n2]])
        return sp.ImmutableMatrix(rows)

    @cached_property
    def g_indices(self) -> tuple[int, ...]:
        """The k whose g_k occurs in some coordinate (nonzero column of c_ik)."""
        C = self.g_coefficients
        return tuple(k for k in range(C.shape[1]) if any(C[i, k] != 0 for i in range(C.shape[0])))

    @cached_property
    def g_basis(self) -> dict[int, sp.Expr]:
        """g_k(t) = L⁻¹[λ^k/Δ(λ)] for the k in :attr:`g_indices`, exactly."""
        D = self.g_denominator
        monomials = [sp.Poly(lam**k, lam, domain=D.domain) for k in self.g_indices]
        return {k: terms_expr(list(row), t)
                for k, row in zip(self.g_indices, _terms_of(decompose(monomials, D)))}

    def g_form(self) -> sp.ImmutableMatrix:
        """x(t) written as Σ c_ik g_k with g_k as undefined functions g_k(t)."""
        C = self.g_coefficients
        g = {k: sp.Function(f"g_{k}")(t) for k in self.g_indices}
        return sp.ImmutableMatrix([sp.Add(*(C[i, k] * g[k] for k in self.g_indices))
                                   for i in range(C.shape[0])])

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
            By default one ``aligned`` block per part (x(t) and its "where" list first).
            See :mod:`laplace_springs.latex_export` for the conventions (no imaginary
            unit, algebraic numbers as named constants, θ(t − τ) for switched inputs).
        """
        from .latex_export import solution_latex

        output = "document" if standalone else "markdown" if markdown else "fragment"
        return solution_latex(self, form=form, resolvent=resolvent, sylvester=sylvester,
                              output=output)

    def _repr_latex_(self) -> str:
        return "$$" + self.latex() + "$$"

    def __repr__(self) -> str:
        body = ", ".join(f"{name}(t) = {expr}" for name, expr in zip(self.scene.names, self.x))
        return f"Solution({body})"

    def verify(self, *, samples: Sequence = ("0.37", "1.3", "4.1"), dps: int = 40) -> Verification:
        """Check at high precision that x satisfies the equations and initial data.

        The exact expression :attr:`x` is differentiated symbolically and
        M x'' + C x' + K x is evaluated at the sample times with ``dps`` digits
        (algebraic numbers from certified root enclosures), also at t = 0⁺ where a
        massless node's constraint must already hold. At the start the jump conditions
        of :func:`laplace_springs.jumps.jump_residuals` are checked: M(x(0⁺) - x0) = 0 and
        M(x'(0⁺) - v0) + C(x(0⁺) - x0) = 0 (plus impulse terms, if any), which for an
        invertible M is x(0) = x0, x'(0) = v0. Symbolic parameters are given fixed
        generic values first (the residual is an identity in them). Residuals are
        relative to the data's size.

        Returns
        -------
        Verification
            Truthy when both residuals are below 10^(10 - dps).
        """
        s = self.scene
        generic = generic_values(s.free_symbols)
        x = sp.Matrix(self.x)
        v = x.diff(t)
        force = sp.Matrix(s.forcing) if s.is_forced else sp.zeros(s.n, 1)
        force = force.replace(sp.Heaviside, lambda arg, *_: sp.Heaviside(arg, 1))  # t = 0⁺
        residual = (s.M * v.diff(t) + s.C * v + s.K * x - force).xreplace(generic)
        residual = residual.replace(sp.DiracDelta, lambda *args: sp.S.Zero)  # 0 off the delays
        jump = self.initial_jump
        x, v = x.replace(sp.DiracDelta, lambda *a: sp.S.Zero), v.replace(sp.DiracDelta, lambda *a: sp.S.Zero)
        start = jump_residuals(s, x.subs(t, 0) - s.x0, v.subs(t, 0) - s.v0,
                               jump.impulses, load=self._impulsive_load())
        start = [sp.sympify(e).xreplace(generic) for e in start]
        times = _sample_times(samples, [piece.delay for piece in self.pieces])
        sizes = [*s.x0, *s.v0, *(f.subs(t, tv) for f in force.xreplace(generic) for tv in times)]
        scale = max(1.0, _size([e.replace(sp.DiracDelta, lambda *a: 0) for e in sizes], generic, 20))
        ode = _size([e.subs(t, tv) for e in residual for tv in times], {}, dps)
        return Verification(ode / scale, _size(start, generic, dps) / scale, 10.0 ** (10 - dps))

    def _impulsive_load(self) -> sp.Matrix | None:
        """J with J·δ(t) the impulses the forcing applies at t = 0 (None without)."""
        s = self.scene
        if not s.is_forced or not s.forcing.has(sp.DiracDelta):
            return None
        inputs = [input_transform(f, f"forcing[{j}]", lam) for j, f in enumerate(s.forcing)]
        return sp.Matrix([sp.limit(dict(T.parts).get(sp.S.Zero, 0), lam, sp.oo) for T in inputs])

    @cached_property
    def initial_jump(self) -> InitialJump:
        """x(0⁺), x'(0⁺) and what jumped at t = 0 (nothing unless M is singular).

        A massless node joined only by springs starts where its springs balance; one with
        a dashpot keeps its position but takes the velocity its dashpot law sets. Masses
        keep position and velocity. ``impulses`` lists δ^(k) terms of x at t = 0 (only
        non-physical, indefinite data produce them). From X(λ) at λ = ∞, exactly.

        Examples
        --------
        >>> from laplace_springs.scene import Scene
        >>> scene = Scene.from_components(masses={"n": 0, "m": 1},
        ...     springs={"k1": ("wall", "n", 3), "k2": ("n", "m", 2)}, x0=[1, 2], v0=[0, 1])
        >>> jump = solve(scene).initial_jump
        >>> jump.x_plus.T, jump.position.T, jump.velocity.T
        (Matrix([[4/5, 2]]), Matrix([[-1/5, 0]]), Matrix([[2/5, 0]]))
        """
        first = self.pieces[0]
        if first.denominator is None:
            return initial_jump(self.resolvent)
        return initial_jump(self.resolvent, list(first.numerators), first.denominator)

    # -- plots (see laplace_springs.plotting; need matplotlib) ---------------
    def plot(self, ax=None, **kw):
        """The seed's "Mass Position vs. Time" plot; see :func:`laplace_springs.plotting.plot_motion`."""
        from .plotting import plot_motion

        return plot_motion(self, ax, **kw)

    def plot_phase(self, ax=None, **kw):
        """Phase portraits x_i' against x_i; see :func:`laplace_springs.plotting.plot_phase`."""
        from .plotting import plot_phase

        return plot_phase(self, ax, **kw)

    def plot_energy(self, ax=None, **kw):
        """Kinetic, potential, dissipated energy; see :func:`laplace_springs.plotting.plot_energy`."""
        from .plotting import plot_energy

        return plot_energy(self, ax, **kw)

    # -- named quantities of symbolic scenes (see laplace_springs.symbolic_forms) --
    @property
    def definitions(self) -> dict:
        """Named quantity → definition for the names in :attr:`x` (ω_j, γ_j, S_j, P_j).

        Empty for numeric scenes. A definition may use names listed before it.

        Examples
        --------
        >>> from laplace_springs.scene import Scene
        >>> sol = solve(Scene.from_matrices(M=[["m"]], K=[["k"]], x0=[1], v0=[0]))
        >>> sol.x[0], sol.definitions
        (cos(t*omega_1), {omega_1: sqrt(k)/sqrt(m)})
        """
        from .symbolic_forms import definitions

        return definitions(list(self.x))

    def substituted(self) -> sp.ImmutableMatrix:
        """:attr:`x` with every named quantity replaced by its definition in the parameters."""
        from .symbolic_forms import expand_names

        return sp.ImmutableMatrix(expand_names(self.x))


def _sample_times(samples: Sequence, delays: Sequence[sp.Expr]) -> list[sp.Expr]:
    """t = 0 and the samples, moved off the switching times of delayed inputs."""
    times = [sp.S.Zero]
    for tv in samples:
        value = sp.Rational(tv)
        while any(value == d for d in delays):
            value += sp.Rational(1, 7)
        times.append(value)
    return times


def generic_values(symbols) -> dict:
    """Fixed, unremarkable positive rationals for symbolic parameters."""
    return {sym: sp.Rational(97 + 13 * i, 89 + 7 * i)
            for i, sym in enumerate(sorted(symbols, key=lambda v: v.name))}


def _size(exprs, values: dict, dps: int) -> float:
    """max |e| over the expressions, at ``dps`` digits (complex values allowed).

    Real expressions go through :func:`laplace_springs.mp_expr.mp_value` (guard digits
    doubled until two evaluations agree, so cancelling coefficients cannot fool it);
    anything it does not take falls back to :func:`numeric_value`.
    """
    caches: dict = {}
    return max((_magnitude(sp.sympify(e).xreplace(values), dps, caches) for e in exprs),
               default=0.0)


def _magnitude(expr: sp.Expr, dps: int, caches: dict) -> float:
    try:
        return float(abs(mp_value(expr, dps, caches)))
    except Exception:  # complex or unsupported pieces: SymPy's evaluation
        return float(abs(numeric_value(expr, dps)))


def _latex_name(name: str) -> str:
    head = name.rstrip("0123456789")
    tail = name[len(head):]
    return f"{head}_{{{tail}}}" if tail and head else name


def solve(scene: Scene, *, method: str = "auto"):
    """Solve M x'' + C x' + K x = f(t) with the scene's initial data.

    Parameters
    ----------
    scene : Scene
        The mechanical system.
    method : {"auto", "exact", "numeric"}
        "exact" inverts the Laplace transform by exact partial fractions. "numeric"
        uses the conditioned eigen-decomposition of the linearised quadratic eigenvalue
        problem (:mod:`laplace_springs.numeric_route`; unforced numeric scenes with
        invertible M). "auto" is exact unless the scene is numeric, unforced, has more
        than :data:`EXACT_LIMIT` coordinates and invertible M. When the float64
        route's own error estimate exceeds 1e-12 (stiff, widely scaled scenes), the
        modes are recomputed in ball arithmetic (:mod:`laplace_springs.precise_route`)
        if the eigenvalues are simple; failing that, the exact route is taken up to
        twice :data:`EXACT_LIMIT` coordinates and the float64 route beyond. The
        result's ``method`` and ``reason`` say which route was taken.

    Returns
    -------
    Solution or NumericSolution
        Closed form :attr:`Solution.x`, evaluation, LaTeX, g-basis and verification;
        the numeric route's result has ``x`` (Float coefficients), ``evaluate`` and
        ``verify``.

    Examples
    --------
    A critically damped mass, x'' + 2x' + x = 0, x(0) = 1:

    >>> from laplace_springs.scene import Scene
    >>> sol = solve(Scene.from_matrices(M=[[1]], C=[[2]], K=[[1]], x0=[1], v0=[0]))
    >>> sol.x[0]
    t*exp(-t) + exp(-t)
    >>> sol.evaluate([0.0, 1.0]).round(12)
    array([[1.        , 0.73575888]])
    """
    if method not in _METHODS:
        raise ValueError(f"method must be one of {_METHODS}, got {method!r}")
    if method == "numeric" or (method == "auto" and _numeric_is_better(scene)):
        from .numeric_route import solve_numeric

        if scene.is_forced:
            raise SceneError("the numeric route does not take forcing yet; use method='exact'")
        reason = ("method='numeric' was requested" if method == "numeric" else
                  f"auto: {scene.n} coordinates > EXACT_LIMIT = {EXACT_LIMIT} "
                  f"(Δ of degree {2 * scene.n}); the exact route would take seconds")
        numeric = solve_numeric(scene, reason=reason)
        if method == "numeric" or _well_conditioned(numeric):
            return numeric
        better = _precise_or_none(scene, reason)
        if better is not None or scene.n > 2 * EXACT_LIMIT:
            return better if better is not None else numeric
    R = resolvent(scene)
    if not scene.is_forced:
        return Solution(scene, R, _terms_of(decompose(list(R.numerators), R.determinant)))
    pieces = _forced_pieces(scene, R)
    return Solution(scene, R, pieces[0].terms, pieces)


def _precise_or_none(scene: Scene, reason: str):
    """The ball-arithmetic modal route (:mod:`~laplace_springs.precise_route`), if it applies."""
    from .precise_route import solve_precise

    return solve_precise(scene, reason=reason + "; float64 eigenvectors were not accurate enough "
                         "(error estimate above 1e-12), so the modes were computed in ball arithmetic")


def _well_conditioned(numeric) -> bool:
    """Whether the numeric route's own error estimate at t = 0 and 1 is below 1e-12."""
    values, error = numeric.modes.values_and_errors(np.array([0.0, 1.0]))  # float64, no escalation
    return float(error.max()) <= 1e-12 * max(float(np.abs(values).max()), 1e-300)


def _numeric_is_better(scene: Scene) -> bool:
    """Whether "auto" takes the numeric route (see :func:`solve`)."""
    return (scene.n > EXACT_LIMIT and not scene.is_forced and not scene.free_symbols
            and scene.M.det() != 0)


def _forced_pieces(scene: Scene, R: Resolvent) -> tuple[Piece, ...]:
    """Pieces of X(λ) = adj·[r(λ) + F(λ)]/Δ: one per delay of the inputs (delay 0 first).

    For each delay τ the inputs' rational parts R_τj = P_j/Q_j are put over their common
    denominator D_τ; the piece is adj·(D_τ F_τ + [τ = 0] D_τ r)/(Δ D_τ), inverted by the
    same partial-fraction engine. A pole group whose factor divides D_τ is steady state.
    """
    inputs = [input_transform(f, f"forcing[{j}]", lam) for j, f in enumerate(scene.forcing)]
    delays = sorted({tau for T in inputs for tau, _ in T.parts} | {sp.S.Zero}, key=float)
    with naming_scope():
        return tuple(_forced_piece(scene, R, inputs, tau) for tau in delays)


def _forced_piece(scene: Scene, R: Resolvent, inputs, tau: sp.Expr) -> Piece:
    """The piece of the response switched on at ``tau``."""
    fractions = [sp.fraction(sp.cancel(dict(T.parts).get(tau, sp.S.Zero))) for T in inputs]
    D = sp.Poly(sp.lcm_list([den for _, den in fractions] or [1]), lam)
    load = [_poly(sp.cancel(num * D.as_expr() / den)) for num, den in fractions]
    numerators = [sum((_poly(R.adjugate[i, j]) * load[j] for j in range(scene.n)), _poly(0))
                  for i in range(scene.n)]
    if tau == 0:
        numerators = [N + D * free for N, free in zip(numerators, R.numerators)]
    denominator = R.determinant * D
    rows, flags, impulses = [], [], []
    for pf in decompose(numerators, denominator):
        pairs = [(term, _divides(group.factor, D))
                 for group in pf.groups for term in group_terms(group)]
        rows.append(tuple(term for term, _ in pairs))
        flags.append(tuple(steady for _, steady in pairs))
        to_sympy = pf.polynomial.domain.to_sympy
        impulses.append(tuple(to_sympy(c) for c in reversed(pf.polynomial.all_coeffs()))
                        if not pf.polynomial.is_zero else ())
    return Piece(tau, tuple(rows), tuple(flags), tuple(impulses) if any(impulses) else (),
                 tuple(numerators), denominator)


def _poly(expr) -> sp.Poly:
    return sp.Poly(sp.expand(expr), lam)


def _divides(factor: sp.Poly, D: sp.Poly) -> bool:
    """Whether the irreducible ``factor`` divides ``D`` (over a common field)."""
    if D.degree() <= 0:
        return False
    return sp.rem(D.as_expr(), factor.as_expr(), lam) == 0
