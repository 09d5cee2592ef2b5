"""The size of a forcing input, estimated before any expensive work is done on it.

A forcing input that passes the text limits of :mod:`laplace_springs.model.numbers` (or
a SymPy expression, which is held to none) may still expand into an enormous sum:
``(cos(t) + sin(2*t) + cos(3*t) + sin(5*t))**30`` is 60 characters and ten million
exponential terms, ``t**1000`` a polynomial no float64 evaluation can use. The transform
of :func:`laplace_springs.model.forcing.input_transform` expands its input into
*atoms* c · t^k · e^{zt} switched on at τ (a cosine or sine is two of them, a step two
alternatives), so the work and the size of the result follow the number of atoms.

:func:`forcing_size` bounds that number and the degree in t from the expression tree,
without expanding it, in time proportional to the tree's size:

* a number or anything free of t: 1 atom, degree 0; ``t``: 1 atom, degree 1;
* ``exp``: 1 atom; ``cos``, ``sin``, ``cosh``, ``sinh``, ``Heaviside``: 2; ``DiracDelta``: 1;
  one period of a periodic input: twice its atoms (the period's window);
* a sum: the sum of its terms' atoms, the largest degree;
* a product: the product of its factors' atoms, the sum of their degrees;
* a power b**n (|n| rounded down): b's atoms A give at most C(n + A - 1, A - 1) distinct
  products (the monomials of degree n in A atoms), degree n times b's;
* a product or power that holds a step: times k + 1 for its degree k (a delayed t^k
  splits into k + 1 powers of t − τ).

:func:`check_forcing_size` refuses an input whose bound exceeds
:attr:`~laplace_springs.limits.Limits.max_forcing_terms` or whose degree exceeds
:attr:`~laplace_springs.limits.Limits.max_forcing_degree` (the function arguments inside
it are held to the same limits), with a :class:`~laplace_springs.model.errors.LimitError`
naming the entry, the limit and the way out.

Examples
--------
>>> import sympy as sp
>>> from laplace_springs.model.symbols import TIME as t
>>> forcing_size(10 * sp.cos(20 * t) + sp.Heaviside(t - 1))
ForcingSize(terms=4, degree=0)
>>> forcing_size((sp.cos(t) + sp.sin(2 * t) + sp.cos(3 * t) + sp.sin(5 * t))**30).terms
10295472
>>> forcing_size((t + 1)**40)
ForcingSize(terms=41, degree=40)
"""

from __future__ import annotations

import math
from typing import NamedTuple

import sympy as sp

from ..limits import limits
from .errors import LimitError

__all__ = ["ForcingSize", "forcing_size", "check_forcing_size"]

#: Atoms counted at most (a bound beyond every limit): the counts saturate here.
_CAP = 2**62
#: Atoms per function of t: two exponentials for the waves, two alternatives for a step.
_ATOMS = {sp.exp: 1, sp.cos: 2, sp.sin: 2, sp.cosh: 2, sp.sinh: 2, sp.Heaviside: 2,
          sp.DiracDelta: 1}


class ForcingSize(NamedTuple):
    """A bound on the atoms an input expands into, and its degree in t."""

    terms: int
    degree: int


def _monomials(count: int, power: int) -> int:
    """C(power + count − 1, count − 1), the monomials of degree ``power`` in ``count``
    atoms, saturated at the cap (computed in logarithms when large)."""
    if count <= 1 or power == 0:
        return 1
    if count >= _CAP or power >= _CAP:
        return _CAP
    log = math.lgamma(power + count) - math.lgamma(power + 1) - math.lgamma(count)
    if log > math.log(_CAP):
        return _CAP
    return min(math.comb(power + count - 1, count - 1), _CAP)


def _exponent(value: sp.Expr) -> int | None:
    """|n| rounded down for a numeric exponent, else None."""
    if not value.is_number or value.is_extended_real is not True:
        return None
    try:
        return int(min(abs(float(value)), float(_CAP)))
    except (TypeError, ValueError, OverflowError):
        return None


class _Node(NamedTuple):
    size: ForcingSize
    time: bool  # holds t
    step: bool  # holds a step (a delayed power splits)


class _Estimate:
    """The walk behind :func:`forcing_size`, remembering shared subtrees and the largest
    size of a function argument."""

    def __init__(self, cap: int = _CAP) -> None:
        self.known: dict[sp.Basic, _Node] = {}
        self.arguments = ForcingSize(0, 0)
        self.cap = cap

    def size(self, root: sp.Basic) -> ForcingSize:
        """Post-order walk with an explicit stack (no recursion limit). A sum of more than
        ``cap`` terms is not walked: it has at least that many atoms."""
        stack: list[tuple[sp.Basic, bool]] = [(root, False)]
        while stack:
            node, expanded = stack.pop()
            if node in self.known:
                continue
            if not node.args:
                self.known[node] = _leaf(node)
                continue
            if isinstance(node, sp.Add) and len(node.args) > self.cap:
                self.known[node] = _Node(ForcingSize(len(node.args), 0), True, False)
                continue
            if expanded:
                self.known[node] = self._combine(node, [self.known[child] for child in node.args])
                continue
            stack.append((node, True))
            stack.extend((child, False) for child in node.args if child not in self.known)
        return self.known[root].size

    def _combine(self, node: sp.Basic, children: list[_Node]) -> _Node:
        time = any(child.time for child in children) or (
            isinstance(node, sp.Symbol) and node.name == "t")
        step = isinstance(node, sp.Heaviside) or any(child.step for child in children)
        if not time:
            return _Node(ForcingSize(1, 0), False, step)
        return _Node(self._sized(node, [child.size for child in children], step), True, step)

    def _sized(self, node: sp.Basic, sizes: list[ForcingSize], step: bool) -> ForcingSize:
        if isinstance(node, sp.Symbol):
            return ForcingSize(1, 1)
        if isinstance(node, sp.Add):
            return ForcingSize(min(sum(size.terms for size in sizes), _CAP),
                               max(size.degree for size in sizes))
        if isinstance(node, sp.Mul):
            terms, degree = 1, 0
            for size in sizes:
                terms, degree = min(terms * size.terms, _CAP), min(degree + size.degree, _CAP)
            return ForcingSize(min(terms * (degree + 1), _CAP) if step else terms, degree)
        if isinstance(node, sp.Pow):
            base, power = sizes[0], _exponent(node.exp)
            if power is None:
                return base
            terms, degree = _monomials(base.terms, power), min(base.degree * power, _CAP)
            return ForcingSize(min(terms * (degree + 1), _CAP) if step else terms, degree)
        if _is_periodic(node):
            return ForcingSize(min(2 * sizes[0].terms, _CAP), sizes[0].degree)
        for size in sizes:  # a function: its arguments are expanded on their own
            self.arguments = ForcingSize(max(self.arguments.terms, size.terms),
                                         max(self.arguments.degree, size.degree))
        return ForcingSize(_ATOMS.get(type(node), 1), 0)


_CONSTANT = _Node(ForcingSize(1, 0), False, False)
_TIME = _Node(ForcingSize(1, 1), True, False)


def _leaf(node: sp.Basic) -> _Node:
    return _TIME if isinstance(node, sp.Symbol) and node.name == "t" else _CONSTANT


def _is_periodic(node: sp.Basic) -> bool:
    return type(node).__name__ == "Periodic" and len(node.args) == 2


def forcing_size(expr: sp.Basic) -> ForcingSize:
    """A bound on the atoms ``expr`` expands into, and its degree in t (see the module notes).

    A Symbol named ``t`` (with any assumptions) is time. The bound is not below the atoms
    :func:`~laplace_springs.model.forcing.input_transform` forms, and the degree is the
    highest power of t after expansion (or more). Function arguments count on their own:
    see :func:`check_forcing_size`.

    Examples
    --------
    >>> from laplace_springs.model.symbols import TIME as t
    >>> forcing_size(t**1000 * sp.exp(-t))
    ForcingSize(terms=1, degree=1000)
    >>> forcing_size(sp.Add(*[sp.Heaviside(t - k) for k in range(10_000)])).terms
    20000
    """
    return _Estimate().size(expr)


def check_forcing_size(expr: sp.Basic, entry: str) -> ForcingSize:
    """The size of a forcing input, or a LimitError when it exceeds the limits.

    Parameters
    ----------
    expr : sympy.Basic
        The input (text already parsed, or a SymPy expression as given).
    entry : str
        What it is, for the message (``"forcing[0]"``).

    Raises
    ------
    LimitError
        When the input (or an argument of a function in it) may expand into more than
        :attr:`~laplace_springs.limits.Limits.max_forcing_terms` atoms, or has a degree in t
        above :attr:`~laplace_springs.limits.Limits.max_forcing_degree`.

    Examples
    --------
    >>> from laplace_springs.model.symbols import TIME as t
    >>> check_forcing_size(t**3 * sp.exp(-t), "forcing[0]")
    ForcingSize(terms=1, degree=3)
    >>> check_forcing_size(t**1000, "forcing[0]")
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.LimitError: forcing[0]: a polynomial in t of degree 1000 is above the limit 32 (Limits.max_forcing_degree): ...
    """
    walk = _Estimate(cap=limits().max_forcing_terms)
    size = walk.size(expr)
    terms, degree = max(size.terms, walk.arguments.terms), max(size.degree, walk.arguments.degree)
    if degree > limits().max_forcing_degree:
        raise LimitError(
            f"{entry}: a polynomial in t of degree {degree} is above the limit "
            f"{limits().max_forcing_degree} (Limits.max_forcing_degree): its exact response "
            "has powers of t that cancel in float64, and its solve grows with the degree; give "
            "the force as samples (ls.sampled) or a lower-degree fit")
    if terms > limits().max_forcing_terms:
        shown = "more than 10^18" if terms >= _CAP else f"{terms:,}"
        raise LimitError(
            f"{entry}: the input expands into an estimated {shown} terms c·t^k·e^(zt) (a cosine "
            f"or a step counts 2), above the limit {limits().max_forcing_terms:,} "
            "(Limits.max_forcing_terms); give it as samples (ls.sampled), as a periodic input "
            "(ls.periodic) or with fewer terms")
    return size
