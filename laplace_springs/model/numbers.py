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
from collections.abc import Callable, Iterable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from types import MappingProxyType

import numpy
import sympy

from .errors import SceneError
from .symbols import TIME

__all__ = [
    "ALLOWED_FUNCTIONS",
    "CONSTANTS",
    "NOT_FINITE_REAL",
    "MAX_EXPRESSION_LENGTH",
    "MAX_NESTING_DEPTH",
    "TIME",
    "generic_values",
    "parse_expression",
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

#: Names refused in text (any case): they would read as a number that is not finite and
#: real (SymPy's nan, oo, zoo, the imaginary unit I), never as a parameter.
NOT_FINITE_REAL = frozenset({"nan", "inf", "infinity", "oo", "zoo", "i", "j"})


#: Longest text accepted by :func:`parse_expression`, in characters.
MAX_EXPRESSION_LENGTH = 10_000
#: Deepest nesting of parentheses, calls, signs and powers accepted.
MAX_NESTING_DEPTH = 100
#: Largest decimal exponent of a number literal (``1e4000`` is refused).
MAX_LITERAL_EXPONENT = 4_000
#: Largest size, in bits, of an exact power of numbers (``2**10**9`` is refused).
MAX_POWER_BITS = 100_000

_NON_FINITE = (sympy.nan, sympy.zoo, sympy.oo, -sympy.oo)
_DEFAULT_ASSUMPTIONS: Mapping[str, bool] = MappingProxyType({"real": True})

_NUMBER = re.compile(r"(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*")
_OPERATORS = ("**", "+", "-", "*", "/", "^", "(", ")", ",")


def _shorten(text: str, limit: int = 80) -> str:
    """``repr`` of ``text``, cut to about ``limit`` characters."""
    return repr(text) if len(text) <= limit else repr(text[:limit]) + "..."


@dataclass(frozen=True)
class _Token:
    kind: str  # "number", "name", "op" or "end"
    text: str
    column: int  # 1-based


class _ParseError(Exception):
    """Internal: a syntax error at a column; turned into a SceneError."""

    def __init__(self, reason: str, column: int) -> None:
        super().__init__(reason)
        self.reason = reason
        self.column = column


def _tokenize(text: str) -> list[_Token]:
    """Split ``text`` into tokens, refusing every character outside the grammar."""
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
            if end < len(text) and (text[end].isalnum() or text[end] in "_."):
                raise _ParseError(f"unexpected character {text[end]!r}", end + 1)
            tokens.append(_Token(kind, match.group(), position + 1))
            position = end
            continue
        operator = next((op for op in _OPERATORS if text.startswith(op, position)), None)
        if operator is None:
            raise _ParseError(f"unexpected character {char!r}", position + 1)
        tokens.append(_Token("op", operator, position + 1))
        position += len(operator)
    tokens.append(_Token("end", "", len(text) + 1))
    return tokens


def _literal_value(token: _Token) -> sympy.Rational:
    """The exact rational a number literal denotes."""
    mantissa, _, exponent = token.text.lower().partition("e")
    if exponent and abs(int(exponent)) > MAX_LITERAL_EXPONENT:
        raise _ParseError(
            f"exponent {exponent} is beyond +-{MAX_LITERAL_EXPONENT}", token.column
        )
    value = fractions.Fraction(token.text)
    return sympy.Rational(value.numerator, value.denominator)


def _checked_power(base: sympy.Expr, exponent: sympy.Expr, column: int) -> sympy.Expr:
    """``base**exponent``, refusing exact powers too large to build."""
    if base.is_Rational and exponent.is_Rational and abs(base) not in (0, 1):
        size = max(abs(base.p).bit_length(), base.q.bit_length())
        if abs(exponent) * size > MAX_POWER_BITS:
            raise _ParseError(
                f"power {base}**{exponent} would have more than {MAX_POWER_BITS} bits",
                column,
            )
    return sympy.Pow(base, exponent)


class _Parser:
    """Recursive-descent parser over a token list (see the module grammar)."""

    def __init__(
        self,
        tokens: list[_Token],
        functions: Mapping[str, Callable[..., sympy.Expr]],
        variables: Mapping[str, sympy.Expr],
        assumptions: Mapping[str, bool],
    ) -> None:
        self.tokens = tokens
        self.index = 0
        self.depth = 0
        self.functions = functions
        self.variables = variables
        self.assumptions = assumptions

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
        if self.depth > MAX_NESTING_DEPTH:
            raise _ParseError(f"nesting deeper than {MAX_NESTING_DEPTH}", self.current.column)
        yield
        self.depth -= 1

    # -- grammar -------------------------------------------------------
    def parse(self) -> sympy.Expr:
        value = self.expression()
        if self.current.kind != "end":
            raise _ParseError(f"unexpected {self._describe()}", self.current.column)
        return value

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
        base = self.atom()
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
        return sympy.Symbol(name, **self.assumptions)

    def call(self, token: _Token) -> sympy.Expr:
        if self._accept("(") is None:
            raise _ParseError(f"function {token.text!r} must be called, as {token.text}(...)", token.column)
        with self._nested():
            arguments = [self.expression()]
            while self._accept(",") is not None:
                arguments.append(self.expression())
            self._expect(")")
        try:
            return self.functions[token.text](*arguments)
        except (TypeError, ValueError) as exc:
            raise _ParseError(f"cannot call {token.text} with {len(arguments)} argument(s): {exc}",
                              token.column) from exc


def parse_expression(
    text: str,
    entry: str,
    *,
    allowed_functions: Mapping[str, Callable[..., sympy.Expr]] = ALLOWED_FUNCTIONS,
    variables: Mapping[str, sympy.Expr] | None = None,
    symbol_assumptions: Mapping[str, bool] | None = None,
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
        Identifiers with fixed meanings. ``t`` means :data:`TIME` unless given here.
    symbol_assumptions : mapping of str to bool, optional
        Assumptions of the Symbols made for other identifiers (default ``real=True``).

    Returns
    -------
    sympy.Expr
        The exact value: decimal literals become Rationals.

    Raises
    ------
    SceneError
        On any text outside the grammar, naming ``entry``, the text and the column;
        on a division by zero or a non-finite result.

    Notes
    -----
    The parser is hand-written and builds SymPy objects directly; the text is
    never evaluated. Text longer than :data:`MAX_EXPRESSION_LENGTH` characters
    or nested deeper than :data:`MAX_NESTING_DEPTH` is refused.

    Examples
    --------
    >>> parse_expression("0.2", "k1")
    1/5
    >>> parse_expression("-2**2 + 3/6", "x0[0]")
    -7/2
    >>> parse_expression("k1 + k2/2", "K[0,0]")
    k1 + k2/2
    >>> parse_expression("__import__('os')", "M[0,0]")
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: M[0,0]: expected a number, got "__import__('os')": unexpected character '_' at column 1
    """
    if not isinstance(text, str):
        raise SceneError(f"{entry}: expected text, got {text!r}")
    if len(text) > MAX_EXPRESSION_LENGTH:
        raise SceneError(
            f"{entry}: expression has {len(text)} characters, more than {MAX_EXPRESSION_LENGTH}"
        )
    names = {"t": TIME, **(variables or {})}
    assumptions = _DEFAULT_ASSUMPTIONS if symbol_assumptions is None else symbol_assumptions
    try:
        tokens = _tokenize(text)
        if tokens[0].kind == "end":
            raise _ParseError("the text is empty", 1)
        value = _Parser(tokens, allowed_functions, names, assumptions).parse()
    except _ParseError as exc:
        raise SceneError(
            f"{entry}: expected a number, got {_shorten(text)}: {exc.reason} at column {exc.column}"
        ) from None
    return _require_finite(value, entry, text)


def _require_finite(value: sympy.Expr, entry: str, shown: object) -> sympy.Expr:
    """``value`` unless it is or contains NaN, an infinity or the imaginary unit."""
    if value.has(*_NON_FINITE):
        raise SceneError(f"{entry}: expected a finite number, got {shown!r}")
    if value.has(sympy.I):
        raise SceneError(f"{entry}: expected a real number, got {shown!r}")
    return value


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
    if abs(exponent) > MAX_LITERAL_EXPONENT + 100:
        raise SceneError(f"{entry}: exponent of {shown!r} is too large to hold exactly")
    return _fraction_to_rational(fractions.Fraction(value))


def _sympy_to_exact(value: sympy.Basic, entry: str) -> sympy.Expr:
    """Pass a SymPy expression through, with every Float made an exact Rational."""
    if not isinstance(value, sympy.Expr) or isinstance(value, sympy.MatrixBase):
        raise SceneError(f"{entry}: expected a number, got {value!r}")
    _require_finite(value, entry, value)
    floats = value.atoms(sympy.Float)
    if floats:
        value = value.xreplace({f: _decimal_text_to_rational(str(f), entry, f) for f in floats})
    return value


def to_exact(
    value: object,
    entry: str,
    *,
    symbol_assumptions: Mapping[str, bool] | None = None,
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
    symbol_assumptions : mapping of str to bool, optional
        Assumptions for Symbols made from identifiers in text (default ``real=True``).

    Returns
    -------
    sympy.Expr
        An exact expression: Integer, Rational, or a symbolic expression.

    Raises
    ------
    SceneError
        For booleans, NaN, infinities, complex numbers, text that does not parse,
        and any other type; the message names ``entry`` and the value.

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
    if isinstance(value, (bool, numpy.bool_)):
        raise SceneError(f"{entry}: expected a number, got {value!r}")
    if isinstance(value, sympy.Basic):
        return _sympy_to_exact(value, entry)
    if isinstance(value, str):
        return parse_expression(value.strip(), entry, symbol_assumptions=symbol_assumptions)
    if isinstance(value, numbers.Integral):
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
    raise SceneError(f"{entry}: expected a number, got {value!r}")


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
