"""Hostile text, units, equations, scene files and command lines, second round.

Each input here was accepted (a silently wrong scene) or failed with an exception from
deep inside SymPy or pint before it was fixed: a complex number written as a root of a
negative number (``(-8)**(1/3)`` is 1 + i√3 in SymPy), an impulse at a fixed instant
(``DiracDelta(0)``, not a finite number), SymPy's optional arguments passed from text
(``sqrt(4, 0)`` set SymPy's ``evaluate`` flag, ``Heaviside(t - 1, 5)`` the step's value
at its jump), SymPy objects that are not numbers (``Derivative(k**2, k)``), unit texts
whose float factors overflow or divide by zero (``kg^10000``, ``kg/0``), times on the
command line that Python's ``float`` reads but the scene's parser does not (``1_0``,
``٣``) or rounds to another number (``1e-400`` is 0), and ``coordinates`` that are not a
list of names. Every one is now a SceneError (or the CLI's one line and exit 2) naming
the entry and its value.
"""

from __future__ import annotations

import pytest
import sympy as sp

import laplace_springs as ls
from laplace_springs.cli import UsageError, main, parse_frequencies, parse_times
from laplace_springs.model.errors import LimitError, SceneError
from laplace_springs.model.scene_files import load_scene

pytest.importorskip("pint")


def stiffness(value, **kwargs):
    return ls.Scene.from_matrices(M=[[1]], K=[[value]], x0=[1], v0=[0], **kwargs)


# -- numbers that are not real, or not finite ---------------------------------------------

@pytest.mark.parametrize("text", ["(-8)**(1/3)", "(-1)**(1/3)", "2*(-1)**(1/3)", "(-1)**pi",
                                  "(-2)**(1/2 + 1/4)", "(-1)^(2/3)"])
def test_roots_of_negative_numbers_are_refused_as_complex(text):
    # SymPy (as Python's ** on floats) takes the principal root: (-8)**(1/3) = 1 + i*sqrt(3)
    assert abs(complex(sp.sympify(text.replace("^", "**")).evalf()).imag) > 0.1
    with pytest.raises(SceneError, match=r"K\[0,0\]: expected a real number"):
        stiffness(text)


@pytest.mark.parametrize("text", ["(-8)**(1/3)", "(-1)**pi"])
def test_complex_numbers_are_refused_in_every_place(text):
    with pytest.raises(SceneError, match=r"x0\[0\]: expected a real number"):
        ls.Scene.from_matrices(M=[[1]], K=[[1]], x0=[text], v0=[0])
    with pytest.raises(SceneError, match="forcing"):
        ls.Scene.from_matrices(M=[[1]], K=[[1]], x0=[0], v0=[0], forcing=[f"{text}*cos(t)"])
    with pytest.raises(SceneError, match="expected a real number"):
        ls.Scene.from_equations(f"x'' + {text}*x = 0; x(0) = 1; x'(0) = 0")
    with pytest.raises(SceneError, match="expected a real number"):
        stiffness(sp.Integer(-8) ** sp.Rational(1, 3))


def test_real_roots_and_odd_powers_stay_accepted():
    assert stiffness("8**(1/3)").K[0, 0] == 2
    assert stiffness("(-2)**3 + 9").K[0, 0] == 1
    assert stiffness("sqrt(2)**2").K[0, 0] == 2
    assert stiffness("(-1)**2").K[0, 0] == 1


@pytest.mark.parametrize("text", ["DiracDelta(0)", "1 + DiracDelta(0)", "DiracDelta(2 - 2)"])
def test_an_impulse_at_a_fixed_instant_is_not_a_number(text):
    with pytest.raises(SceneError, match=r"K\[0,0\]: DiracDelta\(0\) .* is not a finite number"):
        stiffness(text)
    with pytest.raises(SceneError, match="is not a finite number"):
        ls.Scene.from_matrices(M=[[1]], K=[[1]], x0=[0], v0=[0], forcing=[text])
    with pytest.raises(SceneError, match="is not a finite number"):
        ls.Scene.from_equations(f"x'' + x = 0; x(0) = 1; x'(0) = {text}")


def test_impulses_in_time_stay_accepted():
    scene = ls.Scene.from_matrices(M=[[1]], K=[[1]], x0=[0], v0=[0],
                                   forcing=["DiracDelta(t - tau)"], parameters=["tau"])
    assert scene.forcing[0].has(sp.DiracDelta)
    x = ls.solve(ls.Scene.from_matrices(M=[[1]], K=[[1]], x0=[0], v0=[0], forcing=["DiracDelta(t - 1)"]))
    assert abs(x.evaluate([2.0])[0, 0] - float(sp.sin(1))) < 1e-14   # sin(t - 1) after the kick


# -- functions called with SymPy's optional arguments ---------------------------------------

@pytest.mark.parametrize(("text", "name"), [("sqrt(4, 0)", "sqrt"), ("sqrt(1, 2)", "sqrt"),
                                            ("Heaviside(1, 2)", "Heaviside"), ("Abs(1, 2)", "Abs"),
                                            ("DiracDelta(1, 2, 3)", "DiracDelta")])
def test_functions_take_their_arguments_only(text, name):
    with pytest.raises(SceneError, match=rf"cannot call {name} with \d argument\(s\): {name} takes"):
        stiffness(text)


def test_a_step_with_a_value_at_its_jump_is_refused_in_forcing_and_equations():
    with pytest.raises(SceneError, match="with 2 argument.*Heaviside takes 1 argument in text"):
        ls.Scene.from_matrices(M=[[1]], K=[[1]], x0=[0], v0=[0], forcing=["Heaviside(t - 1, 5)"])
    with pytest.raises(SceneError, match="with 2 argument.*Heaviside takes 1 argument in text"):
        ls.Scene.from_equations("x'' + x = Heaviside(t, t); x(0) = 0; x'(0) = 0")
    with pytest.raises(SceneError, match="with 2 argument.*Heaviside takes 1 argument in text"):
        ls.Scene.from_equations("x(t).Heaviside(t) + x'' = 0; x(0) = 0; x'(0) = 0")


# -- SymPy objects that are not numbers -------------------------------------------------

def test_sympy_objects_sympy_cannot_evaluate_are_scene_errors():
    k, y = sp.symbols("k y")
    for value in (sp.Derivative(k**2, k), sp.Lambda(y, y), sp.O(y)):
        with pytest.raises(SceneError, match=r"K\[0,0\]: .* is not a number or an expression"):
            stiffness(value)
    f = sp.Function("x")
    with pytest.raises(SceneError, match="is not a number or an expression"):
        ls.Scene.from_equations([sp.Eq(f(ls.t).diff(ls.t, 2) + sp.Integral(f(ls.t), ls.t), 0)],
                                x0=[1], v0=[0])


# -- units ------------------------------------------------------------------------------

@pytest.mark.parametrize("unit", ["kg^10000", "kg^(10**400)", "kg/0", "kg^(1/0)", "kg^1e308"])
def test_units_that_overflow_or_divide_by_zero_are_scene_errors(unit):
    with pytest.raises(SceneError, match=r"mass 'm': .* unit .*expected a mass"):
        ls.Scene.from_components(masses={"m": f"2 {unit}"}, springs={"k": ("wall", "m", "1 N/m")})


def test_a_unit_error_message_stays_short():
    with pytest.raises(SceneError) as info:
        ls.Scene.from_components(masses={"m": "2 m^(2^1000)"}, springs={"k": ("wall", "m", "1 N/m")})
    assert len(str(info.value)) < 400, str(info.value)
    with pytest.raises(SceneError) as info:
        ls.Scene.from_components(masses={"m": "2 kg^" + "9" * 5000}, springs={"k": ("wall", "m", "1 N/m")})
    assert len(str(info.value)) < 600, str(info.value)


def test_unit_file_entries_that_overflow_are_scene_errors(tmp_path):
    path = tmp_path / "over.toml"
    path.write_text('[masses]\nm = "1 kg^10000"\n')
    with pytest.raises(SceneError, match="over.toml: mass 'm'"):
        load_scene(path)


# -- equations' coordinates and types ---------------------------------------------------------

EQUATIONS = "x'' + 4*x = 0; x(0) = 1; x'(0) = 0"


@pytest.mark.parametrize("coordinates", ["x", 5, [None], ["x y"], {"x": 1}, [b"x"]])
def test_coordinates_must_be_a_list_of_names(coordinates):
    with pytest.raises(SceneError, match="coordinates: "):
        ls.Scene.from_equations(EQUATIONS, coordinates=coordinates)


def test_coordinates_beyond_the_dense_limit_are_refused_before_reading():
    with pytest.raises(LimitError, match="max_matrix_input_size"):
        ls.Scene.from_equations(EQUATIONS, coordinates=(f"x{i}" for i in range(10**7)))


def test_coordinates_as_a_tuple_or_iterator_work():
    assert ls.Scene.from_equations(EQUATIONS, coordinates=("x",)).K[0, 0] == 4
    assert ls.Scene.from_equations(EQUATIONS, coordinates=iter(["x"])).K[0, 0] == 4


@pytest.mark.parametrize("equations", [b"x'' + x = 0", bytearray(b"x"), {"a": EQUATIONS}])
def test_equations_that_are_bytes_or_a_mapping_are_named(equations):
    with pytest.raises(SceneError, match="equations: expected text, an Eq or a list of them, got"):
        ls.Scene.from_equations(equations)


@pytest.mark.parametrize("title", [5, None, b"x", ["a"]])
def test_a_title_must_be_text(title):
    with pytest.raises(SceneError, match="title must be a string"):
        ls.Scene.from_matrices(M=[[1]], K=[[1]], x0=[1], v0=[0], title=title)


# -- scene files with a byte-order mark -------------------------------------------------------

def test_scene_and_equation_files_with_a_byte_order_mark_read(tmp_path, capsys):
    scene = tmp_path / "bom.toml"
    scene.write_text('[masses]\nm = 1\n[springs]\nk = ["wall", "m", 4]\n[initial]\nx0 = [1]\n',
                     encoding="utf-8-sig")
    assert load_scene(scene).K[0, 0] == 4
    equations = tmp_path / "bom.txt"
    equations.write_text(EQUATIONS + "\n", encoding="utf-8-sig")
    assert main(["solve", "--equations", str(equations), "--at", "0.5"]) == 0
    assert abs(float(capsys.readouterr().out.split()[-1]) - float(sp.cos(1))) < 1e-11


# -- times and frequencies on the command line -------------------------------------------------

@pytest.mark.parametrize("text", ["1_0", "٣", "1 2", "1e", "0x10", "1e-400", "5e-325"])
def test_times_the_scene_parser_would_refuse_are_refused(text):
    with pytest.raises(UsageError, match="--at: "):
        parse_times(text)
    with pytest.raises(UsageError, match="--at: "):
        parse_frequencies(text)


def test_plain_times_read_as_before():
    assert parse_times("0, 0.5,1e-3") == [0.0, 0.5, 0.001]
    assert parse_times("0,0.5s,250ms,1 min") == [0.0, 0.5, 0.25, 60.0]
    assert parse_times("+1,1.,.5,1e-310") == [1.0, 1.0, 0.5, 1e-310]
    assert [str(value) for value in parse_times("-0,-0.0e5")] == ["0.0", "0.0"]   # no -0
    assert parse_frequencies("1 Hz")[0] == pytest.approx(2 * 3.141592653589793, rel=1e-15)


@pytest.mark.parametrize("args", [["solve", "wall-pair", "--at", "1 2"], ["solve", "wall-pair", "--at", "1_0"],
                                  ["solve", "wall-pair", "--at", "1e-400"], ["response", "wall-pair", "--at", "1 2"],
                                  ["solve", "wall-pair", "--forcing", "x1=(-8)**(1/3)"],
                                  ["solve", "wall-pair", "--forcing", "x1=DiracDelta(0)"],
                                  ["solve", "wall-pair", "--forcing", "x1=Heaviside(t - 1, 5)"]])
def test_the_command_line_says_so_in_one_line(capsys, args):
    code = main(args)
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and err[0].startswith("laplace-springs: error: --"), err


# -- parameter declarations --------------------------------------------------------------------

@pytest.mark.parametrize("word", ["complex", "imaginary", "integer", "Nonzero", " rational ", "zero"])
def test_sympy_assumption_words_are_not_read_as_descriptions(word):
    # a description declares a positive parameter: "complex" must not silently do so
    with pytest.raises(SceneError, match=f"parameter 'k': the assumption '{word.strip().lower()}' is not supported"):
        stiffness("k", parameters={"k": word})


def test_descriptions_and_the_four_assumptions_still_declare():
    assert stiffness("k", parameters={"k": "stiffness of the spring"}).K[0, 0].is_positive
    assert stiffness("k", parameters={"k": "complex stiffness"}).K[0, 0].is_positive   # a description
    for word, fact in (("real", "is_real"), ("nonnegative", "is_nonnegative"), ("negative", "is_negative")):
        assert getattr(stiffness("k", parameters={"k": word}).K[0, 0], fact)


@pytest.mark.parametrize(("assumptions", "reason"), [({"imaginary": True}, "declared not real"),
                                                     ({"real": False}, "declared not real"),
                                                     ({"infinite": True}, "declared infinite"),
                                                     ({"commutative": False}, "noncommutative")])
def test_sympy_symbols_that_cannot_be_real_numbers_are_refused(assumptions, reason):
    symbol = sp.Symbol("m", **assumptions)
    with pytest.raises(SceneError, match=reason):
        stiffness(symbol)
    with pytest.raises(SceneError, match=reason):
        ls.Scene.from_matrices(M=[[1]], K=[[1]], x0=[symbol], v0=[0])
    with pytest.raises(SceneError, match=reason):
        stiffness("m", parameters=[symbol])


def test_sympy_symbols_of_unknown_sign_stay_parameters():
    for assumptions in ({}, {"real": True}, {"negative": True}, {"integer": True}):
        assert stiffness(sp.Symbol("m", **assumptions)).K[0, 0].is_Symbol


@pytest.mark.parametrize("args", [["solve", "wall-pair", "--at", "1", "--dps", "٣"],
                                  ["solve", "wall-pair", "--at", "1", "--dps", "1_0"],
                                  ["response", "wall-pair", "--force", "٢"],
                                  ["bench", "--list", "--time-limit", "1_0"],
                                  ["animate", "wall-pair", "-o", "a.gif", "--t-end", "٣"],
                                  ["animate", "wall-pair", "-o", "a.gif", "--duration", "1_0"],
                                  ["animate", "wall-pair", "-o", "a.gif", "--speed", "٢"],
                                  ["animate", "wall-pair", "-o", "a.gif", "--fps", "1_0"],
                                  ["animate", "wall-pair", "-o", "a.gif", "--dpi", "8_0"]])
def test_integer_and_number_options_read_as_the_scene_parser_does(capsys, args):
    # Python's int() and float() take 1_0 and other scripts' digits; the options do not
    code = main(args)
    err = capsys.readouterr().err
    assert code == 2 and "expected" in err and "Traceback" not in err, err


def test_a_parameter_value_with_a_second_equals_sign_is_a_usage_error(capsys):
    code = main(["solve", "wall-pair", "--param", "k=2=3"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and err == "laplace-springs: error: --param: expected NAME=VALUE such as k=2, got 'k=2=3'"


@pytest.mark.parametrize("names", ["a", b"a", 5, {"a": 1}])
def test_names_must_be_a_sequence_of_strings(names):
    # a string was taken as its characters: names="a" named the one coordinate 'a'
    with pytest.raises(SceneError, match="names must be a sequence of strings"):
        ls.Scene.from_matrices(M=[[1]], K=[[1]], x0=[1], v0=[0], names=names)


def test_animate_masses_option_names_the_empty_item_and_reads_numbers(capsys, tmp_path):
    code = main(["animate", "wall-pair", "-o", str(tmp_path / "a.gif"), "--masses", "1,,2"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and err == "laplace-springs: error: animate: --masses '1,,2': item 2 is empty"
    code = main(["animate", "wall-pair", "-o", str(tmp_path / "a.gif"), "--masses", "3"])
    err = capsys.readouterr().err
    assert code == 2 and "numbers from 1 to 2; got 3" in err, err


def test_the_cli_names_initial_data_a_massless_node_cannot_keep(capsys, tmp_path):
    path = tmp_path / "massless.toml"
    path.write_text('[masses]\nm1 = 1\nm2 = 0\n[springs]\nk1 = ["wall", "m1", 1]\n'
                    'k2 = ["m1", "m2", 1]\n[initial]\nx0 = [1, 5]\nv0 = [0, 0]\n')
    code = main(["solve", str(path)])
    captured = capsys.readouterr()
    assert code == 0 and "x2(t) = cos(t)" in captured.out
    assert captured.err.strip() == ("laplace-springs: note: x0[x2] = 5 is not kept: x2 has no "
                                    "mass and its springs set x2(0⁺) = 1 (a jump at t = 0)")
