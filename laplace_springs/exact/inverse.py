"""Inverse Laplace transform of rational functions in real form."""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from .partial_fractions import PartialFractions, partial_fractions, transform_of
from .real_terms import Term, group_terms, terms_expr

__all__ = ["InverseTransform", "inverse_laplace", "inverse_laplace_terms"]


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

    def as_expr(self, t: sp.Symbol) -> sp.Expr:
        """The inverse as an expression in ``t`` (valid for t > 0, plus impulses at 0)."""
        deltas = sp.Add(*(c * (sp.DiracDelta(t) if j == 0 else sp.DiracDelta(t, j))
                          for j, c in enumerate(self.impulses) if c != 0))
        return terms_expr(list(self.terms), t) + deltas


def inverse_laplace_terms(F: sp.Expr | str, s: sp.Symbol, *, parameters: object = None) -> InverseTransform:
    """Structured real-form inverse Laplace transform of a rational F(s).

    See :func:`inverse_laplace` for the forms; this returns the terms instead of one
    expression.
    """
    decomposition = partial_fractions(transform_of(F, s, parameters), s, closed_form=True)
    terms = tuple(term for group in decomposition.groups for term in group_terms(group))
    to_sympy = decomposition.polynomial.domain.to_sympy
    impulses = tuple(to_sympy(c) for c in reversed(decomposition.polynomial.all_coeffs()))
    if decomposition.polynomial.is_zero:
        impulses = ()
    return InverseTransform(terms, impulses, decomposition)


def inverse_laplace(F: sp.Expr | str, s: sp.Symbol, t: sp.Symbol, *, parameters: object = None) -> sp.Expr:
    """Inverse Laplace transform of a rational function, in real form.

    The result is a sum of terms t^k e^{αt}(a cos βt + b sin βt): complex-conjugate
    roots give damped cosines and sines, pairs of real quadratic surds α ± σ give
    e^{αt}(a cosh σt + b sinh σt), rational roots give exponentials (polynomials in t
    for roots at 0), and repeated roots give the powers t^k. It contains no ``I`` and no
    ``Heaviside``: it is the inverse for t > 0 (multiply by the unit step for all t).
    Exact input gives exact output: irreducible factors of degree ≤ 2 give radicals,
    those of degree ≥ 3 give exact algebraic numbers built on ``CRootOf`` (their
    ``re``/``im`` for complex roots), which evaluate to any precision.

    Parameters
    ----------
    F : sympy expression or str
        Rational function of ``s`` with rational, algebraic or symbolic coefficients.
        Floats are taken as their decimal value (0.2 is 1/5). Text such as
        ``"1/(s**2 + 2*s + 5)"`` is read by the safe parser (never evaluated) and may
        name ``s`` and the declared ``parameters`` only.
    s, t : sympy.Symbol
        Transform variable and time.
    parameters : sequence or mapping, optional
        Names text ``F`` may use as symbols (positive by default), e.g. ``["a"]``.

    Returns
    -------
    sympy.Expr
        f(t) for t > 0. An improper F (degree of numerator ≥ degree of denominator)
        also yields its impulse part Σ c_j DiracDelta(t, j), which vanishes for t > 0.

    Raises
    ------
    InversionError
        At once, before any residue is computed: F is not rational in s, or has an
        irreducible factor of degree ≥ 3 with symbolic coefficients (no closed-form
        roots; even quartics s⁴ + p s² + r excepted), or one of degree above
        :data:`~laplace_springs.exact.partial_fractions.MAX_EXACT_FACTOR_DEGREE` (24):
        the message names the degree.

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
    """
    return inverse_laplace_terms(F, s, parameters=parameters).as_expr(t)
