"""Named algebraic numbers for large exact solutions: ρ_j, α_j, β_j, r_j and c_j.

A rational scene whose Δ(λ) has an irreducible factor q of degree d ≥ 3 has roots
that are algebraic numbers. Written out, each coefficient of x_i(t) is a polynomial of
degree d − 1 in re ρ and im ρ with rational coefficients of dozens of digits (a damped
chain of 12 unequal masses: d = 24, six million operations), and SymPy needs seconds
per factor just to number the roots of q the way ``CRootOf`` does. Above
:attr:`~laplace_springs.limits.Limits.exact_expanded_max_degree` the exact motion is
written instead in named numbers (:class:`~laplace_springs.exact.named.NamedNumber`):

- ρ_j, a complex root of Δ in the upper half-plane (slowest frequency first), α_j and
  β_j its real and imaginary parts (α_j is left out, being 0, for a root on the
  imaginary axis); r_j a real root;
- c_j, a coefficient of x_i(t): for a simple root 2·Re[N_i(ρ_j)/Δ'(ρ_j)] (the cosine)
  or −2·Im[N_i(ρ_j)/Δ'(ρ_j)] (the sine), N_i(ρ_j)/Δ'(ρ_j) for a real root, with Δ the
  seed's integer characteristic polynomial and X_i(λ) = N_i(λ)/Δ(λ).

Each number is exact: its definition in SymPy's ``CRootOf`` (the form the expanded
route writes) is built only when asked (``sol.substituted()``, ``.definition``). Its
value comes from python-flint: certified root enclosures (arb) refined to the precision
asked, and N_i(ρ)/Δ'(ρ) as the residue h(ρ), h computed exactly in ℚ[x]/(q)
(:func:`~laplace_springs.exact.rational.rational_partial_fractions`) and evaluated in
ball arithmetic, the working precision doubled until the ball is small relative to the
value (cancellation costs digits, never correctness).

Exact zeros are decided exactly: a residue that vanishes modulo q drops its terms; on
an even factor q(λ) = p(λ²) a root ρ = iβ (ρ² a negative root of p) has α = 0, and
Re h(iβ) = E(−β²), Im h(iβ) = β·O(−β²) (h(x) = E(x²) + x·O(x²)) vanish exactly when E
or O is 0 (p is irreducible).

Examples
--------
A damped chain of three unequal masses, Δ of degree 6 (irreducible):

>>> import sympy as sp
>>> from laplace_springs.model.scene import Scene
>>> from laplace_springs.exact.rational import rational_transform, rational_partial_fractions
>>> scene = Scene.from_matrices(M=sp.diag(1, 2, 3), C=sp.diag(1, 2, 4) / 10,
...     K=[[2, -1, 0], [-1, 2, -1], [0, -1, 2]], x0=[1, 0, 0], v0=[0, 0, 0])
>>> delta, (numerators,) = rational_transform(scene)
>>> spectrum = spectrum_of(delta)
>>> [root.name for root in spectrum.upper_names()]
['rho_1', 'rho_2', 'rho_3']
>>> _, groups = rational_partial_fractions(numerators, delta)
>>> builder = NamedTermsBuilder(spectrum, numerator_names=spectrum.numerator_names(numerators, delta))
>>> rows = builder.rows(groups, len(numerators))
>>> rows[0][0]
Term(kind='oscillatory', power=0, alpha=alpha_1, beta=beta_1, a=c_1, b=c_2)
>>> rows[0][0].a.display
2*re(N_1(rho_1)/Delta'(rho_1)) ≈ 0.0740320276569
>>> sp.N(rows[0][0].a, 20)
0.074032027656854203767
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import cached_property, lru_cache
from math import factorial
from typing import Any

import flint
import mpmath
import sympy as sp
from mpmath.libmp import from_man_exp

from ..kernels.precision import flint_workprec, workdps
from ..limits import limits
from ..model.errors import InversionError
from ..model.scene import Scene
from ..model.symbols import lam
from .isolation import isolation_work
from .named import NamedNumber, NamedQuantity, Shown, named, named_number
from .partial_fractions import PoleGroup, check_closed_form, isolation_obstacle
from .rational import (
    RationalGroup,
    from_poly,
    initial_vector,
    rational_partial_fractions,
    rational_pencil,
    to_poly,
)
from .real_terms import Term, _complex_parts, _upper_roots, group_terms, naming_scope

__all__ = ["FactorRoots", "Spectrum", "spectrum_of", "needs_algebraic_roots", "uses_named_roots",
           "NamedTermsBuilder", "named_rows", "free_rational"]

#: Bits of the first enclosure of the roots (flint raises it itself until they separate).
_BASE_BITS = 128
#: Digits of the values shown in the "where" lists (as the text and LaTeX outputs).
_SHOWN_DIGITS = 12
#: A value whose ball still holds 0 at this many bits is taken as 0 (an exact zero that
#: no structural test caught; its error is below 2^-_MAX_BITS of the terms summed).
_MAX_BITS = 1 << 14


def _mpf(x: flint.arb, prec: int) -> mpmath.mpf:
    """The midpoint of an arb as an mpmath number (exactly, then rounded to ``prec`` bits)."""
    man, exp = x.mid().man_exp()
    value = mpmath.mpf(0)
    value._mpf_ = from_man_exp(int(man), int(exp), prec, "n")
    return value


def _is_even(q: flint.fmpq_poly) -> bool:
    coeffs = q.coeffs()
    return all(c == 0 for c in coeffs[1::2])


def _even_part(q: flint.fmpq_poly) -> flint.fmpq_poly:
    """p with q(x) = p(x²) (q even)."""
    return flint.fmpq_poly(q.coeffs()[0::2])


def _split(h: flint.fmpq_poly) -> tuple[flint.fmpq_poly, flint.fmpq_poly]:
    """(E, O) with h(x) = E(x²) + x·O(x²)."""
    coeffs = h.coeffs()
    return flint.fmpq_poly(coeffs[0::2]), flint.fmpq_poly(coeffs[1::2])


def needs_algebraic_roots(q: flint.fmpq_poly) -> bool:
    """Whether the exact real terms of the irreducible factor q need ``CRootOf``: degree
    ≥ 3, except an even quartic whose roots are ±i√(−μ) with μ rational-quadratic (the
    expanded route writes those in radicals)."""
    if q.degree() < 3:
        return False
    if q.degree() == 4 and _is_even(q):
        with flint_workprec(_BASE_BITS):
            mus = _complex_roots(_even_part(q))
        return not all(mu.imag.is_zero() and mu.real < 0 for mu in mus)
    return True


def uses_named_roots(factors: Sequence[flint.fmpq_poly]) -> bool:
    """Whether a motion over these irreducible factors is written in named numbers: some
    factor needs algebraic roots and has degree above
    :attr:`~laplace_springs.limits.Limits.exact_expanded_max_degree`, or roots that SymPy
    numbers only after more work than
    :attr:`~laplace_springs.limits.Limits.exact_expanded_max_isolation`
    (:func:`~laplace_springs.exact.isolation.isolation_work`: entries of very different
    scales, such as masses of 1e-300 on springs of 1).

    >>> uses_named_roots([flint.fmpq_poly([1, 1, 0, 1])])           # x³ + x + 1
    False
    >>> tiny = flint.fmpq(1, 10**300)                               # masses of 1e-300
    >>> uses_named_roots([flint.fmpq_poly([2, tiny, tiny]) * flint.fmpq_poly([1, 0, tiny]) - 1])
    True
    """
    most = limits()
    return any(needs_algebraic_roots(q) and (
        q.degree() > most.exact_expanded_max_degree
        or isolation_work(q) > most.exact_expanded_max_isolation) for q in factors)


# ---------------------------------------------------------------------------
# certified roots of one factor
# ---------------------------------------------------------------------------
@lru_cache(maxsize=64)
def _enclosures(coeffs: tuple[tuple[int, int], ...], prec: int) -> tuple[flint.acb, ...]:
    """All roots of the (squarefree) polynomial at ``prec`` bits: real ones first
    (imaginary part exactly 0), then conjugate pairs."""
    poly = flint.fmpq_poly([flint.fmpq(p, q) for p, q in coeffs])
    with flint_workprec(prec):
        return tuple(_complex_roots(poly))


def _complex_roots(poly: flint.fmpq_poly) -> list[flint.acb]:
    """The roots of a squarefree polynomial at the working precision (flint's stubs type
    the (root, multiplicity) pairs as one acb)."""
    pairs: Any = poly.complex_roots()
    return [root for root, _ in pairs]


def _key(q: flint.fmpq_poly) -> tuple[tuple[int, int], ...]:
    return tuple((int(c.p), int(c.q)) for c in q.coeffs())


@dataclass(frozen=True, eq=False)
class FactorRoots:
    """The roots of one irreducible rational factor, in a fixed order.

    Attributes
    ----------
    factor : flint.fmpq_poly
        Monic q.
    real : tuple of flint.acb
        Enclosures of the real roots, ascending.
    upper : tuple of flint.acb
        Enclosures of the roots with positive imaginary part, by imaginary part
        (slowest frequency first), then real part.
    imaginary : tuple of bool
        Per upper root: exactly on the imaginary axis (q even, ρ² a negative root of p).
    """

    factor: flint.fmpq_poly
    real: tuple[flint.acb, ...]
    upper: tuple[flint.acb, ...]
    imaginary: tuple[bool, ...]
    #: Refined enclosures: bits → {(kind, j): acb}.
    _refined: dict[int, dict[tuple[str, int], flint.acb]] = field(default_factory=dict, repr=False)

    @classmethod
    def of(cls, q: flint.fmpq_poly) -> FactorRoots:
        """Isolate the roots of q (milliseconds: degree 24 takes 3 ms)."""
        roots = _enclosures(_key(q), _BASE_BITS)
        real = sorted((r for r in roots if r.imag.is_zero()), key=lambda r: float(r.real.mid()))
        upper = sorted((r for r in roots if r.imag > 0),
                       key=lambda r: (float(r.imag.mid()), float(r.real.mid())))
        imaginary = [False] * len(upper)
        if _is_even(q):
            for mu in _enclosures(_key(_even_part(q)), _BASE_BITS):
                if mu.imag.is_zero() and mu.real < 0:
                    beta = float((-mu.real).sqrt().mid())
                    nearest = min(range(len(upper)), key=lambda j: abs(complex(0, beta) - _complex(upper[j])))
                    imaginary[nearest] = True
        return cls(q, tuple(real), tuple(upper), tuple(imaginary))

    def refined(self, kind: str, j: int, prec: int) -> flint.acb:
        """Root ``j`` of ``kind`` ("real" or "upper") enclosed at ``prec`` bits or better.

        The roots are refined together, the precision rounded up to a multiple of
        :data:`_BASE_BITS`, and kept: a later call at a lower precision takes them."""
        base = (self.real if kind == "real" else self.upper)[j]
        if prec <= _BASE_BITS - 16:
            return base
        bits = -(-(prec + 16) // _BASE_BITS) * _BASE_BITS
        cache = self._refined
        found = min((b for b in cache if b >= bits), default=None)
        if found is None:
            roots = _enclosures(_key(self.factor), bits)
            cache[bits] = {(k, i): _nearest(roots, w)
                           for k, group in (("real", self.real), ("upper", self.upper))
                           for i, w in enumerate(group)}
            found = bits
        return cache[found][kind, j]


def _complex(z: flint.acb) -> complex:
    return complex(float(z.real.mid()), float(z.imag.mid()))


def _nearest(roots: Sequence[flint.acb], w: flint.acb) -> flint.acb:
    """The enclosure in ``roots`` of the root that ``w`` isolates (the one it overlaps:
    flint's enclosures isolate the roots), else the nearest."""
    overlapping = [z for z in roots if z.overlaps(w)]
    if len(overlapping) == 1:
        return overlapping[0]
    target = _complex(w)
    return min(roots, key=lambda z: abs(_complex(z) - target))


def _shown_number(x: float) -> str:
    return f"{x:.{_SHOWN_DIGITS}g}"


def _shown_complex(z: complex, digits: int) -> tuple[str, str]:
    """``a + b*I`` (text) and ``a + b\\,i`` (LaTeX) with ``digits`` significant digits."""
    re, im = f"{z.real:.{digits}g}", f"{abs(z.imag):.{digits}g}"
    sign = "-" if z.imag < 0 else "+"
    if z.real == 0:
        return f"{'-' if sign == '-' else ''}{im}*I", rf"{'-' if sign == '-' else ''}{im}\,i"
    return f"{re} {sign} {im}*I", rf"{re} {sign} {im}\,i"


# ---------------------------------------------------------------------------
# the spectrum of Δ: one name per root
# ---------------------------------------------------------------------------
@dataclass(eq=False)
class Spectrum:
    """Named roots of the factors of Δ(λ) that need algebraic roots.

    Build it with :func:`spectrum_of`. ``delta`` is Δ with integer coefficients and
    content 1 (the seed's form); the names are shared by every motion with this Δ (the
    coordinates, the g-basis), so one "where" list defines them once.
    """

    delta: flint.fmpq_poly
    factors: tuple[FactorRoots, ...]
    _names: dict = field(default_factory=dict)

    @cached_property
    def delta_name(self) -> NamedQuantity:
        """Δ(λ) as the named quantity ``Delta``."""
        expr = to_poly(self.delta, lam, domain=None).as_expr()
        return named("Delta", 0, expr, meaning="det(lambda**2*M + lambda*C + K), integer coefficients")

    def roots_of(self, q: flint.fmpq_poly) -> FactorRoots:
        """The named roots of factor q (monic)."""
        for roots in self.factors:
            if roots.factor == q:
                return roots
        raise KeyError(q)

    @cached_property
    def _order(self) -> dict[tuple[int, str, int], int]:
        """(factor index, kind, j) → the name's index: real roots ascending, then the
        upper roots by frequency, across factors."""
        real = sorted(((float(r.real.mid()), f, j) for f, roots in enumerate(self.factors)
                       for j, r in enumerate(roots.real)))
        upper = sorted(((float(z.imag.mid()), float(z.real.mid()), f, j)
                        for f, roots in enumerate(self.factors) for j, z in enumerate(roots.upper)))
        order = {(f, "real", j): k for k, (_, f, j) in enumerate(real, start=1)}
        order.update({(f, "upper", j): k for k, (_, _, f, j) in enumerate(upper, start=1)})
        return order

    def names(self, q: flint.fmpq_poly, kind: str, j: int) -> dict[str, sp.Expr]:
        """The named numbers of one root: {"r"} for a real root, {"rho", "alpha",
        "beta"} for an upper one ("alpha" is 0 on the imaginary axis)."""
        f = next(k for k, roots in enumerate(self.factors) if roots.factor == q)
        key = (f, kind, j)
        if key not in self._names:
            self._names[key] = _root_names(self, self.factors[f], kind, j, self._order[key])
        return self._names[key]

    def upper_names(self) -> list[NamedNumber]:
        """ρ_j of every upper root, in the order of their indices."""
        found = [self.names(roots.factor, "upper", j)["rho"]
                 for roots in self.factors for j in range(len(roots.upper))]
        return sorted(found, key=lambda q: q.index)

    def numerator_names(self, numerators: Sequence[flint.fmpq_poly],
                        determinant: flint.fmpq_poly) -> list[sp.Expr]:
        """N_i with X_i = N_i/Δ over the integer Δ (the numerators of the free motion,
        scaled as the seed's g-coefficients), as named quantities ``N_1``, ``N_2``, ..."""
        scale = self.delta.coeffs()[-1] / determinant.coeffs()[-1]
        out = []
        for i, N in enumerate(numerators, start=1):
            expr = to_poly(N * scale, lam, domain=None).as_expr()
            out.append(named("N", i, expr, meaning=f"numerator of X_{i}(lambda) = N_{i}/Delta")
                       if expr.free_symbols else expr)
        return out


def spectrum_of(delta: flint.fmpq_poly) -> Spectrum:
    """The named roots of Δ(λ) (any rational scaling): one :class:`Spectrum` per Δ."""
    _, factors = delta.factor()
    integer = flint.fmpq_poly([1])
    for f, m in factors:
        integer *= f ** m
    content = flint.fmpq(1) / integer.coeffs()[-1] if integer.coeffs()[-1] < 0 else flint.fmpq(1)
    return _spectrum(_key(integer * content))


@lru_cache(maxsize=32)
def _spectrum(key: tuple[tuple[int, int], ...]) -> Spectrum:
    delta = flint.fmpq_poly([flint.fmpq(p, q) for p, q in key])
    _, factors = delta.factor()
    monic = [f / f.coeffs()[-1] for f, _ in factors]
    chosen = sorted((q for q in monic if needs_algebraic_roots(q)), key=lambda q: (q.degree(), str(q)))
    return Spectrum(delta, tuple(FactorRoots.of(q) for q in chosen))


def _root_value(roots: FactorRoots, kind: str, j: int, part: str):
    """prec ↦ the value of re/im of root j (or the complex root: part "z")."""

    def value(prec: int):
        z = roots.refined(kind, j, prec)
        if part == "re":
            return _mpf(z.real, prec)
        if part == "im":
            return _mpf(z.imag, prec)
        return mpmath.mpc(_mpf(z.real, prec), _mpf(z.imag, prec))

    return value


@lru_cache(maxsize=64)
def _sympy_roots(key: tuple[tuple[int, int], ...]) -> tuple[list, list]:
    """The expanded route's exact roots of q: (real roots, (α, β) of the upper ones),
    with their values, in SymPy's numbering (SymPy isolates q: seconds at degree 24).
    An InversionError when that isolation is beyond Limits.max_exact_isolation."""
    q = to_poly(flint.fmpq_poly([flint.fmpq(p, d) for p, d in key]), lam)
    if (why := isolation_obstacle(q.all_coeffs())) is not None:
        raise InversionError(f"the definition of a named root in CRootOf: {why}")
    real, upper = _upper_roots(q)
    with workdps(30):
        upper_values = [complex(sp.N(alpha, 30)) + 1j * complex(sp.N(beta, 30))
                        for alpha, beta in upper]
    return real, list(zip(upper, upper_values))


def _root_definition(roots: FactorRoots, kind: str, j: int) -> tuple[sp.Expr, sp.Expr]:
    """(α, β) of upper root j (or (r, 0) of real root j) as the expanded route writes them."""
    real, upper = _sympy_roots(_key(roots.factor))
    if kind == "real":
        return real[j], sp.S.Zero
    target = _complex(roots.upper[j])
    (alpha, beta), _ = min(upper, key=lambda pair: abs(pair[1] - target))
    return (sp.S.Zero if roots.imaginary[j] else alpha), beta


def _root_names(spectrum: Spectrum, roots: FactorRoots, kind: str, j: int,
                index: int) -> dict[str, sp.Expr]:
    delta = spectrum.delta_name
    f = spectrum.factors.index(roots)
    if kind == "real":
        value = float(roots.real[j].real.mid())
        text = _shown_number(value)
        r = named_number("r", index, value=_root_value(roots, kind, j, "re"),
                         definition=lambda: _root_definition(roots, kind, j)[0],
                         display=Shown(f"root of #0 near {text}", rf"\text{{root of }} #0 \text{{ near }} {text}", delta),
                         sign=(1 if roots.real[j].real > 0 else -1 if roots.real[j].real < 0 else None),
                         meaning="real root", order=(1, f, index))
        return {"r": r}
    z = roots.upper[j]
    digits = max(_SHOWN_DIGITS, _separating_digits(roots, j))
    plain, tex = _shown_complex(complex(0.0, _complex(z).imag) if roots.imaginary[j] else _complex(z), digits)
    rho = named_number("rho", index, value=_root_value(roots, kind, j, "z"),
                       definition=lambda: _rho_definition(roots, j),
                       display=Shown(f"root of #0 near {plain}", rf"\text{{root of }} #0 \text{{ near }} {tex}", delta),
                       order=(2, index, 0), real=False)
    beta_value = float(z.imag.mid())
    beta = named_number("beta", index, value=_root_value(roots, kind, j, "im"),
                        definition=lambda: _root_definition(roots, kind, j)[1],
                        display=Shown(f"im(#0) ≈ {_shown_number(beta_value)}",
                                      rf"\operatorname{{Im}} #0 \approx {_shown_number(beta_value)}", rho),
                        sign=1, meaning="frequency", order=(2, index, 2))
    if roots.imaginary[j]:
        return {"rho": rho, "alpha": sp.S.Zero, "beta": beta}
    alpha_value = float(z.real.mid())
    alpha = named_number("alpha", index, value=_root_value(roots, kind, j, "re"),
                         definition=lambda: _root_definition(roots, kind, j)[0],
                         display=Shown(f"re(#0) ≈ {_shown_number(alpha_value)}",
                                       rf"\operatorname{{Re}} #0 \approx {_shown_number(alpha_value)}", rho),
                         sign=(-1 if z.real < 0 else 1 if z.real > 0 else None),
                         meaning="exponential rate", order=(2, index, 1))
    return {"rho": rho, "alpha": alpha, "beta": beta}


def _rho_definition(roots: FactorRoots, j: int) -> sp.Expr:
    alpha, beta = _root_definition(roots, "upper", j)
    return alpha + sp.I * beta


def _separating_digits(roots: FactorRoots, j: int) -> int:
    """Digits that tell upper root j from every other root of its factor."""
    z = _complex(roots.upper[j])
    others = [_complex(w) for w in roots.real + roots.upper] + [_complex(w).conjugate() for w in roots.upper]
    gaps = [abs(z - w) for w in others if w != z]
    gap = min(gaps, default=1.0)
    size = max(abs(z), 1e-300)
    return max(1, int(mpmath.ceil(mpmath.log10(size / gap))) + 3) if gap < size else 1


# ---------------------------------------------------------------------------
# coefficients and terms
# ---------------------------------------------------------------------------
class _Residue:
    """h(ρ) at one root of a factor, in ball arithmetic, kept at the highest working
    precision reached (the re and im coefficients of a term share it)."""

    def __init__(self, h: flint.fmpq_poly, roots: FactorRoots, kind: str, j: int) -> None:
        self.h, self.roots, self.kind, self.j = h, roots, kind, j
        self.values: dict[int, flint.acb] = {}

    def at(self, work: int) -> flint.acb:
        """h(ρ) evaluated with ``work`` bits (or a value computed with more)."""
        found = min((b for b in self.values if b >= work), default=None)
        if found is None:
            with flint_workprec(work):
                self.values[work] = flint.acb_poly(self.h)(self.roots.refined(self.kind, self.j, work))
            found = work
        return self.values[found]

    def part(self, part: str, scale: flint.fmpq):
        """prec ↦ scale·Re h(ρ) or scale·Im h(ρ), correct to ``prec`` bits (the working
        precision doubled until the ball is small relative to the value)."""

        def value(prec: int) -> mpmath.mpf:
            work = prec + 32
            while True:
                v = self.at(work)
                with flint_workprec(work):
                    x = (v.real if part == "re" else v.imag) * flint.arb(scale)
                if not x.contains(0) and x.rad() <= abs(x.mid()) * flint.arb(2) ** (-prec - 2):
                    return _mpf(x, prec)
                if work > _MAX_BITS:
                    return _mpf(x, prec) if not x.contains(0) else mpmath.mpf(0)
                work *= 2

        return value


def _sign(value) -> int | None:
    x = value(64)
    return None if x == 0 else (1 if x > 0 else -1)


@dataclass
class NamedTermsBuilder:
    """Builds the real terms of the groups of named-root factors, numbering c_1, c_2, ...

    Parameters
    ----------
    spectrum : Spectrum
        The named roots.
    numerator_names : sequence of sympy.Expr, optional
        How N_i is shown in the coefficients' definitions (``N_1``, ...); without them a
        coefficient shows its residue polynomial h(ρ).
    powers : sequence of int, optional
        For the g-basis: numerator i is λ^powers[i] (shown as ρ^k).
    """

    spectrum: Spectrum
    numerator_names: Sequence[sp.Expr] | None = None
    powers: Sequence[int] | None = None
    count: int = 0

    def rows(self, groups: Sequence[RationalGroup], n: int) -> list[list[Term]]:
        """Per numerator, the terms of ``groups`` (factors of the spectrum only)."""
        rows: list[list[Term]] = [[] for _ in range(n)]
        for i in range(n):
            for group in groups:
                rows[i] += self._terms(group, i)
        return rows

    def _terms(self, group: RationalGroup, i: int) -> list[Term]:
        roots = self.spectrum.roots_of(group.factor)
        out: list[Term] = []
        for k, h in enumerate(group.residues[i], start=1):
            if h == 0:  # the pole cancels
                continue
            for j in range(len(roots.real)):
                r = self.spectrum.names(roots.factor, "real", j)["r"]
                c = self._coefficient(_Residue(h, roots, "real", j), "re", k, group, i, r)
                out.append(Term("real", k - 1, r, sp.S.Zero, c, sp.S.Zero))
            for j in range(len(roots.upper)):
                names = self.spectrum.names(roots.factor, "upper", j)
                zero_re = zero_im = False
                if roots.imaginary[j]:  # h(iβ) = E(−β²) + iβ·O(−β²), p irreducible
                    p = _even_part(roots.factor)
                    even, odd = _split(h)
                    zero_re, zero_im = even % p == 0, odd % p == 0
                rho, residue = names["rho"], _Residue(h, roots, "upper", j)
                a = sp.S.Zero if zero_re else self._coefficient(residue, "re", k, group, i, rho)
                b = sp.S.Zero if zero_im else self._coefficient(residue, "im", k, group, i, rho)
                if a != 0 or b != 0:
                    out.append(Term("oscillatory", k - 1, names["alpha"], names["beta"], a, b))
        return out

    def _coefficient(self, residue: _Residue, part: str, k: int, group: RationalGroup, i: int,
                     root: sp.Expr) -> NamedNumber:
        """The named c of h at one root: h(r)/(k−1)! (real root), 2·Re h(ρ)/(k−1)! (part
        "re") or −2·Im h(ρ)/(k−1)! (part "im")."""
        h, roots, kind, j = residue.h, residue.roots, residue.kind, residue.j
        factor = flint.fmpq(1 if kind == "real" else 2 if part == "re" else -2, factorial(k - 1))
        value = residue.part(part, factor)
        self.count += 1
        with workdps(20):
            shown_value = _shown_number(float(value(64)))
        text, tex = self._shown(group, i, kind, part, factor)
        display = Shown(f"{text} ≈ {shown_value}", rf"{tex} \approx {shown_value}",
                        *self._arguments(h, i, root, group))

        def definition() -> sp.Expr:  # as the expanded route writes it
            alpha, beta = _root_definition(roots, kind, j)
            h_poly = to_poly(h, lam)
            if kind == "real":
                return (h_poly * sp.Rational(1, factorial(k - 1))).as_expr().xreplace({lam: alpha})
            x, y = _complex_parts(h_poly * sp.Rational(2, factorial(k - 1)), alpha, beta)
            return x if part == "re" else -y

        return named_number("c", self.count, value=value, definition=definition, display=display,
                            sign=_sign(value), order=(3, self.count))

    def _simple(self, group: RationalGroup) -> bool:
        return group.multiplicity == 1 and (self.numerator_names is not None or self.powers is not None)

    def _arguments(self, h: flint.fmpq_poly, i: int, root: sp.Expr, group: RationalGroup) -> tuple:
        if not self._simple(group):
            return (to_poly(h, lam).as_expr().xreplace({lam: root}),)
        top = self.numerator_names[i] if self.numerator_names is not None else sp.S.One
        return (top, root, self.spectrum.delta_name)

    def _shown(self, group: RationalGroup, i: int, kind: str, part: str,
               factor: flint.fmpq) -> tuple[str, str]:
        """The definition's text and LaTeX, the arguments written #0, #1, #2."""
        if not self._simple(group):
            quotient, tex = "#0", "#0"
        else:
            if self.powers is not None:
                power = self.powers[i]
                top = "1" if power == 0 else "#1" if power == 1 else f"#1**{power}"
                top_tex = "1" if power == 0 else "#1" if power == 1 else f"#1^{{{power}}}"
            else:
                assert self.numerator_names is not None
                named_top = isinstance(self.numerator_names[i], NamedQuantity)  # a constant N stays a number
                top, top_tex = ("#0(#1)", r"#0\left(#1\right)") if named_top else ("#0", "#0")
            quotient, tex = f"{top}/#2'(#1)", rf"\frac{{{top_tex}}}{{#2'\left(#1\right)}}"
        value = sp.Rational(int(factor.p), int(factor.q))
        prefix = "" if value == 1 else "-" if value == -1 else f"{value}*"
        prefix_tex = "" if value == 1 else "-" if value == -1 else sp.latex(value) + r"\,"
        if kind == "real":
            return f"{prefix}{quotient}" if not prefix else f"{prefix}({quotient})", prefix_tex + tex
        name = "re" if part == "re" else "im"
        return f"{prefix}{name}({quotient})", rf"{prefix_tex}\operatorname{{{name.capitalize()}}}\left({tex}\right)"


# ---------------------------------------------------------------------------
# a whole motion
# ---------------------------------------------------------------------------
def free_rational(scene: Scene) -> bool:
    """Whether the free motion of ``scene`` is built over ℚ: no forcing, rational M, C, K,
    x0 and v0, at most :attr:`~laplace_springs.limits.Limits.max_exact_coordinates`
    coordinates. Every factor of its Δ(λ) then has exact terms at any degree (named
    numbers above :attr:`~laplace_springs.limits.Limits.exact_expanded_max_degree`), so
    :attr:`~laplace_springs.limits.Limits.max_exact_factor_degree` does not apply.

    >>> free_rational(Scene.from_matrices(M=[[1]], K=[[4]], x0=[1], v0=[0]))
    True
    """
    if scene.is_forced or scene.n > limits().max_exact_coordinates:
        return False
    pencil = rational_pencil(scene)
    return pencil is not None and initial_vector(scene, pencil) is not None


def named_rows(numerators: Sequence[sp.Poly], denominator: sp.Poly, *,
               powers: Sequence[int] | None = None) -> tuple[tuple[Term, ...], ...] | None:
    """The real terms of every N_i/D, in named numbers where D has a factor above
    :attr:`~laplace_springs.limits.Limits.exact_expanded_max_degree` that needs algebraic
    roots; None when it has none (or a coefficient is not rational): the caller writes
    the terms out as before.

    Parameters
    ----------
    numerators : sequence of sympy.Poly
        N_i (the free motion's X_i = N_i/Δ), or λ^k for the g-basis (``powers``).
    denominator : sympy.Poly
        Δ(λ), any rational scaling.
    powers : sequence of int, optional
        For the g-basis: numerator i is λ^powers[i].

    Raises
    ------
    InversionError
        A factor written out (not named) without exact terms that does not cancel from
        every numerator (:func:`~laplace_springs.exact.partial_fractions.check_closed_form`).
    """
    delta = from_poly(denominator)
    found = [from_poly(N) for N in numerators]
    tops = [N for N in found if N is not None]
    if delta is None or delta.degree() < 1 or len(tops) < len(found):
        return None
    _, factors = delta.factor()
    monic = [(f / f.coeffs()[-1], m) for f, m in factors]
    if not uses_named_roots([q for q, _ in monic]):
        return None
    gen = denominator.gen
    spectrum = spectrum_of(delta)
    named_factors = {_key(roots.factor) for roots in spectrum.factors}
    check_closed_form([(to_poly(q, gen), m) for q, m in monic if _key(q) not in named_factors],
                      list(numerators))
    _, groups = rational_partial_fractions(tops, delta, monic)
    builder = NamedTermsBuilder(spectrum, powers=powers,
                                numerator_names=None if powers is not None
                                else spectrum.numerator_names(tops, delta))
    rows: list[list[Term]] = [[] for _ in tops]
    with naming_scope():
        for group in groups:
            if _key(group.factor) in named_factors:
                for i, terms in enumerate(builder.rows([group], len(tops))):
                    rows[i] += terms
                continue
            q = to_poly(group.factor, gen)
            for i, residues in enumerate(group.residues):
                pole = PoleGroup(q, group.multiplicity, tuple(to_poly(h, gen) for h in residues))
                if pole.order:
                    rows[i] += group_terms(pole)
    return tuple(tuple(row) for row in rows)
