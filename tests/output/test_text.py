"""Readable text: x(t) with named rates, frequencies and coefficients; modal summaries; reprs.

Expected values come from outside the code under test: the 60-digit matrix exponential of
laplace_springs.bench.reference, the roots of the seed's characteristic polynomials taken
by numpy here, the seed's Example 1 closed form, and the textbook modes of a uniform chain
(ω_k = 2 sqrt(k/m) sin(kπ/(2(n+1))), shapes sin(ikπ/(n+1))).
"""

from __future__ import annotations

import math
import re
import time

import numpy as np
import pytest
import sympy as sp

import laplace_springs as ls
from laplace_springs.analysis.modes import float_modes
from laplace_springs.bench.reference import reference_motion
from laplace_springs.cli import main
from laplace_springs.output.text import formula_lines, participation, summary_lines

T = sp.Symbol("t")
TIMES = ["0.37", "1.3", "4.1"]

# The seed's Example 5 (three-dashpots): M = diag(1, 0.8), three spring-dashpot pairs.
EX5_M = np.diag([1.0, 0.8])
EX5_C = np.array([[0.5 + 1.4, -1.4], [-1.4, 1.4 + 0.9]])
EX5_K = np.array([[400.0 + 379.0, -379.0], [-379.0, 379.0 + 100.0]])


def run(capsys, *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def where_values(lines: list[str]) -> dict[sp.Symbol, float]:
    """Printed ``name ≈ value`` pairs of a "where" list, parsed back with float."""
    out = {}
    for line in lines:
        for item in line.split(", "):
            name, approx, value = item.strip().partition(" ≈ ")
            if approx and re.fullmatch(r"[a-z]+_\d+", name):
                out[sp.Symbol(name)] = float(value.split()[0])
    return out


def exact_definitions(lines: list[str]) -> dict[sp.Symbol, str]:
    """``c_j ≈ value`` followed by ``= (exact)``: name → the exact text."""
    out = {}
    for first, second in zip(lines, lines[1:]):
        match = re.fullmatch(r"\s+(c_\d+) ≈ \S+", first)
        if match and second.strip().startswith("= "):
            out[sp.Symbol(match.group(1))] = second.strip()[2:]
    return out


def characteristic_roots(M, C, K) -> np.ndarray:
    """Roots of det(λ²M + λC + K) by numpy: the quadratic eigenvalues via the companion."""
    n = len(M)
    Z = np.block([[np.zeros((n, n)), np.eye(n)], [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    return np.linalg.eigvals(Z)


# ---------------------------------------------------------------------------- three-dashpots


def test_three_dashpots_is_short_and_has_no_re_or_im(capsys):
    code, out, err = run(capsys, "solve", "three-dashpots")
    assert (code, err) == (0, "")
    assert "re(" not in out and "im(" not in out and "CRootOf" not in out
    assert len(out) <= 3000
    lines = out.splitlines()
    assert lines[0] == "Example 5: two masses, three spring-dashpot pairs"
    assert lines[1] == ("x1(t) = (c_1*cos(beta_1*t) + c_2*sin(beta_1*t))*exp(alpha_1*t) + "
                        "(c_3*cos(beta_2*t) + c_4*sin(beta_2*t))*exp(alpha_2*t)")
    assert lines[3] == "where"


def test_three_dashpots_values_match_the_reference(capsys):
    _, out, _ = run(capsys, "solve", "three-dashpots")
    lines = out.splitlines()
    values = where_values(lines[4:])
    assert {s.name for s in values} == {"alpha_1", "beta_1", "alpha_2", "beta_2"} | {
        f"c_{j}" for j in range(1, 9)}
    # α_j ± iβ_j are the roots of det(λ²M + λC + K), slowest frequency first
    roots = sorted((r for r in characteristic_roots(EX5_M, EX5_C, EX5_K) if r.imag > 0),
                   key=lambda r: r.imag)
    for j, root in enumerate(roots, start=1):
        assert values[sp.Symbol(f"alpha_{j}")] == pytest.approx(root.real, rel=1e-10)
        assert values[sp.Symbol(f"beta_{j}")] == pytest.approx(root.imag, rel=1e-10)
    # the printed formula with the printed 12-digit values against the 60-digit reference
    scene = ls.load_scene("three-dashpots")
    reference = reference_motion(scene, TIMES, dps=60)
    local = {"t": T, **{s.name: s for s in values}}
    for i, line in enumerate(lines[1:3]):
        printed = sp.sympify(line.split(" = ", 1)[1], locals=local).subs(values)
        for k, time_ in enumerate(TIMES):
            assert float(printed.subs(T, sp.Rational(time_))) == pytest.approx(
                float(reference[i, k]), rel=1e-10, abs=1e-12)


def test_three_dashpots_exact_definitions_give_the_printed_values(capsys):
    _, out, _ = run(capsys, "solve", "three-dashpots")
    lines = out.splitlines()
    values = where_values(lines)
    definitions = exact_definitions(lines)
    assert len(definitions) == 8
    roots = sorted((r for r in characteristic_roots(EX5_M, EX5_C, EX5_K) if r.imag > 0),
                   key=lambda r: r.imag)
    at = {}
    for j, root in enumerate(roots, start=1):
        at[sp.Symbol(f"alpha_{j}")] = sp.Float(root.real, 17)
        at[sp.Symbol(f"beta_{j}")] = sp.Float(root.imag, 17)
    local = {s.name: s for s in at}
    for name, text in definitions.items():
        exact = sp.sympify(text, locals=local)
        assert exact.free_symbols <= set(at)
        assert float(exact.subs(at)) == pytest.approx(values[name], rel=1e-9, abs=1e-12)


def test_pretty_uses_unicode_names(capsys):
    code, out, _ = run(capsys, "solve", "three-dashpots", "--pretty")
    assert code == 0
    assert "x₁(t) = (c₁·cos(β₁·t) + c₂·sin(β₁·t))·e^(α₁·t)" in out
    assert "α₁ ≈" in out and "β₂ ≈" in out and "c₈ ≈" in out
    assert "(λ - α₁)² + β₁² is a factor of 80·λ⁴" in out
    assert "**" not in out and "re(" not in out and "alpha" not in out


def test_pretty_powers_with_fractional_exponents_read_back_as_the_same_number(capsys):
    """Example 5 in its units has (625 − 25√193)^(3/2): the product's · must not eat the
    power's ** (it printed "··(3/2)"). The pretty line, read back with ^ as a power, is the
    plain line's number at t = 0.3."""
    lines = []
    for flags in ((), ("--pretty",)):
        code, out, _ = run(capsys, "solve", "example5-in-units", *flags)
        assert code == 0
        lines.append(next(line for line in out.splitlines() if line.startswith("x")))
    plain, pretty = lines
    assert "··" not in pretty and "**" not in pretty and "^(3/2)" in pretty
    readable = re.sub(r"√(\d+)", r"sqrt(\1)", pretty.split("= ", 1)[1])
    readable = readable.replace("√", "sqrt").replace("·", "*").replace("^", "**")
    t = sp.Symbol("t")
    at = {t: sp.Rational(3, 10)}
    expected = sp.sympify(plain.split("= ", 1)[1], locals={"t": t}).subs(at)
    assert sp.N(sp.sympify(readable, locals={"t": t}).subs(at) - expected, 30) == \
        pytest.approx(0, abs=1e-25)


# ---------------------------------------------------------------------------- str(sol)


def seed_example_1(time_: float) -> tuple[float, float]:
    c1, c2, s1, s2 = math.cos(time_), math.cos(2 * time_), math.sin(time_), math.sin(2 * time_)
    return (c1 / 3 + 2 * c2 / 3 + s1 / 3 - s2 / 6, 2 * c1 / 3 - 2 * c2 / 3 + 2 * s1 / 3 + s2 / 6)


@pytest.mark.parametrize("name", sorted(ls.bundled_scenes()))
def test_str_of_seed_examples_evaluates_to_the_reference(name):
    scene = ls.load_scene(name)
    text = str(ls.solve(scene))
    lines = text.splitlines()
    assert lines[0] == scene.title
    assert "re(" not in text and "im(" not in text and "CRootOf" not in text
    assert [line.split(" = ")[0] for line in lines[1:3]] == ["x1(t)", "x2(t)"]
    values = where_values(lines[3:])
    local = {"t": T, **{s.name: s for s in values}}
    reference = reference_motion(scene, TIMES, dps=40)
    for i, line in enumerate(lines[1:3]):
        printed = sp.sympify(line.split(" = ", 1)[1], locals=local).subs(values)
        for k, time_ in enumerate(TIMES):
            assert float(printed.subs(T, sp.Rational(time_))) == pytest.approx(
                float(reference[i, k]), rel=1e-10, abs=1e-12)


def test_str_of_example_1_is_the_seed_closed_form():
    lines = str(ls.solve(ls.load_scene("vertical-pair"))).splitlines()
    for time_ in (0.5, 2.0):
        for i in range(2):
            printed = sp.sympify(lines[1 + i].split(" = ", 1)[1], locals={"t": T})
            assert float(printed.subs(T, time_)) == pytest.approx(seed_example_1(time_)[i], abs=1e-14)


def test_symbolic_formula_lists_named_quantities_in_unicode():
    scene = ls.Scene.from_matrices(M=[[1]], C=[["c"]], K=[["k"]], x0=[1], v0=[0], parameters=["c", "k"])
    lines = formula_lines(scene, ls.solve(scene).x, pretty=True)
    assert lines[1] == "where"
    assert lines[2].startswith("  γ₁ = c/2") and lines[3].startswith("  ω₁ = √(k - γ₁²)")


# ---------------------------------------------------------------------------- reprs


def test_scene_shows_its_diagram_as_png_and_svg():
    pytest.importorskip("matplotlib")
    scene = ls.load_scene("three-dashpots")
    png = scene._repr_png_()
    assert isinstance(png, bytes) and png.startswith(b"\x89PNG")
    svg = scene._repr_svg_()
    assert isinstance(svg, str) and "<svg" in svg
    assert scene._repr_latex_().startswith("$")  # the equations are still there


def test_scene_without_a_drawable_layout_has_no_diagram():
    # a non-diagonal mass matrix is not a chain of springs (draw_scene refuses it)
    scene = ls.Scene.from_matrices(M=[[2, 1], [1, 2]], K=[[1, 0], [0, 1]], x0=[1, 0], v0=[0, 0])
    assert scene._repr_png_() is None and scene._repr_svg_() is None


def test_mode_repr_is_short_with_exact_values():
    (mode,) = ls.modes(ls.Scene.from_matrices(M=[[1]], C=[["0.4"]], K=[[4]], x0=[1], v0=[0]))
    assert repr(mode) == "Mode(ω_n=2, ζ=1/10, oscillatory)"
    text = repr(ls.modes(ls.load_scene("three-dashpots"))[0])
    assert text.startswith("Mode(ω_n≈15.99") and "ζ≈0.0299" in text and len(text) < 60


def test_resolvent_and_verification_reprs():
    R = ls.resolvent(ls.load_scene("vertical-pair-damped"))
    assert repr(R) == ("Resolvent(2 coordinates, Δ(λ) = 25*lambda**4 + 10*lambda**3 + "
                       "126*lambda**2 + 25*lambda + 100)")
    check = ls.solve(ls.load_scene("three-dashpots")).verify()
    text = repr(check)
    assert text.startswith("Verification(ok: ODE residual ") and "tolerance 1e-09" in text


# ---------------------------------------------------------------------------- modal summaries


def chain_toml(n: int, dashpot: str | None = None) -> str:
    lines = [f'title = "chain of {n} unit masses"', "[masses]"]
    lines += [f'm{i} = "1"' for i in range(1, n + 1)]
    lines += ["[springs]", 'k1 = ["wall", "m1", "1"]']
    lines += [f'k{i} = ["m{i - 1}", "m{i}", "1"]' for i in range(2, n + 1)]
    lines.append(f'k{n + 1} = ["m{n}", "wall", "1"]')
    if dashpot:
        lines += ["[dashpots]", f'mu1 = ["wall", "m1", "{dashpot}"]']
    lines += ["[initial]", "x0 = [" + ", ".join('"1"' if i == 0 else '"0"' for i in range(n)) + "]"]
    return "\n".join(lines) + "\n"


def summary_rows(out: str) -> list[list[str]]:
    return [line.split() for line in out.splitlines() if re.match(r"\s+\d+\s", line)]


def test_summary_of_a_200_mass_chain(capsys, tmp_path):
    n = 200
    path = tmp_path / "chain.toml"
    path.write_text(chain_toml(n), encoding="utf-8")
    start = time.perf_counter()
    code, out, err = run(capsys, "solve", str(path))
    elapsed = time.perf_counter() - start
    assert (code, err) == (0, ""), err
    assert len(out) < 3000 and elapsed < 30  # about a second alone; generous on a shared machine
    assert "200 coordinates, 200 modes (undamped)" in out and "190 more modes" in out
    rows = summary_rows(out)
    assert [int(row[0]) for row in rows] == list(range(1, 11))
    # textbook chain: ω_k = 2 sin(kπ/(2(n+1))); x0 = e1 puts q_k = sqrt(2/(n+1)) sin(kπ/(n+1))
    # into mode k, whose energy is ω_k² q_k²/2 of the total K11/2 = 1.
    for row in rows:
        k = int(row[0])
        omega = 2 * math.sin(k * math.pi / (2 * (n + 1)))
        assert float(row[1]) == pytest.approx(omega, abs=1e-9)
        assert float(row[2]) == 0 and float(row[3]) == pytest.approx(omega, abs=1e-9)
        shape = math.sqrt(2 / (n + 1)) * np.sin(np.arange(1, n + 1) * k * math.pi / (n + 1))
        assert float(row[4]) == pytest.approx(abs(shape[0]) * np.max(np.abs(shape)), rel=1e-5)
        assert float(row[5].rstrip("%")) / 100 == pytest.approx(omega**2 * shape[0] ** 2 / 2, rel=6e-3)


def test_summary_of_a_damped_chain_has_damping_ratios(capsys, tmp_path):
    path = tmp_path / "damped.toml"
    path.write_text(chain_toml(60, dashpot="1/10"), encoding="utf-8")
    code, out, err = run(capsys, "solve", str(path), "--pretty")
    assert code == 0, err
    assert "ω_n" in out and "(damped)" in out
    rows = summary_rows(out)
    assert len(rows) == 10 and all(float(row[2]) > 0 for row in rows)
    # the pencil's own eigenvalues, by numpy here
    n = 60
    K = 2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1)
    C = np.zeros((n, n))
    C[0, 0] = 0.1
    roots = sorted((r for r in characteristic_roots(np.eye(n), C, K) if r.imag > 0), key=abs)
    for row, root in zip(rows, roots):
        assert float(row[1]) == pytest.approx(abs(root), rel=1e-9)
        assert float(row[2]) == pytest.approx(-root.real / abs(root), rel=2e-6)  # 6 digits


def test_formula_of_a_large_scene_needs_a_choice_of_coordinates(capsys, tmp_path):
    n = 200
    path = tmp_path / "chain.toml"
    path.write_text(chain_toml(n), encoding="utf-8")
    code, out, err = run(capsys, "solve", str(path), "--formula")
    assert code == 2 and "--coordinates" in err
    code, out, err = run(capsys, "solve", str(path), "--formula", "--coordinates", "x1")
    assert code == 0, err
    lines = out.splitlines()
    assert lines[1].startswith("x1(t) = ") and lines[2] == "where"
    values = {s.name: v for s, v in where_values(lines[3:]).items()}
    # an undamped chain: a sum of A_k*cos(beta_k*t) terms only (read by a pattern, not evaluated)
    body = lines[1].split(" = ", 1)[1]
    terms = re.findall(r"([-+]? ?[0-9.e+-]+)\*cos\((beta_\d+)\*t\)", body)
    assert len(terms) == n and "sin(" not in body and "exp(" not in body
    # textbook modal sum: x1(t) = Σ_k q_k² cos(ω_k t)
    k = np.arange(1, n + 1)
    q = math.sqrt(2 / (n + 1)) * np.sin(k * math.pi / (n + 1))
    omega = 2 * np.sin(k * math.pi / (2 * (n + 1)))
    for time_ in (0.0, 3.5):
        expected = float(np.sum(q**2 * np.cos(omega * time_)))
        found = sum(float(a.replace(" ", "")) * math.cos(values[b] * time_) for a, b in terms)
        assert found == pytest.approx(expected, abs=1e-10)


def test_modes_of_a_small_scene_and_their_energy(capsys):
    code, out, err = run(capsys, "solve", "vertical-pair", "--modes")
    assert code == 0, err
    rows = summary_rows(out)
    assert [float(row[1]) for row in rows] == [1, 2]
    # the seed's closed form: mode 1 is (cos t + sin t)(1/3, 2/3), mode 2 (2cos 2t/3 - sin 2t/6)(1, -1)
    M, K = np.diag([1.0, 0.5]), np.array([[3.0, -1.0], [-1.0, 1.0]])
    x1, v1 = np.array([1 / 3, 2 / 3]), np.array([1 / 3, 2 / 3])
    x2, v2 = np.array([2 / 3, -2 / 3]), np.array([-1 / 3, 1 / 3])
    energy = [0.5 * (v @ M @ v + x @ K @ x) for x, v in ((x1, v1), (x2, v2))]
    total = 0.5 * (np.array([0, 1.0]) @ M @ np.array([0, 1.0]) + np.array([1.0, 0]) @ K @ np.array([1.0, 0]))
    for row, part in zip(rows, energy):
        assert float(row[5].rstrip("%")) == pytest.approx(100 * part / total, abs=0.006)
    assert float(rows[0][4]) == pytest.approx(math.sqrt(2) * 2 / 3, rel=1e-5)


def test_participation_is_none_for_a_defective_mode():
    scene = ls.Scene.from_matrices(M=[[1]], C=[[2]], K=[[1]], x0=[1], v0=[0])  # critical damping
    assert participation(scene, ls.modes(scene)) is None
    assert "(no participation" in summary_lines(scene)[-1]


def test_float_modes_of_a_chain_match_the_textbook():
    n = 30
    K = (2 * sp.eye(n) - sp.Matrix(n, n, lambda i, j: 1 if abs(i - j) == 1 else 0))
    scene = ls.Scene.from_matrices(M=sp.eye(n), K=K, x0=[1] + [0] * (n - 1), v0=[0] * n)
    found = [m.natural_frequency for m in float_modes(scene)]
    expected = [2 * math.sin(k * math.pi / (2 * (n + 1))) for k in range(1, n + 1)]
    assert found == pytest.approx(expected, abs=1e-13)
