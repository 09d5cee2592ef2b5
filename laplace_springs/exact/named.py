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

from collections.abc import Callable, Iterable
from functools import lru_cache
from typing import Any

import mpmath
import sympy as sp
from sympy.core.symbol import Str
from sympy.printing.pretty.stringpict import prettyForm

__all__ = ["NamedQuantity", "NamedNumber", "Shown", "named", "named_number",
           "named_quantities", "definitions", "expand_names", "is_named"]

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
        """The plain-text name, e.g. ``omega_1`` (the bare base for index 0: ``Delta``)."""
        return f"{self.base}_{self.index}" if self.index else self.base

    @property
    def latex_name(self) -> str:
        """The LaTeX name, e.g. ``\\omega_{1}``."""
        base = _GREEK.get(self.base, self.base)
        return f"{base}_{{{self.index}}}" if self.index else base

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
        greek = {"omega": "ω", "gamma": "γ", "sigma": "σ", "alpha": "α", "beta": "β",
                 "rho": "ρ", "Delta": "Δ"}
        subscript = str(self.index).translate(str.maketrans("0123456789", "₀₁₂₃₄₅₆₇₈₉"))
        return prettyForm(greek.get(self.base, self.base) + (subscript if self.index else ""))


class _Lazy:
    """A class attribute computed on first use (a named number's exact definition)."""

    def __init__(self, build: Callable[[], sp.Expr]) -> None:
        self.build: Callable[[], sp.Expr] | None = build
        self.value: sp.Expr | None = None

    def __get__(self, obj: Any, owner: type) -> sp.Expr:
        if self.value is None:
            assert self.build is not None
            self.value, self.build = sp.sympify(self.build(), strict=True), None
        return self.value


class NamedNumber(NamedQuantity):
    """A named real number without parameters (α_j, β_j, c_j of a numeric scene).

    Its value comes from ``value(prec)`` (an mpmath number good to ``prec`` bits, e.g.
    from certified flint enclosures), so ``evalf`` never needs the exact definition;
    the ``definition`` (in SymPy's ``CRootOf``) is built on first use only. Build them
    with :func:`named_number`.
    """

    value: Callable[[int], Any]
    sign: int | None = None
    order: tuple[int, ...] = ()
    real: bool = True

    @classmethod
    def eval(cls, *args):
        return None

    @classmethod
    def class_key(cls):
        """Printed sums list c_2 before c_10 (the index compared as a number)."""
        return 4, 0, f"{cls.base}_{cls.index:09d}"

    def _eval_evalf(self, prec):
        value = self.value(prec)
        if isinstance(value, mpmath.mpc):
            return _float(value.real, prec) + sp.I * _float(value.imag, prec)
        return _float(value, prec)

    def _eval_is_real(self):
        return self.real

    def _eval_is_extended_real(self):
        return self.real

    def _eval_is_positive(self):
        return None if self.sign is None else self.sign > 0

    def _eval_is_negative(self):
        return None if self.sign is None else self.sign < 0

    def _eval_is_zero(self):
        return None if self.sign is None else self.sign == 0


def _float(value: Any, prec: int) -> sp.Float:
    """An mpmath number as a SymPy Float of ``prec`` bits (its digits kept)."""
    mpf = value if isinstance(value, mpmath.mpf) else mpmath.mpf(value)
    return sp.Float._new(mpf._mpf_, prec)


def named_number(base: str, index: int, *, value: Callable[[int], Any],
                 definition: Callable[[], sp.Expr], display: sp.Expr, sign: int | None = None,
                 meaning: str = "", order: tuple[int, ...] = (), real: bool = True) -> NamedNumber:
    """A named real number: printed ``base_index``, evaluated by ``value``, defined lazily.

    Parameters
    ----------
    base, index : str, int
        The name (``index`` 0: the bare base).
    value : callable
        prec (bits) → an mpmath number (``mpc`` for a complex one) correct to ``prec``
        bits.
    definition : callable
        Builds the exact SymPy definition (called once, when asked:
        :func:`expand_names`, ``.definition``).
    display : sympy.Expr
        What the "where" lists show (a :class:`Shown`, possibly with other names).
    sign : int, optional
        −1, 0 or 1 when known exactly.
    meaning : str
        A short description for listings.
    order : tuple of int
        Where it is listed among other named numbers.
    real : bool
        False for a complex number (a root ρ_j, named for the definitions of others).

    Examples
    --------
    >>> import mpmath
    >>> half = named_number("c", 7, value=lambda prec: mpmath.mpf(1) / 2,
    ...                     definition=lambda: sp.Rational(1, 2), display=sp.Rational(1, 2),
    ...                     sign=1)
    >>> half, sp.N(3 * half), half.is_positive, expand_names(half + 1)
    (c_7, 1.50000000000000, True, 3/2)
    """
    namespace = {"definition": _Lazy(definition), "parameters": (), "base": base,
                 "index": index, "positive": sign == 1 if sign is not None else None,
                 "meaning": meaning, "display": display, "value": staticmethod(value),
                 "sign": sign, "order": order, "real": real, "__module__": __name__}
    return type(f"{base}_{index}", (NamedNumber,), namespace)()


class Shown(sp.Expr):
    """How a definition is written out: a template with the printed arguments filled in.

    Display only (the "where" lists): ``Shown("re(#0)", "\\mathrm{Re}\\,#0", rho)``
    prints ``re(rho_1)`` and keeps ``rho`` visible to :func:`named_quantities`; ``#k``
    stands for the k-th argument as the printer in use writes it.

    >>> x = sp.Symbol("x")
    >>> shown = Shown("root of #0 near 1.5", r"\\text{root of } #0", x**2 - 2)
    >>> str(shown), sp.latex(shown)
    ('root of x**2 - 2 near 1.5', '\\\\text{root of } x^{2} - 2')
    """

    def __new__(cls, text: str | Str, latex: str | Str, *args: sp.Basic) -> Shown:
        text, latex = (t if isinstance(t, Str) else Str(t) for t in (text, latex))
        return sp.Expr.__new__(cls, text, latex, *(sp.sympify(a, strict=True) for a in args))

    def _filled(self, template: str, printer) -> str:
        for k in reversed(range(len(self.args) - 2)):  # #10 before #1
            template = template.replace(f"#{k}", printer._print(self.args[k + 2]))
        return template

    def _sympystr(self, printer) -> str:
        return self._filled(self.args[0].name, printer)

    def _latex(self, printer, exp=None) -> str:
        return self._filled(self.args[1].name, printer)


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
    """Where a named quantity is listed. Its class decides, and keeps the key: a long
    definition (Δ(λ) of degree 24) is printed once, not per comparison."""
    cls = type(q)
    key = cls.__dict__.get("_rank_key")
    if key is None:
        if isinstance(q, NamedNumber):  # listed in their own order, definitions never built
            key = (0, *q.order)
        else:
            key = (1, q.base, q.index, str(q.definition))
        cls._rank_key = key
    return key


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
