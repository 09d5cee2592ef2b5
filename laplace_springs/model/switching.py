"""Switching times of steps and impulses, exact or symbolic, and where a transform holds.

An input ``Heaviside(c t + d)`` switches at τ = -d/c and ``DiracDelta(c t + d)`` acts at
τ. With numbers, τ's sign decides at once how the input looks for t > 0. With a symbol
it may not: ``Heaviside(t - a)`` is a step at a when a ≥ 0, but 1 for all t > 0 when
a < 0. The transforms take the symbolic switching time as a delay (e^{-as}) and state
the condition under which that holds, a :class:`SwitchCondition` (``a >= 0``), unless the
assumptions of the symbols decide it (a positive parameter needs no condition).

A plain SymPy ``Symbol`` (no assumptions) is a complex number: ``Heaviside(t - a)`` then
needs a real, and the condition ``a >= 0`` says so (it holds only for real a).

Examples
--------
>>> import sympy as sp
>>> from laplace_springs.model.symbols import TIME as t
>>> a = sp.Symbol("a")
>>> [c.meaning for c in switch_conditions(sp.Heaviside(t - a))]
['a >= 0 (the switching time of Heaviside(-a + t))']
>>> switch_conditions(sp.Heaviside(t - sp.Symbol("b", positive=True)))
()
>>> [c.meaning for c in switch_conditions(sp.DiracDelta(a * t))]
['a != 0 and a is real (the scale of DiracDelta(a*t))']
>>> sorted_delays([sp.Integer(3), sp.S.Zero, sp.Rational(1, 2)])
[0, 1/2, 3]
"""

from __future__ import annotations

import functools
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import sympy as sp

from .symbols import TIME

__all__ = ["SwitchCondition", "switch_conditions", "switching_time", "sorted_delays",
           "latest_delay", "UndecidableOrder"]

_RELATIONS = {">=": sp.Ge, ">": sp.Gt, "!=": sp.Ne}
_LATEX = {">=": r"\geq", ">": ">", "!=": r"\neq"}


@dataclass(frozen=True)
class SwitchCondition:
    """Where a transform with a symbolic switching time or scale holds.

    Attributes
    ----------
    expr : sympy.Expr
        The quantity in the parameters: a switching time τ, a period, or a scale c.
    relation : str
        ``">="`` (τ ≥ 0, a step or impulse at τ), ``">"`` (a period T > 0) or ``"!="``
        (a scale c ≠ 0, c real: ``DiracDelta(c t)`` is δ(t)/|c|).
    source : str
        What the quantity belongs to, for the reader.

    The same small interface as the other conditions of the package (``meaning``,
    ``latex()``, ``expr``, ``as_relational()``, ``holds_at(values)``).
    """

    expr: sp.Expr
    relation: str
    source: str

    @property
    def meaning(self) -> str:
        """The condition in words, e.g. ``a >= 0 (the switching time of Heaviside(t - a))``."""
        real = f" and {self.expr} is real" if self.relation == "!=" else ""
        return f"{self.expr} {self.relation} 0{real} ({self.source})"

    def latex(self) -> str:
        """The condition in LaTeX, e.g. ``a \\geq 0``."""
        return rf"{sp.latex(self.expr)} {_LATEX[self.relation]} 0"

    def as_relational(self) -> sp.Basic:
        """The relation as a SymPy Relational, e.g. ``a >= 0``."""
        return _RELATIONS[self.relation](self.expr, 0)

    def holds_at(self, values: dict) -> bool:
        """Whether the condition holds at numbers for the parameters.

        Examples
        --------
        >>> a = sp.Symbol("a")
        >>> condition = SwitchCondition(a, ">=", "the switching time of Heaviside(t - a)")
        >>> condition.holds_at({a: 2}), condition.holds_at({a: -1}), condition.holds_at({a: sp.I})
        (True, False, False)
        """
        by_name = {symbol.name: symbol for symbol in self.expr.free_symbols}
        value = self.expr.xreplace({by_name.get(k, k) if isinstance(k, str) else k: sp.sympify(v)
                                    for k, v in values.items()})
        if value.is_extended_real is not True:
            return False
        if self.relation == "!=":
            return bool(value.is_zero is False)
        truth = _RELATIONS[self.relation](value, 0)
        return bool(truth) if truth in (sp.true, sp.false) else False


def switching_time(argument: sp.Expr, t: sp.Symbol = TIME) -> tuple[sp.Expr, sp.Expr, sp.Expr] | None:
    """(c, d, τ) for an argument c t + d linear in t with c ≠ 0, else None.

    Examples
    --------
    >>> a = sp.Symbol("a")
    >>> switching_time(2 * TIME - 2 * sp.exp(a))
    (2, -2*exp(a), exp(a))
    >>> switching_time(TIME**2 - 1) is None
    True
    """
    argument = sp.expand(argument)
    if argument.is_polynomial(t) is not True:
        return None
    poly = sp.Poly(argument, t)
    if poly.degree() != 1:
        return None
    c, d = poly.coeff_monomial(t), poly.coeff_monomial(1)
    return c, d, sp.expand(-d / c)


def _step_condition(atom: sp.Expr) -> list[SwitchCondition]:
    found = switching_time(atom.args[0])
    if found is None:
        return []
    c, _, tau = found
    out = []
    if isinstance(atom, sp.DiracDelta) and c.is_extended_real is not True:
        out.append(SwitchCondition(c, "!=", f"the scale of {atom}"))
    if tau.is_nonnegative is None and tau.is_negative is None:
        kind = "time of the impulse" if isinstance(atom, sp.DiracDelta) else "switching time"
        out.append(SwitchCondition(tau, ">=", f"the {kind} of {atom}"))
    return out


def switch_conditions(f: sp.Expr, t: sp.Symbol = TIME) -> tuple[SwitchCondition, ...]:
    """The conditions under which the symbolic switching times of f are delays.

    One :class:`SwitchCondition` per step or impulse whose time τ has no known sign
    (τ ≥ 0), and per impulse ``DiracDelta(c t + d)`` whose scale c is not known to be real;
    none for numbers or parameters declared positive, nonnegative or negative.
    """
    found: dict[tuple, SwitchCondition] = {}
    for atom in sorted(f.atoms(sp.Heaviside, sp.DiracDelta), key=sp.default_sort_key):
        if atom.args[0].has(t):
            for condition in _step_condition(atom):
                found.setdefault((condition.expr, condition.relation), condition)
    return tuple(found.values())


class UndecidableOrder(ValueError):
    """Two symbolic times whose order the assumptions do not decide."""

    def __init__(self, first: sp.Expr, second: sp.Expr) -> None:
        super().__init__(f"cannot tell which of {first} and {second} comes first")
        self.first, self.second = first, second


def _compare(first: sp.Expr, second: sp.Expr) -> int:
    if first.is_number and second.is_number:
        difference = float(first - second) if first != second else 0.0
        return (difference > 0) - (difference < 0)
    difference = sp.expand(first - second)
    if difference == 0:
        return 0
    if difference.is_positive:
        return 1
    if difference.is_negative:
        return -1
    raise UndecidableOrder(first, second)


def sorted_delays(delays: Iterable[sp.Expr], *, strict: bool = False) -> list[sp.Expr]:
    """Delays in increasing order; symbolic ones by their assumptions.

    Numbers sort by value. When the assumptions do not decide an order (a and b without
    assumptions), the order is SymPy's canonical one, or :class:`UndecidableOrder` with
    ``strict``.
    """
    items = list(delays)
    try:
        return sorted(items, key=functools.cmp_to_key(_compare))
    except UndecidableOrder:
        if strict:
            raise
        numbers = sorted((d for d in items if d.is_number), key=functools.cmp_to_key(_compare))
        return numbers + sorted((d for d in items if not d.is_number), key=sp.default_sort_key)


def latest_delay(delays: Sequence[sp.Expr]) -> sp.Expr:
    """The latest of several switching times (0 for none); :class:`UndecidableOrder` when
    the assumptions cannot tell."""
    if not delays:
        return sp.S.Zero
    return sorted_delays(delays, strict=True)[-1]
