"""Exact numbers for scenes, and a safe parser for the expressions users type.

Every number that enters a scene passes through :func:`to_exact`, which returns
an exact SymPy expression: integers stay integers, decimals become the rationals
they denote (``0.2`` is ``1/5``, not the binary float nearest to it), and text is
read by :func:`parse_expression`, a small hand-written parser that builds SymPy
objects directly. Text is never handed to ``eval``, ``exec``, ``sympify`` or
``parse_expr``, so a scene file cannot run code.

Grammar of :func:`parse_expression` (``^`` is a synonym of ``**``)::

    expression := term (("+" | "-") term)*
    term       := unary (("*" | "/") unary)*
    unary      := ("+" | "-") unary | power
    power      := atom (("**" | "^") unary)?          # right-associative
    atom       := NUMBER | NAME | NAME "(" arguments ")" | "(" expression ")"
    arguments  := expression ("," expression)*

so ``-2**2`` is ``-4``, ``2**3**2`` is ``512`` and ``2**-1`` is ``1/2``.
"""

from __future__ import annotations

import decimal
import fractions
import math
import numbers
import re
import reprlib
from collections.abc import Callable, Iterable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from types import MappingProxyType

import numpy
import sympy

from ..limits import limits
from .errors import SceneError
from .symbols import TIME, reserved_name_message

__all__ = [
    "ALLOWED_FUNCTIONS",
    "ARITY",
    "CONSTANTS",
    "TRANSCENDENTAL",
    "NOT_FINITE_REAL",
    "ASSUMPTIONS",
    "MAX_MAGNITUDE",
    "TIME",
    "check_depth",
    "declare_parameters",
    "generic_values",
    "shown",
    "parse_expression",
    "split_unit",
    "to_exact",
]

#: Functions a scene expression may call, by the name used in the text.
ALLOWED_FUNCTIONS: Mapping[str, Callable[..., sympy.Expr]] = MappingProxyType(
    {
        "sqrt": sympy.sqrt,
        "exp": sympy.exp,
        "sin": sympy.sin,
        "cos": sympy.cos,
        "sinh": sympy.sinh,
        "cosh": sympy.cosh,
        "Heaviside": sympy.Heaviside,
        "DiracDelta": sympy.DiracDelta,
        "Abs": sympy.Abs,
    }
)

#: Named constants.
CONSTANTS: Mapping[str, sympy.Expr] = MappingProxyType({"pi": sympy.pi, "E": sympy.E})
#: Numbers exact algebra takes as unknowns over the field of the algebraic ones
#: (transcendental: Lindemann for π, Hermite for e; taken as independent of each other).
TRANSCENDENTAL: tuple[sympy.Expr, ...] = (sympy.pi, sympy.E, sympy.EulerGamma, sympy.Catalan)

#: Arguments each allowed function takes in text, (fewest, most). SymPy's optional extra
#: arguments are not text: ``sqrt(4, 0)`` would pass 0 as SymPy's ``evaluate`` flag and
#: ``Heaviside(t - 1, 5)`` would make 5 the step's value at its jump.
#: ``DiracDelta(t, k)``, the k-th derivative of an impulse, is read and refused later
#: with its reason.
ARITY: Mapping[str, tuple[int, int]] = MappingProxyType({
    "sqrt": (1, 1), "exp": (1, 1), "sin": (1, 1), "cos": (1, 1), "sinh": (1, 1), "cosh": (1, 1),
    "Heaviside": (1, 1), "DiracDelta": (1, 2), "Abs": (1, 1)})

#: Names refused in text (any case): they would read as a number that is not finite and
#: real (SymPy's nan, oo, zoo, the imaginary unit I), never as a parameter.
NOT_FINITE_REAL = frozenset({"nan", "inf", "infinity", "oo", "zoo", "i", "j"})



#: Largest magnitude of a number; nonzero numbers must also exceed ``1/MAX_MAGNITUDE``.
#: Float64 evaluation cannot honour more (``exp(10**6)`` or a 4,001-digit stiffness
#: is refused before any work is done).
MAX_MAGNITUDE = sympy.Integer(10) ** 300

#: Assumptions a declared parameter may carry, by the word that declares them.
#: A parameter declared without one (or with a description) is positive.
ASSUMPTIONS: Mapping[str, Mapping[str, bool]] = MappingProxyType({
    "positive": MappingProxyType({"positive": True}),
    "nonnegative": MappingProxyType({"nonnegative": True}),
    "real": MappingProxyType({"real": True}),
    "negative": MappingProxyType({"negative": True}),
})

#: SymPy's other assumption words: refused as a declaration, never read as a description
#: (which would declare the parameter positive: ``"complex"`` or ``"integer"`` silently so).
UNSUPPORTED_ASSUMPTIONS = frozenset({
    "algebraic", "antihermitian", "commutative", "complex", "composite", "even", "extended_negative",
    "extended_nonnegative", "extended_nonpositive", "extended_nonzero", "extended_positive",
    "extended_real", "finite", "hermitian", "imaginary", "infinite", "integer", "irrational",
    "noninteger", "nonpositive", "nonzero", "odd", "polar", "prime", "rational", "transcendental",
    "zero"})

#: Largest |argument| of exp, sinh and cosh, and of sin and cos, in text (checked at a
#: generic value of the parameters): ``exp(exp(exp(10)))`` is refused as it is read.
MAX_ARGUMENT = MappingProxyType({"exp": 10_000, "sinh": 10_000, "cosh": 10_000,
                                 "sin": 10**300, "cos": 10**300})

_NON_FINITE = (sympy.nan, sympy.zoo, sympy.oo, -sympy.oo)
_MAX_BITS = int(limits().max_digits * math.log2(10)) + 1
_REPR = reprlib.Repr()
_REPR.maxlevel, _REPR.maxstring, _REPR.maxother, _REPR.maxlist = 3, 80, 80, 8

_NUMBER = re.compile(r"(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*")
_OPERATORS = ("**", "+", "-", "*", "/", "^", "(", ")", ",")
#: Operators of text with unknown functions (equations of motion): primes ``x''``,
#: Mathematica's brackets ``x[t]``, and the method call ``x(t).diff(t)``.
_UNKNOWN_OPERATORS = ("'", "[", "]", ".")

#: Builds the value of an unknown function as written: (derivative order, argument or
#: None for a bare name) -> expression. See :func:`parse_expression`'s ``unknowns``.
UnknownFunction = Callable[[int, "sympy.Expr | None"], sympy.Expr]


def _shorten(text: str, limit: int = 80) -> str:
    """``repr`` of ``text``, cut to about ``limit`` characters."""
    return repr(text) if len(text) <= limit else repr(text[:limit]) + "..."


def shown(value: object) -> str:
    """A short ``repr`` of any value for error messages: long, deep or huge values are cut.

    Examples
    --------
    >>> shown("x" * 200)
    "'xxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx...xxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx'"
    >>> nested = [1]
    >>> for _ in range(10_000):
    ...     nested = [nested]
    >>> shown(nested)
    '[[[[...]]]]'
    """
    if isinstance(value, int) and not isinstance(value, bool) and value.bit_length() > _MAX_BITS:
        return f"<an integer of {value.bit_length()} bits>"
    try:
        return _REPR.repr(value)
    except (RecursionError, ValueError):  # ValueError: int too large to print
        return f"<{type(value).__name__}>"


@dataclass(frozen=True)
class _Token:
    kind: str  # "number", "name", "op" or "end"
    text: str
    column: int  # 1-based


class _ParseError(Exception):
    """Internal: a syntax error at a column; turned into a SceneError."""

    def __init__(self, reason: str, column: int, hint: str = "") -> None:
        super().__init__(reason)
        self.reason = reason
        self.column = column
        self.hint = hint


def _tokenize(text: str, units: bool = False, extra: tuple[str, ...] = ()) -> list[_Token]:
    """Split ``text`` into tokens, refusing every character outside the grammar.

    With ``units``, a number may touch a letter (``2.5N/cm``) and the first character
    outside the grammar ends the tokens with a ``"rest"`` token (the text of a unit).
    ``extra`` operators are accepted too (:data:`_UNKNOWN_OPERATORS` for equations).
    """
    tokens: list[_Token] = []
    position = 0
    while position < len(text):
        char = text[position]
        if char.isspace():
            position += 1
            continue
        number = _NUMBER.match(text, position)
        match = number or _NAME.match(text, position)
        if match:
            kind = "number" if number else "name"
            end = match.end()
            touching = units and number is not None and text[end:end + 1].isalpha()
            if end < len(text) and (text[end].isalnum() or text[end] in "_.") and not touching:
                raise _ParseError(f"unexpected character {text[end]!r}", end + 1)
            tokens.append(_Token(kind, match.group(), position + 1))
            position = end
            continue
        operator = next((op for op in (*_OPERATORS, *extra) if text.startswith(op, position)), None)
        if operator is None and units:
            tokens.append(_Token("rest", text[position:], position + 1))
            break
        if operator is None:
            raise _ParseError(f"unexpected character {char!r}", position + 1)
        tokens.append(_Token("op", operator, position + 1))
        position += len(operator)
    tokens.append(_Token("end", "", len(text) + 1))
    return tokens


def _literal_value(token: _Token) -> sympy.Rational:
    """The exact rational a number literal denotes."""
    mantissa, _, exponent = token.text.lower().partition("e")
    digits = len(mantissa.replace(".", "").lstrip("0"))
    if digits > limits().max_digits:
        raise _ParseError(f"number with {digits} digits, more than {limits().max_digits}", token.column)
    if exponent and abs(int(exponent)) > limits().max_literal_exponent:
        raise _ParseError(
            f"exponent {exponent} is beyond +-{limits().max_literal_exponent}", token.column
        )
    value = fractions.Fraction(token.text)
    return sympy.Rational(value.numerator, value.denominator)


def _checked_power(base: sympy.Expr, exponent: sympy.Expr, column: int) -> sympy.Expr:
    """``base**exponent``, refusing exact powers too large to build."""
    if base.is_Rational and exponent.is_Rational and abs(base) not in (0, 1):
        size = max(abs(base.p).bit_length(), base.q.bit_length())
        if abs(exponent) * size > _MAX_BITS + size:
            raise _ParseError(f"power {base}**{exponent} would have more than {limits().max_digits} digits "
                              f"(the limit Limits.max_digits)", column)
    return sympy.Pow(base, exponent)


def _check_arity(name: str, count: int, column: int) -> None:
    """Refuse a call of an allowed function with a number of arguments outside :data:`ARITY`."""
    fewest, most = ARITY.get(name, (0, count))
    if not fewest <= count <= most:
        wanted = str(fewest) if fewest == most else f"{fewest} or {most}"
        raise _ParseError(f"cannot call {name} with {count} argument(s): {name} takes {wanted} "
                          f"argument{'s' if most > 1 else ''} in text", column)


class _Parser:
    """Recursive-descent parser over a token list (see the module grammar)."""

    def __init__(
        self,
        tokens: list[_Token],
        functions: Mapping[str, Callable[..., sympy.Expr]],
        variables: Mapping[str, sympy.Expr],
        unknowns: Mapping[str, UnknownFunction] | None = None,
    ) -> None:
        self.tokens = tokens
        self.index = 0
        self.depth = 0
        self.functions = functions
        self.variables = variables
        self.unknowns = unknowns

    # -- token helpers -------------------------------------------------
    @property
    def current(self) -> _Token:
        return self.tokens[self.index]

    def _accept(self, *ops: str) -> _Token | None:
        token = self.current
        if token.kind == "op" and token.text in ops:
            self.index += 1
            return token
        return None

    def _expect(self, op: str) -> None:
        if self._accept(op) is None:
            raise _ParseError(f"expected {op!r}, found {self._describe()}", self.current.column)

    def _describe(self) -> str:
        token = self.current
        return "end of text" if token.kind == "end" else repr(token.text)

    @contextmanager
    def _nested(self) -> Iterator[None]:
        """Count one level of nesting while the body runs."""
        self.depth += 1
        if self.depth > limits().max_nesting_depth:
            raise _ParseError(f"nesting deeper than {limits().max_nesting_depth}", self.current.column)
        yield
        self.depth -= 1

    # -- grammar -------------------------------------------------------
    def parse(self) -> sympy.Expr:
        value = self.expression()
        if self.current.kind != "end":
            raise _ParseError(f"unexpected {self._describe()}", self.current.column)
        return value

    def parse_with_unit(self) -> tuple[sympy.Expr, int | None]:
        """The expression, and the column where the unit written after it starts (or None)."""
        value = self.expression()
        token = self.current
        if token.kind == "end":
            return value, None
        if token.kind in ("name", "number", "rest"):  # juxtaposed: "5 cm", "2.5N/cm", "3 1/s"
            return value, token.column
        raise _ParseError(f"unexpected {self._describe()}", token.column)

    def expression(self) -> sympy.Expr:
        value = self.term()
        while (token := self._accept("+", "-")) is not None:
            right = self.term()
            value = value + right if token.text == "+" else value - right
        return value

    def term(self) -> sympy.Expr:
        value = self.unary()
        while (token := self._accept("*", "/")) is not None:
            right = self.unary()
            if token.text == "/" and right == 0:
                raise _ParseError("division by zero", token.column)
            value = value * right if token.text == "*" else value / right
        return value

    def unary(self) -> sympy.Expr:
        token = self._accept("+", "-")
        if token is None:
            return self.power()
        with self._nested():
            operand = self.unary()
        return -operand if token.text == "-" else operand

    def power(self) -> sympy.Expr:
        base = self.atom() if self.unknowns is None else self.method_calls(self.atom())
        token = self._accept("**", "^")
        if token is None:
            return base
        with self._nested():
            exponent = self.unary()
        return _checked_power(base, exponent, token.column)

    def atom(self) -> sympy.Expr:
        token = self.current
        if token.kind == "number":
            self.index += 1
            return _literal_value(token)
        if token.kind == "name":
            self.index += 1
            return self.name(token)
        if self._accept("(") is not None:
            with self._nested():
                value = self.expression()
                self._expect(")")
            return value
        raise _ParseError(f"expected a number, name or '(', found {self._describe()}", token.column)

    def name(self, token: _Token) -> sympy.Expr:
        name = token.text
        if self.unknowns is not None and name in self.unknowns:
            return self.unknown(token)
        if name in self.functions:
            return self.call(token)
        if self.current.kind == "op" and self.current.text == "(":
            known = ", ".join(sorted(self.functions))
            raise _ParseError(f"unknown function {name!r} (allowed: {known})", token.column)
        if name in self.variables:
            return self.variables[name]
        if name in CONSTANTS:
            return CONSTANTS[name]
        if name.lower() in NOT_FINITE_REAL:
            raise _ParseError(f"{name!r} is not a finite real number", token.column)
        raise _ParseError(f"unknown name {name!r}", token.column, _undeclared(name, self.variables))

    def call(self, token: _Token) -> sympy.Expr:
        if self._accept("(") is None:
            raise _ParseError(f"function {token.text!r} must be called, as {token.text}(...)", token.column)
        with self._nested():
            arguments = [self.expression()]
            while self._accept(",") is not None:
                arguments.append(self.expression())
            self._expect(")")
        _check_arity(token.text, len(arguments), token.column)
        limit = MAX_ARGUMENT.get(token.text)
        if limit is not None and len(arguments) == 1:
            size = _magnitude(arguments[0])
            if size is not None and size > limit:
                symbols = arguments[0].free_symbols
                where = f" at {_shown_values(generic_values(symbols))}" if symbols else ""
                raise _ParseError(f"the argument of {token.text} has magnitude {_order(size)}{where}, "
                                  f"beyond {_order(sympy.Integer(limit))}", token.column)
        try:
            return self.functions[token.text](*arguments)
        except (TypeError, ValueError) as exc:
            raise _ParseError(f"cannot call {token.text} with {len(arguments)} argument(s): {exc}",
                              token.column) from exc

    # -- unknown functions (equations of motion) ---------------------------
    def unknown(self, token: _Token) -> sympy.Expr:
        """``x``, ``x'``, ``x''(t)``, ``x'[0]``: primes, then an optional argument."""
        order = 0
        while self._accept("'") is not None:
            order += 1
        argument = None
        opening = self._accept("(", "[")
        if opening is not None:
            with self._nested():
                argument = self.expression()
                self._expect(")" if opening.text == "(" else "]")
        assert self.unknowns is not None
        try:
            return self.unknowns[token.text](order, argument)
        except ValueError as exc:  # SceneError from the builder: where it was written
            raise _ParseError(str(exc), token.column) from None

    def method_calls(self, value: sympy.Expr) -> sympy.Expr:
        """``value.f(arguments)`` as ``f(value, arguments)``, for allowed functions ``f``
        (``x1(t).diff(t)``)."""
        while (dot := self._accept(".")) is not None:
            method = self.current
            if method.kind != "name" or method.text not in self.functions:
                known = ", ".join(sorted(self.functions))
                raise _ParseError(f"expected a method after '.' (one of {known}), found "
                                  f"{self._describe()}", dot.column)
            self.index += 1
            self._expect("(")
            with self._nested():
                arguments = [value, self.expression()]
                while self._accept(",") is not None:
                    arguments.append(self.expression())
                self._expect(")")
            _check_arity(method.text, len(arguments), method.column)
            try:
                value = self.functions[method.text](*arguments)
            except (TypeError, ValueError) as exc:
                raise _ParseError(f"cannot call .{method.text} with {len(arguments) - 1} argument(s): "
                                  f"{exc}", method.column) from exc
        return value


def parse_expression(
    text: str,
    entry: str,
    *,
    allowed_functions: Mapping[str, Callable[..., sympy.Expr]] = ALLOWED_FUNCTIONS,
    variables: Mapping[str, sympy.Expr] | None = None,
    expected: str = "a number",
    unknowns: Mapping[str, UnknownFunction] | None = None,
) -> sympy.Expr:
    """Parse an arithmetic expression into an exact SymPy expression, safely.

    Parameters
    ----------
    text : str
        The expression, e.g. ``"0.2"``, ``"-1.5e-3"``, ``"k1 + k2/2"``.
    entry : str
        What the text is, for error messages, e.g. ``"K[0,1]"``.
    allowed_functions : mapping of str to callable, optional
        Functions that may be called, by name (default :data:`ALLOWED_FUNCTIONS`).
    variables : mapping of str to sympy.Expr, optional
        The names the text may use besides ``t`` (:data:`TIME` unless given here) and
        the constants ``pi`` and ``E``: the declared parameters (see
        :func:`declare_parameters`). Any other name is refused.
    expected : str, optional
        What the text should be, for error messages (``"an expression in t"``).
    unknowns : mapping of str to callable, optional
        Unknown functions of an equation of motion, by name: ``x1``, ``x1'``,
        ``x1''(t)``, ``x1(0)``, Mathematica's ``x'[t]`` (primes, then an optional argument
        in parentheses or brackets) become ``unknowns["x1"](order, argument)``
        (argument None for a bare name); a value may be followed by ``.f(...)`` for an
        allowed function f (``x1(t).diff(t)`` is ``diff(x1(t), t)``). Only the
        characters ``' [ ] .`` are added to the grammar, and only with ``unknowns``.

    Returns
    -------
    sympy.Expr
        The exact value: decimal literals become Rationals.

    Raises
    ------
    SceneError
        On any text outside the grammar, naming ``entry``, the text and the column;
        on an undeclared name, a division by zero, a non-finite result, or a number
        beyond the limits :attr:`~laplace_springs.limits.Limits.max_digits` and :data:`MAX_MAGNITUDE`.

    Notes
    -----
    The parser is hand-written and builds SymPy objects directly; the text is
    never evaluated. Text longer than :attr:`~laplace_springs.limits.Limits.max_expression_length` characters
    or nested deeper than :attr:`~laplace_springs.limits.Limits.max_nesting_depth` is refused.

    Examples
    --------
    >>> parse_expression("0.2", "k1")
    1/5
    >>> parse_expression("-2**2 + 3/6", "x0[0]")
    -7/2
    >>> k1, k2 = sympy.symbols("k1 k2", positive=True)
    >>> parse_expression("k1 + k2/2", "K[0,0]", variables={"k1": k1, "k2": k2})
    k1 + k2/2
    >>> parse_expression("k3", "K[0,0]", variables={"k1": k1, "k2": k2})
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: K[0,0]: expected a number, got 'k3': unknown name 'k3' at column 1 (declared parameters: k1, k2; to make 'k3' a parameter, declare it: parameters=['k3'], or a [parameters] table in a scene file)
    >>> parse_expression("__import__('os')", "M[0,0]")
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: M[0,0]: expected a number, got "__import__('os')": unexpected character '_' at column 1
    """
    value, _ = _parse_text(text, entry, allowed_functions, variables, expected, units=False,
                           unknowns=unknowns)
    return value


def split_unit(
    text: str,
    entry: str,
    *,
    allowed_functions: Mapping[str, Callable[..., sympy.Expr]] = ALLOWED_FUNCTIONS,
    variables: Mapping[str, sympy.Expr] | None = None,
    expected: str = "a number",
) -> tuple[sympy.Expr, str]:
    """Split text such as ``"2.5 N/cm"`` into its exact value and the text of its unit.

    The value is read as :func:`parse_expression` reads text; it ends where a name, a
    number or a character outside the grammar follows it without an operator, and the
    rest of the text (stripped) is the unit, ``""`` when there is none. Only the unit
    text goes to a units library (see :mod:`laplace_springs.model.units`).

    Examples
    --------
    >>> split_unit("2.5 N/cm", "spring 'k1'")
    (5/2, 'N/cm')
    >>> split_unit("10*cos(3*t) N", "forcing[0]")
    (10*cos(3*t), 'N')
    >>> split_unit("0.5s", "times[1]"), split_unit("1/20", "x0[0]"), split_unit("3 µm", "x0[1]")
    ((1/2, 's'), (1/20, ''), (3, 'µm'))
    >>> split_unit("2 * kg", "mass 'm1'")
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: mass 'm1': expected a number, got '2 * kg': unknown name 'kg' at column 5 (to make 'kg' a parameter, declare it: parameters=['kg'], or a [parameters] table in a scene file)
    """
    value, column = _parse_text(text, entry, allowed_functions, variables, expected, units=True)
    return value, "" if column is None else text[column - 1:].strip()


def _parse_text(
    text: str,
    entry: str,
    allowed_functions: Mapping[str, Callable[..., sympy.Expr]],
    variables: Mapping[str, sympy.Expr] | None,
    expected: str,
    units: bool,
    unknowns: Mapping[str, UnknownFunction] | None = None,
) -> tuple[sympy.Expr, int | None]:
    """The checked value of ``text`` and, with ``units``, the column where its unit starts."""
    if not isinstance(text, str):
        raise SceneError(f"{entry}: expected text, got {text!r}")
    if len(text) > limits().max_expression_length:
        raise SceneError(
            f"{entry}: expression has {len(text)} characters, more than {limits().max_expression_length}"
        )
    names = {"t": TIME, **(variables or {})}
    column = None
    try:
        tokens = _tokenize(text, units, _UNKNOWN_OPERATORS if unknowns is not None else ())
        if tokens[0].kind == "end":
            raise _ParseError("the text is empty", 1)
        parser = _Parser(tokens, allowed_functions, names, unknowns)
        if units:
            value, column = parser.parse_with_unit()
        else:
            value = parser.parse()
    except _ParseError as exc:
        hint = f" ({exc.hint})" if exc.hint else ""
        raise SceneError(
            f"{entry}: expected {expected}, got {_shorten(text)}: {exc.reason} at column {exc.column}{hint}"
        ) from None
    finite = _require_finite(value, entry, text)
    # with unknowns, the size of each coefficient is checked where the equation is split
    # (laplace_springs.model.equations): a side such as 1e300*x + 1e300*x' has no one size
    return _require_bounded(finite, entry, _shorten(text), check_size=unknowns is None), column


def _undeclared(name: str, variables: Mapping[str, sympy.Expr]) -> str:
    """How to declare an undeclared ``name``, and which names are declared."""
    declared = sorted(key for key in variables if key != "t")
    listed = f"declared parameters: {', '.join(declared)}; " if declared else ""
    return (f"{listed}to make {name!r} a parameter, declare it: parameters=[{name!r}], "
            f"or a [parameters] table in a scene file")


def _digits_ok(value: sympy.Rational) -> bool:
    return max(abs(value.p).bit_length(), value.q.bit_length()) <= _MAX_BITS


def _magnitude(value: sympy.Expr) -> sympy.Expr | None:
    """|value| as a SymPy number, exactly for rationals, else to 15 digits; None if unknown."""
    if value.is_Rational:
        return abs(value)
    if value.free_symbols:
        value = value.xreplace(_magnitude_values(value))
    try:
        number = sympy.Abs(value).evalf(15, maxn=400)
    except (ValueError, TypeError, ArithmeticError, RecursionError):
        return None
    return number if number.is_Number else None


#: Above this integer exponent of an expression in symbols, :func:`_magnitude` puts
#: 50-digit floats in place of the generic rationals: ``t**1000000`` at t = 97/89 is a
#: rational of 13 million bits (5 s to form and divide), its float is formed at once.
_EXACT_POWER = 1000


def _magnitude_values(value: sympy.Expr) -> dict[sympy.Symbol, sympy.Expr]:
    """The generic values of ``value``'s symbols: exact, or as floats for huge powers."""
    exact = generic_values(value.free_symbols)
    if any(power.exp.is_Integer and abs(power.exp) > _EXACT_POWER for power in value.atoms(sympy.Pow)):
        return {symbol: sympy.Float(number, 50) for symbol, number in exact.items()}
    return exact


def _shown_values(values: Mapping[sympy.Symbol, sympy.Expr]) -> str:
    """``t = 97/89, k = 55/48``: the generic values a magnitude was taken at."""
    return ", ".join(f"{symbol} = {number}" for symbol, number in values.items())


def _order(number: sympy.Expr) -> str:
    """A positive number in a few digits, cheaply even for 10**(10**4)."""
    if number.is_Rational:
        bits = abs(number.p).bit_length() - number.q.bit_length()
    else:
        _, mantissa, exponent, _ = sympy.Float(number, 3)._mpf_
        bits = exponent + mantissa.bit_length()
    if abs(bits) < 3000:
        return str(sympy.Float(number, 3)).lower()
    return f"about 1e{round(bits * math.log10(2)):+d}"


def _require_bounded(value: sympy.Expr, entry: str, shown_value: str, check_size: bool = True) -> sympy.Expr:
    """``value`` unless a number in it exceeds :attr:`~laplace_springs.limits.Limits.max_digits` or
    (with ``check_size``) its size is beyond :data:`MAX_MAGNITUDE`."""
    for rational in value.atoms(sympy.Rational):
        if not _digits_ok(rational):
            raise SceneError(f"{entry}: {shown_value} has a number of more than {limits().max_digits} digits "
                             f"(the limit Limits.max_digits)")
    if not check_size:
        return value
    if value.is_Rational and value != 0 and 1 / MAX_MAGNITUDE <= abs(value) <= MAX_MAGNITUDE:
        return value
    try:
        magnitude = _magnitude(value)
    except (ValueError, TypeError, IndexError, AttributeError, ArithmeticError) as exc:
        # SymPy objects that are not numbers in a parameter, say Derivative(k**2, k),
        # Lambda(k, k), O(k): SymPy's own error on substituting a value
        raise SceneError(f"{entry}: {shown_value} is not a number or an expression in the parameters "
                         f"(SymPy cannot evaluate it: {type(exc).__name__}: {exc})") from None
    if magnitude is None or magnitude.is_zero:
        return value
    if not 1 / MAX_MAGNITUDE <= magnitude <= MAX_MAGNITUDE:
        where = f" at {_shown_values(generic_values(value.free_symbols))}" if value.free_symbols else ""
        raise SceneError(f"{entry}: {shown_value} has magnitude {_order(magnitude)}{where}, beyond "
                         f"the limit 1e-300 <= |value| <= 1e300 (MAX_MAGNITUDE) that float64 "
                         f"evaluation can honour")
    return value


def _require_finite(value: sympy.Expr, entry: str, shown: object) -> sympy.Expr:
    """``value`` unless it is or contains NaN, an infinity, the imaginary unit, a number
    that is not real (``(-8)**(1/3)`` is ``1 + i√3``) or an impulse at a fixed instant
    (``DiracDelta(0)``: not a finite number)."""
    if value.has(*_NON_FINITE):
        raise SceneError(f"{entry}: expected a finite number, got {shown!r}")
    if value.has(sympy.I):
        raise SceneError(f"{entry}: expected a real number, got {shown!r}")
    complex_part = _complex_part(value)
    if complex_part is not None:
        raise SceneError(f"{entry}: expected a real number, got {shown!r} ({complex_part} is not real; "
                         f"a root of a negative number is complex in SymPy, as in Python)")
    for impulse in value.atoms(sympy.DiracDelta):
        if not any(getattr(symbol, "name", None) == TIME.name for symbol in impulse.args[0].free_symbols):
            raise SceneError(f"{entry}: {impulse} in {shown!r} is not a finite number (an impulse "
                             f"is DiracDelta(t - tau), a function of the time t)")
    return value


def _complex_part(value: sympy.Expr) -> sympy.Expr | None:
    """A constant part of ``value`` (the whole, or a power in it) that is not real, or None.

    SymPy says so for ``(-1)**(1/3)``; where it cannot tell (``(-1)**pi``) the part is
    evaluated to 30 digits and its imaginary part compared with its size.
    """
    parts = [value] if value.is_number else [power for power in value.atoms(sympy.Pow) if power.is_number]
    for part in parts:
        try:
            real = part.is_extended_real
            if real is None:
                number = sympy.N(part, 30, maxn=400)
                imaginary = abs(sympy.im(number))
                real = not (imaginary.is_Number and imaginary > abs(number) * sympy.Float("1e-25"))
        except (ValueError, TypeError, IndexError, AttributeError, ArithmeticError, RecursionError):
            real = True  # not a number SymPy can evaluate: the magnitude check says so
        if real is False:
            return part
    return None


def _fraction_to_rational(value: fractions.Fraction) -> sympy.Rational:
    return sympy.Rational(value.numerator, value.denominator)


def _decimal_text_to_rational(text: str, entry: str, shown: object) -> sympy.Rational:
    """The exact rational of a decimal string such as ``'0.2'`` or ``'1e-300'``."""
    try:
        value = decimal.Decimal(text)
    except decimal.InvalidOperation:
        raise SceneError(f"{entry}: expected a number, got {shown!r}") from None
    return _decimal_to_rational(value, entry, shown)


def _decimal_to_rational(value: decimal.Decimal, entry: str, shown: object) -> sympy.Rational:
    exponent = value.as_tuple().exponent  # 'n', 'N' or 'F' for NaN and infinities
    if not value.is_finite() or not isinstance(exponent, int):
        raise SceneError(f"{entry}: expected a finite number, got {shown!r}")
    if abs(exponent) > limits().max_literal_exponent + 100:
        raise SceneError(f"{entry}: exponent of {shown!r} is too large to hold exactly")
    return _fraction_to_rational(fractions.Fraction(value))


def check_depth(value: sympy.Basic, entry: str) -> None:
    """Refuse a SymPy expression nested deeper than Limits.max_nesting_depth, as text is
    refused by the parser: SymPy's own recursive walks (``free_symbols``, ``xreplace``)
    fail on it with RecursionError (sin(sin(...)) 500 deep). The walk is iterative.

    Examples
    --------
    >>> deep = TIME
    >>> for _ in range(200):
    ...     deep = sympy.sin(deep, evaluate=False)
    >>> check_depth(deep, "forcing[0]")
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: forcing[0]: the expression is nested more than 100 levels deep (Limits.max_nesting_depth)
    """
    most = limits().max_nesting_depth
    stack: list[tuple[sympy.Basic, int]] = [(value, 1)]
    deepest: dict[int, int] = {}  # a shared subexpression is walked again only deeper
    while stack:
        node, depth = stack.pop()
        if depth > most:
            raise SceneError(f"{entry}: the expression is nested more than {most} levels deep "
                             f"(Limits.max_nesting_depth)")
        if node.args and deepest.get(id(node), 0) < depth:
            deepest[id(node)] = depth
            stack.extend((arg, depth + 1) for arg in node.args)


def _sympy_to_exact(value: sympy.Basic, entry: str) -> sympy.Expr:
    """Pass a SymPy expression through, with every Float made an exact Rational."""
    if not isinstance(value, sympy.Expr) or isinstance(value, sympy.MatrixBase):
        raise SceneError(f"{entry}: expected a number, got {value!r}")
    check_depth(value, entry)
    _require_finite(value, entry, value)
    for symbol in value.free_symbols:
        unfit = _unfit_symbol(symbol)
        if unfit is not None:
            raise SceneError(f"{entry}: {shown(value)}: {unfit}")
    floats = value.atoms(sympy.Float)
    if floats:
        value = value.xreplace({f: _decimal_text_to_rational(str(f), entry, f) for f in floats})
    return value


def to_exact(
    value: object,
    entry: str,
    *,
    parameters: Mapping[str, sympy.Expr] | None = None,
) -> sympy.Expr:
    """Convert a user-supplied number or expression to an exact SymPy expression.

    Parameters
    ----------
    value : int, Fraction, Decimal, float, str or sympy.Expr
        The value. A float means its shortest decimal representation
        (``repr``): ``0.2`` is ``1/5``. Text is read by :func:`parse_expression`.
        SymPy objects pass through, with Floats made exact from their decimal string.
    entry : str
        What the value is, for error messages, e.g. ``"M[1,0]"`` or ``"mass 'm2'"``.
    parameters : mapping of str to sympy.Symbol, optional
        The declared parameters text may name (see :func:`declare_parameters`);
        SymPy objects may hold any Symbol.

    Returns
    -------
    sympy.Expr
        An exact expression: Integer, Rational, or a symbolic expression.

    Raises
    ------
    SceneError
        For booleans, NaN, infinities, complex numbers, text that does not parse or
        names an undeclared parameter, numbers beyond :attr:`~laplace_springs.limits.Limits.max_digits` or
        :data:`MAX_MAGNITUDE`, and any other type; the message names ``entry`` and
        the value.

    Examples
    --------
    >>> to_exact(0.2, "k1")
    1/5
    >>> to_exact(0.1 + 0.2, "k1")
    7500000000000001/25000000000000000
    >>> from fractions import Fraction
    >>> to_exact(Fraction(2, 3), "m2"), to_exact(" 3 ", "m1")
    (2/3, 3)
    >>> to_exact("abc$", "M[1,0]")
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: M[1,0]: expected a number, got 'abc$': unexpected character '$' at column 4
    """
    if isinstance(value, str):
        return parse_expression(value.strip(), entry, variables=parameters)
    return _require_bounded(_exact_of_object(value, entry), entry, shown(value))


def _exact_of_object(value: object, entry: str) -> sympy.Expr:
    """The exact value of a non-text entry (no limits checked yet)."""
    if isinstance(value, (bool, numpy.bool_)):
        raise SceneError(f"{entry}: expected a number, got {value!r}")
    if isinstance(value, sympy.Basic):
        return _sympy_to_exact(value, entry)
    if isinstance(value, numbers.Integral):
        if int(value).bit_length() > _MAX_BITS:
            raise SceneError(f"{entry}: an integer of {int(value).bit_length()} bits has more than "
                             f"{limits().max_digits} digits (the limit Limits.max_digits)")
        return sympy.Integer(int(value))
    if isinstance(value, fractions.Fraction):
        return _fraction_to_rational(value)
    if isinstance(value, decimal.Decimal):
        return _decimal_to_rational(value, entry, value)
    if isinstance(value, float):
        if not math.isfinite(value):
            raise SceneError(f"{entry}: expected a finite number, got {value!r}")
        return _decimal_text_to_rational(repr(float(value)), entry, value)
    if isinstance(value, numbers.Real):  # numpy float32, mpmath mpf, ...: their shortest str
        return _decimal_text_to_rational(str(value), entry, value)
    raise SceneError(f"{entry}: expected a number, got {shown(value)}")


def generic_values(symbols: Iterable[sympy.Symbol]) -> dict[sympy.Symbol, sympy.Rational]:
    """Fixed, unremarkable positive rationals for symbolic parameters, by name order.

    Identities in the parameters (a residual, a determinant that must not vanish) are
    checked at these values.

    Examples
    --------
    >>> a, b = sympy.symbols("a b")
    >>> generic_values([b, a])
    {a: 97/89, b: 55/48}
    """
    return {symbol: sympy.Rational(97 + 13 * i, 89 + 7 * i)
            for i, symbol in enumerate(sorted(symbols, key=lambda symbol: symbol.name))}


def _parameter_name(name: object) -> str:
    """``name`` if it can name a parameter, else a SceneError saying why not."""
    if not isinstance(name, str) or _NAME.fullmatch(name) is None:
        raise SceneError(f"parameter names must be identifiers (a letter, then letters, digits "
                         f"or '_'), got {shown(name)}")
    reserved = reserved_name_message(name)  # t, s, lambda, lam, omega: the toolkit's symbols
    if reserved is not None:
        raise SceneError(reserved)
    if name in ALLOWED_FUNCTIONS or name in CONSTANTS or name.lower() in NOT_FINITE_REAL:
        raise SceneError(f"{name!r} cannot be a parameter name: in text it is {_meaning(name)}; "
                         f"rename the parameter, e.g. '{name}_0'")
    return name


def _meaning(name: str) -> str:
    """What a refused parameter name means in the text syntax."""
    if name in ALLOWED_FUNCTIONS:
        return f"the function {name}(...)"
    if name in CONSTANTS:
        return f"the constant {CONSTANTS[name]}"
    if name.lower() in ("i", "j"):
        return "the imaginary unit (i, j, I and J all are), and a parameter is real"
    return "a number that is not finite and real"


def _parameter_symbol(name: str, declaration: object) -> sympy.Symbol:
    """The Symbol of parameter ``name`` declared by an assumption word or a description."""
    if isinstance(declaration, sympy.Symbol):
        if declaration.name != name:
            raise SceneError(f"parameter {name!r} is declared as the Symbol {declaration.name!r}")
        return declaration
    if declaration is None:
        declaration = "positive"
    if not isinstance(declaration, str):
        raise SceneError(f"parameter {name!r}: expected an assumption ({', '.join(ASSUMPTIONS)}) or "
                         f"a description, got {shown(declaration)}")
    word = declaration.strip().lower()
    if word in UNSUPPORTED_ASSUMPTIONS:
        raise SceneError(f"parameter {name!r}: the assumption {word!r} is not supported; declare one of "
                         f"{', '.join(ASSUMPTIONS)} (or give a description: then it is positive)")
    return sympy.Symbol(name, **ASSUMPTIONS.get(word, ASSUMPTIONS["positive"]))


def declare_parameters(parameters: object = None, *objects: object) -> dict[str, sympy.Symbol]:
    """The declared parameters, name -> Symbol: the names text may use.

    Parameters
    ----------
    parameters : sequence or mapping, optional
        Names (``["k", "c"]``) or SymPy Symbols, positive by default; or a mapping
        from name to an assumption word (one of :data:`ASSUMPTIONS`: ``"positive"``,
        ``"nonnegative"``, ``"real"``, ``"negative"``) or to a free description
        (then positive), as in the ``[parameters]`` table of a scene file.
    *objects
        Values (numbers, SymPy objects, nested lists, matrices) whose SymPy Symbols
        are declared too: a Symbol object is a declaration. A Symbol named ``t`` is time.

    Returns
    -------
    dict of str to sympy.Symbol

    Raises
    ------
    SceneError
        For a name that is not an identifier or is reserved (the toolkit's symbols ``t``,
        ``s``, ``lambda``, ``lam``, ``omega`` of
        :data:`~laplace_springs.model.symbols.RESERVED_NAMES`, whether named or given as a
        Symbol; a function, a constant, ``nan``, ``I`` ...), an unknown declaration, or two different
        Symbols of the same name (say ``Symbol("k")`` and ``Symbol("k", positive=True)``).

    Examples
    --------
    >>> declare_parameters(["k", "c"])
    {'k': k, 'c': c}
    >>> declare_parameters(["k"])["k"].is_positive
    True
    >>> declare_parameters({"a": "real", "k": "stiffness of the spring, N/m"})["a"].is_positive is None
    True
    >>> declare_parameters(["t"])
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: 't' cannot be a parameter name: it is the time (ls.t); rename the parameter, e.g. 't_0'
    >>> declare_parameters(["omega"])
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: 'omega' cannot be a parameter name: it is the driving frequency of ls.frequency_response (ls.omega); rename the parameter, e.g. 'omega_0'
    """
    if isinstance(parameters, (Mapping, list, tuple)) and len(parameters) > limits().max_parameters:
        raise SceneError(f"parameters: {len(parameters):,} declared, more than the limit "
                         f"{limits().max_parameters:,} (Limits.max_parameters)")
    declared: dict[str, sympy.Symbol] = {}
    origins: dict[str, str] = {}
    for symbol in _declarations(parameters):
        _add_parameter(declared, symbol, origins, "declared in parameters")
    for symbol in sorted(_symbols_in(objects), key=lambda symbol: symbol.name):
        _add_parameter(declared, symbol, origins, "a Symbol in the data")
    if len(declared) > limits().max_parameters:
        raise SceneError(f"parameters: {len(declared):,} named or found in the data, more than the "
                         f"limit {limits().max_parameters:,} (Limits.max_parameters)")
    return declared


def _declarations(parameters: object) -> Iterator[sympy.Symbol]:
    if parameters is None:
        return
    if isinstance(parameters, Mapping):
        for name, declaration in parameters.items():
            yield _parameter_symbol(_parameter_name(name), declaration)
        return
    if isinstance(parameters, (str, bytes)) or not isinstance(parameters, Iterable):
        raise SceneError(f"parameters must be a list of names or a mapping name -> assumption, "
                         f"got {shown(parameters)}")
    for item in parameters:
        if isinstance(item, sympy.Symbol):
            yield _parameter_symbol(_parameter_name(item.name), item)
        else:
            yield _parameter_symbol(_parameter_name(item), None)


def _unfit_symbol(symbol: sympy.Basic) -> str | None:
    """Why a SymPy Symbol cannot stand for a real parameter (declared imaginary, not real,
    infinite or noncommutative), or None."""
    if symbol.is_commutative is False:
        return f"the Symbol {symbol} is noncommutative; a parameter is a real number"
    if symbol.is_finite is False:
        return f"the Symbol {symbol} is declared infinite; a parameter is a finite number"
    if symbol.is_real is False:
        return f"the Symbol {symbol} is declared not real; a parameter is a real number"
    return None


def _symbol_text(symbol: sympy.Symbol) -> str:
    """``Symbol('k', positive=True)``: the Symbol with the assumptions it was made with."""
    given = getattr(symbol, "_assumptions_orig", None)
    if given is None:  # an older SymPy: the assumptions that are True, less the implied ones
        given = {key: True for key in ("positive", "nonnegative", "negative", "real", "integer")
                 if symbol.assumptions0.get(key)}
    words = "".join(f", {key}={value!r}" for key, value in sorted(given.items()))
    return f"{type(symbol).__name__}({symbol.name!r}{words})"


def _add_parameter(declared: dict[str, sympy.Symbol], symbol: sympy.Symbol,
                   origins: dict[str, str], origin: str) -> None:
    reserved = reserved_name_message(symbol.name)
    if reserved is not None:  # a Symbol given in the data, say ls.omega or ls.s
        raise SceneError(f"the Symbol {symbol.name!r} in the data: {reserved}")
    unfit = _unfit_symbol(symbol)
    if unfit is not None:
        raise SceneError(f"parameter {symbol.name!r}: {unfit}")
    known = declared.setdefault(symbol.name, symbol)
    first = origins.setdefault(symbol.name, origin)
    if known != symbol:
        hint = (" (a name declared in parameters is positive unless its declaration says "
                "otherwise)" if "declared in parameters" in (first, origin) else "")
        raise SceneError(f"two different Symbols are named {symbol.name!r}: {_symbol_text(known)} "
                         f"({first}) and {_symbol_text(symbol)} ({origin}); use one Symbol for "
                         f"the parameter {symbol.name!r}{hint}")


def _free_symbols(item: sympy.Basic) -> set[sympy.Basic]:
    """``item.free_symbols``, after :func:`check_depth` for an expression; a matrix (whose
    walk would cost a second at 10⁵ coordinates) has SymPy's RecursionError named."""
    where = "a SymPy expression in the data"
    if not isinstance(item, sympy.MatrixBase):
        check_depth(item, where)
        return set(item.free_symbols)
    try:
        return set(item.free_symbols)
    except RecursionError:
        raise SceneError(f"{where}: an entry of a matrix is nested too deeply for SymPy "
                         f"(Limits.max_nesting_depth = {limits().max_nesting_depth} levels)") from None


def _symbols_in(objects: Iterable[object], depth: int = 0) -> set[sympy.Symbol]:
    """The Symbols (but ``t``) of the SymPy objects in nested containers, depth-limited."""
    found: set[sympy.Symbol] = set()
    if depth > 8:
        return found
    for item in objects:
        if isinstance(item, sympy.Basic):
            found |= {symbol for symbol in _free_symbols(item)
                      if isinstance(symbol, sympy.Symbol) and symbol.name != "t"}
        elif isinstance(item, numpy.ndarray):
            if item.dtype == object:
                found |= _symbols_in(item.ravel().tolist(), depth + 1)
        elif isinstance(item, Mapping):
            found |= _symbols_in(item.values(), depth + 1)
        elif isinstance(item, (list, tuple)):
            found |= _symbols_in(item, depth + 1)
    return found
