"""Worked-example pages: self-contained, their sliders' data right, their LaTeX compiles."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import base64
import json
import re
import shutil
import subprocess

import numpy as np
import pytest
import sympy as sp

import laplace_springs as ls
from laplace_springs.cli import main
from laplace_springs.publish.grid import slider_grid
from laplace_springs.publish.page import worked_example

pytest.importorskip("mathjax", reason="the pages need the packaged MathJax (django-static-mathjax)")


@pytest.fixture(scope="module")
def pair_page():
    return worked_example(ls.load_scene("vertical-pair"), animation=False)


def test_the_page_carries_everything_it_needs(pair_page):
    page = pair_page.html()
    assert [s.key for s in pair_page.sections] == [
        "system", "resolvent", "partial-fractions", "g-functions", "solution", "check", "plots"]
    markup = re.sub(r"<script[^>]*>.*?</script>", "", page, flags=re.S)  # MathJax's own text aside
    external = re.findall(r'(?:src|href)\s*=\s*"(?!data:|#)([^"]*)"', markup)
    assert external == []  # images inline, no stylesheet or script from elsewhere
    assert page.count("data:image/png;base64,") == 3  # diagram, motion, energy
    assert "tex-svg-full" not in page and "MathJax.startup" in page and len(page) > 2_000_000
    # the seed's Example 1: Δ(λ) = (λ² + 1)(λ² + 4), split into one fraction per factor
    assert "Partial fractions" in page and "\\lambda^{2} + 4" in page


def test_the_sliders_data_are_the_solutions_at_those_values(pair_page):
    grid = pair_page.grid
    assert [k.name for k in grid.knobs] == ["k1", "k2", "m1"]
    values = np.frombuffer(base64.b64decode(grid.encoded()), dtype="<f4").reshape(grid.values.shape)
    start = grid.start()
    own = values[grid.set_index(start)]
    expected = ls.solve(ls.load_scene("vertical-pair")).evaluate(grid.times)
    assert np.allclose(own, expected, atol=1e-6)  # float32 in the page
    # one slider moved: k1 at another value, against the scene written out with it (exact route)
    moved = list(start)
    moved[0] = 1
    k1 = sp.Rational(float(grid.axes[0][1]))  # the float the sweep used, exactly
    other = ls.Scene.from_components(masses={"m1": 1, "m2": "1/2"},
                                     springs={"k1": ("ceiling", "m1", k1), "k2": ("m1", "m2", 1)},
                                     x0=[1, 0], v0=[0, 1], layout="vertical")
    reference = np.asarray(ls.solve(other, method="exact").evaluate(grid.times), dtype=float)
    assert np.allclose(grid.values[grid.set_index(moved)], reference, rtol=0, atol=1e-11)
    page = pair_page.html()
    data = json.loads(re.search(r'id="ls-grid-data">(.*?)</script>', page, re.S).group(1))
    assert data["values"] == grid.encoded() and len(data["knobs"]) == 3


def test_a_symbolic_scene_is_plotted_at_the_values_given():
    scene = ls.Scene.from_matrices(M=[[1]], C=[["c"]], K=[["k"]], x0=[1], v0=[0], parameters=["c", "k"])
    example = worked_example(scene, values={"c": "1/2", "k": 4}, animation=False)
    plots = next(s for s in example.sections if s.key == "plots")
    assert plots.text == ("Plotted at \\(c = \\frac{1}{2}\\), \\(k = 4\\).",)
    assert [k.name for k in example.grid.knobs] == ["c", "k"] and example.grid.values.shape[0] == 15 * 15
    assert ls.t in example.solution.x[0].free_symbols and sp.Symbol("k", positive=True) in example.solution.x[0].free_symbols


def test_the_animation_plays_offline():
    example = worked_example(ls.load_scene("wall-pair"), animation=True)
    assert "font-awesome" not in example.animation_html and "data:image/jpeg;base64" in example.animation_html


@pytest.mark.skipif(shutil.which("pdflatex") is None, reason="pdflatex not installed (.ci/run installs it)")
def test_the_latex_document_compiles(pair_page, tmp_path):
    path = pair_page.save_tex(tmp_path / "pair.tex")
    assert (tmp_path / "pair-1.png").exists()
    done = subprocess.run(["pdflatex", "-interaction=nonstopmode", "-halt-on-error", path.name],
                          cwd=tmp_path, capture_output=True, text=True, timeout=120, check=False)
    assert done.returncode == 0, done.stdout[-3000:]
    assert (tmp_path / "pair.pdf").stat().st_size > 10_000


def test_the_command_line_writes_pages_and_animations(tmp_path, capsys):
    assert main(["page", "wall-pair", "-o", str(tmp_path / "page.html"), "--no-animation"]) == 0
    assert (tmp_path / "page.html").read_text(encoding="utf-8").startswith("<!DOCTYPE html>")
    assert main(["animate", "wall-pair", "-o", str(tmp_path / "pair.gif"), "--duration", "0.5",
                 "--fps", "4", "--dpi", "30"]) == 0
    assert "wrote" in capsys.readouterr().out and (tmp_path / "pair.gif").stat().st_size > 1000
    assert main(["animate", "wall-pair", "-o", str(tmp_path / "pair.avi")]) == 2
    assert "must end in .gif, .mp4 or .html" in capsys.readouterr().err


def test_a_scene_that_cannot_be_swept_says_why():
    periodic = ls.Scene.from_matrices(M=[[1]], C=[["1/2"]], K=[[4]], x0=[1], v0=[0],
                                      forcing=[ls.square_wave(1, 2)])
    with pytest.raises(ls.SceneError, match="periodic"):
        slider_grid(periodic, t_end=5.0)
