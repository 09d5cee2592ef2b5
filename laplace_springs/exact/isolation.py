"""How much work SymPy's ``CRootOf`` needs to number the roots of a rational factor.

The written-out exact terms of an irreducible factor q of degree ≥ 3 are polynomials in
``re`` and ``im`` of ``CRootOf(q, i)``, and SymPy numbers those roots by isolating them:
it bisects a rectangle around all of them until each root off the real line has a box of
its own, clear of the real and imaginary axes and of the other boxes. Each bisection
costs polynomial arithmetic on the coefficients, so the work grows with

* k, the number of roots off the real line (real roots are isolated on the line, by
  continued fractions, and stay cheap); the boxes are refined root by root and pair by
  pair, and the measured cost grows about like k²;
* D = log₂(largest |root| / smallest feature), the bisections: a feature is a real or
  imaginary part of such a root, or its distance to another one (a root on the imaginary
  axis, of an even q, has no real part to separate);
* b, the bits of q's coefficients as a primitive integer polynomial.

:func:`isolation_work` returns k²·D·b. Measured on one core (SymPy 1.14, the quartics of a
pair of masses m on springs k, a dashpot c on the first, one process each): 2.1e4 took
0.26 s (m = 1, k = 1, c = 1e-10), 1.7e5 1.1 s (c = 1e-30), 6.5e5 3.3 s (c = 1e-60), 8.9e5
2.0 s (m = 1e-100, k = 1, c = 1: one pair off the line), 1.8e6 8.3 s (c = 1e-100) and 5.5
to 15 s (m = 1e100 or 1e-100 with c = m), 7.1e6 21 s, 8e6 18 s, 1.6e7 43 s, 97 s and more
than 300 s (m = 1e-300, k = 1, c = 1e-300): 1.5e-6 to 2e-5 s per unit, more for large
roots. Entries of ordinary scales stay far below: a pair of 2 g masses on springs of
2·10⁹ N/m with a dashpot of 0.35 N·s/m is 2e4 (0.2 s).

The roots come from python-flint (certified enclosures, milliseconds at any size), at a
precision raised until every feature is resolved.

Examples
--------
Two masses of 1 on springs of 1 (K = [[2, -1], [-1, 1]]) with a dashpot of ε on the
first: Δ(λ) = λ⁴ + ελ³ + 3λ² + ελ + 1 has four roots of size about 1 whose real parts
are about ε/10:

>>> import flint
>>> def pair(eps):
...     return flint.fmpq_poly([1, eps, 3, eps, 1])
>>> round(isolation_work(pair(flint.fmpq(1, 10))))                # ε = 0.1
550
>>> isolation_size(pair(flint.fmpq(1, 10**30)))                   # ε = 1e-30
IsolationSize(off_line=4, bisections=103.2..., bits=102, largest='1.62', smallest='1.38e-31')
>>> isolation_work(pair(flint.fmpq(0)))                           # undamped: roots ±iω
0.0
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import flint

from ..kernels.precision import flint_workprec

__all__ = ["isolation_work", "IsolationSize", "isolation_size"]

#: The first precision (bits) of the enclosures, doubled until the features separate.
_FIRST_BITS = 64
#: Beyond this precision a feature still unresolved counts as 2^-_MAX_BITS of the scale.
_MAX_BITS = 1 << 14


@dataclass(frozen=True)
class IsolationSize:
    """What :func:`isolation_work` multiplies: ``off_line`` roots off the real line (k),
    ``bisections`` (D) and ``bits`` (b); ``largest`` and ``smallest`` (3 digits) are the
    largest |root| and the smallest feature whose ratio gives D."""

    off_line: int
    bisections: float
    bits: int
    largest: str = "0"
    smallest: str = "0"

    @property
    def work(self) -> float:
        """k²·D·b."""
        return self.off_line**2 * self.bisections * self.bits


def isolation_work(q: flint.fmpq_poly) -> float:
    """k²·D·b for the rational polynomial ``q`` (see the module notes): the largest of its
    irreducible factors'; 0 when every root is real or on the imaginary axis."""
    return isolation_size(q).work


def isolation_size(q: flint.fmpq_poly) -> IsolationSize:
    """The factors of :func:`isolation_work`, with the sizes behind D (see the module
    notes).

    A pair of masses of 1e-300 on springs of 1 with a dashpot of 1e-300 (frequencies of
    about 1e150, decay rates of about 0.1):

    >>> import flint
    >>> tiny = flint.fmpq(1, 10**300)
    >>> isolation_size(flint.fmpq_poly([2, tiny, tiny]) * flint.fmpq_poly([1, 0, tiny]) - 1)
    IsolationSize(off_line=4, bisections=501.8..., bits=1994, largest='1.62e+150', smallest='0.138')
    """
    if q.degree() < 1:
        return IsolationSize(0, 0.0, 0)
    _, factors = q.factor()
    return max((_irreducible_size(f) for f, _ in factors), key=lambda size: size.work)


def _irreducible_size(q: flint.fmpq_poly) -> IsolationSize:
    """:func:`isolation_size` of an irreducible q."""
    bits = _bits(q)
    on_axis = _roots_on_imaginary_axis(q)
    prec = _FIRST_BITS
    while True:
        with flint_workprec(prec):
            roots = _roots(q)
            found = _features(roots, on_axis)
        if found is not None or prec >= _MAX_BITS:
            break
        prec *= 2
    off_line = sum(1 for r in roots if not r.imag.is_zero())
    largest = _shown(max((abs(r) for r in roots), key=lambda size: size.mid()))
    if off_line in (0, on_axis):
        return IsolationSize(0, 0.0, bits, largest)
    if found is None:  # a feature below 2^-_MAX_BITS of the scale
        return IsolationSize(off_line, float(_MAX_BITS), bits, largest)
    smallest, bisections = found
    return IsolationSize(off_line, bisections, bits, largest, _shown(smallest))


def _bits(q: flint.fmpq_poly) -> int:
    """The bits of the largest coefficient of q as a primitive integer polynomial."""
    integer = q.numer()
    coeffs = [int(c) for c in integer.coeffs()]
    content = math.gcd(*coeffs) or 1
    return max((abs(c) // content).bit_length() for c in coeffs)


def _roots(q: flint.fmpq_poly) -> list[Any]:
    """The roots of q at the working precision (flint's stubs type the pairs as one acb)."""
    pairs: Any = q.complex_roots()
    return [root for root, _ in pairs]


def _roots_on_imaginary_axis(q: flint.fmpq_poly) -> int:
    """How many roots of q lie on the imaginary axis: for an even q(x) = p(x²), two per
    negative real root of p (flint gives real roots an exactly zero imaginary part);
    none for an irreducible q that is not even (its roots ±iβ would make q(x) and q(−x)
    share a factor; x itself has its root on the real line)."""
    coeffs = q.coeffs()
    if any(c != 0 for c in coeffs[1::2]):
        return 0
    p = flint.fmpq_poly(coeffs[0::2])
    with flint_workprec(_FIRST_BITS):
        mus = _roots(p)
    return 2 * sum(1 for mu in mus if mu.imag.is_zero() and mu.real < 0)


def _shown(size: Any) -> str:
    """An arb's midpoint with 3 digits (it may lie beyond float64's range)."""
    return str(size.mid().str(3, radius=False))


def _features(roots: list[Any], on_axis: int) -> tuple[Any, float] | None:
    """(smallest feature, log₂(largest |root| / smallest feature)) of the roots off the
    real line, or None while an enclosure still holds 0 where it must not."""
    off = [r for r in roots if not r.imag.is_zero()]
    if not off:
        return flint.arb(1), 0.0
    sizes: list[Any] = []
    straddling = 0
    for i, r in enumerate(off):
        if r.imag.contains(0):
            return None
        sizes.append(abs(r.imag))
        if r.real.contains(0):
            straddling += 1
        else:
            sizes.append(abs(r.real))
        for other in off[i + 1:]:
            gap = abs(r - other)
            if gap.contains(0):
                return None
            sizes.append(gap)
    if straddling != on_axis:  # a real part not yet resolved
        return None
    largest = max((abs(r) for r in roots), key=lambda size: size.mid())
    smallest = min(sizes, key=lambda size: size.mid())
    return smallest, max(0.0, float((largest / smallest).log().mid()) / math.log(2))
