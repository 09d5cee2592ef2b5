"""Command line for driven systems: ``solve --forcing`` and ``response``.

Expected values: the textbook resonance form x = F0 t sin(ω t)/(2 m ω) (Rao, Mechanical
Vibrations, eq. 3.16) and |H(iω)| = 1/√((k − mω²)² + (cω)²) for one mass.
"""

from __future__ import annotations

import math

import pytest

from laplace_springs.cli import main


def run(capsys, *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def test_solve_with_forcing_table_matches_textbook(capsys, tmp_path):
    path = tmp_path / "one.toml"
    path.write_text('[matrices]\nM = [["1"]]\nK = [["4"]]\n[initial]\nx0 = ["0"]\nv0 = ["0"]\n')
    code, out, err = run(capsys, "solve", str(path), "--forcing", "6*cos(2*t)", "--at", "0,1.5,7")
    assert code == 0, err
    rows = [line.split() for line in out.splitlines()[1:]]
    for time, value in rows:
        t = float(time)
        assert math.isclose(float(value), 6 * t * math.sin(2 * t) / 4, rel_tol=1e-11, abs_tol=1e-12)


def test_solve_forcing_by_name_and_formula(capsys):
    code, out, err = run(capsys, "solve", "vertical-pair", "--forcing", "x2=Heaviside(t - 1)")
    assert code == 0, err
    assert "Heaviside(t - 1)" in out


@pytest.mark.parametrize("args, fragment", [
    (("--forcing", "cos(t)"), "--forcing was given once; the scene has 2 coordinates (x1, x2)"),
    (("--forcing", "1", "--forcing", "2", "--forcing", "3"), "given 3 times; the scene has 2 coordinates"),
    (("--forcing", "x1=cos(t**2)"), "not linear in t"),
    (("--forcing", "x9=1"), "unknown mass or coordinate 'x9'; masses are m1, m2; coordinates are x1, x2"),
    (("--forcing", "1", "--forcing", "x2=1"), "not both"),
    (("--forcing", "m1=1", "--forcing", "x1=2"), "coordinate x1 is given twice"),
    (("--forcing", "m2=cos(x)"), "--forcing m2: expected an expression in t, got 'cos(x)': unknown name 'x'"),
    (("--forcing", "cos(t", "--forcing", "0"), "--forcing #1 (x1): expected an expression in t, got 'cos(t'"),
    (("--forcing", "x1=__import__('os')"), "--forcing x1: expected an expression in t"),
])
def test_bad_forcing_is_one_line_error(capsys, args, fragment):
    code, out, err = run(capsys, "solve", "wall-pair", *args)
    assert code == 2 and out == ""
    assert len(err.splitlines()) == 1 and fragment in err and "Traceback" not in err


def test_response_prints_modes_and_amplitudes(capsys, tmp_path):
    path = tmp_path / "one.toml"
    path.write_text('[matrices]\nM = [["2"]]\nC = [["1"]]\nK = [["8"]]\n'
                    '[initial]\nx0 = ["0"]\nv0 = ["0"]\n')
    png = tmp_path / "response.png"
    code, out, err = run(capsys, "response", str(path), "--at", "1,2", "--plot", str(png))
    assert code == 0, err
    mode = out.splitlines()[1].split()
    assert math.isclose(float(mode[1]), 2.0) and math.isclose(float(mode[2]), 0.125)
    table = out.splitlines()[-3:-1]
    for line in table:
        w, amplitude = map(float, line.split())
        assert math.isclose(amplitude, 1 / math.hypot(8 - 2 * w * w, w), rel_tol=1e-10)  # 12 digits printed
    assert png.stat().st_size > 10_000


def test_response_rejects_a_bad_force_index(capsys):
    code, out, err = run(capsys, "response", "wall-pair", "--force", "3")
    assert code == 2 and "--force must be between 1 and 2" in err


def test_forcing_mixes_mass_and_coordinate_names(capsys):
    # m1 is coordinate x1 of the wall pair: forcing x2 = 1 and m1 = 0 gives the static offset
    code, out, err = run(capsys, "solve", "wall-pair", "--forcing", "m1=0", "--forcing", "x2=1")
    assert code == 0, err
    assert "x2(t) =" in out
