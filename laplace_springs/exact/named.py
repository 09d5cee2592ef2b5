"""Named quantities for readable symbolic solutions: ω₁, ω₂, γ₁, ... with definitions.

A symbolic scene (masses, stiffnesses or damping left as symbols) has natural
frequencies and damping rates that are long radical expressions in the parameters.
Written out inline they repeat in every term (the seed's Example 3 in Mathematica is a
page of nested radicals). Here such a quantity is a :class:`NamedQuantity`: a SymPy
object that prints as its name (``omega_1``, ``\\omega_{1}`` in LaTeX), carries its
definition and its sign, and turns into that definition as soon as any parameter it
depends on is replaced. So

- ``sol.x`` stays short (``cos(t*omega_1)``, ``omega_2**2 - omega_1**2``),
- ``sol.x.subs({m1: 1, ...})`` is the right function of t (the names evaluate),
- :func:`definitions` lists name → expression, :func:`expand_names` substitutes all.

Named quantities depend on the parameters only, never on t, so ``diff(t)`` treats them
as constants; derivatives with respect to a parameter use the definition.

Examples
--------
>>> import sympy as sp
>>> k, m = sp.symbols("k m", positive=True)
>>> w = named("omega", 1, sp.sqrt(k / m), positive=True, meaning="natural frequency")
>>> x = sp.cos(w * sp.Symbol("t"))
>>> x
cos(t*omega_1)
>>> definitions([x])
{omega_1: sqrt(k)/sqrt(m)}
>>> x.subs({k: 4, m: 1})
cos(2*t)
>>> sp.latex(w**2)
'\\\\omega_{1}^{2}'
"""

from __future__ import annotations

from collections.abc import Iterable
from functools import lru_cache

import sympy as sp
from sympy.printing.pretty.stringpict import prettyForm

__all__ = ["NamedQuantity", "named", "named_quantities", "definitions", "expand_names",
           "is_named"]

#: LaTeX of the Greek base names used here.
_GREEK = {"omega": r"\omega", "gamma": r"\gamma", "sigma": r"\sigma", "alpha": r"\alpha",
          "beta": r"\beta", "Omega": r"\Omega", "Delta": r"\Delta"}


class NamedQuantity(sp.Function):
    """Base class of named quantities; build them with :func:`named`.

    Class attributes (set per quantity): ``definition`` (in the parameters only),
    ``parameters`` (its free symbols, the call arguments), ``base`` and ``index``
    (the name), ``positive`` (sign known from the physics, or None) and ``meaning``
    (a short phrase for listings, e.g. "natural frequency").
    """

    definition: sp.Expr = sp.S.Zero
    parameters: tuple[sp.Symbol, ...] = ()
    base: str = "q"
    index: int = 0
    positive: bool | None = None
    meaning: str = ""
    display: sp.Expr | None = None

    @classmethod
    def eval(cls, *args):
        # Unchanged parameters keep the name; any substitution expands the definition.
        if tuple(args) != cls.parameters:
            return cls.definition.xreplace(dict(zip(cls.parameters, args)))
        return None

    @property
    def name(self) -> str:
        """The plain-text name, e.g. ``omega_1``."""
        return f"{self.base}_{self.index}"

    @property
    def latex_name(self) -> str:
        """The LaTeX name, e.g. ``\\omega_{1}``."""
        return f"{_GREEK.get(self.base, self.base)}_{{{self.index}}}"

    def _eval_is_positive(self):
        return self.positive

    def _eval_is_real(self):
        return True if self.positive else None

    def _eval_is_zero(self):
        return False if self.positive else None

    def fdiff(self, argindex=1):
        return self.definition.diff(self.parameters[argindex - 1])

    def _sympystr(self, printer) -> str:
        return self.name

    def _latex(self, printer, exp=None) -> str:
        return f"{self.latex_name}^{{{exp}}}" if exp else self.latex_name

    def _pretty(self, printer):
        greek = {"omega": "ω", "gamma": "γ", "sigma": "σ", "alpha": "α", "beta": "β"}
        subscript = str(self.index).translate(str.maketrans("0123456789", "₀₁₂₃₄₅₆₇₈₉"))
        return prettyForm(greek.get(self.base, self.base) + subscript)


@lru_cache(maxsize=1024)
def _named_class(base: str, index: int, definition: sp.Expr, positive: bool | None,
                 meaning: str, display: sp.Expr | None) -> type[NamedQuantity]:
    parameters = tuple(sorted(definition.free_symbols, key=lambda s: s.name))
    namespace = {"definition": definition, "parameters": parameters, "base": base,
                 "index": index, "positive": positive, "meaning": meaning,
                 "display": display, "__module__": __name__}
    return type(f"{base}_{index}", (NamedQuantity,), namespace)


def named(base: str, index: int, definition: sp.Expr, *, positive: bool | None = None,
          meaning: str = "", display: sp.Expr | None = None) -> sp.Expr:
    """The named quantity ``base_index`` standing for ``definition``.

    Parameters
    ----------
    base : str
        Name without index: "omega", "gamma", "sigma" print as Greek letters.
    index : int
        Subscript.
    definition : sympy.Expr
        The quantity in terms of the scene's parameters (no t, no other names).
    positive : bool, optional
        True when the physics makes it positive (a natural frequency of a stable
        undamped system, a damping rate): SymPy then simplifies √(ω²) to ω.
    meaning : str
        A short description used in listings and LaTeX.
    display : sympy.Expr, optional
        The definition as it should be shown, in terms of other named quantities
        (e.g. ω₁ = √((S₁ − √(S₁² − 4P₁))/2)); ``definition`` itself by default.

    Returns
    -------
    sympy.Expr
        The named atom, or ``definition`` itself when it has no free symbols or is a lone
        symbol (a number or a parameter needs no other name).
    """
    definition = sp.sympify(definition, strict=True)
    if not definition.free_symbols or definition.is_Symbol:
        return definition
    cls = _named_class(base, index, definition, positive, meaning,
                       None if display is None else sp.sympify(display, strict=True))
    return cls(*cls.parameters)


def is_named(expr) -> bool:
    """True for a named-quantity atom."""
    return isinstance(expr, NamedQuantity)


def _shown(q: NamedQuantity) -> sp.Expr:
    return q.definition if q.display is None else q.display


def named_quantities(exprs: Iterable[sp.Expr]) -> list[NamedQuantity]:
    """The named atoms in ``exprs`` and in their shown definitions, each after the
    names its own definition uses (so a listing reads top to bottom)."""
    found: set = set()
    todo = [sp.sympify(e, strict=True) for e in exprs]
    while todo:
        for q in todo.pop().atoms(NamedQuantity):
            if q not in found:
                found.add(q)
                todo.append(_shown(q))
    order: list[NamedQuantity] = []

    def visit(q: NamedQuantity) -> None:
        if q in order:
            return
        for inner in sorted(_shown(q).atoms(NamedQuantity), key=_rank):
            visit(inner)
        order.append(q)

    for q in sorted(found, key=_rank):
        visit(q)
    return order


def _rank(q: NamedQuantity) -> tuple:
    return (q.base, q.index, str(q.definition))


def definitions(exprs: Iterable[sp.Expr]) -> dict[NamedQuantity, sp.Expr]:
    """Name → shown definition for every named quantity ``exprs`` use, in reading order.

    A shown definition may use names listed before it; :func:`expand_names` removes
    them all.
    """
    return {q: _shown(q) for q in named_quantities(exprs)}


def expand_names(expr):
    """``expr`` with every named quantity replaced by its definition.

    Works on expressions and matrices.
    """
    expr = sp.sympify(expr, strict=True)
    quantities = named_quantities([expr] if not isinstance(expr, sp.MatrixBase) else list(expr))
    if not quantities:
        return expr
    return expr.xreplace({q: q.definition for q in quantities})
