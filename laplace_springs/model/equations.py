"""Equations of motion as input: ``m1*x1'' + c*x1' + k*x1 - k*x2 = F(t)`` to M, C, K, f.

:meth:`laplace_springs.Scene.from_equations` reads a linear second-order system in the
notations people write it in, and builds the scene M x'' + C x' + K x = f(t),
x(0) = x0, x'(0) = v0:

- primes: ``x1'' + 3*x1 - x2 = 0`` (``x1`` alone is x1(t)), ``x1(0) = 1/20``,
  ``x1'(0) = 2``;
- SymPy's: ``Derivative(x1(t), t, 2)``, ``x1(t).diff(t)``, ``diff(x1(t), t, 2)``, and SymPy
  objects themselves (``Eq(m*x(t).diff(t, 2) + k*x(t), 0)``, ``Eq(x(0), 1)``,
  ``Eq(Subs(Derivative(x(t), t), t, 0), 0)``);
- Newton's dots: ``ẍ + 0.2*ẋ + 4*x = 0``, ``ẋ(0) = 2`` (a product needs ``*``: ``B*ẋ``);
- Mathematica's, as on the seed page: ``m1*x''[t] + (mu1 + mu2)*x'[t] - mu2*y'[t] == 0``,
  ``x[0] == d1``, ``x'[0] == v1``.

Text holds one statement per line, or several separated by ``;`` or by commas (a
Mathematica list ``{eqn1, eqn2, x[0] == d1}`` reads too); ``#`` and ``(* ... *)`` start
comments. The seed's Mathematica program reads as printed: labelled equations
``eqn1 = ... == 0`` (and the labels listed again), ``ClearAll`` and ``sol = DSolve[...]`` are
passed over, ``\\[Mu]1`` is the name ``mu1``. A statement is an equation of motion, an
initial condition, a value ``k1 = 400`` (a name that is no unknown; later statements use the value) or the
declaration ``parameters: k, c`` (names kept as positive symbols). The unknown
functions are the names written with primes or an argument (``x1''``, ``x1(t)``,
``x[t]``) or listed in ``coordinates``. Each side is read by the package's safe parser
(:func:`laplace_springs.model.numbers.parse_expression` with ``unknowns``): the text is
never evaluated.

What is refused, with the statement and the reason: a term that is not linear in the
unknowns (``x1**2``, ``sin(x1)``, ``x1*x2``), a coefficient that depends on t
(``t*x1``), a third derivative, a coordinate without an equation (or more equations than
coordinates), a missing or repeated initial condition, an initial value of x'', a value for a
name whose meaning in text is fixed (``t``, ``pi``, ``E``, ``I``, ``nan``, a function). The
right-hand side (everything free of the unknowns) is the force f(t), which must be of the
forcing class (:mod:`laplace_springs.model.forcing`).

Size: at most :attr:`~laplace_springs.limits.Limits.max_matrix_input_size` coordinates (the
matrices are dense input), and each statement at most
:attr:`~laplace_springs.limits.Limits.max_equation_terms` terms once expanded (estimated from
the expression before SymPy expands it: :func:`expanded_size`); each statement is parsed once, so a chain of 500 masses written
as 1,500 statements reads in about 4 s (measured on one core, most of it the parser).

Examples
--------
>>> system = read_equations('''
...     x1'' + 3*x1 - x2 = 0
...     x2'' - 2*x1 + 2*x2 = cos(t)
...     x1(0) = 1/20; x1'(0) = 2; x2(0) = 0; x2'(0) = 0
... ''')
>>> system.names, system.M, system.K
(('x1', 'x2'), [[1, 0], [0, 1]], [[3, -1], [-2, 2]])
>>> system.x0, system.v0, system.forcing
([1/20, 0], [2, 0], [0, cos(t)])
"""

from __future__ import annotations

import math
import re
import unicodedata
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import sympy as sp
from sympy.core.function import AppliedUndef

from ..limits import limits
from .errors import LimitError, SceneError
from .numbers import (
    ALLOWED_FUNCTIONS,
    CONSTANTS,
    NOT_FINITE_REAL,
    declare_parameters,
    parse_expression,
    shown,
    to_exact,
)
from .periodic import PERIODIC_FUNCTIONS
from .symbols import TIME

__all__ = ["EquationSystem", "read_equations"]

#: Highest derivative order written in text before it is refused (x1''' is read, to be
#: refused with its name; x1'''''''''' is refused as it is read).
_MAX_ORDER = 4

_NAME = r"[A-Za-z][A-Za-z0-9_]*"
#: A name written as a function: followed by a prime or an opening parenthesis/bracket.
_CALLED = re.compile(rf"(?<![A-Za-z0-9_.])({_NAME})\s*(?=['(\[])")
_DEFINITION = re.compile(rf"^\s*({_NAME})\s*$")
_DECLARATION = re.compile(r"^\s*parameters\s*:(.*)$")
_COMMENT = re.compile(r"\(\*.*?\*\)|#[^\n]*", re.S)
_MATHEMATICA_NAME = re.compile(r"\\\[([A-Za-z]+)\]")
#: Mathematica commands that are no equations: ClearAll, and the solver call itself.
_COMMAND = re.compile(rf"\bClearAll\b(\s*\[)?|(?:\b{_NAME}\s*=\s*)?\b(?:N?DSolve)\b(\s*\[)")
_LIST_ASSIGNMENT = re.compile(rf"\b{_NAME}\s*=\s*\{{")


@dataclass(frozen=True)
class EquationSystem:
    """A linear second-order system read from equations: rows are equations, columns
    coordinates, entries exact SymPy expressions.

    Attributes
    ----------
    M, C, K : list of list of sympy.Expr
        Coefficients of x'', x' and x (n x n).
    x0, v0 : list of sympy.Expr
        Initial displacements and velocities.
    forcing : list of sympy.Expr or None
        The right-hand side f(t) of each equation, None when all are 0.
    names : tuple of str
        The coordinates (unknown functions), in column order.
    parameters : dict of str to sympy.Symbol
        The declared parameters and the Symbols of SymPy input.
    """

    M: list[list[sp.Expr]]
    C: list[list[sp.Expr]]
    K: list[list[sp.Expr]]
    x0: list[sp.Expr]
    v0: list[sp.Expr]
    forcing: list[sp.Expr] | None
    names: tuple[str, ...]
    parameters: dict[str, sp.Symbol] = field(default_factory=dict)

    def matrices(self) -> dict[str, Any]:
        """The keyword arguments of :meth:`laplace_springs.Scene.from_matrices` (M, C, K as
        sparse matrices: only their nonzero entries are read). Equations whose M is not
        symmetric but invertible are solved for the accelerations first (M⁻¹ times both
        sides, so M = I): a scene's M is symmetric.

        >>> system = read_equations(["2*x'' + y'' + 2*x - y = 0", "y'' - x + 2*y = 0",
        ...                          "x(0) = 1", "x'(0) = 0", "y(0) = 0", "y'(0) = 0"],
        ...                         coordinates=["x", "y"])
        >>> found = system.matrices()
        >>> found["M"], found["K"]
        (Matrix([
        [1, 0],
        [0, 1]]), Matrix([
        [3/2, -3/2],
        [ -1,    2]]))
        """
        def sparse(rows: list[list[sp.Expr]]) -> sp.ImmutableSparseMatrix:
            return sp.ImmutableSparseMatrix(len(rows), len(rows), {
                (i, j): value for i, row in enumerate(rows) for j, value in enumerate(row) if value != 0})

        M, C, K, forcing = self.M, self.C, self.K, self.forcing
        symmetric = all(M[j][i] == value for i, row in enumerate(M)
                        for j, value in enumerate(row) if value != 0)
        if not symmetric and sp.simplify(sp.Matrix(M).det()) != 0:
            inverse = sp.Matrix(M).inv()
            M = sp.eye(len(M)).tolist()
            C, K = ((inverse * sp.Matrix(A)).applyfunc(sp.cancel).tolist() for A in (C, K))
            if forcing is not None:
                forcing = [sp.expand(v) for v in inverse * sp.Matrix(forcing)]
        return {"M": sparse(M), "C": sparse(C), "K": sparse(K),
                "x0": self.x0, "v0": self.v0, "names": self.names, "forcing": forcing,
                "parameters": self.parameters}


# ---------------------------------------------------------------------------
# unknowns as placeholders: x_j^{(k)}(t) and x_j^{(k)}(0) are Dummy symbols
# ---------------------------------------------------------------------------
@dataclass
class _Unknowns:
    """Placeholder symbols for the unknowns and their initial values, by (name, order)."""

    names: list[str] = field(default_factory=list)
    motion: dict[tuple[str, int], sp.Dummy] = field(default_factory=dict)
    initial: dict[tuple[str, int], sp.Dummy] = field(default_factory=dict)
    functions: dict[str, Any] = field(default_factory=dict)
    owners: dict[sp.Basic, tuple[str, int, bool]] = field(default_factory=dict)

    def add(self, name: str) -> None:
        if name not in self.names:
            self.names.append(name)
            self.functions[name] = sp.Function(name)

    def at(self, name: str, order: int, initial: bool = False) -> sp.Dummy:
        """The placeholder of x^{(order)}(t), or of x^{(order)}(0) with ``initial``."""
        self.add(name)
        table = self.initial if initial else self.motion
        if (name, order) not in table:
            table[name, order] = sp.Dummy(_written(name, order, initial))
            self.owners[table[name, order]] = (name, order, initial)
        return table[name, order]

    def builder(self, name: str) -> Any:
        """The parser's builder for ``name``: x, x', x''(t), x[t], x(0), x'[0]."""

        def build(order: int, argument: sp.Expr | None) -> sp.Expr:
            if order > _MAX_ORDER:
                raise SceneError(f"{_written(name, order)}: a derivative of order {order}")
            if argument is None or argument == TIME:
                return self.at(name, order)
            if argument == 0:
                return self.at(name, order, initial=True)
            raise SceneError(f"{name}({argument}): write the unknown as {name}, {name}(t) or "
                             f"{name}[t] in an equation and as {name}(0) in an initial condition")

        return build

    def info(self, placeholder: sp.Basic) -> tuple[str, int, bool] | None:
        """(name, order, initial) of a placeholder, None for anything else."""
        return self.owners.get(placeholder)

    @property
    def all(self) -> set[sp.Basic]:
        return set(self.owners)

    def has_initial(self, expr: sp.Expr) -> bool:
        return any(self.owners[x][2] for x in expr.free_symbols if x in self.owners)

    def has_motion(self, expr: sp.Expr) -> bool:
        return any(not self.owners[x][2] for x in expr.free_symbols if x in self.owners)

    def shown(self, expr: Any) -> str:
        """``expr`` with placeholders written as the user wrote them (x1'', x1'(0))."""
        if not isinstance(expr, sp.Basic):
            return str(expr)
        names = {symbol: sp.Symbol(symbol.name) for symbol in self.all}
        return str(expr.xreplace(names))

    # -- derivatives of placeholder expressions -------------------------------
    def to_functions(self, expr: sp.Expr) -> sp.Expr:
        return expr.xreplace({symbol: sp.Derivative(self.functions[name](TIME), (TIME, order))
                              if order else self.functions[name](TIME)
                              for (name, order), symbol in self.motion.items()})

    def from_functions(self, expr: sp.Expr) -> sp.Expr:
        """x_j^{(k)}(t) as placeholders (new ones for new orders)."""
        by_function = {f: name for name, f in self.functions.items()}
        replacement: dict[sp.Basic, sp.Expr] = {}
        for atom in expr.atoms(sp.Derivative):
            function = atom.expr
            if isinstance(function, AppliedUndef) and function.func in by_function:
                replacement[atom] = self.at(by_function[function.func], int(atom.derivative_count))
        expr = expr.xreplace(replacement)
        return expr.xreplace({f(TIME): self.at(name, 0) for f, name in by_function.items()})

    def differentiate(self, value: sp.Expr, *spec: Any) -> sp.Expr:
        """d^k value / dt^k for ``Derivative``, ``diff`` and ``.diff``, with SymPy's ways of
        writing the order: ``(t)`` or nothing (first), ``(t, 2)`` and ``(t, t)`` (second)."""
        order = 0
        items = list(spec) or [TIME]
        while items:
            variable = items.pop(0)
            if variable != TIME:
                raise SceneError(f"derivatives are taken in t, got {self.shown(variable)}")
            count: Any = sp.S.One
            if items and items[0] != TIME and not isinstance(items[0], sp.Symbol):
                count = items.pop(0)
            if not (isinstance(count, sp.Integer) and 1 <= count <= _MAX_ORDER):
                raise SceneError(f"the order of a derivative must be 1 .. {_MAX_ORDER}, got "
                                 f"{self.shown(count)}")
            order += int(count)
        if order > _MAX_ORDER:
            raise SceneError(f"the order of a derivative must be 1 .. {_MAX_ORDER}, got {order}")
        if self.has_initial(value):
            raise SceneError("the derivative of an initial value x(0) is 0: write x'(0)")
        return self.from_functions(sp.diff(self.to_functions(value), TIME, order))


def _written(name: str, order: int, initial: bool = False) -> str:
    return name + "'" * order + ("(0)" if initial else "")


# ---------------------------------------------------------------------------
# statements: text, and SymPy objects
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class _Statement:
    """One equation as lhs - rhs in placeholders; ``source`` is what the user wrote."""

    expr: sp.Expr
    source: str
    lhs: sp.Expr
    rhs: sp.Expr


def _split_top_level(text: str) -> list[str]:
    """``text`` split at newlines, ``;``, braces and commas outside () and []."""
    pieces: list[str] = []
    current: list[str] = []
    depth = 0
    for char in text:
        if char in "([":
            depth += 1
        elif char in ")]":
            depth = max(depth - 1, 0)
        if char in "\n;{}" or (char == "," and depth == 0):
            pieces.append("".join(current))
            current = []
            continue
        current.append(char)
    pieces.append("".join(current))
    return [piece.strip() for piece in pieces if piece.strip()]


def _without_commands(text: str) -> str:
    """The seed's Mathematica program reduced to its statements: ``ClearAll``, ``ClearAll[...]``
    and ``sol = DSolve[...]`` (or ``NDSolve``) dropped, ``eqns = {...}`` read as the list."""
    out, position = [], 0
    for match in _COMMAND.finditer(text):
        if match.start() < position:
            continue
        out.append(text[position:match.start()])
        position = match.end()
        if match.group(1) or match.group(2):  # skip the command's bracketed arguments
            depth = 1
            while position < len(text) and depth:
                depth += {"[": 1, "]": -1}.get(text[position], 0)
                position += 1
    out.append(text[position:])
    return _LIST_ASSIGNMENT.sub("{", "".join(out))


def _plain(text: str) -> str:
    """The text as the statements are read: comments removed, Newton's dots written as
    primes, Mathematica's named characters as names and its commands dropped."""
    return _without_commands(_MATHEMATICA_NAME.sub(lambda m: m.group(1).lower(),
                                                   _dots_as_primes(_COMMENT.sub("", text))))


#: Combining dot above and diaeresis (Newton's ẋ and ẍ, decomposed): the primes they stand for.
_DOTS = {"\u0307": "'", "\u0308": "''"}
_DOTTED = re.compile("[A-Za-z][A-Za-z0-9_\u0307\u0308]*")


def _dots_as_primes(text: str) -> str:
    """Newton's notation as primes: ``ẍ + 0.2*ẋ`` is ``x'' + 0.2*x'``, and ``ẋ1(0) = 2`` is
    ``x1'(0) = 2`` (the dots stand over a name's first letter and follow the name; a dot
    over a later letter, ``Bẋ``, is a SceneError asking for the product ``B*ẋ``).

    >>> _dots_as_primes("ẍ1 + 0.2*ẋ1 + 4*x1 = 0; ẋ1(0) = 2")
    "x1'' + 0.2*x1' + 4*x1 = 0; x1'(0) = 2"
    """
    decomposed = unicodedata.normalize("NFD", text)
    if "\u0307" not in decomposed and "\u0308" not in decomposed:
        return text

    def primed(match: re.Match[str]) -> str:
        name = match.group(0)
        if name[1:2] not in _DOTS and any(c in _DOTS for c in name):
            written = unicodedata.normalize("NFC", name)
            marked = next(i for i, c in enumerate(name) if c in _DOTS) - 1
            head = name[:marked]
            product = f"; a product needs '*', e.g. {head}*{written[len(head):]}" \
                if name[marked].isalpha() else ""
            raise SceneError(f"{written!r}: Newton's dots stand over a name's first letter "
                             f"(ẋ1 is x1'){product}")
        primes = "".join(_DOTS.get(mark, "") for mark in name)
        return "".join(c for c in name if c not in _DOTS) + primes

    return unicodedata.normalize("NFC", _DOTTED.sub(primed, decomposed))


def _text_statements(text: str) -> tuple[list[str], list[str]]:
    """(declared names, statements) of a text: comments removed, declarations apart,
    Newton's dots as primes, Mathematica's named characters written as names
    (``\\[Mu]1`` is ``mu1``)."""
    text = _plain(text)
    declared: list[str] = []
    lines = []
    for line in text.splitlines():
        kept = []
        for piece in line.split(";"):  # a declaration is a statement: on its line or between ';'
            match = _DECLARATION.match(piece)
            if match:
                declared += [name.strip() for name in match.group(1).split(",") if name.strip()]
            else:
                kept.append(piece)
        lines.append(";".join(kept))
    return declared, _split_top_level("\n".join(lines))


def _label(statement: str) -> str | None:
    """The label of a Mathematica ``eqn1 = left == right``, else None."""
    parts = re.split(r"(==|=)", statement)
    if len(parts) == 5 and parts[1] == "=" and parts[3] == "==":
        match = _DEFINITION.match(parts[0])
        return match.group(1) if match else None
    return None


def _sides(statement: str) -> tuple[str, str]:
    """(left, right) of ``left = right`` or ``left == right``; a Mathematica label
    ``eqn1 = left == right`` is dropped."""
    parts = re.split(r"(==|=)", statement)
    if _label(statement) is not None:
        parts = parts[2:]
    if len(parts) != 3:
        count = (len(parts) - 1) // 2
        raise SceneError(f"equation {shown(statement)}: expected one '=' (or '=='), found {count}")
    return parts[0], parts[2]


class _TextReader:
    """Reads the statements of one text with one set of unknowns and values."""

    def __init__(self, unknowns: _Unknowns, variables: dict[str, sp.Expr]) -> None:
        self.unknowns = unknowns
        self.variables = variables
        self.labels: set[str] = set()
        differentiate = unknowns.differentiate
        self.functions = {**ALLOWED_FUNCTIONS, **PERIODIC_FUNCTIONS,
                          "Derivative": differentiate, "diff": differentiate}
        self.builders = {name: unknowns.builder(name) for name in unknowns.names}

    def side(self, text: str, statement: str) -> sp.Expr:
        return parse_expression(text.strip(), f"equation {shown(statement)}",
                                allowed_functions=self.functions, variables=self.variables,
                                expected="an expression in t and the unknowns", unknowns=self.builders)

    def mentions_unknowns(self, text: str, statement: str) -> bool:
        """Whether ``text`` reads as an expression in the unknowns (x, x'(0), ...)."""
        try:
            value = self.side(text, statement)
        except SceneError:
            return False  # not an expression in the unknowns: read as a value, which says why
        return self.unknowns.has_motion(value) or self.unknowns.has_initial(value)

    def statement(self, statement: str) -> _Statement | None:
        """An equation or initial condition; None for a value ``k1 = 400`` (stored) and for
        a label ``eqn1`` of an equation already read (the seed's ``{eqn1, eqn2, ...}``)."""
        if statement.strip() in self.labels:
            return None
        label = _label(statement)
        if label is not None:
            self.labels.add(label)
        left, right = _sides(statement)
        definition = _DEFINITION.match(left)
        if definition and definition.group(1) not in self.unknowns.names \
                and not self.mentions_unknowns(right, statement):  # t = x'' + x is an equation
            name = definition.group(1)
            _check_value_name(name, statement)
            if name in self.variables and isinstance(self.variables[name], sp.Symbol):
                raise SceneError(f"{shown(statement)}: {name!r} is a declared parameter; give it a "
                                 "value or declare it, not both")
            value = parse_expression(right.strip(), f"the value of {name!r}", variables=self.variables,
                                     allowed_functions=ALLOWED_FUNCTIONS)
            self.variables[name] = value
            return None
        lhs, rhs = self.side(left, statement), self.side(right, statement)
        return _Statement(_expanded(lhs - rhs, statement), statement, lhs, rhs)


#: Terms counted at most (beyond every limit): the estimate saturates here.
_TERMS_CAP = 2**62


def _terms(count: int, power: int) -> int:
    """Terms of a sum of ``count`` terms raised to ``power``: C(power + count - 1, count - 1)."""
    if count <= 1 or power == 0:
        return 1
    if math.lgamma(power + count) - math.lgamma(power + 1) - math.lgamma(count) > math.log(_TERMS_CAP):
        return _TERMS_CAP
    return min(math.comb(power + count - 1, count - 1), _TERMS_CAP)


def expanded_size(expr: sp.Basic) -> int:
    """A bound on the terms ``sp.expand(expr)`` forms, from the expression tree, without
    expanding it: a leaf is 1, a sum adds, a product multiplies, a power b**n gives the
    C(n + A - 1, A - 1) monomials of its base's A terms, and a function counts as 1 while
    its arguments are expanded on their own (the largest of them counts).

    >>> k = sp.symbols("k0:30")
    >>> expanded_size(sp.Add(*k)**12 * sp.Symbol("x"))
    7898654920
    >>> expanded_size(sp.cos(sp.Add(*k[:3])**2) + 1)
    6
    """
    known: dict[sp.Basic, int] = {}
    widest = 1
    stack: list[tuple[sp.Basic, bool]] = [(expr, False)]
    while stack:  # post-order, without recursion
        node, ready = stack.pop()
        if node in known:
            continue
        if not node.args or not isinstance(node, sp.Expr):
            known[node] = 1
            continue
        if not ready:
            stack.append((node, True))
            stack.extend((child, False) for child in node.args if child not in known)
            continue
        sizes = [known[child] for child in node.args]
        if isinstance(node, sp.Add):
            size = min(sum(sizes), _TERMS_CAP)
        elif isinstance(node, sp.Mul):
            size = 1
            for part in sizes:
                size = min(size * part, _TERMS_CAP)
        elif isinstance(node, sp.Pow):
            power = node.exp
            size = _terms(sizes[0], int(min(abs(power), _TERMS_CAP))) if power.is_Integer else sizes[0]
        else:  # a function: 1 term outside, its arguments expanded inside
            widest = max(widest, *sizes)
            size = 1
        known[node] = size
    return max(known[expr], widest)


def _expanded(expr: sp.Expr, statement: object) -> sp.Expr:
    """``sp.expand(expr)``, or a LimitError when it would form more than
    :attr:`~laplace_springs.limits.Limits.max_equation_terms` terms."""
    size, most = expanded_size(expr), limits().max_equation_terms
    if size > most:
        shown_size = "more than 10^18" if size >= _TERMS_CAP else f"{size:,}"
        raise LimitError(f"equation {shown(statement)}: expands into an estimated {shown_size} terms, "
                         f"above the limit {most:,} (Limits.max_equation_terms); write it with "
                         "fewer products and powers of sums")
    return sp.expand(expr)


def _check_value_name(name: str, statement: str) -> None:
    """Refuse a value ``name = ...`` for a name whose meaning in text is fixed: the time t,
    a function, the constants pi and E, and the names of numbers that are not finite and
    real (I, nan, ...): ``pi = 3`` would silently change every later pi."""
    if name == "t":
        meaning = "the time"
    elif name in ALLOWED_FUNCTIONS or name in PERIODIC_FUNCTIONS:
        meaning = f"the function {name}(...)"
    elif name in CONSTANTS:
        meaning = f"the constant {CONSTANTS[name]}"
    elif name.lower() in NOT_FINITE_REAL:
        meaning = "a number that is not finite and real"
    else:
        return
    raise SceneError(f"{shown(statement)}: {name!r} cannot be given a value: in text it is "
                     f"{meaning}; rename it, e.g. '{name}_0'")


def _unknown_names(text: str, excluded: Iterable[str]) -> list[str]:
    """Names written as functions (x1'', x1(t), x[t]) that are not functions or values."""
    skip = {*ALLOWED_FUNCTIONS, *PERIODIC_FUNCTIONS, "Derivative", "diff", "t", *excluded}
    found: list[str] = []
    for match in _CALLED.finditer(_plain(text)):
        name = match.group(1)
        if name not in skip and name not in found:
            found.append(name)
    return found


def _sympy_statement(item: sp.Basic, unknowns: _Unknowns) -> _Statement:
    """An Eq (or an expression = 0) with unknown functions as placeholders."""
    if isinstance(item, sp.Equality):
        lhs, rhs = item.lhs, item.rhs
    elif isinstance(item, sp.Expr):
        lhs, rhs = item, sp.S.Zero
    else:
        raise SceneError(f"equation {shown(item)}: expected an Eq, an expression or text "
                         "(an Eq that SymPy evaluated to True or False says nothing about the unknowns)")
    time = _time_symbol(item)
    lhs, rhs = (_placeholders(side, time, unknowns, item) for side in (lhs, rhs))
    return _Statement(_expanded(lhs - rhs, item), str(item), lhs, rhs)


def _time_symbol(item: sp.Basic) -> sp.Symbol:
    """The one time symbol of the unknown functions in ``item`` (TIME if there are none)."""
    found: set[sp.Basic] = set()
    for atom in item.atoms(AppliedUndef):
        if len(atom.args) == 1 and isinstance(atom.args[0], sp.Symbol):
            found.add(atom.args[0])
    for derivative in item.atoms(sp.Derivative):
        found |= {variable for variable, _ in derivative.variable_count}
    if len(found) > 1:
        raise SceneError(f"equation {shown(item)}: the unknowns are functions of one time, "
                         f"found {', '.join(sorted(map(str, found)))}")
    return found.pop() if found else TIME


def _placeholders(expr: sp.Expr, time: sp.Symbol, unknowns: _Unknowns, item: sp.Basic) -> sp.Expr:
    """x(t), Derivative(x(t), (t, k)), x(0), Subs(Derivative(x(t), (t, k)), t, 0) as
    placeholders; time as :data:`~laplace_springs.model.symbols.TIME`; Floats exact."""
    expr = expr.replace(lambda e: isinstance(e, sp.Derivative) and not isinstance(e.expr, AppliedUndef),
                        lambda e: e.doit())
    replacement: dict[sp.Basic, sp.Expr] = {}
    for subs in expr.atoms(sp.Subs):
        inner = subs.expr
        if (subs.variables == (time,) and subs.point == (0,) and isinstance(inner, sp.Derivative)
                and isinstance(inner.expr, AppliedUndef) and inner.expr.args == (time,)):
            replacement[subs] = unknowns.at(inner.expr.func.__name__, int(inner.derivative_count), True)
        else:
            raise SceneError(f"equation {shown(item)}: {subs} is not an initial value x'(0)")
    for derivative in expr.atoms(sp.Derivative):
        inner = derivative.expr
        if derivative in replacement or any(derivative.has(s) for s in replacement):
            continue
        if not (isinstance(inner, AppliedUndef) and inner.args == (time,)):
            raise SceneError(f"equation {shown(item)}: {derivative} is not a derivative of an "
                             f"unknown function of {time}")
        replacement[derivative] = unknowns.at(inner.func.__name__, int(derivative.derivative_count))
    expr = expr.xreplace(replacement)
    functions: dict[sp.Basic, sp.Expr] = {}
    for atom in expr.atoms(AppliedUndef):
        if atom.args == (time,):
            functions[atom] = unknowns.at(atom.func.__name__, 0)
        elif atom.args == (0,):
            functions[atom] = unknowns.at(atom.func.__name__, 0, True)
        else:
            raise SceneError(f"equation {shown(item)}: {atom} is not an unknown function of "
                             f"{time} (write {atom.func}({time})) or its initial value {atom.func}(0)")
    expr = expr.xreplace(functions)
    if time != TIME:
        expr = expr.xreplace({time: TIME})
    return to_exact(expr, f"equation {shown(item)}")


# ---------------------------------------------------------------------------
# the linear system
# ---------------------------------------------------------------------------
@dataclass
class _Row:
    """One equation of motion: coefficients by (coordinate, order), and its force."""

    coefficients: dict[tuple[str, int], sp.Expr]
    force: sp.Expr
    source: str

    def second_order(self) -> list[str]:
        return [name for (name, order), c in self.coefficients.items() if order == 2 and c != 0]


def _row(statement: _Statement, unknowns: _Unknowns) -> _Row:
    coefficients: dict[tuple[str, int], sp.Expr] = {}
    rest = []
    for term in sp.Add.make_args(statement.expr):
        factors = sp.Mul.make_args(term)
        inside = [unknowns.has_initial(f) or unknowns.has_motion(f) for f in factors]
        if not any(inside):
            rest.append(term)
            continue
        core = sp.Mul(*(f for f, flag in zip(factors, inside) if flag))
        coefficient = sp.Mul(*(f for f, flag in zip(factors, inside) if not flag))
        info = unknowns.info(core)
        if info is None:
            raise SceneError(f"equation {shown(statement.source)}: the term {unknowns.shown(term)} is "
                             "not linear in the unknowns (only constant multiples of x, x' and x'' "
                             "are allowed: a linear system M x'' + C x' + K x = f(t))")
        name, order, _ = info
        if order > 2:
            raise SceneError(f"equation {shown(statement.source)}: {_written(name, order)} is a derivative "
                             f"of order {order}; only second-order systems M x'' + C x' + K x = f(t) "
                             "are solved")
        if coefficient.has(TIME):
            raise SceneError(f"equation {shown(statement.source)}: the coefficient {coefficient} of "
                             f"{_written(name, order)} depends on t; only constant coefficients are solved")
        coefficients[name, order] = coefficients.get((name, order), sp.S.Zero) + coefficient
    where = f"equation {shown(statement.source)}"
    for (name, order), coefficient in coefficients.items():  # each within the limits of a number
        coefficients[name, order] = to_exact(coefficient, f"{where}: the coefficient of {_written(name, order)}")
    force = -sp.Add(*rest)
    return _Row(coefficients, to_exact(force, f"{where}: the force") if force != 0 else force,
                statement.source)


def _order_coordinates(rows: list[_Row], unknowns: _Unknowns,
                       coordinates: Sequence[str] | None) -> list[str]:
    """Coordinates: as declared, else each equation's own x'' in equation order, then the
    others as they first appear."""
    used = [name for name in unknowns.names
            if any(key[0] == name for row in rows for key in row.coefficients)]
    if coordinates is not None:
        names = [str(name) for name in coordinates]
        missing = [name for name in used if name not in names]
        if missing:
            raise SceneError(f"{', '.join(missing)} appear in the equations but not in "
                             f"coordinates={names}")
        return names
    owned = [row.second_order()[0] for row in rows if len(row.second_order()) == 1]
    ordered = list(dict.fromkeys(owned))
    return ordered + [name for name in used if name not in ordered]


def _assign_rows(rows: list[_Row], names: list[str]) -> list[_Row]:
    """Rows permuted so that row j is the equation of coordinate j (its one x_j'')."""
    if len(rows) < len(names):
        owned = {row.second_order()[0] for row in rows if len(row.second_order()) == 1}
        without = [name for name in names if name not in owned] or names[len(rows):]
        raise SceneError(f"{len(names)} coordinates ({', '.join(names)}) but {len(rows)} equations of "
                         f"motion: {', '.join(without)} {'has' if len(without) == 1 else 'have'} no "
                         "equation")
    if len(rows) > len(names):
        raise SceneError(f"{len(rows)} equations of motion for {len(names)} coordinates "
                         f"({', '.join(names)}): one equation per coordinate")
    placed: list[_Row | None] = [None] * len(names)
    free = []
    for row in rows:
        own = row.second_order()
        index = names.index(own[0]) if len(own) == 1 and own[0] in names else None
        if index is not None and placed[index] is None:
            placed[index] = row
        else:
            free.append(row)
    for index in range(len(names)):
        if placed[index] is None:
            placed[index] = free.pop(0)
    return [row for row in placed if row is not None]


def _normalised_sign(row: _Row, name: str) -> _Row:
    """The row times -1 when its own leading coefficient (x'', else x', else x) is negative."""
    for order in (2, 1, 0):
        lead = row.coefficients.get((name, order), sp.S.Zero)
        if lead != 0:
            if lead.is_negative:
                return _Row({key: -c for key, c in row.coefficients.items()}, -row.force, row.source)
            return row
    return row


def _initial_values(statements: list[_Statement], unknowns: _Unknowns, names: list[str]
                    ) -> dict[tuple[str, int], sp.Expr]:
    values: dict[tuple[str, int], sp.Expr] = {}
    initial = set(unknowns.initial.values())
    for statement in statements:
        lhs, rhs = statement.lhs, statement.rhs
        if rhs in initial and not unknowns.has_initial(lhs):
            lhs, rhs = rhs, lhs
        info = unknowns.info(lhs)
        if info is None or not info[2] or unknowns.has_initial(rhs) or unknowns.has_motion(rhs):
            raise SceneError(f"initial condition {shown(statement.source)}: write it as "
                             "x1(0) = value or x1'(0) = value")
        name, order, _ = info
        if name not in names:
            raise SceneError(f"initial condition {shown(statement.source)}: {name} is not a coordinate "
                             f"(coordinates: {', '.join(names)})")
        if order > 1:
            raise SceneError(f"initial condition {shown(statement.source)}: {_written(name, order, True)} "
                             f"is not an initial condition of a second-order system; give "
                             f"{name}(0) and {name}'(0)")
        if (name, order) in values:
            raise SceneError(f"initial condition {_written(name, order, True)} is given twice")
        values[name, order] = rhs
    return values


def _vector(given: Any, names: list[str], what: str) -> dict[str, Any]:
    if given is None:
        return {}
    if isinstance(given, Mapping):
        unknown = [str(name) for name in given if str(name) not in names]
        if unknown:
            raise SceneError(f"{what}: {unknown[0]!r} is not a coordinate (coordinates: {', '.join(names)})")
        return {str(name): value for name, value in given.items()}
    values = list(given)
    if len(values) != len(names):
        raise SceneError(f"{what} has {len(values)} entries, expected {len(names)} "
                         f"(one per coordinate: {', '.join(names)})")
    return dict(zip(names, values))


def _initial_column(values: dict[tuple[str, int], sp.Expr], given: dict[str, Any], names: list[str],
                    order: int, inertial: set[str]) -> list[Any]:
    column = []
    for name in names:
        written = _written(name, order, True)
        if (name, order) in values and name in given:
            raise SceneError(f"initial condition {written} is given twice (an equation and "
                             f"{'x0' if order == 0 else 'v0'})")
        if (name, order) in values:
            column.append(values[name, order])
        elif name in given:
            column.append(given[name])
        elif order == 1 and name not in inertial:
            column.append(sp.S.Zero)  # a massless coordinate: its velocity is no initial datum
        else:
            raise SceneError(f"missing initial condition {written} = ... for the coordinate {name} "
                             f"(every coordinate needs {name}(0)" + (f" and {name}'(0))" if order else ")"))
    return column


def _statements(equations: Any, unknowns: _Unknowns, declared: dict[str, sp.Symbol]
                ) -> list[_Statement]:
    items = [equations] if isinstance(equations, (str, sp.Basic)) else list(_items(equations))
    texts = [item for item in items if isinstance(item, str)]
    declared.update(declare_parameters([name for text in texts for name in _text_statements(text)[0]]))
    defined = _defined_names(texts)
    for name in _unknown_names("\n".join(texts), ()):
        if name in declared or name in defined:  # x'' or x(t) of a name that is no unknown
            what = "declared a parameter" if name in declared else "given a value"
            raise SceneError(f"{name!r} is written as an unknown function ({name}'', {name}(t) or "
                             f"{name}[t]) but is {what}; a coordinate is neither")
        unknowns.add(name)
    reader = _TextReader(unknowns, dict(declared))
    out: list[_Statement] = []
    for item in items:
        if isinstance(item, str):
            for statement in _text_statements(item)[1]:
                read = reader.statement(statement)
                if read is not None:
                    out.append(read)
        else:
            out.append(_sympy_statement(item, unknowns))
    for symbol in declare_parameters(None, *(s.expr for s in out)).values():
        if symbol.name not in declared and symbol not in unknowns.all:
            declared[symbol.name] = symbol
    return out


def _coordinate_names(coordinates: object) -> list[str] | None:
    """``coordinates`` as a list of names, or a SceneError (LimitError for too many) saying why."""
    if coordinates is None:
        return None
    if isinstance(coordinates, (str, bytes, Mapping)) or not isinstance(coordinates, Iterable):
        raise SceneError(f"coordinates: expected a list of names such as ['x1', 'x2'], got "
                         f"{shown(coordinates)}")
    names: list[str] = []
    for item in coordinates:
        if len(names) >= limits().max_matrix_input_size:
            raise LimitError(f"coordinates: more than Limits.max_matrix_input_size = "
                             f"{limits().max_matrix_input_size} names (dense input)")
        if not isinstance(item, str) or re.fullmatch(_NAME, item) is None:
            raise SceneError(f"coordinates: a name is a letter, then letters, digits or '_', got "
                             f"{shown(item)}")
        if item in names:
            raise SceneError(f"coordinates: {item!r} is listed twice")
        names.append(item)
    return names


def _items(equations: Any) -> Iterable[Any]:
    if isinstance(equations, (bytes, bytearray, Mapping)) or not isinstance(equations, Iterable):
        raise SceneError(f"equations: expected text, an Eq or a list of them, got {shown(equations)}")
    for item in equations:
        if not isinstance(item, (str, sp.Basic)):
            raise SceneError(f"equations: expected text or SymPy Eq objects, got {shown(item)}")
        yield item


def _defined_names(texts: list[str]) -> list[str]:
    """Names given values in the texts (``k1 = 400``): they are never unknowns."""
    names = []
    for text in texts:
        for statement in _text_statements(text)[1]:
            parts = re.split(r"(==|=)", statement)
            match = _DEFINITION.match(parts[0])
            if match and parts[1:2] == ["="] and "==" not in parts:
                names.append(match.group(1))
    return names


def read_equations(equations: Any, *, parameters: object = None,
                   coordinates: Sequence[str] | None = None, x0: Any = None,
                   v0: Any = None) -> EquationSystem:
    """Read a linear second-order system and its initial conditions from equations.

    Parameters
    ----------
    equations : str, sympy.Eq, or a sequence of them
        Text (one statement per line, or separated by ``;`` or commas; see the module
        docstring for the notations), SymPy ``Eq`` objects or expressions (= 0), or a
        list mixing them. Initial conditions may be among them.
    parameters : sequence or mapping, optional
        Names the text may use as symbols (positive by default; see
        :func:`~laplace_springs.model.numbers.declare_parameters`). Symbols in SymPy
        input are declared by being there.
    coordinates : sequence of str, optional
        The unknown functions in column order (default: each equation's own x'' in the
        order of the equations, then the others as they first appear).
    x0, v0 : sequence or mapping name -> value, optional
        Initial data not given as equations.

    Returns
    -------
    EquationSystem

    Raises
    ------
    SceneError
        For text outside the grammar, and for what the module docstring lists as refused;
        the message quotes the statement.
    LimitError
        For more coordinates than
        :attr:`~laplace_springs.limits.Limits.max_matrix_input_size` (dense input).

    Examples
    --------
    The seed's Example 5 in its Mathematica notation:

    >>> system = read_equations('''
    ...     mu1 = 0.5; mu2 = 1.4; mu3 = 0.9; k1 = 400; k2 = 379; k3 = 100; m1 = 1; m2 = 0.8
    ...     m1*x''[t] + (mu1 + mu2)*x'[t] - mu2*y'[t] + (k1 + k2)*x[t] - k2*y[t] == 0
    ...     m2*y''[t] - mu2*x'[t] + (mu2 + mu3)*y'[t] - k2*x[t] + (k2 + k3)*y[t] == 0
    ...     {x[0] == 0.05, y[0] == 0.07, x'[0] == 3, y'[0] == 2}
    ... ''')
    >>> system.names, system.C, system.K
    (('x', 'y'), [[19/10, -7/5], [-7/5, 23/10]], [[779, -379], [-379, 479]])
    >>> read_equations("x1'' + x1**2 = 0; x1(0) = 1; x1'(0) = 0")
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: equation "x1'' + x1**2 = 0": the term x1**2 is not linear in the unknowns (only constant multiples of x, x' and x'' are allowed: a linear system M x'' + C x' + K x = f(t))
    """
    declared = declare_parameters(parameters)
    coordinates = _coordinate_names(coordinates)
    unknowns = _Unknowns()
    for name in coordinates or ():
        unknowns.add(name)
    statements = _statements(equations, unknowns, declared)
    for statement in statements:
        if unknowns.has_initial(statement.expr) and unknowns.has_motion(statement.expr):
            raise SceneError(f"equation {shown(statement.source)} mixes the unknowns and their "
                             "initial values")
        if not unknowns.has_motion(statement.expr) and not (unknowns.has_initial(statement.lhs)
                                                            or unknowns.has_initial(statement.rhs)):
            raise SceneError(f"equation {shown(statement.source)} has no unknown function (written "
                             "x1, x1', x1'' or x1(t), x1[t]) and no initial value x1(0)")
    rows = [_row(s, unknowns) for s in statements if unknowns.has_motion(s.expr)]
    names = _order_coordinates(rows, unknowns, coordinates)
    if len(names) > limits().max_matrix_input_size:
        raise LimitError(f"{len(names)} coordinates, more than Limits.max_matrix_input_size = "
                         f"{limits().max_matrix_input_size} (dense input); describe a larger scene "
                         "by its masses, springs and dashpots")
    if not names:
        raise SceneError("no equation of motion among the equations")
    rows = [_normalised_sign(row, name) for row, name in zip(_assign_rows(rows, names), names)]
    values = _initial_values([s for s in statements if not unknowns.has_motion(s.expr)],
                             unknowns, names)
    inertial = {name for row in rows for name in row.second_order()}
    matrix = [[[row.coefficients.get((name, order), sp.S.Zero) for name in names] for row in rows]
              for order in (2, 1, 0)]
    forcing = [row.force for row in rows]
    return EquationSystem(
        M=matrix[0], C=matrix[1], K=matrix[2],
        x0=_initial_column(values, _vector(x0, names, "x0"), names, 0, inertial),
        v0=_initial_column(values, _vector(v0, names, "v0"), names, 1, inertial),
        forcing=None if all(f == 0 for f in forcing) else forcing,
        names=tuple(names), parameters=declared)
