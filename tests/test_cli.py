"""Tests of the command line, ``laplace-springs`` / ``python -m laplace_springs``.

Expected values come from outside the code under test: the seed's Example 1 closed
form (from its Φ and Ψ), and an mpmath matrix exponential of the first-order system
built here from the seed's numbers for Example 4.
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
from pathlib import Path

import mpmath
import numpy as np
import pytest
import sympy

import laplace_springs as ls
from laplace_springs.cli import main, parse_times

BUNDLED = ["example5-in-units", "three-dashpots", "vertical-pair", "vertical-pair-damped", "wall-pair",
           "wall-pair-dashpot"]


def run(capsys, *args: str) -> tuple[int, str, str]:
    """Exit status, stdout and stderr of ``laplace-springs ARGS``."""
    code = main(list(args))
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def assert_one_line_error(code: int, out: str, err: str, *fragments: str) -> None:
    assert code == 2
    assert out == ""
    lines = err.splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("laplace-springs: error: ")
    assert "Traceback" not in err
    for fragment in fragments:
        assert fragment in lines[0]


def table(out: str) -> tuple[list[str], list[list[float]]]:
    """Header and float rows of an ``--at`` table (after the title line)."""
    lines = out.splitlines()
    header = lines[1].split()
    return header, [[float(cell) for cell in line.split()] for line in lines[2:]]


# The seed's Example 1, A = [[3, -1], [-2, 2]], x0 = [1, 0], v0 = [0, 1]: x = Φ x0 + Ψ v0.
def example_1(time: float) -> tuple[float, float]:
    c1, c2, s1, s2 = math.cos(time), math.cos(2 * time), math.sin(time), math.sin(2 * time)
    return (c1 / 3 + 2 * c2 / 3 + s1 / 3 - s2 / 6,
            2 * c1 / 3 - 2 * c2 / 3 + 2 * s1 / 3 + s2 / 6)


def example_4(time: str, dps: int = 50) -> list[mpmath.mpf]:
    """The seed's Example 4 (delta = 0.1) by the matrix exponential of [[0, I], [-M⁻¹K, -M⁻¹C]].

    m1 = 1, m2 = 2, k1 = 1, k3 = 2, b = 0.5, delta = 0.1; x0 = [0.1, 0.3], v0 = [0.2, -0.5].
    """
    with mpmath.workdps(dps):
        f = mpmath.mpf
        M = mpmath.diag([1, 2])
        K = mpmath.matrix([[1, 0], [0, 2]])
        C = mpmath.matrix([[f("0.6"), f("-0.5")], [f("-0.5"), f("0.6")]])
        Minv = M**-1
        state = mpmath.zeros(4, 4)
        state[0, 2] = state[1, 3] = 1
        lower = -Minv * K, -Minv * C
        for i in range(2):
            for j in range(2):
                state[2 + i, j] = lower[0][i, j]
                state[2 + i, 2 + j] = lower[1][i, j]
        start = mpmath.matrix([f("0.1"), f("0.3"), f("0.2"), f("-0.5")])
        x = mpmath.expm(state * f(time)) * start
        return [+x[0], +x[1]]


# ---------------------------------------------------------------------------- solve


def test_solve_prints_title_and_one_line_per_coordinate(capsys):
    code, out, err = run(capsys, "solve", "vertical-pair")
    assert (code, err) == (0, "")
    lines = out.splitlines()
    assert lines[0] == "Example 1: two masses hanging from the ceiling"
    assert [line.split(" = ")[0] for line in lines[1:]] == ["x1(t)", "x2(t)"]
    t = sympy.Symbol("t")
    expected = [
        sympy.cos(t) / 3 + 2 * sympy.cos(2 * t) / 3 + sympy.sin(t) / 3 - sympy.sin(2 * t) / 6,
        2 * sympy.cos(t) / 3 - 2 * sympy.cos(2 * t) / 3 + 2 * sympy.sin(t) / 3 + sympy.sin(2 * t) / 6,
    ]
    for line, exact in zip(lines[1:], expected):
        printed = sympy.sympify(line.split(" = ", 1)[1], locals={"t": t})
        assert sympy.simplify(printed - exact) == 0


def named_values(lines: list[str]) -> dict[sympy.Symbol, float]:
    """The names and printed values of a "where" list: ``  alpha_1 ≈ -0.4, beta_1 ≈ 0.9``."""
    values = {}
    for line in lines:
        for item in line.split(", "):
            name, approx, value = item.strip().partition(" ≈ ")
            if approx and name.replace("_", "").isalnum():
                values[sympy.Symbol(name)] = float(value.split()[0])
    return values


def test_solve_names_rates_frequencies_and_coefficients(capsys):
    code, out, _ = run(capsys, "solve", "wall-pair-dashpot")
    assert code == 0
    lines = out.splitlines()
    assert lines[1].startswith("x1(t) = ") and lines[2].startswith("x2(t) = ")
    assert lines[3] == "where"
    assert "CRootOf" not in out and "re(" not in out and "im(" not in out
    values = named_values(lines[4:])
    names = {"alpha_1", "beta_1", "alpha_2", "beta_2"} | {f"c_{j}" for j in range(1, 9)}
    assert {symbol.name for symbol in values} == names
    # (λ - α)² + β² divides the seed's characteristic polynomial 200λ⁴ + 180λ³ + 411λ² + 180λ + 200
    for j in (1, 2):
        root = complex(values[sympy.Symbol(f"alpha_{j}")], values[sympy.Symbol(f"beta_{j}")])
        assert abs(np.polyval([200, 180, 411, 180, 200], root)) < 1e-8

    # The printed formula with the printed 12-digit values, against the matrix exponential.
    t = sympy.Symbol("t")
    local = {"t": t, **{symbol.name: symbol for symbol in values}}
    for index, line in enumerate(lines[1:3]):
        printed = sympy.sympify(line.split(" = ", 1)[1], locals=local)
        value = float(printed.subs(values).subs(t, sympy.Rational(3, 2)))
        assert value == pytest.approx(float(example_4("1.5")[index]), abs=1e-10)


def test_at_table_matches_seed_example_1(capsys):
    times = [0.0, 0.5, 1.0, 2.5, 10.0, 123.25]
    code, out, err = run(capsys, "solve", "vertical-pair", "--at", ",".join(map(str, times)))
    assert (code, err) == (0, "")
    header, rows = table(out)
    assert header == ["t", "x1", "x2"]
    assert [row[0] for row in rows] == times
    for time, x1, x2 in rows:
        assert (x1, x2) == pytest.approx(example_1(time), abs=1e-10)


def test_at_table_matches_matrix_exponential_on_a_quartic(capsys):
    code, out, _ = run(capsys, "solve", "wall-pair-dashpot", "--at", "0, 0.75, 3, 40")
    assert code == 0
    for time, *values in table(out)[1]:
        expected = example_4(repr(time))
        assert values == pytest.approx([float(v) for v in expected], abs=1e-10)


def test_dps_table_has_the_requested_digits(capsys):
    code, out, _ = run(capsys, "solve", "wall-pair-dashpot", "--at", "0,1.5", "--dps", "30")
    assert code == 0
    lines = out.splitlines()[2:]
    for line in lines:
        time, *cells = line.split()
        with mpmath.workdps(40):
            expected = example_4(time)
            for cell, exact in zip(cells, expected):
                assert abs(mpmath.mpf(cell) - exact) <= mpmath.mpf("1e-28") * max(1, abs(exact))


def test_dps_table_prints_the_requested_number_of_digits(capsys):
    code, out, _ = run(capsys, "solve", "vertical-pair", "--at", "1", "--dps", "25")
    assert code == 0
    _, x1, x2 = out.splitlines()[2].split()
    assert len(x1.lstrip("-0.").replace(".", "")) == 25
    assert float(x1) == pytest.approx(example_1(1.0)[0], abs=1e-15)


def test_latex_prints_the_aligned_block(capsys):
    code, out, _ = run(capsys, "solve", "vertical-pair", "--latex")
    assert code == 0
    assert out.startswith("\\begin{aligned}\n")
    assert out.rstrip().endswith("\\end{aligned}")
    assert "x_{1}(t) &=" in out and "x_{2}(t) &=" in out


def test_pretty_prints_unicode_formulas(capsys):
    code, out, _ = run(capsys, "solve", "vertical-pair", "--pretty")
    assert code == 0
    assert "x₁(t) =" in out and "x₂(t) =" in out
    assert "2·cos(2·t)/3" in out and "**" not in out


def test_solve_reads_a_scene_file(capsys, tmp_path):
    path = tmp_path / "one.toml"
    path.write_text('title = "one mass"\n[masses]\nm1 = "1"\n[springs]\nk1 = ["wall", "m1", "4"]\n'
                    '[initial]\nx0 = ["1"]\n', encoding="utf-8")
    code, out, _ = run(capsys, "solve", str(path), "--at", "0.3")
    assert code == 0
    assert table(out)[1] == [[0.3, pytest.approx(math.cos(0.6), abs=1e-11)]]


def test_parse_times():
    assert parse_times(" 0 ,0.5, 1e2") == [0.0, 0.5, 100.0]


# ---------------------------------------------------------------------------- scenes, version


def test_scenes_lists_names_and_aligned_titles(capsys):
    code, out, _ = run(capsys, "scenes")
    assert code == 0
    lines = out.splitlines()
    assert [line.split()[0] for line in lines] == BUNDLED
    titles = ls.bundled_scenes()
    column = {line.index(titles[line.split()[0]]) for line in lines}
    assert len(column) == 1
    assert "Example 1: two masses hanging from the ceiling" in out


def test_version(capsys):
    code, out, _ = run(capsys, "--version")
    assert code == 0
    assert out.strip() == f"laplace-springs {ls.__version__}"


# ---------------------------------------------------------------------------- errors


def test_unknown_scene_is_one_line_naming_it(capsys):
    assert_one_line_error(*run(capsys, "solve", "no-such-scene"), "'no-such-scene'", "vertical-pair")


def test_code_in_a_scene_file_is_refused_and_never_run(capsys, tmp_path):
    marker = tmp_path / "x"
    path = tmp_path / "evil.toml"
    path.write_text(f"title = \"evil\"\n[masses]\nm1 = \"__import__('os').system('touch {marker}')\"\n"
                    "[springs]\nk1 = [\"wall\", \"m1\", \"1\"]\n", encoding="utf-8")
    assert_one_line_error(*run(capsys, "solve", str(path)), "evil.toml", "m1")
    assert not marker.exists()


@pytest.mark.parametrize("text", ['title = "unclosed\n', "[masses]\nm1 = -1\n"])
def test_bad_scene_file_is_one_line(capsys, tmp_path, text):
    path = tmp_path / "bad.toml"
    path.write_text(text, encoding="utf-8")
    assert_one_line_error(*run(capsys, "solve", str(path)), "bad.toml")


def test_missing_scene_file_is_one_line(capsys, tmp_path):
    assert_one_line_error(*run(capsys, "solve", str(tmp_path / "absent.toml")), "absent.toml")


@pytest.mark.parametrize("times, fragment", [
    ("1,abc", "'abc'"), ("1,,2", "''"), ("nan", "finite"), ("0,inf", "finite"),
    ("-1", ">= 0"), ("-0.5,1", ">= 0"),
])
def test_bad_times_are_one_line(capsys, times, fragment):
    assert_one_line_error(*run(capsys, "solve", "vertical-pair", f"--at={times}"), "--at", fragment)


@pytest.mark.parametrize("args, fragment", [
    (["--dps", "30"], "--dps needs --at"),
    (["--at", "1", "--dps", "0"], "--dps"),
])
def test_bad_dps_is_one_line(capsys, args, fragment):
    assert_one_line_error(*run(capsys, "solve", "vertical-pair", *args), fragment)


@pytest.mark.parametrize("args, fragment", [
    (["--formula", "--latex"], "--formula and --modes go without --latex and --at"),
    (["--modes", "--at", "1"], "--formula and --modes go without --latex and --at"),
    (["--modes", "--coordinates", "x1"], "--coordinates goes with the formula"),
    (["--coordinates", "x3"], "--coordinates: unknown mass or coordinate 'x3'; masses are m1, m2; "
                              "coordinates are x1, x2"),
    (["--coordinates", "x1,m1"], "--coordinates: 'm1' is given twice"),
])
def test_bad_formula_options_are_one_line(capsys, args, fragment):
    assert_one_line_error(*run(capsys, "solve", "vertical-pair", *args), fragment)


def test_coordinates_choose_formula_lines_and_their_names(capsys):
    code, out, err = run(capsys, "solve", "three-dashpots", "--coordinates", "m2")
    assert code == 0, err
    lines = out.splitlines()
    assert lines[1].startswith("x2(t) = (c_1*cos(beta_1*t)") and not any(
        line.startswith("x1(t)") for line in lines)
    assert sum(line.strip().startswith("c_") and "≈" in line for line in lines) == 4


def test_modes_of_a_symbolic_scene_need_numbers(capsys, tmp_path):
    path = tmp_path / "osc.toml"
    path.write_text('[parameters]\nk = "stiffness"\n[masses]\nm1 = "1"\n[springs]\n'
                    'k1 = ["wall", "m1", "k"]\n[initial]\nx0 = ["1"]\n', encoding="utf-8")
    assert_one_line_error(*run(capsys, "solve", str(path), "--modes"),
                          "the modal summary (--modes) needs numbers", "--param k=...")
    code, out, err = run(capsys, "solve", str(path), "--modes", "--param", "k=4")
    assert code == 0, err
    assert out.splitlines()[2].split()[:2] == ["1", "2"]  # ω = sqrt(k/m) = 2


@pytest.mark.parametrize("args", [
    [], ["frobnicate"], ["solve"], ["solve", "vertical-pair", "--latex", "--at", "1"],
    ["solve", "vertical-pair", "--at", "1", "--dps", "many"],
])
def test_usage_errors_exit_2(capsys, args):
    code, out, err = run(capsys, *args)
    assert code == 2
    assert "usage: laplace-springs" in err
    assert "Traceback" not in err


SYMBOLIC_FILE = """title = "mass on a spring"
[parameters]
k = "stiffness, N/m"
c = "nonnegative"
[masses]
m1 = 1
[springs]
k1 = ["wall", "m1", "k"]
[dashpots]
c1 = ["wall", "m1", "c"]
[initial]
x0 = [1]
"""


@pytest.fixture
def symbolic_file(tmp_path):
    path = tmp_path / "symbolic.toml"
    path.write_text(SYMBOLIC_FILE, encoding="utf-8")
    return str(path)


def test_a_typo_in_a_scene_file_is_an_error_not_a_symbol(capsys, tmp_path):
    path = tmp_path / "typo.toml"
    path.write_text('[masses]\nm1 = 1\n[springs]\nk1 = ["wall", "m1", "abc"]\n', encoding="utf-8")
    assert_one_line_error(*run(capsys, "solve", str(path), "--at", "0,1"),
                          "typo.toml: spring 'k1'", "unknown name 'abc'", "[parameters]")


def test_symbolic_scene_prints_its_formula(capsys, symbolic_file):
    code, out, err = run(capsys, "solve", symbolic_file)
    assert code == 0, err
    lines = out.splitlines()
    assert lines[1].startswith("x1(t) = ") and "omega_1" in lines[1]
    # every name in the formula is defined under "where" (c/2 is the textbook decay rate)
    assert lines[2] == "where" and lines[3].startswith("  gamma_1 = c/2")
    assert lines[4].startswith("  omega_1 = sqrt(k - gamma_1**2)")


@pytest.mark.parametrize("args, fragment", [
    (["--at", "0,1"], "a table of values (--at) needs numbers, but the scene has the parameters c, k; "
                      "give them values with --param c=... --param k=..."),
    (["--param", "k=2", "--at", "1"], "the parameter c; give it a value with --param c=..."),
    (["--plot", "x.png"], "a plot (--plot) needs numbers"),
    (["--param", "q=2"], "--param: 'q' is not a parameter of this scene; its parameters are c, k"),
    (["--param", "k"], "--param: expected NAME=VALUE such as k=2, got 'k'"),
    (["--param", "k=1", "--param", "k=2"], "'k' is given twice"),
    (["--param", "k=-1"], "parameter 'k' is positive, got -1"),
    (["--param", "k=c", "--param", "c=k"], "the values of c, k refer to each other in a cycle"),
    (["--param", "k=1", "--param", "c=-2*k"], "parameter 'c' is nonnegative, got -2"),
    (["--param", "k=abc"], "parameter 'k': expected a number, got 'abc': unknown name 'abc'"),
    (["--param", "k=2", "--param", "c=nan"], "'nan' is not a finite real number"),
])
def test_parameters_need_values_for_numbers(capsys, symbolic_file, args, fragment):
    assert_one_line_error(*run(capsys, "solve", symbolic_file, *args), fragment)


def test_param_values_give_the_textbook_oscillator(capsys, symbolic_file):
    # x'' + c x' + k x = 0, x(0) = 1: with k = 4, c = 0 it is cos 2t
    code, out, err = run(capsys, "solve", symbolic_file, "--param", "k=4", "--param", "c=0",
                         "--at", "0.5,2")
    assert code == 0, err
    _, rows = table(out)
    for time, x1 in rows:
        assert x1 == pytest.approx(math.cos(2 * time), abs=1e-12)
    # critical damping c = 2 sqrt(k) = 4: (1 + 2t) e^{-2t}; a value may name another parameter
    code, out, err = run(capsys, "solve", symbolic_file, "--param", "k=4", "--param", "c=2*sqrt(k)",
                         "--at", "0.5")
    assert code == 0, err
    assert table(out)[1][0][1] == pytest.approx(2 * math.exp(-1), abs=1e-12)


def test_response_needs_numbers_too(capsys, symbolic_file):
    assert_one_line_error(*run(capsys, "response", symbolic_file), "needs numbers", "--param")
    code, out, err = run(capsys, "response", symbolic_file, "--param", "k=4", "--param", "c=1")
    assert code == 0, err


@pytest.mark.parametrize("args, fragment", [
    (["--plot", "/nonexistent/dir/x.png"], "--plot: '/nonexistent/dir/x.png': the folder '/nonexistent/dir' does not exist"),
    (["--plot", "x.unknown-format"], "--plot: 'x.unknown-format' has the suffix '.unknown-format'; the file name must end in .png"),
    (["--latex", "-o", "/nonexistent/dir/x.tex"], "-o/--output: '/nonexistent/dir/x.tex': the folder '/nonexistent/dir' does not exist"),
])
def test_unwritable_output_is_one_line(capsys, tmp_path, monkeypatch, args, fragment):
    monkeypatch.chdir(tmp_path)
    assert_one_line_error(*run(capsys, "solve", "vertical-pair", *args), fragment)


def test_an_internal_error_is_one_line_with_a_hint_and_debug_shows_the_traceback(capsys, monkeypatch):
    def broken(*args, **kwargs):
        raise KeyError("a bug")

    monkeypatch.setattr("laplace_springs.cli.solve", broken)
    code, out, err = run(capsys, "solve", "vertical-pair")
    assert code == 1 and out == ""
    assert err.splitlines() == ["laplace-springs: internal error: KeyError: 'a bug'; "
                                "run with --debug for the traceback"]
    for args in (["--debug", "solve", "vertical-pair"], ["solve", "vertical-pair", "--debug"]):
        code, out, err = run(capsys, *args)
        assert code == 1 and "Traceback (most recent call last)" in err and "KeyError" in err


def test_a_value_error_from_a_library_is_internal_but_one_from_our_checks_is_the_users(capsys, monkeypatch):
    monkeypatch.setattr("laplace_springs.cli.solve", lambda scene: np.zeros(2).reshape(3))
    code, out, err = run(capsys, "solve", "vertical-pair")
    assert code == 1 and err.startswith("laplace-springs: internal error: ValueError: cannot reshape")
    code, out, err = run(capsys, "bench", "--methods", "no-such-method")
    assert code == 2 and err.startswith("laplace-springs: error: no method matches 'no-such-method'")


# ---------------------------------------------------------------------------- subprocess


def _environment() -> dict[str, str]:
    return {**os.environ, "PYTHONIOENCODING": "utf-8"}


def test_python_dash_m_runs_the_command_line():
    result = subprocess.run([sys.executable, "-m", "laplace_springs", "solve", "vertical-pair",
                             "--at", "0.5,2"], check=False, capture_output=True, text=True,
                            timeout=120, env=_environment())
    assert result.returncode == 0, result.stderr
    _, rows = table(result.stdout)
    for time, x1, x2 in rows:
        assert (x1, x2) == pytest.approx(example_1(time), abs=1e-10)


def test_installed_entry_point_reports_errors_without_traceback():
    script = Path(sys.executable).with_name("laplace-springs")
    command = [str(script)] if script.exists() else [sys.executable, "-m", "laplace_springs"]
    result = subprocess.run([*command, "solve", "no-such-scene"], check=False, capture_output=True,
                            text=True, timeout=120, env=_environment())
    assert result.returncode == 2
    assert result.stdout == ""
    assert result.stderr.splitlines() == [result.stderr.strip()]
    assert result.stderr.startswith("laplace-springs: error: unknown scene 'no-such-scene'")


IRRATIONAL_PAIR = """
title = "irrational pair"
[masses]
m1 = "sqrt(2)"
m2 = "1"
[springs]
k1 = ["wall", "m1", "2"]
k2 = ["m1", "m2", "pi"]
[dashpots]
c1 = ["wall", "m1", "1/10"]
[initial]
x0 = {m1 = 1}
"""


def test_solve_without_an_exact_form_prints_the_float_modes_formula(capsys, tmp_path):
    """√2 and π: Δ is an irreducible quartic with irrational coefficients, so there are no
    exact roots; the formula comes from the float64 modes, after a note (it was an error)."""
    path = tmp_path / "pair.toml"
    path.write_text(IRRATIONAL_PAIR)
    code, out, _ = run(capsys, "solve", str(path))
    assert code == 0
    lines = out.splitlines()
    assert lines[1].startswith("note: no exact closed form (irreducible factor of degree 4")
    assert lines[2].startswith("x1(t) = ") and lines[3].startswith("x2(t) = ")
    values = named_values(lines[5:])
    # Δ(λ) = (√2λ² + λ/10 + 2 + π)(λ² + π) − π², written out by hand
    delta = np.polysub(np.polymul([math.sqrt(2), 0.1, 2 + math.pi], [1, 0, math.pi]),
                       [math.pi**2])
    for j in (1, 2):
        root = complex(values[sympy.Symbol(f"alpha_{j}")], values[sympy.Symbol(f"beta_{j}")])
        assert abs(np.polyval(delta, root)) < 1e-9


def test_solve_of_a_forced_scene_without_an_exact_form_says_to_tabulate(capsys, tmp_path):
    path = tmp_path / "pair.toml"
    path.write_text(IRRATIONAL_PAIR + '[forcing]\nm1 = "cos(t)"\n')
    assert_one_line_error(*run(capsys, "solve", str(path)), "no closed form", "--at")
    code, out, _ = run(capsys, "solve", str(path), "--at", "0,1")
    assert code == 0 and out.splitlines()[2].split()[:2] == ["0", "1"]
