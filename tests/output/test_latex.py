"""LaTeX export: renders with a real parser, and reads back as the same function.

Every bundled scene's ``sol.latex()`` is rendered row by row with matplotlib's mathtext
(and as whole blocks with KaTeX when node and the katex package are available), then
parsed back with ``sympy.parsing.latex.parse_latex``. The parsed x(t) rows, with the
named constants replaced by the values printed in the "where" rows, are compared with
the independent mpmath matrix exponential of laplace_springs.bench.reference.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
from decimal import Decimal

import numpy as np
import pytest
import sympy as sp

import laplace_springs as ls
from laplace_springs.bench.reference import reference_forced_motion, reference_motion
from laplace_springs.cli import main as cli_main
from laplace_springs.output.latex import LatexWriter, resolvent_latex, sylvester_latex

parse_latex = pytest.importorskip("sympy.parsing.latex").parse_latex
pytest.importorskip("antlr4")

SCENES = sorted(ls.bundled_scenes())
TIMES = ["0.3", "1.7", "6.1"]
E = sp.Symbol("e")


# ---------------------------------------------------------------------------
# helpers: rows of aligned blocks, mathtext, parsing back
# ---------------------------------------------------------------------------
def blocks(text: str) -> list[str]:
    return re.findall(r"\\begin\{aligned\}\n(.*?)\n\\end\{aligned\}", text, flags=re.S)


def rows(block: str) -> list[str]:
    return [row.strip() for row in block.split(" \\\\\n")]


def equations(block: str) -> list[tuple[str, str]]:
    """(lhs, rhs) pairs with continuation rows (``&\\quad ...``) joined."""
    out: list[list[str]] = []
    for raw in rows(block):
        row = raw.replace(r"\text{where}\quad ", "")
        if row.startswith(r"&\quad"):
            out[-1][1] += " " + row[len(r"&\quad"):].strip()
        else:
            lhs, _, rhs = row.partition("&")
            rhs = rhs.strip()
            out.append([lhs.strip(), rhs[1:].strip() if rhs.startswith("=") else rhs])
    return [(lhs, rhs) for lhs, rhs in out]


def mathtext_ok(row: str) -> None:
    """Render one row with matplotlib's mathtext parser (raises on bad LaTeX)."""
    from matplotlib.mathtext import MathTextParser
    MathTextParser("path").parse("$" + row.replace("&", " ") + "$")


def parse(tex: str) -> sp.Expr:
    return parse_latex(tex).subs(E, sp.E)


def name_values(block: str) -> dict[str, sp.Expr]:
    """Named constants from the "where" rows: ``name &\\approx v`` and ``... \\approx v``."""
    values = {}
    for lhs, rhs in equations(block):
        if rhs.startswith(r"\approx"):  # alpha_1 &\approx a, \quad beta_1 \approx b
            pairs = re.findall(r"(\\?[a-z]+_\{\d+\})\s*\\approx\s*(-?[\d.]+)", lhs + " " + rhs)
            pairs += [(lhs, re.match(r"\\approx\s*(-?[\d.]+)", rhs).group(1))]
            for name, value in pairs:
                values[str(parse(name))] = sp.Float(value, 15)
        elif r"\approx" in rhs:
            values[str(parse(lhs))] = sp.Float(rhs.rsplit(r"\approx", 1)[1].strip(), 15)
    return values


def motion_rows(text: str) -> tuple[list[tuple[str, str]], dict]:
    first = blocks(text)[0]
    eqs = equations(first)
    return [(lhs, rhs) for lhs, rhs in eqs if lhs.endswith("(t)")], name_values(first)


def numeric(expr: sp.Expr, values: dict, time: str) -> complex:
    subs = {s: values[str(s)] for s in expr.free_symbols if str(s) in values}
    subs[sp.Symbol("t")] = sp.Rational(time)
    return complex(sp.N(expr.xreplace(subs), 20))


# ---------------------------------------------------------------------------
# every bundled scene
# ---------------------------------------------------------------------------
@pytest.fixture(scope="module", params=SCENES)
def scene_latex(request):
    scene = ls.load_scene(request.param)
    return scene, ls.solve(scene).latex()


def test_no_heaviside_i_or_crootof(scene_latex):
    _, text = scene_latex
    assert "Heaviside" not in text and "CRootOf" not in text and "operatorname" not in text
    assert "re(" not in text and "im(" not in text and r"\Re" not in text
    without_text = re.sub(r"\\text\{[^}]*\}", "", text)
    assert not re.search(r"(?<![\\A-Za-z])i(?![A-Za-z])", without_text), "imaginary unit printed"


def test_every_row_renders_with_mathtext(scene_latex):
    _, text = scene_latex
    for block in blocks(text):
        for row in rows(block):
            mathtext_ok(row)


def test_round_trip_is_the_same_function(scene_latex):
    scene, text = scene_latex
    eqs, values = motion_rows(text)
    assert [lhs for lhs, _ in eqs] == [f"x_{{{i + 1}}}(t)" for i in range(scene.n)]
    reference = reference_motion(scene, TIMES, dps=30)
    for i, (_, rhs) in enumerate(eqs):
        expr = parse(rhs)
        unknown = {str(s) for s in expr.free_symbols} - set(values) - {"t"}
        assert not unknown, f"unnamed symbols {unknown} in {rhs}"
        got = [numeric(expr, values, time) for time in TIMES]
        scale = max(abs(complex(r)) for r in reference[i]) or 1.0
        for value, ref in zip(got, reference[i]):
            assert abs(value.imag) < 1e-12
            assert abs(value.real - float(ref)) < 1e-9 * scale


def test_g_form_round_trip():
    scene = ls.load_scene("vertical-pair-damped")
    text = ls.solve(scene).latex(form="g")
    eqs = equations(blocks(text)[0])
    g = {}
    for lhs, rhs in eqs:
        match = re.match(r"g_\{(\d+)\}\(t\)", lhs)
        if match:
            g[int(match.group(1))] = parse(rhs)
    assert sorted(g) == [0, 1, 2, 3]
    # the seed's Example 2 resolvent: Δ(λ) = 25λ⁴ + 10λ³ + 126λ² + 25λ + 100 (corrected 10λ³)
    (delta,) = [rhs for lhs, rhs in eqs if lhs == r"\Delta(\lambda)"]
    lam = sp.Symbol("lambda")
    assert sp.expand(parse(delta) - (25 * lam**4 + 10 * lam**3 + 126 * lam**2 + 25 * lam + 100)) == 0
    reference = reference_motion(scene, TIMES, dps=30)
    for i, (_, rhs) in enumerate(eqs[:scene.n]):
        expr = parse(rhs).replace(lambda f: isinstance(f, sp.Function) and str(f.func).startswith("g_"),
                                  lambda f: g[int(str(f.func).strip("g_{}"))])
        for time, ref in zip(TIMES, reference[i]):
            assert abs(numeric(expr, {}, time).real - float(ref)) < 1e-20


def test_markdown_and_standalone_shapes():
    sol = ls.solve(ls.load_scene("wall-pair-dashpot"))
    markdown = sol.latex(markdown=True)
    assert markdown.startswith("$$\n\\begin{aligned}") and markdown.rstrip().endswith("\\end{aligned}\n$$")
    document = sol.latex(standalone=True, resolvent=True)
    assert document.startswith("\\documentclass") and document.rstrip().endswith("\\end{document}")
    assert document.count("\\begin{align*}") == document.count("\\end{align*}") == 2
    assert "\\section*{Example 4" in document


@pytest.mark.skipif(shutil.which("pdflatex") is None,
                    reason="pdflatex not installed (.ci/run installs texlive-latex-base)")
def test_standalone_document_compiles(tmp_path):
    for name in sorted(ls.bundled_scenes()):  # every bundled scene's exported formulas
        path = tmp_path / f"{name}.tex"
        path.write_text(ls.solve(ls.load_scene(name)).latex(standalone=True, resolvent=True),
                        encoding="utf-8")
        done = subprocess.run(["pdflatex", "-interaction=nonstopmode", "-halt-on-error", path.name],
                              cwd=tmp_path, capture_output=True, text=True, timeout=120,
                              check=False)
        assert done.returncode == 0, done.stdout[-2000:]


def test_resolvent_latex_matches_the_seeds_example_2():
    text = resolvent_latex(ls.resolvent(ls.load_scene("vertical-pair-damped")))
    # the seed's R(λ): [[25λ² + 5λ + 50, 25], [50, 25λ² + 5λ + 75]]/Δ (its 500 is a misprint)
    matrix = re.search(r"\\begin\{bmatrix\}(.*?)\\end\{bmatrix\}", text).group(1)
    entries = [parse(cell) for row in matrix.split(r"\\") for cell in row.split("&")]
    lam = sp.Symbol("lambda")
    expected = [25 * lam**2 + 5 * lam + 50, 25, 50, 25 * lam**2 + 5 * lam + 75]
    assert all(sp.expand(a - b) == 0 for a, b in zip(entries, expected))


def test_sylvester_matrices_of_example_1():
    text = sylvester_latex(ls.load_scene("vertical-pair"))
    # the seed's (1.4): Z_1 = [[1, 1], [2, 2]]/3, Z_4 = [[2, -1], [-2, 1]]/3
    found = dict(re.findall(r"Z_\{(\d+)\} &= \\begin\{bmatrix\}(.*?)\\end\{bmatrix\}", text))
    for key, expected in (("1", [1, 1, 2, 2]), ("4", [2, -1, -2, 1])):
        cells = [parse(c) for row in found[key].split(r"\\") for c in row.split("&")]
        assert all(sp.simplify(c - sp.Rational(v, 3)) == 0 for c, v in zip(cells, expected))


def test_switched_input_prints_as_a_unit_step():
    writer = LatexWriter()
    t = ls.t
    (row,) = writer.equation("x(t)", sp.Heaviside(t) * sp.cos(t) + sp.Heaviside(t - 2) * sp.sin(t - 2))
    assert r"\theta\left(t - 2\right)" in row and "Heaviside" not in row
    assert r"\theta\left(t\right)" not in row  # the solution holds for t >= 0 anyway
    assert "unit step" in writer.where_rows()[-1]
    mathtext_ok(row)


# ---------------------------------------------------------------------------
# symbolic: the seed's Example 3
# ---------------------------------------------------------------------------
SEED3 = {"m1": "1", "m2": "2/3", "k1": "0.3", "k2": "0.08", "k3": "0.2",
         "d1": "-0.08", "d2": "0.4", "v1": "0.15", "v2": "-0.3"}


def example3(values):
    return ls.Scene.from_components(
        masses={"m1": values["m1"], "m2": values["m2"]},
        springs={"k1": ("wall", "m1", values["k1"]), "k2": ("m1", "m2", values["k2"]),
                 "k3": ("m2", "wall", values["k3"])},
        x0=[values["d1"], values["d2"]], v0=[values["v1"], values["v2"]],
        parameters={name: "real" if name[0] in "dv" else "positive"
                    for name in values.values() if name.isidentifier()})


def test_example3_symbolic_latex_round_trip():
    text = ls.solve(example3({k: k for k in SEED3})).latex()
    for block in blocks(text):
        for row in rows(block):
            mathtext_ok(row)
    eqs = equations(blocks(text)[0])
    values = {f"{k[0]}_{{{k[1]}}}": sp.Rational(v) for k, v in SEED3.items()}
    for lhs, rhs in eqs:  # definitions in reading order: each uses earlier names only
        if not lhs.endswith("(t)"):
            definition = parse(rhs.split("&&")[0])
            values[str(parse(lhs))] = sp.N(definition.xreplace(
                {s: values[str(s)] for s in definition.free_symbols}), 30)
    assert {"omega_{1}", "omega_{2}"} <= set(values)
    reference = reference_motion(example3(SEED3), TIMES, dps=30)
    motion = [rhs for lhs, rhs in eqs if lhs.endswith("(t)")]
    for i, rhs in enumerate(motion):
        expr = parse(rhs)
        for time, ref in zip(TIMES, reference[i]):
            assert abs(numeric(expr, values, time).real - float(ref)) < 1e-15


# ---------------------------------------------------------------------------
# KaTeX, when node and katex are available (NODE_PATH or a global install)
# ---------------------------------------------------------------------------
def _katex_available() -> bool:
    if shutil.which("node") is None:
        return False
    done = subprocess.run(["node", "-e", "require('katex')"], capture_output=True,
                          env={**os.environ}, timeout=30, check=False)
    return done.returncode == 0


@pytest.mark.skipif(not _katex_available(), reason="node with the katex package not available")
def test_katex_renders_every_block():
    texts = []
    for name in SCENES:
        sol = ls.solve(ls.load_scene(name))
        texts += blocks(sol.latex(resolvent=True, sylvester=not sol.scene.is_damped, form="terms"))
        texts += blocks(sol.latex(form="g"))
    texts += blocks(ls.solve(example3({k: k for k in SEED3})).latex(resolvent=True))
    texts = ["\\begin{aligned}\n" + body + "\n\\end{aligned}" for body in texts]
    script = ("const katex = require('katex'); const input = JSON.parse(require('fs')"
              ".readFileSync(0, 'utf8')); for (const tex of input) { katex.renderToString(tex, "
              "{displayMode: true, throwOnError: true, strict: 'error'}); } console.log(input.length);")
    done = subprocess.run(["node", "-e", script], input=json.dumps(texts), capture_output=True,
                          text=True, timeout=120, check=False)
    assert done.returncode == 0, done.stderr[-2000:]
    assert int(done.stdout) == len(texts)


def test_numbers_in_where_rows_are_plain_decimals():
    text = ls.solve(ls.load_scene("three-dashpots")).latex()
    values = name_values(blocks(text)[0])
    assert values and all(np.isfinite(float(v)) for v in values.values())


def test_cli_writes_a_standalone_document(tmp_path, capsys):
    path = tmp_path / "wall-pair.tex"
    assert cli_main(["solve", "wall-pair", "--latex", "--standalone", "-o", str(path)]) == 0
    text = path.read_text(encoding="utf-8")
    assert text.startswith("\\documentclass") and "\\end{document}" in text
    assert str(path) in capsys.readouterr().out
    assert cli_main(["solve", "wall-pair", "--standalone"]) == 2
    assert "--latex" in capsys.readouterr().err


def _bmatrix_cells(text: str) -> list[list[sp.Expr]]:
    matrix = re.search(r"\\begin\{bmatrix\}(.*?)\\end\{bmatrix\}", text).group(1)
    return [[parse(cell) for cell in row.split("&")] for row in matrix.split(r"\\")]


def test_resolvent_latex_of_example_3_is_the_textbook_inverse():
    # wall-pair: P(λ) = λ²M + K = [[λ² + k1 + k2, −k2], [−k2, m2λ² + k2 + k3]] (m1 = 1), and the
    # seed's R(λ) = (λ²I + A)⁻¹ = P⁻¹M, with P⁻¹ from the 2x2 formula [[d, −b], [−c, a]]/(ad − bc).
    lam = sp.Symbol("lambda")
    m1, m2, k1, k2, k3 = 1, sp.Rational(2, 3), sp.Rational(3, 10), sp.Rational(2, 25), sp.Rational(1, 5)
    a, b, c, d = m1 * lam**2 + k1 + k2, -k2, -k2, m2 * lam**2 + k2 + k3
    det = a * d - b * c
    R = sp.Matrix([[d, -b], [-c, a]]) / det * sp.diag(m1, m2)
    X = R * sp.Matrix([lam * sp.Rational(-8, 100) + sp.Rational(15, 100),
                       lam * sp.Rational(4, 10) - sp.Rational(3, 10)])  # R(λ)(λ x0 + v0)

    text = resolvent_latex(ls.resolvent(ls.load_scene("wall-pair")))
    eqs = equations(blocks(text)[0])
    (delta,) = [rhs for lhs, rhs in eqs if lhs == r"\Delta(\lambda)"]
    delta = parse(delta).doit()
    assert sp.Poly(delta, lam).is_primitive and sp.cancel(delta / det).is_Rational  # integer, content 1
    (matrix,) = [rhs for lhs, rhs in eqs if lhs.startswith("R(")]
    assert matrix.startswith(r"\frac{1}{\Delta(\lambda)}")
    cells = sp.Matrix(_bmatrix_cells(matrix))
    assert (cells / delta - R).applyfunc(sp.cancel) == sp.zeros(2, 2)
    for i, name in enumerate(("x_{1}", "x_{2}")):
        (rhs,) = [rhs for lhs, rhs in eqs if lhs == name + "^{L}(\\lambda)"]
        numerator = re.match(r"\\frac\{(.*)\}\{\\Delta\(\\lambda\)\}$", rhs).group(1)
        assert sp.cancel(parse(numerator) / delta - X[i]) == 0
    for row in rows(blocks(text)[0]):
        if "bmatrix" not in row:
            mathtext_ok(row)


def test_resolvent_latex_markdown_and_document():
    R = ls.resolvent(ls.load_scene("wall-pair"))
    fragment = resolvent_latex(R)
    snippet = resolvent_latex(R, output="markdown")
    assert snippet == f"$$\n{fragment}\n$$\n"
    document = resolvent_latex(R, output="document")
    assert document.startswith("\\documentclass") and document.rstrip().endswith("\\end{document}")
    assert fragment.replace("{aligned}", "{align*}") in document
    with pytest.raises(ValueError, match="output must be"):
        resolvent_latex(R, output="html")


def test_two_factors_print_two_distinct_frequencies():
    scene = ls.Scene.from_components(
        masses={"m1": "m", "m2": "m"},
        springs={"k1": ("wall", "m1", "k"), "k2": ("m1", "m2", "K"), "k3": ("m2", "wall", "k")},
        x0=[1, 0], v0=[0, 0], parameters=["m", "k", "K"])
    eqs = equations(blocks(ls.solve(scene).latex())[0])
    defined = [lhs for lhs, _ in eqs if not lhs.endswith("(t)")]
    assert defined == [r"\omega_{1}", r"\omega_{2}"]
    values = {"m": 5, "k": 2, "K": 3}
    numbers = {}
    for lhs, rhs in eqs:
        if lhs in defined:
            expr = parse(rhs.split("&&")[0])
            numbers[str(parse(lhs))] = expr.xreplace({s: values[str(s)] for s in expr.free_symbols})
    numeric_scene = ls.Scene.from_components(
        masses={"m1": 5, "m2": 5},
        springs={"k1": ("wall", "m1", 2), "k2": ("m1", "m2", 3), "k3": ("m2", "wall", 2)},
        x0=[1, 0], v0=[0, 0])
    reference = reference_motion(numeric_scene, TIMES, dps=30)
    for i, (_, rhs) in enumerate(eqs[:2]):
        for time, ref in zip(TIMES, reference[i]):
            assert abs(numeric(parse(rhs), numbers, time).real - float(ref)) < 1e-15


def test_forced_piece_switched_on_at_tau_round_trips():
    # x'' + x'/2 + 4x = θ(t − 2) + sin 3t, x(0) = 1, x'(0) = 0. Reference by superposition of
    # two matrix exponentials with an exosystem (no Laplace transform): the sine-driven motion
    # from the initial data, plus the zero-state response to a unit constant force delayed by 2.
    scene = ls.Scene.from_matrices(M=[[1]], C=[["0.5"]], K=[[4]], x0=[1], v0=[0],
                                   forcing=[ls.step(1, at=2) + ls.sine(1, 3)])
    text = ls.solve(scene).latex()
    assert "Heaviside" not in text and r"\theta\left(t - 2\right)" in text
    for row in rows(blocks(text)[0]):
        mathtext_ok(row)
    ((_, rhs),) = [(lhs, rhs) for lhs, rhs in equations(blocks(text)[0]) if lhs.endswith("(t)")]
    expr = parse(rhs).replace(lambda f: isinstance(f, sp.Function) and str(f.func) == "theta",
                              lambda f: sp.Heaviside(f.args[0], 1))
    times = ["0.5", "2", "3.7", "6.1"]
    driven = reference_forced_motion(scene, [[0, -3], [3, 0]], [1, 0], [[0, 1]], times, dps=30)
    at_rest = scene.with_initial(x0=[0], v0=[0])
    delayed = [str(Decimal(time) - 2) for time in times if Decimal(time) >= 2]
    stepped = reference_forced_motion(at_rest, [[0]], [1], [[1]], delayed, dps=30)
    steps = iter(stepped[0])
    for time, base in zip(times, driven[0]):
        expected = float(base) + (float(next(steps)) if Decimal(time) >= 2 else 0.0)
        value = numeric(expr, {}, time)
        assert abs(value.imag) < 1e-15
        assert abs(value.real - expected) < 1e-14
