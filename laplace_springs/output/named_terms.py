"""The named structure of a closed form, shared by the LaTeX and the plain-text output.

A closed form x(t) of a numeric scene with a quartic (or higher) factor of Δ(λ) is a sum
of damped waves whose rates, frequencies and coefficients are algebraic numbers:
written out they are ``re(CRootOf(...))`` and fractions of 30 digits. Both outputs
(:mod:`laplace_springs.output.latex` and :mod:`laplace_springs.output.text`) show
instead the same named structure, built here once:

- a real root of a factor is r_j; a complex one α_j + iβ_j, so that
  (λ − α_j)² + β_j² is a factor of P(λ) (α_j is the exponential rate, β_j the
  frequency);
- a time-independent coefficient built on them is c_j, defined as a polynomial in
  the α_j, β_j, r_j with rational coefficients;
- named quantities of symbolic scenes (ω_j, γ_j, ... of :mod:`laplace_springs.exact.named`)
  that share a printed name but differ are re-indexed;
- θ(t) (a step at t = 0) is dropped, since the solution holds for t ≥ 0.

Each output prints the names and their "where" list in its own notation.

Examples
--------
>>> import laplace_springs as ls
>>> terms = NamedTerms()
>>> (x1, x2) = terms.prepare(ls.solve(ls.load_scene("three-dashpots"), method="exact").x)
>>> x1
(c_1*cos(beta_1*t) + c_2*sin(beta_1*t))*exp(alpha_1*t) + (c_3*cos(beta_2*t) + c_4*sin(beta_2*t))*exp(alpha_2*t)
>>> [names for names in terms.constants.roots.values()]
[(alpha_1, beta_1), (alpha_2, beta_2)]
>>> len(terms.constants.coefficients)
8
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import sympy as sp

from ..exact.named import definitions, named, named_quantities
from ..model.symbols import TIME
from ..numeric.mp_expr import numeric_value

__all__ = ["NamedConstants", "NamedTerms", "reading_order", "is_step_at_zero"]


def _argument_key(arg: sp.Expr) -> tuple:
    at_one = arg.subs(TIME, 1)
    if at_one.is_number:
        value = complex(sp.N(at_one))
        return (0, abs(value.real), abs(value.imag), "")
    return (1, 0.0, 0.0, sp.sstr(arg))


def reading_order(term: sp.Expr) -> tuple:
    """Sort key: terms of one mode together, slowest first, cos before sin, in rising powers of t."""
    waves = sorted(_argument_key(f.args[0]) for f in term.atoms(sp.cos, sp.sin, sp.cosh, sp.sinh))
    rates = sorted(_argument_key(f.args[0]) for f in term.atoms(sp.exp))
    kind = 0 if term.has(sp.cos, sp.cosh) else 1
    power = sp.degree(term, TIME) if (waves or rates) and term.is_polynomial(TIME) else 0
    return (tuple(waves), tuple(rates), kind, power)


def is_step_at_zero(expr: sp.Basic) -> bool:
    """θ(t): the solution holds for t ≥ 0, where it is 1."""
    return isinstance(expr, sp.Heaviside) and expr.args[0] == TIME


def _root_order(root: sp.CRootOf) -> tuple:
    value = complex(numeric_value(root, 20))
    return (value.imag != 0, abs(value.imag), value.real, str(root.poly.as_expr()))


def _is_bare_root_part(expr: sp.Expr) -> bool:
    """re(r), im(r), r itself or a rational multiple: shown through the root's names."""
    core = expr.as_coeff_Mul()[1]
    return isinstance(core, (sp.re, sp.im, sp.CRootOf))


@dataclass
class NamedConstants:
    """Names for algebraic numbers (α_j, β_j, r_j) and for coefficients built on them.

    Attributes
    ----------
    roots : dict
        CRootOf → (r_j,) for a real root, (α_j, β_j) for a complex one; in order of
        registration (real roots first, then by frequency).
    coefficients : dict
        Coefficient (an expression in CRootOf objects) → its name c_j.
    values : dict
        Name → the exact number it stands for.
    reserved : set of str
        Names no constant may take: the parameters of the expressions (a parameter c_1 of
        the initial data is not the coefficient c_1), see :meth:`reserve`.
    """

    roots: dict[sp.Expr, tuple[sp.Symbol, ...]] = field(default_factory=dict)
    coefficients: dict[sp.Expr, sp.Symbol] = field(default_factory=dict)
    values: dict[sp.Symbol, sp.Expr] = field(default_factory=dict)
    reserved: set[str] = field(default_factory=set)
    counts: dict[str, int] = field(default_factory=dict)

    def reserve(self, exprs: Sequence[sp.Expr]) -> None:
        """Keep the names of the symbols in ``exprs`` (parameters) away from the constants."""
        self.reserved.update(symbol.name for e in exprs for symbol in e.free_symbols)

    def _index(self, kind: str, *bases: str) -> int:
        """The next index of ``kind`` whose names ``base_index`` are all free."""
        index = self.counts.get(kind, 0) + 1
        while any(f"{base}_{index}" in self.reserved for base in bases):
            index += 1
        self.counts[kind] = index
        return index

    def register_roots(self, exprs: Sequence[sp.Expr]) -> None:
        """Name every CRootOf in ``exprs`` not named yet."""
        found: set[sp.CRootOf] = set().union(*(e.atoms(sp.CRootOf) for e in exprs))
        for root in sorted(found - set(self.roots), key=_root_order):
            count = self._index("root", "r", "alpha", "beta")
            names: tuple[sp.Symbol, ...]
            if bool(root.is_real):
                names = (sp.Symbol(f"r_{count}", real=True),)
                self.values[names[0]] = root
            else:
                names = (sp.Symbol(f"alpha_{count}", real=True), sp.Symbol(f"beta_{count}", real=True))
                self.values[names[0]], self.values[names[1]] = sp.re(root), sp.im(root)
            self.roots[root] = names

    def root_map(self) -> dict:
        """CRootOf, re(·) and im(·) of it → its names (α_j + iβ_j for the root itself)."""
        out = {}
        for root, names in self.roots.items():
            if len(names) == 1:
                out[root] = names[0]
            else:
                out[sp.re(root)], out[sp.im(root)] = names
                out[root] = names[0] + sp.I * names[1]
        return out

    def replace(self, expr: sp.Expr) -> sp.Expr:
        """``expr`` with coefficients on algebraic numbers named, roots replaced by names."""
        expr = sp.sympify(expr, strict=True)
        if not expr.has(sp.CRootOf):
            return expr
        return self._name_coefficients(expr).xreplace(self.root_map())

    def definition(self, name: sp.Symbol) -> sp.Expr:
        """A coefficient's exact value in terms of the root names (α_j, β_j, r_j)."""
        for expr, symbol in self.coefficients.items():
            if symbol == name:
                return expr.xreplace(self.root_map())
        raise KeyError(name)

    def _name_coefficients(self, expr: sp.Expr) -> sp.Expr:
        if not expr.has(sp.CRootOf):
            return expr
        if isinstance(expr, sp.Add):
            return sp.Add(*(self._name_coefficients(a) for a in sorted(expr.args, key=reading_order)))
        if isinstance(expr, sp.Mul):
            timed = [a for a in expr.args if a.has(TIME)]
            constant = sp.Mul(*(a for a in expr.args if not a.has(TIME)))
            return self._constant(constant) * sp.Mul(*(self._name_coefficients(a) for a in timed))
        if expr.has(TIME):
            return expr  # exp(α t), cos(β t): the root inside is renamed afterwards
        return self._constant(expr)

    def _constant(self, expr: sp.Expr) -> sp.Expr:
        """Name the algebraic coefficient(s) of a time-independent factor."""
        if not expr.has(sp.CRootOf) or _is_bare_root_part(expr):
            return expr
        symbols = sorted(expr.free_symbols, key=lambda s: s.name)
        if symbols:  # symbolic initial data: name the coefficient of each symbol
            parts = sp.collect(sp.expand(expr), symbols, evaluate=False)
            return sp.Add(*(self._constant(c) * m for m, c in parts.items()))
        if expr not in self.coefficients:
            name = sp.Symbol(f"c_{self._index('coefficient', 'c')}", real=True)
            self.coefficients[expr] = name
            self.values[name] = expr
        return self.coefficients[expr]


@dataclass
class NamedTerms:
    """The names one output uses: algebraic constants, named quantities, the unit step.

    :meth:`prepare` turns expressions into their printable named form and records what
    the "where" list must define.
    """

    constants: NamedConstants = field(default_factory=NamedConstants)
    named: list[sp.Expr] = field(default_factory=list)
    has_step: bool = False
    renames: dict = field(default_factory=dict)
    taken: dict = field(default_factory=dict)

    def prepare(self, exprs: Sequence[sp.Expr]) -> list[sp.Expr]:
        """Drop θ(t), note θ(t − τ), name algebraic numbers; returns the printable forms."""
        out = []
        given = [sp.sympify(e, strict=True) for e in exprs]
        steps_dropped = [e.replace(is_step_at_zero, lambda h: sp.S.One) for e in given]
        renamed = self._distinct_names(steps_dropped)
        self.constants.reserve(renamed)
        self.constants.register_roots(renamed)
        for e in renamed:
            self.has_step |= e.has(sp.Heaviside)
            self.named.append(e)
            out.append(self.constants.replace(e))
        return out

    def definitions(self) -> dict:
        """Named quantity → shown definition for every name used so far, in reading order."""
        return definitions(self.named)

    def _distinct_names(self, exprs: list[sp.Expr]) -> list[sp.Expr]:
        """Re-index named quantities that share a printed name but differ (ω₁ of two factors)."""
        symbols = {symbol.name for e in exprs for symbol in e.free_symbols}  # parameters' names
        for q in named_quantities(exprs):
            if q in self.renames:
                continue
            key = (q.base, q.index)
            if self.taken.setdefault(key, q) == q:
                self.renames[q] = q
                continue
            index = 1 + max(i for base, i in self.taken if base == q.base)
            while f"{q.base}_{index}" in symbols:
                index += 1
            display = None if q.display is None else q.display.xreplace(self.renames)
            twin = named(q.base, index, q.definition, positive=q.positive, meaning=q.meaning,
                         display=display)
            self.taken[(q.base, index)] = twin
            self.renames[q] = twin
        return [e.xreplace(self.renames) for e in exprs]
