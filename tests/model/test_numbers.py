"""Tests of exact number conversion and the safe expression parser."""

from __future__ import annotations

import builtins
import decimal
import math
import re
import time
from fractions import Fraction

import mpmath
import numpy as np
import pytest
import sympy

import laplace_springs as ls
from laplace_springs.limits import limits
from laplace_springs.model.errors import SceneError
from laplace_springs.model.numbers import (
    ALLOWED_FUNCTIONS,
    TIME,
    declare_parameters,
    parse_expression,
    to_exact,
)

R = sympy.Rational


def test_scene_error_is_a_value_error():
    with pytest.raises(ValueError):
        to_exact("abc$", "M[1,0]")


# --- to_exact: Python and library numbers -----------------------------------------


@pytest.mark.parametrize(
    ("value", "expected"),
    [
        (3, sympy.Integer(3)),
        (-7, sympy.Integer(-7)),
        (10**40, sympy.Integer(10**40)),
        (0.2, R(1, 5)),
        (-1.5e-3, R(-3, 2000)),
        (1e300, sympy.Integer(10**300)),
        (0.5, R(1, 2)),
        (Fraction(2, 3), R(2, 3)),
        (decimal.Decimal("0.125"), R(1, 8)),
        (decimal.Decimal("-1E-3"), R(-1, 1000)),
        (np.int64(4), sympy.Integer(4)),
        (np.float64(0.2), R(1, 5)),
        (np.float32(0.2), R(1, 5)),  # its own shortest repr, not the binary value
        (mpmath.mpf("0.2"), R(1, 5)),
    ],
)
def test_numbers_become_exact(value, expected):
    result = to_exact(value, "entry")
    assert result == expected
    assert isinstance(result, sympy.Rational)


def test_float_is_its_shortest_decimal_repr_not_a_rounded_sum():
    # repr(0.1 + 0.2) is '0.30000000000000004': that exact decimal, not 3/10.
    assert repr(0.1 + 0.2) == "0.30000000000000004"
    assert to_exact(0.1 + 0.2, "k") == R(30000000000000004, 10**17)
    assert to_exact(0.1 + 0.2, "k") != R(3, 10)


def test_decimal_is_exact_not_rounded_through_float():
    value = decimal.Decimal("0.1000000000000000000000000001")
    assert to_exact(value, "k") == R(1000000000000000000000000001, 10**28)


def test_sympy_values_pass_through():
    x = sympy.Symbol("x", positive=True)
    assert to_exact(x, "k") is x
    assert to_exact(R(2, 7), "k") == R(2, 7)
    assert to_exact(sympy.sqrt(2) * x, "k") == sympy.sqrt(2) * x


def test_sympy_floats_become_rationals_of_their_decimal_string():
    x = sympy.Symbol("x")
    assert to_exact(sympy.Float(0.2), "k") == R(1, 5)
    assert to_exact(sympy.Float("0.5") * x + 1, "k") == x / 2 + 1
    assert not to_exact(sympy.Float("1.25") * x, "k").atoms(sympy.Float)


# --- to_exact: text ----------------------------------------------------------------


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("0.2", R(1, 5)),
        ("2/3", R(2, 3)),
        ("-1.5e-3", R(-3, 2000)),
        ("1E2", sympy.Integer(100)),
        ("2.5e+1", sympy.Integer(25)),
        (" 3 ", sympy.Integer(3)),
        (".5", R(1, 2)),
        ("5.", sympy.Integer(5)),
        ("0.30000000000000004", R(30000000000000004, 10**17)),
        ("1e-300", R(1, 10**300)),
    ],
)
def test_number_text(text, expected):
    assert to_exact(text, "entry") == expected


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("-2**2", -4),  # power binds tighter than unary minus
        ("(-2)**2", 4),
        ("2**3**2", 512),  # right-associative
        ("2^3^2", 512),
        ("2**-1", R(1, 2)),
        ("-2^-2", R(-1, 4)),
        ("1 - 2 - 3", -4),  # left-associative
        ("8/4/2", 1),
        ("2*3 + 4", 10),
        ("2*(3 + 4)", 14),
        ("+3", 3),
        ("--3", 3),
        ("-(-(1/2))", R(1, 2)),
        ("3/6 - 1/3", R(1, 6)),
    ],
)
def test_arithmetic_and_precedence(text, expected):
    assert to_exact(text, "entry") == expected


def test_declared_names_become_their_symbols():
    k1, k2 = sympy.symbols("k1 k2", positive=True)
    declared = {"k1": k1, "k2": k2}
    assert to_exact("k1", "K[0,0]", parameters=declared) == k1
    assert to_exact("k1 + k2/2", "K[0,0]", parameters=declared) == k1 + k2 / 2


@pytest.mark.parametrize("text", ["abc", "k1 + x", "cos(x)", "k_1a"])
def test_undeclared_names_are_refused_with_how_to_declare_them(text):
    with pytest.raises(SceneError, match=r"unknown name '\w+' at column \d+ \(declared parameters: "
                                         r"k1; to make '\w+' a parameter, declare it: parameters="):
        to_exact(text, "K[0,0]", parameters={"k1": sympy.Symbol("k1", positive=True)})
    with pytest.raises(SceneError, match=r"^K\[0,0\]: expected a number, got .*unknown name"):
        to_exact(text, "K[0,0]")


@pytest.mark.parametrize(
    ("declaration", "positive", "real"),
    [(None, True, True), ("positive", True, True), ("nonnegative", None, True),
     ("real", None, True), ("negative", False, True), ("stiffness of k1, N/m", True, True)],
)
def test_declarations_give_assumptions(declaration, positive, real):
    parameters = ["a"] if declaration is None else {"a": declaration}
    symbol = declare_parameters(parameters)["a"]
    assert symbol.name == "a" and symbol.is_positive is positive and symbol.is_real is real


def test_symbol_objects_declare_themselves_and_clashing_ones_are_refused():
    k = sympy.Symbol("k")
    assert declare_parameters(None, [[k, 1]], {"m": [2 * k]}) == {"k": k}
    with pytest.raises(SceneError, match="two different Symbols are named 'k'"):
        declare_parameters(["k"], [[k]])  # "k" declared positive, Symbol("k") has no assumption


@pytest.mark.parametrize("name", ["t", "sin", "pi", "nan", "I", "2k", "k-1", "", 3])
def test_reserved_and_malformed_parameter_names_are_refused(name):
    with pytest.raises(SceneError, match="parameter"):
        declare_parameters([name])


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("sqrt(4)", 2),
        ("sqrt(2)", sympy.sqrt(2)),
        ("exp(0)", 1),
        ("sin(pi)", 0),
        ("cos(0)", 1),
        ("sinh(0)", 0),
        ("cosh(0)", 1),
        ("Abs(-3)", 3),
        ("pi", sympy.pi),
        ("E", sympy.E),
        ("2*pi/3", 2 * sympy.pi / 3),
        ("exp(1)", sympy.E),
    ],
)
def test_functions_and_constants(text, expected):
    assert to_exact(text, "entry") == expected


def test_t_is_the_time_symbol_and_forcing_functions_parse():
    assert to_exact("t", "f") is TIME
    assert to_exact("Heaviside(t - 1)", "f") == sympy.Heaviside(TIME - 1)
    assert to_exact("DiracDelta(t - 2)", "f") == sympy.DiracDelta(TIME - 2)
    assert to_exact("exp(-t/10)*sin(2*t)", "f") == sympy.exp(-TIME / 10) * sympy.sin(2 * TIME)


def test_variables_map_to_the_given_symbols():
    s = sympy.Symbol("s")
    tau = sympy.Symbol("tau", positive=True)
    value = parse_expression("s**2 + t", "F", variables={"s": s, "t": tau})
    assert value == s**2 + tau


def test_allowed_functions_can_be_narrowed():
    assert set(ALLOWED_FUNCTIONS) == {
        "sqrt", "exp", "sin", "cos", "sinh", "cosh", "Heaviside", "DiracDelta", "Abs",
    }
    with pytest.raises(SceneError, match="unknown function 'sin'"):
        parse_expression("sin(1)", "f", allowed_functions={"cos": sympy.cos})


def test_parser_never_calls_eval_exec_or_sympify(monkeypatch):
    def forbidden(*args, **kwargs):
        raise AssertionError("text was evaluated")

    monkeypatch.setattr(builtins, "eval", forbidden)
    monkeypatch.setattr(builtins, "exec", forbidden)
    monkeypatch.setattr(sympy, "sympify", forbidden)
    monkeypatch.setattr(sympy, "parse_expr", forbidden)
    k1 = sympy.Symbol("k1", real=True)
    value = parse_expression("-(k1 + 2.5e-1)**2 / sqrt(4) + sin(pi*t)", "e", variables={"k1": k1})
    assert value == -((k1 + R(1, 4)) ** 2) / 2 + sympy.sin(sympy.pi * TIME)


def test_injection_text_is_refused_and_runs_nothing(tmp_path):
    target = tmp_path / "pwned"
    text = f"__import__('os').system('touch {target}')"
    with pytest.raises(SceneError, match=r"M\[0,0\]: expected a number.*column 1"):
        to_exact(text, "M[0,0]")
    assert not target.exists()


# --- errors -------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("abc$", r"unexpected character '\$' at column 4"),
        ("", "empty"),
        ("   ", "empty"),
        ("1_000", "unexpected character '_' at column 2"),
        ("2x", "unexpected character 'x' at column 2"),
        ("1.2.3", r"unexpected character '\.' at column 4"),
        ("__import__", "unexpected character '_' at column 1"),
        ("k1.real", r"unexpected character '\.' at column 3"),
        ("x[0]", r"unexpected character '\[' at column 2"),
        ("1, 2", "unexpected ',' at column 2"),
        ("'text'", "unexpected character"),
        ('"text"', "unexpected character"),
        ("lambda x: x", "unexpected"),
        ("foo(1)", "unknown function 'foo'"),
        ("eval(1)", "unknown function 'eval'"),
        ("sin", "function 'sin' must be called"),
        ("sin()", "column 5"),
        ("sin(1, 2)", "cannot call sin with 2 argument"),
        ("1 +", "end of text"),
        ("(1", "expected '\\)', found end of text"),
        ("1)", r"unexpected '\)' at column 2"),
        ("1 2", "unexpected '2' at column 3"),
        ("2 ** ", "end of text"),
        ("1/0", "division by zero at column 2"),
        ("1/(2 - 2)", "division by zero"),
        ("0**-1", "finite"),
        ("sqrt(-1)", "real"),
        ("2**10**10", "more than 1000 digits"),
        ("1e99999", "exponent 99999"),
        ("x @ y", "unexpected character '@'"),
        ("x; y", "unexpected character ';'"),
    ],
)
def test_bad_text_names_entry_text_and_reason(text, message):
    with pytest.raises(SceneError, match=r"K\[0,1\]: expected") as info:
        to_exact(text, "K[0,1]")
    assert re.search(message, str(info.value)), str(info.value)


def test_message_names_entry_and_value():
    with pytest.raises(SceneError, match=r"^M\[1,0\]: expected a number, got 'abc\$'"):
        to_exact("abc$", "M[1,0]")


def test_text_length_is_limited():
    with pytest.raises(SceneError, match=f"more than {limits().max_expression_length}"):
        to_exact("1" + "+1" * limits().max_expression_length, "e")


def test_nesting_depth_is_limited():
    depth = limits().max_nesting_depth + 1
    with pytest.raises(SceneError, match="nesting deeper"):
        to_exact("(" * depth + "1" + ")" * depth, "e")
    with pytest.raises(SceneError, match="nesting deeper"):
        to_exact("-" * (depth + 1) + "1", "e")
    ok = limits().max_nesting_depth - 1
    assert to_exact("(" * ok + "1" + ")" * ok, "e") == 1


@pytest.mark.parametrize(
    "value",
    [
        math.nan,
        math.inf,
        -math.inf,
        decimal.Decimal("NaN"),
        decimal.Decimal("Infinity"),
        sympy.nan,
        sympy.zoo,
        sympy.oo,
        -sympy.oo,
        sympy.Symbol("x") + sympy.oo,
    ],
)
def test_non_finite_values_are_refused(value):
    with pytest.raises(SceneError, match="C\\[0,0\\]: expected a finite number"):
        to_exact(value, "C[0,0]")


@pytest.mark.parametrize(
    "value",
    [True, False, np.bool_(True), None, [1], (1,), {"a": 1}, 1j, np.complex128(1), object(),
     sympy.Matrix([1]), sympy.true, b"1", sympy.I, 1 + sympy.I],
)
def test_other_types_are_refused(value):
    with pytest.raises(SceneError, match="x0\\[1\\]: expected a"):
        to_exact(value, "x0[1]")


@pytest.mark.parametrize(("text", "fragment"), [
    ("exp(exp(exp(10)))", "the argument of exp has magnitude 2.20e+4, beyond 1.00e+4"),
    ("sin(exp(exp(exp(5))))", "the argument of exp has magnitude 2.85e+64"),
    ("sinh(exp(exp(9)))", "the argument of sinh has magnitude about 1e+3519"),
    ("cos(10**400)", "the argument of cos has magnitude 1.00e+400, beyond 1.00e+300"),
    ("sin(10**10**4)", "more than 1000 digits"),
    ("exp(10**6)", "the argument of exp has magnitude 1.00e+6"),
    ("(1+sqrt(2))**10000", "magnitude about 1e+3828, beyond the limit 1e-300 <= |value| <= 1e300"),
    ("0.5**2000", "power 1/2**2000 would have more than 1000 digits"),
    ("(1/2)**900 * (1/2)**900", "magnitude 1.40e-542, beyond the limit"),
    ("1" + "0" * 1001, "number with 1002 digits, more than 1000"),
    ("0." + "0" * 999 + "12", "has a number of more than 1000 digits"),  # its denominator 10**1001
    ("sqrt(2)**100000", "more than 1000 digits"),
])
def test_limits_refuse_at_once_naming_the_limit(text, fragment):
    started = time.perf_counter()
    with pytest.raises(SceneError, match=re.escape(fragment)):
        to_exact(text, "K[0,0]")
    assert time.perf_counter() - started < 1.0  # a guard against a hang, not a speed target


def test_an_argument_in_t_names_the_time_its_magnitude_was_taken_at():
    """exp(9999*t) against a limit of 1e4 read as a contradiction until the message said
    it was measured at the generic time."""
    with pytest.raises(SceneError, match=re.escape("magnitude 1.09e+4 at t = 97/89, beyond 1.00e+4")):
        ls.Scene.from_matrices(M=[[1]], K=[[1]], x0=[1], v0=[0], forcing=["exp(9999*t)"])


@pytest.mark.parametrize("value", [10**301, -(10**301), Fraction(1, 10**301), 1e-305, 1.7e308,
                                   decimal.Decimal("1e-400"), sympy.Integer(10) ** 400,
                                   sympy.exp(1000), sympy.Rational(1, 3) ** 700])
def test_magnitude_limit_holds_for_every_input_type(value):
    with pytest.raises(SceneError, match=r"K\[0,0\]: .* beyond the limit 1e-300 <= \|value\| <= 1e300"):
        to_exact(value, "K[0,0]")


@pytest.mark.parametrize("value", [10**300, Fraction(1, 10**300), 1e-300, "1e300", "exp(600)",
                                   "sin(10**300)", "exp(-600)", sympy.exp(600), "1 + exp(-700)"])
def test_values_inside_the_limits_are_kept_exactly(value):
    exact = to_exact(value, "K[0,0]")
    assert exact.is_finite and not isinstance(exact, sympy.Float)


def test_huge_integers_are_refused_before_any_conversion():
    with pytest.raises(SceneError, match=r"an integer of 19932 bits has more than 1000 digits"):
        to_exact(10**6000, "K[0,0]")
    with pytest.raises(SceneError, match=r"number with 6000 digits, more than 1000"):
        to_exact("9" * 6000, "K[0,0]")


def test_deeply_nested_values_are_shown_shortly():
    nested: list = [1]
    for _ in range(10_000):
        nested = [nested]
    with pytest.raises(SceneError, match=r"expected a number, got \[\[\[\[\.\.\.\]\]\]\]"):
        to_exact(nested, "M[0,0]")
