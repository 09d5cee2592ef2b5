"""Assemble the exact motion x(t) from the resolvent: pieces, terms, g-basis, jumps.

Each coordinate X_i(λ) = N_i(λ)/Δ(λ) is inverted by the shared partial-fraction engine
(the denominator is factored once). A driven scene adds one *piece* per delay τ of its
inputs: terms in t − τ switched on at t = τ. The seed's basis g_k(t) = L⁻¹[λ^k/Δ(λ)] and
the coefficients c_ik with x_i(t) = Σ_k c_ik g_k(t) are available beside the closed form.
Where Δ(λ) has a factor without closed-form roots (symbolic coefficients, degree ≥ 3) its
part of x_i(t) is a sum over its roots, Σ_{Δ(λ)=0} N_i(λ)/Δ'(λ) e^{λt}, valid where those
roots are simple (:attr:`ExactMotion.conditions`).

A periodic input (:class:`~laplace_springs.model.periodic.Periodic`, transform
Σ_τ e^{−τλ} R_τ(λ)/(1 − e^{−Pλ})) adds a :class:`PeriodicResponse`: with G_τ = adj·R_τ/Δ
and φ_τ the solution of φ_τ(x) − φ_τ(x + P) = g_τ(x) = L⁻¹[G_τ](x)
(:func:`~laplace_springs.exact.shifts.difference_solution`), the response is, for every
t ≥ 0 (0 ≤ τ ≤ P),

    Σ_τ Σ_{j ≥ 0} g_τ(t − τ − jP) θ(t − τ − jP) = Σ_τ φ_τ((t − τ) mod P) − Σ_τ φ_τ(t − τ + P):

a P-periodic function of the reduced time plus an exponential polynomial in t (a
telescoped geometric sum: no infinite sum, no growth of the work with t).

Nothing here evaluates numbers or writes output: :class:`ExactMotion` is the exact data
the later stages (evaluation, LaTeX, plots) read.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from functools import cached_property
from typing import Literal

import sympy as sp

from ..model.errors import InversionError
from ..model.forcing import InputTransform, input_transform
from ..model.periodic import common_period
from ..model.scene import Scene
from ..model.switching import sorted_delays
from ..model.symbols import TIME, lam
from .jumps import InitialJump, initial_jump
from .named import definitions, expand_names
from .named_roots import free_rational, named_rows
from .partial_fractions import GenericCondition, decompose, denominator_conditions
from .real_terms import (
    RootSumTerm,
    Term,
    derivative_terms,
    group_terms,
    naming_scope,
    reserved_names,
    solution_terms,
    terms_expr,
)
from .resolvent import Resolvent, resolvent
from .root_sums import Condition
from .screening import screen_scene
from .shifts import combine_terms, difference_solution, is_resonant, shift_terms

__all__ = ["Piece", "PeriodicResponse", "ExactMotion", "exact_motion"]

Part = Literal["all", "steady", "transient"]


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

    def __post_init__(self) -> None:
        shapes = [len(row) for row in self.terms], [len(row) for row in self.steady]
        if shapes[0] != shapes[1]:
            raise ValueError(f"a piece needs one steady flag per term: {shapes[0]} terms per "
                             f"coordinate, {shapes[1]} flags")

    def expr(self, row: int, part: Part = "all") -> sp.Expr:
        """Coordinate ``row`` of this piece in :data:`TIME` (Heaviside-switched if τ > 0)."""
        chosen = [term for term, steady in zip(self.terms[row], self.steady[row])
                  if part == "all" or steady == (part == "steady")]
        shifted = TIME - self.delay
        deltas = sp.Add(*(c * (sp.DiracDelta(shifted) if j == 0 else sp.DiracDelta(shifted, j))
                          for j, c in enumerate(self.impulses[row] if self.impulses else ())
                          if c != 0)) if part != "steady" else sp.S.Zero
        if self.delay == 0:
            return terms_expr(chosen, TIME) + deltas
        body = terms_expr(chosen, shifted)
        return (sp.Heaviside(shifted) * body if body != 0 else sp.S.Zero) + deltas

    def derivative(self) -> Piece:
        """d/dt of the piece's terms (the impulses at the switching time are left out)."""
        rows = derivative_terms(self.terms)
        steady = tuple(tuple(flag for term, flag in zip(row, flags)
                             for _ in derivative_terms(((term,),))[0])
                       for row, flags in zip(self.terms, self.steady))
        return dataclasses.replace(self, terms=rows, steady=steady, impulses=())


@dataclass(frozen=True)
class PeriodicResponse:
    """The response to the periodic inputs, in closed form for every t ≥ 0.

    x_i(t) = Σ_k φ_ki((t − τ_k) mod P) + resonant_i(t) + tail_i(t):

    - the **periodic steady state** Σ_k φ_ki(w_k), w_k = (t − τ_k) mod P ∈ [0, P), plus
      the ``resonant`` terms (poles of 1/(1 − e^{−Pλ}): the mean value and the input's
      harmonics; at a true resonance — an undamped mode at a multiple of 2π/P, or a
      rigid mode under an input of nonzero mean — they grow like t^k and no periodic
      steady state exists);
    - the **transient** ``tail``: the system's own poles, decaying for a damped scene.

    Attributes
    ----------
    period : sympy.Expr
        P, the common period of the inputs.
    delays : tuple of sympy.Expr
        τ_k, 0 ≤ τ_k ≤ P: the switching times within one period.
    sums : tuple of tuple of tuple of Term
        ``sums[k][i]``: φ_ki, terms in the reduced time w_k.
    resonant, tail : tuple of tuple of Term
        Per coordinate, terms in t (see above).
    """

    period: sp.Expr
    delays: tuple[sp.Expr, ...]
    sums: tuple[tuple[tuple[Term, ...], ...], ...]
    resonant: tuple[tuple[Term, ...], ...]
    tail: tuple[tuple[Term, ...], ...]

    def reduced_time(self, t: sp.Expr, delay: sp.Expr) -> sp.Expr:
        """(t − τ) mod P = t − τ − P·floor((t − τ)/P)."""
        v = t - delay
        return v - self.period * sp.floor(v / self.period)

    def expr(self, row: int, part: Part = "all") -> sp.Expr:
        """Coordinate ``row``: ``"steady"`` (periodic part + resonant terms), ``"transient"``
        (tail) or ``"all"``."""
        out = sp.S.Zero
        if part != "transient":
            out += sp.Add(*(terms_expr(list(rows[row]), self.reduced_time(TIME, tau))
                            for tau, rows in zip(self.delays, self.sums)))
            out += terms_expr(list(self.resonant[row]), TIME)
        if part != "steady":
            out += terms_expr(list(self.tail[row]), TIME)
        return out

    def derivative(self) -> PeriodicResponse:
        """d/dt (dw/dt = 1 between the switching times)."""
        return PeriodicResponse(self.period, self.delays,
                                tuple(derivative_terms(rows) for rows in self.sums),
                                derivative_terms(self.resonant), derivative_terms(self.tail))


@dataclass(frozen=True, eq=False)
class ExactMotion:
    """Exact motion x(t) of a scene, in real damped sine/cosine form.

    Build it with :func:`exact_motion`. ``pieces[k].terms[i]`` hold the structured real
    terms of coordinate i switched on at ``pieces[k].delay``; :attr:`x` is the same as a
    SymPy column matrix in :data:`laplace_springs.t`.
    """

    scene: Scene
    resolvent: Resolvent
    pieces: tuple[Piece, ...]
    periodic: PeriodicResponse | None = None
    named_roots: bool = False

    @property
    def terms(self) -> tuple[tuple[Term, ...], ...]:
        """The terms of the piece switched on at t = 0 (the whole motion of a free scene)."""
        return self.pieces[0].terms

    @cached_property
    def x(self) -> sp.ImmutableMatrix:
        """x(t) as a SymPy column matrix in :data:`laplace_springs.t`.

        A response to an input delayed by τ carries the factor Heaviside(t − τ); nothing
        else does (the whole solution holds for t ≥ 0).
        """
        return self.part("all")

    def part(self, part: Part) -> sp.ImmutableMatrix:
        """``"all"`` of x(t), its ``"steady"`` state or its ``"transient"``."""
        return sp.ImmutableMatrix([sp.Add(*(piece.expr(i, part) for piece in self.pieces))
                                   + (self.periodic.expr(i, part) if self.periodic else 0)
                                   for i in range(self.scene.n)])

    def derivative(self) -> ExactMotion:
        """x'(t) as an exact motion of the same scene (impulses at switching times left out).

        Examples
        --------
        >>> from laplace_springs.model.scene import Scene
        >>> motion = exact_motion(Scene.from_matrices(M=[[1]], K=[[4]], x0=[1], v0=[0]))
        >>> motion.derivative().x[0]
        -2*sin(2*t)
        """
        return dataclasses.replace(self, pieces=tuple(p.derivative() for p in self.pieces),
                                   periodic=self.periodic.derivative() if self.periodic else None)

    # -- the seed's g-basis ---------------------------------------------------
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
    def g_terms(self) -> dict[int, tuple[Term, ...]]:
        """The terms of each g_k(t) = L⁻¹[λ^k/Δ(λ)], k in :attr:`g_indices`."""
        D = self.g_denominator
        monomials = [sp.Poly(lam**k, lam, domain=D.domain) for k in self.g_indices]
        named = named_rows(monomials, D, powers=self.g_indices) if self.named_roots else None
        rows = named if named is not None else solution_terms(
            decompose(monomials, D, closed_form=True, root_sums=True))
        return dict(zip(self.g_indices, rows))

    @cached_property
    def g_basis(self) -> dict[int, sp.Expr]:
        """g_k(t) = L⁻¹[λ^k/Δ(λ)] for the k in :attr:`g_indices`, exactly."""
        return {k: terms_expr(list(row), TIME) for k, row in self.g_terms.items()}

    def g_form(self) -> sp.ImmutableMatrix:
        """x(t) written as Σ c_ik g_k with g_k as undefined functions g_k(t)."""
        C = self.g_coefficients
        g = {k: sp.Function(f"g_{k}")(TIME) for k in self.g_indices}
        return sp.ImmutableMatrix([sp.Add(*(C[i, k] * g[k] for k in self.g_indices))
                                   for i in range(C.shape[0])])

    # -- the start ------------------------------------------------------------
    @cached_property
    def initial_jump(self) -> InitialJump:
        """x(0⁺), x'(0⁺) and what jumped at t = 0 (nothing unless M is singular).

        A massless node joined only by springs starts where its springs balance; one with
        a dashpot keeps its position but takes the velocity its dashpot law sets. Masses
        keep position and velocity. ``impulses`` lists δ^(k) terms of x at t = 0 (only
        non-physical, indefinite data produce them). From X(λ) at λ = ∞, exactly.

        Examples
        --------
        >>> from laplace_springs.model.scene import Scene
        >>> scene = Scene.from_components(masses={"n": 0, "m": 1},
        ...     springs={"k1": ("wall", "n", 3), "k2": ("n", "m", 2)}, x0=[1, 2], v0=[0, 1])
        >>> jump = exact_motion(scene).initial_jump
        >>> jump.x_plus.T, jump.position.T, jump.velocity.T
        (Matrix([[4/5, 2]]), Matrix([[-1/5, 0]]), Matrix([[2/5, 0]]))
        """
        first = self.pieces[0]
        if first.denominator is None:
            return initial_jump(self.resolvent)
        return initial_jump(self.resolvent, list(first.numerators), first.denominator)

    def impulsive_load(self) -> sp.Matrix | None:
        """J with J·δ(t) the impulses the forcing applies at t = 0 (None without)."""
        s = self.scene
        if s.forcing is None or not s.is_forced or not s.forcing.has(sp.DiracDelta):
            return None
        inputs = [input_transform(f, f"forcing[{j}]", lam) for j, f in enumerate(s.forcing)]
        return sp.Matrix([sp.limit(dict(T.parts).get(sp.S.Zero, 0), lam, sp.oo) for T in inputs])

    # -- named quantities of symbolic scenes ------------------------------------
    @property
    def definitions(self) -> dict:
        """Named quantity → definition for the names in :attr:`x` (ω_j, γ_j, S_j, P_j).

        Empty for numeric scenes. A definition may use names listed before it.

        Examples
        --------
        >>> from laplace_springs.model.scene import Scene
        >>> motion = exact_motion(Scene.from_matrices(M=[["m"]], K=[["k"]], x0=[1], v0=[0],
        ...                                             parameters=["m", "k"]))
        >>> motion.x[0], motion.definitions
        (cos(t*omega_1), {omega_1: sqrt(k)/sqrt(m)})
        """
        return definitions(list(self.x))

    def substituted(self) -> sp.ImmutableMatrix:
        """:attr:`x` with every named quantity replaced by its definition in the parameters."""
        return sp.ImmutableMatrix(expand_names(self.x))

    # -- where the formula holds -------------------------------------------------
    @property
    def root_sums(self) -> tuple[tuple[int, int, RootSumTerm], ...]:
        """(piece index, coordinate, term) for every sum over the roots of a factor of Δ(λ)
        without closed-form roots (symbolic coefficients, degree ≥ 3)."""
        return tuple((k, i, term) for k, piece in enumerate(self.pieces)
                     for i, row in enumerate(piece.terms) for term in row
                     if isinstance(term, RootSumTerm))

    @property
    def conditions(self) -> tuple[Condition, ...]:
        """Where the formula holds, beyond the parameters being finite: each sum over the
        roots of a factor q of Δ(λ) needs q's roots to be simple roots of its denominator
        (disc_λ q ≠ 0, and no root shared with the inputs' denominators or the rest of
        Δ). Empty when :attr:`x` has no such sum.

        ``condition.expr`` is the polynomial in the parameters that must not vanish
        (computed on first use), ``condition.holds_at(values)`` checks numbers at once.

        Examples
        --------
        >>> import sympy as sp
        >>> from laplace_springs.model.scene import Scene
        >>> m1, m2, k1, k2, c = sp.symbols("m1 m2 k1 k2 c", positive=True)
        >>> motion = exact_motion(Scene.from_matrices(M=[[m1, 0], [0, m2]],
        ...     C=[[c, -c], [-c, c]], K=[[k1 + k2, -k2], [-k2, k2]], x0=[1, 0], v0=[0, 0]))
        >>> (condition,) = motion.conditions
        >>> condition.meaning  # doctest: +ELLIPSIS
        'c*k1*lambda + k1*k2 + lambda**4*m1*m2 + ... has simple roots (its discriminant is not 0)'
        >>> condition.holds_at({m1: 1, m2: 2, k1: 3, k2: 5, c: sp.Rational(1, 10)})
        True
        """
        found: dict[tuple, Condition] = {}
        for _, _, term in self.root_sums:
            condition = term.condition
            found.setdefault((condition.factor, condition.cofactor), condition)
        return tuple(found.values()) + self.generic_conditions + self.input_conditions

    @property
    def input_conditions(self) -> tuple:
        """Where the inputs' transforms hold: a symbolic switching time of unknown sign is
        a delay where it is ≥ 0 (``b >= 0`` for ``Heaviside(t - b)``, b a plain Symbol);
        see :mod:`laplace_springs.model.switching`."""
        if self.scene.forcing is None:
            return ()
        found = {(c.expr, c.relation): c for j, f in enumerate(self.scene.forcing)
                 for c in input_transform(f, f"forcing[{j}]", lam).conditions}
        return tuple(found.values())

    @cached_property
    def generic_conditions(self) -> tuple[GenericCondition, ...]:
        """Where the partial fractions of a symbolic scene hold: Δ(λ) (and the inputs'
        denominators) keep their degree, their quadratic factors have simple roots
        (c² − 4km ≠ 0 for one damped mass: critical damping is 0/0 in the generic
        formula) and distinct factors share no root.

        Examples
        --------
        >>> from laplace_springs.model.scene import Scene
        >>> scene = Scene.from_matrices(M=[[1]], C=[["c"]], K=[[1]], x0=[1], v0=[0], parameters=["c"])
        >>> [c.meaning for c in exact_motion(scene).generic_conditions]
        ['c**2 - 4 != 0']
        """
        denominators = [piece.denominator for piece in self.pieces if piece.denominator is not None]
        found: list[GenericCondition] = []
        for D in denominators or [self.resolvent.determinant]:
            for condition in denominator_conditions(D):
                if all(sp.expand(condition.expr - c.expr) != 0 for c in found):
                    found.append(condition)
        return tuple(found)


def exact_motion(scene: Scene) -> ExactMotion:
    """The exact motion of a scene, free or driven.

    Examples
    --------
    A critically damped mass, x'' + 2x' + x = 0, x(0) = 1:

    >>> from laplace_springs.model.scene import Scene
    >>> exact_motion(Scene.from_matrices(M=[[1]], C=[[2]], K=[[1]], x0=[1], v0=[0])).x[0]
    t*exp(-t) + exp(-t)

    A factor of Δ(λ) of degree ≥ 3 with symbolic coefficients (an even quartic excepted)
    has no closed-form roots: its part of x_i(t) is the sum over its roots
    Σ_{Δ(λ)=0} N_i(λ)/Δ'(λ) e^{λt} (a :class:`~laplace_springs.exact.root_sums.SumOverRoots`),
    valid where those roots are simple (:attr:`ExactMotion.conditions`).

    A free scene with rational entries is built over ℚ (python-flint); a factor of Δ(λ)
    of degree above :attr:`~laplace_springs.limits.Limits.exact_expanded_max_degree`
    gives terms in named numbers (ρ_j, α_j, β_j, c_j: see
    :mod:`laplace_springs.exact.named_roots`), exact, with ``CRootOf`` built only when
    asked (:meth:`ExactMotion.substituted`); so does a factor of any degree whose roots
    SymPy numbers only slowly (their sizes spanning hundreds of decades:
    :attr:`~laplace_springs.limits.Limits.exact_expanded_max_isolation`).

    Raises
    ------
    InversionError
        At once (before the resolvent is built, see
        :func:`~laplace_springs.exact.screening.screen_scene`) or right after Δ(λ) is
        factored, when Δ has an irreducible factor above
        :attr:`~laplace_springs.limits.Limits.max_exact_factor_degree` (a forced or
        symbolic scene) or one of degree ≥ 3 with irrational coefficients, or one whose
        roots SymPy would number only after more work than
        :attr:`~laplace_springs.limits.Limits.max_exact_isolation` (a forced scene with
        entries of very different sizes), that the solution needs; or when the scene has
        more than
        :attr:`~laplace_springs.limits.Limits.max_exact_coordinates` coordinates.
    """
    with reserved_names(symbol.name for symbol in scene.free_symbols):
        return _exact_motion(scene)


def _exact_motion(scene: Scene) -> ExactMotion:
    """:func:`exact_motion`, its named quantities numbered around the scene's own names."""
    if not free_rational(scene):  # its factors have exact terms at any degree
        screen_scene(scene)
    R = resolvent(scene)
    if not scene.is_forced:
        named = named_rows(list(R.numerators), R.determinant)
        rows = named if named is not None else solution_terms(
            decompose(list(R.numerators), R.determinant, closed_form=True, root_sums=True))
        flags = tuple((False,) * len(row) for row in rows)
        return ExactMotion(scene, R, (Piece(sp.S.Zero, rows, flags),), named_roots=named is not None)
    assert scene.forcing is not None
    inputs = [input_transform(f, f"forcing[{j}]", lam) for j, f in enumerate(scene.forcing)]
    with naming_scope():
        pieces = _forced_pieces(scene, R)
        periodic = _periodic_response(scene, R, inputs)
    return ExactMotion(scene, R, pieces, periodic)


def _periodic_response(scene: Scene, R: Resolvent, inputs: list[InputTransform]
                       ) -> PeriodicResponse | None:
    """The response to the periodic parts of the inputs (None without any)."""
    periods = [T.period for T in inputs if T.period is not None]
    if not periods:
        return None
    P = common_period(periods)
    loads: dict[sp.Expr, list[sp.Expr]] = {}
    for j, T in enumerate(inputs):
        if T.period is None:
            continue
        for tau, part in T.periodic:
            for k in range(int(P / T.period)):
                row = loads.setdefault(tau + k * T.period, [sp.S.Zero] * scene.n)
                row[j] += part
    delays = tuple(sorted(loads, key=float))
    sums = []
    for tau in delays:
        numerators, denominator = _response(scene, R, loads[tau])
        rows = []
        for pf in decompose(numerators, denominator, closed_form=True):
            if not pf.polynomial.is_zero:
                raise InversionError("the response to a periodic input has impulses (an impulsive "
                                     "input on a massless node): a train of impulses is not a "
                                     "function that evaluates at any t")
            terms = [term for group in pf.groups for term in group_terms(group)]
            rows.append(_merged([phi for term in terms for phi in difference_solution(term, P)], P))
        sums.append(tuple(rows))
    resonant, tail = [], []
    for i in range(scene.n):  # −Σ_τ φ_τ(t − τ + P)
        shifted = _merged([term for tau, rows in zip(delays, sums)
                           for term in shift_terms(_negated(rows[i]), tau - P)], P)
        resonant.append(tuple(term for term in shifted if is_resonant(term, P)))
        tail.append(tuple(term for term in shifted if not is_resonant(term, P)))
    return PeriodicResponse(P, delays, tuple(sums), tuple(resonant), tuple(tail))


def _merged(terms: list[Term], period: sp.Expr) -> tuple[Term, ...]:
    """Terms with equal exponents summed. Only sums at the poles of 1/(1 − e^{−Pλ}) are
    proved zero or tidied (there the input's parts cancel exactly, e.g. the t-growth of
    one period's mean); the system's own poles keep their plain sums (a zero proof over
    algebraic numbers costs seconds and never succeeds for them)."""
    keyed: dict[tuple, list[Term]] = {}
    for term in terms:
        keyed.setdefault((term.kind, term.power, term.alpha, term.beta), []).append(term)
    out: list[Term] = []
    for group in keyed.values():
        if is_resonant(group[0], period):
            out += combine_terms(group)
        elif len(group) == 1:
            out += group
        else:
            out.append(dataclasses.replace(group[0], a=sp.Add(*(term.a for term in group)),
                                           b=sp.Add(*(term.b for term in group))))
    return tuple(out)


def _negated(terms: tuple[Term, ...]) -> list[Term]:
    return [dataclasses.replace(term, a=-term.a, b=-term.b) for term in terms]


def _response(scene: Scene, R: Resolvent, load: list[sp.Expr]) -> tuple[list[sp.Poly], sp.Poly]:
    """adj·load/Δ over one denominator: (numerators, Δ·D), D the loads' common denominator."""
    fractions = [sp.fraction(sp.cancel(value)) for value in load]
    D = sp.Poly(sp.lcm_list([den for _, den in fractions] or [1]), lam)
    scaled = [_poly(sp.cancel(num * D.as_expr() / den)) for num, den in fractions]
    numerators = [sum((_poly(R.adjugate[i, j]) * scaled[j] for j in range(scene.n)), _poly(0))
                  for i in range(scene.n)]
    return numerators, R.determinant * D


def _forced_pieces(scene: Scene, R: Resolvent) -> tuple[Piece, ...]:
    """Pieces of X(λ) = adj·[r(λ) + F(λ)]/Δ: one per delay of the inputs (delay 0 first).

    For each delay τ the inputs' rational parts R_τj = P_j/Q_j are put over their common
    denominator D_τ; the piece is adj·(D_τ F_τ + [τ = 0] D_τ r)/(Δ D_τ), inverted by the
    same partial-fraction engine. A pole group whose factor divides D_τ is steady state.
    """
    assert scene.forcing is not None
    inputs = [input_transform(f, f"forcing[{j}]", lam) for j, f in enumerate(scene.forcing)]
    delays = sorted_delays({tau for T in inputs for tau, _ in T.parts} | {sp.S.Zero})
    try:
        return tuple(_forced_piece(scene, R, inputs, tau) for tau in delays)
    except sp.PolynomialError as exc:  # SymPy's expression domain could not cancel (√6 = √2·√3)
        raise InversionError("the exact route could not put the inputs' transforms over one "
                             f"denominator (SymPy: {str(exc)[:120]}); method='auto' solves "
                             "the scene numerically") from None


def _forced_piece(scene: Scene, R: Resolvent, inputs, tau: sp.Expr) -> Piece:
    """The piece of the response switched on at ``tau``.

    Constants of the inputs that are not rational (phases cos(2/3), sin(2/3) of an input
    switched on at τ = 1/3, √2, π; not the scene's parameters) stand as symbols while the
    partial fractions are formed, so they work over ℚ[c₁, c₂, …] rather than SymPy's
    expression domain (cos(2t)·H(t − 1/3) on three masses: 3 s before, 0.4-0.8 s), and are put
    back in the terms. The constants of the inputs' denominators (the poles ±iπ of sin(πt),
    −√2 of e^{−√2t}) stand as symbols too where the partial fractions over them hold at
    the constants (:func:`_pole_constants`): sin(πt) on three masses 100 s in SymPy's
    expression domain, 4 s now; e^{−√2t} on three masses over 280 s, 5 s; t·e^{−et} on two
    28 s, 1 s."""
    fractions = [sp.fraction(sp.cancel(dict(T.parts).get(tau, sp.S.Zero))) for T in inputs]
    forward, back = _constants_as_symbols([num for num, _ in fractions],
                                          [den for _, den in fractions], R.determinant)
    fractions = [(num.xreplace(forward), den.xreplace(forward)) for num, den in fractions]
    D = sp.Poly(sp.lcm_list([den for _, den in fractions] or [1]), lam)
    load = [_poly(sp.cancel(num * D.as_expr() / den)) for num, den in fractions]
    numerators = [sum((_poly(R.adjugate[i, j]) * load[j] for j in range(scene.n)), _poly(0))
                  for i in range(scene.n)]
    if tau == 0:
        numerators = [N + D * free for N, free in zip(numerators, R.numerators)]
    denominator = R.determinant * D
    rows, flags, impulses = [], [], []
    for pf in decompose(numerators, denominator, closed_form=True, root_sums=True,
                        parts=(R.determinant, D)):
        pairs = [(_put_back(term, back), _divides(group.factor, D))
                 for group in pf.groups for term in group_terms(group)]
        rows.append(tuple(term for term, _ in pairs))
        flags.append(tuple(steady for _, steady in pairs))
        to_sympy = pf.polynomial.domain.to_sympy
        impulses.append(tuple(to_sympy(c).xreplace(back)
                              for c in reversed(pf.polynomial.all_coeffs()))
                        if not pf.polynomial.is_zero else ())
    if back:  # the piece's transform holds the constants themselves
        numerators = [_poly(N.as_expr().xreplace(back)) for N in numerators]
        denominator = _poly(denominator.as_expr().xreplace(back))
    return Piece(tau, tuple(rows), tuple(flags), tuple(impulses) if any(impulses) else (),
                 tuple(numerators), denominator)


def _constants_as_symbols(numerators: list[sp.Expr], denominators: list[sp.Expr],
                          determinant: sp.Poly) -> tuple[dict, dict]:
    """Symbols for the constants of the inputs' ``numerators`` that are not rational
    numbers (function values such as cos(2/3), roots, π, E) and appear in no denominator,
    and for the constants of the denominators (:func:`_pole_constants`): the substitution
    and its inverse.

    >>> forward, back = _constants_as_symbols([sp.pi], [lam**2 + sp.pi**2], sp.Poly(lam + 1, lam))
    >>> sorted(map(str, forward.items())), list(back.values())
    (['(pi**2, _p**2)', '(pi, _p)'], [pi])
    >>> _constants_as_symbols([sp.sqrt(2)], [lam**2 + 2], sp.Poly(lam + 1, lam))[0]
    {sqrt(2): _c0}
    """
    found = set().union(*(_constants(part) for part in numerators))
    # an atom inside another (√2 in cos(√2)) stays inside it
    found = {atom for atom in found if not any(atom != other and other.has(atom) for other in found)
             and not any(den.has(atom) for den in denominators)}
    names = {atom: sp.Dummy(f"c{k}", real=True) for k, atom in
             enumerate(sorted(found, key=sp.default_sort_key))}
    back = {stand_in: atom for atom, stand_in in names.items()}
    poles = _pole_constants(denominators, determinant)
    if poles is not None:
        names.update(poles[0])
        back.update(poles[1])
    return names, back


def _pole_constants(denominators: list[sp.Expr], determinant: sp.Poly) -> tuple[dict, dict] | None:
    """Symbols for the constants of the inputs' ``denominators`` (the poles' constants):
    the substitution and its inverse, or None (they stay in SymPy's expression domain).

    Powers of π stand as powers of one symbol for π, and powers of e (e, e² = exp(2),
    e^{1/2}) as powers of one symbol for e^{1/L}; any other constant (√2, cos 1) as a
    symbol of its own, with the constant's sign. Δ(λ) must hold no constant (π in K and in
    a pole would meet: resonance). Where the constants are powers of π alone or of e alone,
    no condition of the partial fractions over ℚ(p), the parameters adjoined, can fail at
    p = g: a transcendental number is a root of no nonzero polynomial with algebraic
    coefficients (Lindemann 1882, Hermite 1873). Otherwise, with Δ(λ) rational, the
    conditions are checked at the constants (:func:`_specializes`: √2 meets the stiffness
    −2 in a resonance, and π² − e² ≠ 0 is known to no theorem).
    """
    domain = determinant.domain
    rational = domain.is_ZZ or domain.is_QQ
    ground = domain.domain if domain.is_PolynomialRing or domain.is_FractionField else domain
    if not (ground.is_ZZ or ground.is_QQ) or _constants(determinant.as_expr()):
        return None
    atoms = set().union(*(_constants(den) for den in denominators))
    if not atoms:
        return None
    powers = {atom: found for atom in atoms if (found := _as_power(atom)) is not None}
    others = sorted(atoms - set(powers), key=sp.default_sort_key)
    forward: dict[sp.Expr, sp.Expr] = {}
    back: dict[sp.Symbol, sp.Expr] = {}
    for base in sorted({base for base, _ in powers.values()}, key=sp.default_sort_key):
        group = {atom: exponent for atom, (b, exponent) in powers.items() if b == base}
        L = math.lcm(*(int(exponent.q) for exponent in group.values()))
        symbol = sp.Dummy("p", positive=True)
        forward.update({atom: symbol ** int(exponent * L) for atom, exponent in group.items()})
        back[symbol] = base ** sp.Rational(1, L)
    for k, atom in enumerate(others):
        value = sp.N(atom, 30)
        if not (value.is_positive or value.is_negative):  # not a real number: no stand-in
            return None
        symbol = sp.Dummy(f"q{k}", positive=True) if value.is_positive \
            else sp.Dummy(f"q{k}", negative=True)
        forward[atom], back[symbol] = symbol, atom
    proven = len(back) == 1 and not others
    if not (proven or rational):
        return None
    D = sp.Poly(sp.lcm_list([den.xreplace(forward) for den in denominators]), lam)
    return (forward, back) if _specializes(D, determinant, back, numeric=not proven) else None


def _constants(expr: sp.Expr) -> set[sp.Expr]:
    """The numbers in ``expr`` that are not rational (π, π², exp(2), √2, cos 1)."""
    return {atom for atom in expr.atoms(sp.Function, sp.Pow, sp.NumberSymbol)
            if atom.is_number and not atom.is_Rational}


def _specializes(D: sp.Poly, determinant: sp.Poly, values: dict[sp.Symbol, sp.Expr], *,
                 numeric: bool = True) -> bool:
    """Whether partial fractions over Δ·D, D's coefficients in ℚ[p₁, p₂, …], hold at
    p = ``values`` as their terms are written: D's factors with stand-ins have degree ≤ 2
    (closed-form roots: the stand-ins for √2, √3 and √6 do not know √2·√3 = √6, and
    (λ + √2)(λ + √3)(λ + √6) expanded is irreducible over them), a quadratic's roots are
    real or complex by the stand-ins' signs alone (e^{−2t}·sinh(√(4 − π)t): the sign of
    4 − p is not), and, with ``numeric``, at the constants those factors keep their
    degrees, stay squarefree and share no root with each other or with Δ (the leading
    coefficients, discriminants and resultants, the only denominators of the residues,
    are nonzero there).

    >>> p = sp.Dummy("q", positive=True)
    >>> one = sp.Poly(lam**2 + 2, lam)
    >>> _specializes(sp.Poly(lam**2 + p**2, lam), one, {p: sp.sqrt(3)})
    True
    >>> _specializes(sp.Poly(lam**2 + p**2, lam), one, {p: sp.sqrt(2)})  # resonance
    False
    >>> _specializes(sp.Poly(lam**2 + 4*lam + p, lam), one, {p: sp.pi}, numeric=False)
    False
    """
    symbols = set(values)
    _, factors = D.factor_list()
    polys = [f for f, _ in factors if f.degree() > 0]
    checks = [D.LC()]
    for i, f in enumerate(polys):
        own = bool(f.free_symbols & symbols)
        if own and f.degree() > 2:
            return False
        if own and f.degree() == 2:
            discriminant = f.discriminant()
            if not (discriminant.is_positive or discriminant.is_negative):
                return False
            checks.append(discriminant)
        if numeric:  # every pair with a stand-in (e^{−√2t} beside sinh(√2t): λ + √2 | λ² − 2)
            checks += [f.LC(), f.resultant(determinant)] if own else []
            checks += [f.resultant(g) for g in polys[i + 1:]
                       if own or g.free_symbols & symbols]
    return not numeric or all(_nonzero(sp.sympify(check), values) for check in checks)


def _nonzero(value: sp.Expr, values: dict[sp.Symbol, sp.Expr]) -> bool:
    """Whether the polynomial ``value`` in the stand-ins is nonzero at ``values``: its
    value at 60 digits exceeds 10⁻⁴⁰ of the sum of its terms' sizes (an exact zero, such as
    (√2)² − 2, evaluates far below that; a true value so small is taken as zero, which
    only sends the scene back to the slower exact domain)."""
    terms = sp.Add.make_args(sp.expand(value))
    at = sp.Add(*(term.xreplace(values) for term in terms))
    size = sum(abs(complex(sp.N(term.xreplace(values), 15))) for term in terms)
    found = abs(complex(sp.N(at, 60, maxn=600)))
    return found > 1e-40 * size


def _as_power(atom: sp.Expr) -> tuple[sp.Expr, sp.Rational] | None:
    """(π, k) for π^k (k an integer), (e, r) for e^r (r rational); else None.

    >>> _as_power(sp.pi**2), _as_power(sp.exp(sp.Rational(3, 2))), _as_power(sp.sqrt(2))
    ((pi, 2), (E, 3/2), None)
    """
    if atom is sp.pi or atom is sp.E:
        return atom, sp.Integer(1)
    if atom.is_Pow and atom.base is sp.pi and atom.exp.is_Integer:
        return sp.pi, atom.exp
    if isinstance(atom, sp.exp) and atom.args[0].is_Rational:
        return sp.E, atom.args[0]
    return None


def _put_back(term: Term, back: dict) -> Term:
    """``term`` with the constants of :func:`_constants_as_symbols` in place of their
    symbols."""
    if not back:
        return term
    changes = {name: getattr(term, name).xreplace(back) for name in ("alpha", "beta", "a", "b")
               if isinstance(getattr(term, name), sp.Basic)}
    if isinstance(term, RootSumTerm):
        changes["weights"] = tuple(w.xreplace(back) for w in term.weights)
        symbols = set(back)

        def restored(poly: sp.Poly) -> sp.Poly:
            return sp.Poly(poly.as_expr().xreplace(back), *poly.gens)
        if term.factor.free_symbols & symbols:
            changes["factor"] = restored(term.factor)
        group = term.group
        changes["group"] = dataclasses.replace(group, **{
            name: restored(poly) for name in ("numerator", "denominator", "factor")
            if (poly := getattr(group, name)).free_symbols & symbols})
    return dataclasses.replace(term, **changes)


def _poly(expr) -> sp.Poly:
    return sp.Poly(sp.expand(expr), lam)


def _divides(factor: sp.Poly, D: sp.Poly) -> bool:
    """Whether the irreducible ``factor`` divides ``D`` (over a common field)."""
    if D.degree() <= 0:
        return False
    return sp.rem(D.as_expr(), factor.as_expr(), lam) == 0
