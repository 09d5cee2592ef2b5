"""Inverse Laplace transform in real form: rational functions, delays, periodic transforms.

A rational F(s) gives a sum of real terms t^k e^{αt}(a cos βt + b sin βt) (valid for
t > 0). A transform with delays, F(s) = Σ_τ e^{-τs} R_τ(s), gives by the shift theorem
Σ_τ g_τ(t - τ) Heaviside(t - τ), g_τ the real-form inverse of R_τ. A periodic transform
R(s)/(1 ∓ e^{-Ts}) (R may carry delays) gives one period's formula evaluated at the time
reduced modulo the period, exact and without an infinite sum
(:mod:`laplace_springs.exact.shifts` has the algebra).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import sympy as sp
from sympy.core.function import AppliedUndef

from ..limits import limits
from ..model.errors import InversionError, LimitError
from .laplace import entrywise
from .partial_fractions import (
    PartialFractions,
    decompose,
    denominator_conditions,
    partial_fractions,
    transform_of,
)
from .real_terms import Term, group_terms, solution_terms, terms_expr
from .shifts import (
    DelaySplit,
    combine_terms,
    difference_solution,
    order_delays,
    shift_terms,
    split_delays,
)

__all__ = ["InverseTransform", "DelayedPiece", "DelayedInverse", "inverse_laplace",
           "inverse_laplace_terms", "delayed_inverse"]


@dataclass(frozen=True)
class InverseTransform:
    """Structured inverse of a rational transform.

    Attributes
    ----------
    terms : tuple of Term
        Real terms t^k e^{αt}(a cos βt + b sin βt) (or cosh/sinh, or real exponentials).
    impulses : tuple of sympy.Expr
        ``impulses[j]`` multiplies DiracDelta(t, j), the j-th derivative of the delta
        function: the inverse of the polynomial part of an improper transform.
    decomposition : PartialFractions
        The partial fractions the terms were built from.
    """

    terms: tuple[Term, ...]
    impulses: tuple[sp.Expr, ...]
    decomposition: PartialFractions

    @property
    def conditions(self) -> tuple:
        """Where the formula holds with symbolic coefficients (e.g. ``a**2 - 4 != 0`` for
        1/(s(s² + a s + 1)), 0/0 at a = 2); () when it always holds. See
        :class:`~laplace_springs.exact.partial_fractions.GenericCondition`.

        Examples
        --------
        >>> s, a = sp.symbols("s a")
        >>> [c.meaning for c in inverse_laplace_terms(1 / (s * (s**2 + a*s + 1)), s).conditions]
        ['a**2 - 4 != 0']
        """
        return self.decomposition.conditions

    def as_expr(self, t: sp.Expr) -> sp.Expr:
        """The inverse as an expression in ``t`` (valid for t > 0, plus impulses at 0)."""
        return terms_expr(list(self.terms), t) + self.impulses_expr(t)

    def impulses_expr(self, t: sp.Expr) -> sp.Expr:
        """The impulse part Σ c_j DiracDelta(t, j) alone."""
        return sp.Add(*(c * (sp.DiracDelta(t) if j == 0 else sp.DiracDelta(t, j))
                        for j, c in enumerate(self.impulses) if c != 0))


def _transform(terms: tuple[Term, ...], decomposition: PartialFractions) -> InverseTransform:
    """The InverseTransform of terms built from ``decomposition``, with its impulses."""
    to_sympy = decomposition.polynomial.domain.to_sympy
    impulses = tuple(to_sympy(c) for c in reversed(decomposition.polynomial.all_coeffs()))
    if decomposition.polynomial.is_zero:
        impulses = ()
    return InverseTransform(terms, impulses, decomposition)


def inverse_laplace_terms(F: sp.Expr | str, s: sp.Symbol, *, parameters: object = None) -> InverseTransform:
    """Structured real-form inverse Laplace transform of a rational F(s).

    See :func:`inverse_laplace` for the forms; this returns the terms instead of one
    expression.
    """
    F = transform_of(F, s, parameters)
    if split_delays(F, s) is not None:
        raise InversionError(f"{F} has delays or a periodic factor e^(-tau*{s}): its inverse is not "
                             "one set of terms; use inverse_laplace (an expression) or "
                             "delayed_inverse (the structured pieces)")
    decomposition = partial_fractions(F, s, closed_form=True, root_sums=True)
    terms = tuple(term for group in decomposition.groups for term in group_terms(group))
    return _transform(terms, decomposition)


def _step(t: sp.Expr, delay: sp.Expr) -> sp.Expr:
    """Heaviside(t - τ), or 1 for τ = 0 (no step clutter at the origin)."""
    return sp.S.One if delay == 0 else sp.Heaviside(t - delay)


@dataclass(frozen=True)
class DelayedPiece:
    """One delay class e^{-τs} R_τ(s) of a transform and its inverse g_τ.

    Attributes
    ----------
    delay : sympy.Expr
        τ ≥ 0.
    inverse : InverseTransform
        g_τ, the real-form inverse of R_τ (the piece contributes g_τ(t - τ) for t > τ).
    sums : tuple of Term
        For a periodic transform without compact support: φ_τ with
        φ_τ(x) - σφ_τ(x + P) = g_τ(x), so that
        Σ_{j=0}^{N} σ^j g_τ(v - jP) = σ^N φ_τ(w) - σφ_τ(v + P) with v = t - τ,
        N = floor(v/P), w = v - N P (σ = ±1, see :class:`DelayedInverse`). Empty otherwise.
    """

    delay: sp.Expr
    inverse: InverseTransform
    sums: tuple[Term, ...] = ()


@dataclass(frozen=True)
class DelayedInverse:
    """Structured inverse of F(s) = Σ_τ e^{-τs} R_τ(s) [/(1 - σe^{-Ps})], σ = ±1.

    f(t) = Σ_τ Σ_{j≥0} σ^j g_τ(t - τ - jP) H(t - τ - jP), in one of three forms chosen
    exactly:

    - no period: f(t) = Σ_τ g_τ(t - τ) H(t - τ) (+ impulses δ^{(j)}(t - τ));
    - ``compact``: one period's function g(x) = Σ_τ g_τ(x - τ) H(x - τ) vanishes for
      x ≥ P (a sawtooth, a rectified sine, 1 + e^{-s} + e^{-2s}), and
      f(t) = σ^N g(t mod P) with N = floor(t/P), t mod P = t - P N;
    - otherwise f(t) = Σ_τ σ^{N_τ} φ_τ(w_τ) H(t - τ) + Σ_i S_i(t) W_i(t): the periodic
      sums in the reduced times w_τ = (t - τ) mod P, plus the transient
      -σ Σ_τ φ_τ(t - τ + P) H(t - τ) collected over the windows W_i between consecutive
      delays; for t ≥ the last delay only :attr:`tail` remains.

    Attributes
    ----------
    pieces : tuple of DelayedPiece
        One per delay, in increasing order of delay where that is decidable.
    period : sympy.Expr or None
        P of the periodic factor 1 - σe^{-Ps}.
    sign : int
        σ: 1, or -1 for 1 + e^{-Ps} (the sums alternate; the steady state is then
        antiperiodic, f(t + P) = -f(t) up to its mean, with period 2P).
    compact : bool
        Whether f(t) = g(t mod P) (see above).
    windows : tuple
        The transient as triples (start, end, S_i): the real terms S_i(t) apply on
        [start, end) (end None: to infinity).
    conditions : tuple
        Where the inverse holds: symbolic delays of unknown sign taken as delays
        (``a >= 0``, :class:`~laplace_springs.model.switching.SwitchCondition`), and the
        genericity conditions of the partial fractions
        (:class:`~laplace_springs.exact.partial_fractions.GenericCondition`).
    """

    pieces: tuple[DelayedPiece, ...]
    period: sp.Expr | None
    sign: int = 1
    compact: bool = False
    windows: tuple[tuple[sp.Expr, sp.Expr | None, tuple[Term, ...]], ...] = ()
    conditions: tuple = ()

    def reduced_time(self, t: sp.Expr, delay: sp.Expr = sp.S.Zero) -> sp.Expr:
        """(t - τ) mod P = t - τ - P floor((t - τ)/P), in [0, P)."""
        assert self.period is not None
        v = t - delay
        return v - self.period * sp.floor(v / self.period)

    def _sign_factor(self, t: sp.Expr, delay: sp.Expr = sp.S.Zero) -> sp.Expr:
        """σ^N with N = floor((t - τ)/P): 1, or (-1)^N for a factor 1 + e^{-Ps}."""
        assert self.period is not None
        return sp.S.One if self.sign == 1 else sp.S.NegativeOne ** sp.floor((t - delay) / self.period)

    def _periodic_part(self, t: sp.Expr, steps: bool) -> sp.Expr:
        return sp.Add(*(self._sign_factor(t, piece.delay)
                        * terms_expr(list(piece.sums), self.reduced_time(t, piece.delay))
                        * (_step(t, piece.delay) if steps else 1) for piece in self.pieces))

    @property
    def tail(self) -> tuple[Term, ...]:
        """The transient's terms after the last delay (empty if compact or not periodic)."""
        return tuple(combine_terms(term for _, end, terms in self.windows if end is None
                                   for term in terms))

    def one_period(self, x: sp.Expr) -> sp.Expr:
        """g(x) = Σ_τ g_τ(x - τ) H(x - τ): the inverse of the numerator R alone."""
        return sp.Add(*(piece.inverse.as_expr(x - piece.delay) if piece.delay == 0 else
                        terms_expr(list(piece.inverse.terms), x - piece.delay) * _step(x, piece.delay)
                        + piece.inverse.impulses_expr(x - piece.delay)
                        for piece in self.pieces))

    def steady_state(self, t: sp.Expr) -> sp.Expr:
        """f(t) without the :meth:`transient`, for t ≥ the last delay (periodic transforms).

        The periodic sums in the reduced times, plus the tail terms that neither decay
        nor grow exponentially (α = 0): the mean value (the residue at s = 0, e.g. 1/2
        for a square wave between 0 and 1), undamped oscillations and resonant growth.
        It is P-periodic (2P-periodic for 1 + e^{-Ps}) when that part is constant.
        """
        if self.period is None:
            raise InversionError("a transform without a periodic factor has no periodic part")
        if self.compact:
            return self._compact_expr(t)
        return self._periodic_part(t, steps=False) + terms_expr(
            [term for term in self.tail if term.alpha == 0], t)

    def transient(self, t: sp.Expr) -> sp.Expr:
        """The tail terms with α ≠ 0, for t ≥ the last delay (periodic transforms only).

        They decay when every pole of R off the imaginary axis has a negative real part.
        """
        if self.period is None:
            raise InversionError("a transform without a periodic factor has no transient")
        return terms_expr([term for term in self.tail if term.alpha != 0], t)

    def _compact_expr(self, t: sp.Expr) -> sp.Expr:
        assert self.period is not None
        w = self.reduced_time(t)
        return self._sign_factor(t) * sp.Add(*(
            terms_expr(list(piece.inverse.terms), w - piece.delay) * _step(w, piece.delay)
            for piece in self.pieces if not (piece.delay - self.period).is_nonnegative))

    def as_expr(self, t: sp.Expr) -> sp.Expr:
        """f(t) for t > 0: exact, no ``I``, evaluates at any t without an infinite sum."""
        if self.period is None:
            return self.one_period(t)
        if self.compact:
            return self._compact_expr(t)
        by_step: dict[sp.Expr, list[sp.Expr]] = {}
        for piece in self.pieces:
            by_step.setdefault(piece.delay, []).append(
                self._sign_factor(t, piece.delay)
                * terms_expr(list(piece.sums), self.reduced_time(t, piece.delay)))
        for start, end, terms in self.windows:
            transient = terms_expr(list(terms), t)
            by_step.setdefault(start, []).append(transient)
            if end is not None:
                by_step.setdefault(end, []).append(-transient)
        return sp.Add(*(_step(t, delay) * sp.Add(*parts) for delay, parts in by_step.items()))


def _pieces(split: DelaySplit) -> list[DelayedPiece]:
    decompositions = decompose(list(split.numerators), split.denominator, closed_form=True)
    rows = solution_terms(decompositions)
    return [DelayedPiece(delay, _transform(terms, decomposition))
            for delay, terms, decomposition in zip(split.delays, rows, decompositions)]


def _is_compact(pieces: list[DelayedPiece], period: sp.Expr, ordered: bool) -> bool:
    """Whether g = Σ_τ g_τ(x - τ)H(x - τ) is proved to vanish for x ≥ P."""
    if not ordered:
        return False
    delays = [piece.delay for piece in pieces]
    for i in range(len(pieces)):
        if i + 1 < len(pieces):
            beyond = (delays[i + 1] - period).is_positive
            if beyond is None:
                return False
            if not beyond:
                continue
        partial = [term for piece in pieces[:i + 1]
                   for term in shift_terms(piece.inverse.terms, piece.delay)]
        if combine_terms(partial):
            return False
    return True


def _periodic(pieces: list[DelayedPiece], period: sp.Expr, sign: int,
              conditions: tuple = ()) -> DelayedInverse:
    if any(piece.inverse.impulses for piece in pieces):
        raise InversionError("a periodic transform with an impulse part (R(s) not proper) is a "
                             "train of impulses: not a function that evaluates at any t")
    ordered = order_delays([piece.delay for piece in pieces]) == list(range(len(pieces)))
    if _is_compact(pieces, period, ordered):
        return DelayedInverse(tuple(pieces), period, sign, compact=True, conditions=conditions)
    pieces = [DelayedPiece(piece.delay, piece.inverse, tuple(
        phi for term in piece.inverse.terms for phi in difference_solution(term, period, sign)))
        for piece in pieces]
    # transient -σ Σ_τ φ_τ(t - τ + P) H(t - τ), and -σ φ_τ(x + P) = g_τ(x) - φ_τ(x)
    shifted = [shift_terms([*piece.inverse.terms, *(Term(term.kind, term.power, term.alpha, term.beta,
                                                         -term.a, -term.b) for term in piece.sums)],
                           piece.delay) for piece in pieces]
    windows: list[tuple[sp.Expr, sp.Expr | None, tuple[Term, ...]]] = []
    if ordered:
        for i, piece in enumerate(pieces):
            end = pieces[i + 1].delay if i + 1 < len(pieces) else None
            terms = combine_terms(term for row in shifted[:i + 1] for term in row)
            if terms or end is None:
                windows.append((piece.delay, end, tuple(terms)))
    else:
        windows = [(piece.delay, None, tuple(combine_terms(row))) for piece, row in zip(pieces, shifted)]
    return DelayedInverse(tuple(pieces), period, sign, compact=False, windows=tuple(windows),
                          conditions=conditions)


def delayed_inverse(F: sp.Expr | str, s: sp.Symbol, *, parameters: object = None) -> DelayedInverse:
    """Structured inverse of a transform with delays e^{-τs} and/or a periodic factor.

    See :func:`inverse_laplace` for what is accepted; :class:`DelayedInverse` for the
    forms. A rational F gives one piece with delay 0.

    Examples
    --------
    >>> import sympy as sp
    >>> s, t = sp.symbols("s t")
    >>> sawtooth = delayed_inverse(1/s**2 - sp.exp(-s) / (s * (1 - sp.exp(-s))), s)
    >>> sawtooth.period, sawtooth.compact, sawtooth.as_expr(t)
    (1, True, t - floor(t))
    >>> drive = delayed_inverse(1 / (s * (s + 1) * (1 + sp.exp(-s))), s)   # a square wave's
    >>> drive.period, drive.sign, drive.compact                            # response
    (1, -1, False)
    >>> drive.steady_state(t)
    (-1)**floor(t)*(-exp(-t + floor(t))/(exp(-1) + 1) + 1/2) + 1/2
    >>> drive.transient(t)
    -exp(-t)/(1 + E)
    """
    F = transform_of(F, s, parameters)
    split = split_delays(F, s)
    if split is None:
        inverse = inverse_laplace_terms(F, s)
        return DelayedInverse((DelayedPiece(sp.S.Zero, inverse),), None, conditions=inverse.conditions)
    pieces = _pieces(split)
    conditions = split.conditions + denominator_conditions(split.denominator)
    if split.period is None:
        return DelayedInverse(tuple(pieces), None, conditions=conditions)
    return _periodic(pieces, split.period, split.sign, conditions)


def inverse_laplace(F: Any, s: sp.Symbol, t: sp.Symbol, *, parameters: object = None,
                    conditions: bool = False) -> Any:
    """Inverse Laplace transform in real form: rational, delayed and periodic transforms.

    For a rational F the result is a sum of terms t^k e^{αt}(a cos βt + b sin βt): complex-conjugate
    roots give damped cosines and sines, pairs of real quadratic surds α ± σ give
    e^{αt}(a cosh σt + b sinh σt), rational roots give exponentials (polynomials in t
    for roots at 0), and repeated roots give the powers t^k. It contains no ``I`` and no
    ``Heaviside``: it is the inverse for t > 0 (multiply by the unit step for all t).
    Exact input gives exact output: irreducible factors of degree ≤ 2 give radicals,
    those of degree ≥ 3 give exact algebraic numbers built on ``CRootOf`` (their
    ``re``/``im`` for complex roots), which evaluate to any precision.

    **Delays.** F(s) = Σ_τ e^{-τs} R_τ(s) with rational R_τ and exact τ ≥ 0 (numbers,
    or expressions in positive parameters) gives, by the shift theorem,
    Σ_τ g_τ(t - τ) Heaviside(t - τ) with g_τ the real-form inverse of R_τ (no step for
    τ = 0). Hyperbolic functions of s (``coth(pi*s/2)`` in the tables) are read as
    exponentials.

    **Periodic transforms.** R(s)/(1 - e^{-Ts}) and R(s)/(1 + e^{-Ts}), R possibly with
    delays (any denominator factor dividing 1 - e^{-Ps}, e.g. 1 + e^{-s} + e^{-2s}),
    give the exact sum Σ_j (±1)^j g(t - jT) in closed form, with no infinite sum: one
    period's formula in the reduced time t - T·floor(t/T) (and the sign (-1)^floor(t/T)
    for 1 + e^{-Ts}), plus the transient, a sum of the same real terms in t, which
    decays when every pole of R has a negative real part. When g vanishes after the
    period (a square wave, a sawtooth, a rectified sine) the result is just g at the
    reduced time. Poles resonating with the period (σ e^{pT} = 1: a pole at 0, or
    undamped frequencies that are multiples of 2π/T) give the true polynomial growth,
    through floor. With symbolic frequencies or periods the formula is the generic
    one: it assumes no such resonance. The structured form is :func:`delayed_inverse`.

    Parameters
    ----------
    F : sympy expression or str
        Rational function of ``s`` with rational, algebraic or symbolic coefficients,
        optionally with delays e^{-τs} and a periodic factor (see above). Floats are taken as their decimal value (0.2 is 1/5). Text such as
        ``"1/(s**2 + 2*s + 5)"`` is read by the safe parser (never evaluated) and may
        name ``s`` and the declared ``parameters`` only.
    s, t : sympy.Symbol
        Transform variable and time.
    parameters : sequence or mapping, optional
        Names text ``F`` may use as symbols (positive by default), e.g. ``["a"]``.
    conditions : bool, optional
        Also return where the inverse holds: a symbolic delay e^{-as} whose sign the
        assumptions do not decide (a plain or real Symbol) is a delay where a ≥ 0
        (:class:`~laplace_springs.model.switching.SwitchCondition`), and symbolic
        partial fractions need their genericity conditions (``a**2 - 4 != 0``).

    Returns
    -------
    sympy.Expr or sympy.Matrix, or (f, conditions) with ``conditions=True``
        f(t) for t > 0. An improper F (degree of numerator ≥ degree of denominator)
        also yields its impulse part Σ c_j DiracDelta(t, j), which vanishes for t > 0
        (DiracDelta(t - τ, j) for a delayed part). A Matrix is inverted entry by entry.

    Raises
    ------
    InversionError
        At once, before any residue is computed: F is not rational in s and e^{-τs}
        (e.g. sqrt(s), e^{-s²}), or has an irreducible factor of degree above
        :attr:`~laplace_springs.limits.Limits.max_exact_factor_degree` (24):
        the message names the degree. (A symbolic factor of degree ≥ 3 has no
        closed-form roots: without delays its part is a sum over its roots, a
        ``RootSum``; with delays or a period it is refused.) For exponentials: a time advance e^{+τs} (no
        causal inverse), a delay of unknown sign, a denominator factor mixing s and
        e^{-τs} such as s + e^{-s} (a delay equation), a factor that is not periodic
        (1 - 2e^{-s}) or is repeated ((1 - e^{-s})²), periodic factors in incommensurate
        periods, and a periodic impulse train (an improper R over 1 - e^{-Ts}).

    Notes
    -----
    Residues are computed exactly in the number field ℚ[x]/(q) of each irreducible
    factor q, never from approximate roots (see :mod:`laplace_springs.exact.partial_fractions`).

    Examples
    --------
    >>> import sympy as sp
    >>> s, t = sp.symbols("s t")
    >>> inverse_laplace(1 / (s**2 + 2*s + 5), s, t)
    exp(-t)*sin(2*t)/2
    >>> inverse_laplace(1 / (s**2 + 1)**2, s, t)
    -t*cos(t)/2 + sin(t)/2
    >>> inverse_laplace(1 / (s**2 - 2), s, t)
    sqrt(2)*sinh(sqrt(2)*t)/2
    >>> inverse_laplace((s + 3) / (s * (s + 1)), s, t)
    3 - 2*exp(-t)
    >>> inverse_laplace("1/(s**2 + a**2)", s, t, parameters=["a"])
    sin(a*t)/a
    >>> inverse_laplace(sp.exp(-2*s) / s, s, t)
    Heaviside(t - 2)
    >>> inverse_laplace((1 - sp.exp(-s)) / s**2, s, t)
    t + (1 - t)*Heaviside(t - 1)
    >>> inverse_laplace(1 / (s * (1 + sp.exp(-s))), s, t)     # square wave, period 2
    (-1)**floor(t)/2 + 1/2
    >>> inverse_laplace(1/s**2 - sp.exp(-s) / (s * (1 - sp.exp(-s))), s, t)   # sawtooth
    t - floor(t)
    >>> inverse_laplace(1 / ((s + 1) * (1 - sp.exp(-s))), s, t)
    exp(-t + floor(t))/(1 - exp(-1)) - exp(-t)/(-1 + E)
    >>> a = sp.Symbol("a")                      # a plain Symbol: the delay needs a >= 0
    >>> f, where = inverse_laplace(sp.exp(-a*s) / s, s, t, conditions=True)
    >>> f, [c.meaning for c in where]
    (Heaviside(-a + t), ['a >= 0 (the delay exp(-(a)*s))'])
    >>> inverse_laplace(sp.Matrix([1 / s, 1 / (s + 1)]), s, t)
    Matrix([
    [      1],
    [exp(-t)]])
    """
    if isinstance(F, sp.MatrixBase):
        return entrywise(F, lambda entry: inverse_laplace(entry, s, t, parameters=parameters,
                                                           conditions=True), conditions)
    F = transform_of(F, s, parameters)
    _refuse_unknowns(F, s)
    _refuse_multiplicity(F, s)
    if split_delays(F, s) is None:
        inverse = inverse_laplace_terms(F, s)
        return (inverse.as_expr(t), inverse.conditions) if conditions else inverse.as_expr(t)
    delayed = delayed_inverse(F, s)
    return (delayed.as_expr(t), delayed.conditions) if conditions else delayed.as_expr(t)


def _refuse_multiplicity(F: sp.Expr, s: sp.Symbol) -> None:
    """A LimitError for a factor (s − a)^k or q(s)^k of ``F`` with k beyond
    Limits.max_pole_multiplicity, read from F's product as given, before any work on it
    (``1/s**1000`` ran for minutes). An irreducible factor of high degree is refused by
    the partial fractions (Limits.max_exact_factor_degree)."""
    most = limits().max_pole_multiplicity
    for factor in sp.Mul.make_args(F):
        if isinstance(factor, sp.Pow) and factor.exp.is_Integer and factor.base.has(s) \
                and abs(int(factor.exp)) > most:
            power = abs(int(factor.exp))
            where = "denominator" if factor.exp < 0 else "numerator"
            raise LimitError(f"the transform has ({factor.base})**{power} in its {where}: a "
                             f"multiplicity {power}, above the limit {most} "
                             "(Limits.max_pole_multiplicity)")


def _refuse_unknowns(F: sp.Expr, s: sp.Symbol) -> None:
    """An InversionError naming an unknown transform or function of s in F."""
    unknown = F.atoms(AppliedUndef, sp.LaplaceTransform, sp.Derivative, sp.Integral, sp.Subs)
    inside = [u for u in unknown if u.has(s)]
    if inside:
        first = sorted(inside, key=sp.default_sort_key)[0]
        raise InversionError(f"{F} is not a rational function of {s} and exponentials "
                             f"e^(-tau*{s}): {first} is an unknown function of {s}, which is not inverted")
