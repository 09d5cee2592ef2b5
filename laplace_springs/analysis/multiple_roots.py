"""The multiple roots of Δ(λ) = det(λ²M + λC + K) for a scene with irrational entries.

:func:`laplace_springs.analysis.modes.modes` takes the modes of a scene with irrational
entries (√2, π) from float64 eigenpairs. A multiple eigenvalue (critical damping, equal
frequencies) comes out of them as a cluster of simple ones, split by rounding by up to
about u^(1/m) of its size (1.5e-8 for a double root: m = 1, k = 2, c = 2√2 gave λ =
−1.4142135(4 and 9)). The squarefree decomposition of Δ decides exactly which roots are
multiple, and with what multiplicity: over the algebraic field of the entries (SymPy's
``extension=True``: QQ<√2>, fast) or over a polynomial ring in one transcendental number
(ZZ[π]); other coefficient domains (√π beside π, √2·π) only over SymPy's EX, whose
squarefree split grows from 0.4 s at two coordinates to 80 s at six, so there up to
:data:`EX_MAX_COORDINATES` coordinates.
"""

from __future__ import annotations

import mpmath
import sympy as sp

from ..exact.partial_fractions import exact_factors
from ..kernels.precision import workdps
from ..numeric.mp_expr import numeric_value

__all__ = ["multiple_roots", "EX_MAX_COORDINATES"]

#: Largest scene whose multiple roots are sought over EX (1.1 s at 3 coordinates).
EX_MAX_COORDINATES = 3


def multiple_roots(determinant: sp.Poly, n: int) -> list[tuple[sp.Expr, int]] | None:
    """The nonzero roots of multiplicity ≥ 2 of a numeric Δ(λ), each real one and each
    complex one with Im λ > 0 with its multiplicity; None where no exact domain is cheap.

    A root of a quadratic (or linear) factor is exact (radicals); one of a higher factor
    a SymPy Float of 15 digits (mpmath's polyroots at 40 digits).

    Examples
    --------
    One mass, k = 2, c = 2√2: Δ = λ² + 2√2λ + 2 = (λ + √2)².

    >>> lam = sp.Symbol("lambda")
    >>> multiple_roots(sp.Poly(lam**2 + 2*sp.sqrt(2)*lam + 2, lam, domain="EX"), 1)
    [(-sqrt(2), 2)]
    """
    parts = _squarefree_parts(determinant, n)
    if parts is None:
        return None
    out: list[tuple[sp.Expr, int]] = []
    for part, multiplicity in parts:
        if multiplicity < 2 or part.degree() < 1:
            continue
        for factor, power in part.factor_list()[1]:
            for root in _upper_roots(factor):
                if root != 0:
                    out.append((root, multiplicity * power))
    return out


def _squarefree_parts(determinant: sp.Poly, n: int) -> list[tuple[sp.Poly, int]] | None:
    """Δ's squarefree parts with their multiplicities, in the cheapest exact domain."""
    expr = determinant.as_expr()
    gen = determinant.gen
    try:
        poly = sp.Poly(expr, gen, extension=True)
    except (sp.PolificationFailed, NotImplementedError, sp.CoercionFailed):
        poly = None
    if poly is not None and (poly.domain.is_QQ or poly.domain.is_ZZ or poly.domain.is_AlgebraicField):
        return list(poly.sqf_list()[1])
    poly = sp.Poly(expr, gen)
    domain = poly.domain
    if (domain.is_PolynomialRing or domain.is_FractionField) and len(domain.symbols) == 1 \
            and sp.sympify(domain.symbols[0]).is_transcendental:  # ZZ[pi]: pi is no unknown
        return list(poly.sqf_list()[1])
    if n <= EX_MAX_COORDINATES:
        return exact_factors(determinant)
    return None


def _upper_roots(factor: sp.Poly) -> list[sp.Expr]:
    """The roots of a factor with Im ≥ 0: exact up to degree 2, else 15-digit Floats."""
    if factor.degree() <= 2:
        found = sp.roots(factor, factor.gen)
        if sum(found.values()) == factor.degree():
            return [r for r in found if numeric_value(sp.im(r), 20) >= 0]
    with workdps(40):
        coeffs = []
        for c in factor.all_coeffs():
            re, im = numeric_value(c, 45).as_real_imag()
            coeffs.append(mpmath.mpc(mpmath.mpf(str(re)), mpmath.mpf(str(im))))
        values = mpmath.polyroots(coeffs, maxsteps=200, extraprec=200)
    out = []
    for value in values:
        z = complex(value)
        if abs(z.imag) <= 1e-25 * abs(z):  # a real root of a real factor
            out.append(sp.Float(z.real, 15))
        elif z.imag > 0:
            out.append(sp.Float(z.real, 15) + sp.I * sp.Float(z.imag, 15))
    return out
