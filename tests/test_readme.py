"""The README's Python snippets run top to bottom as written, in one namespace."""

from __future__ import annotations

import re
from pathlib import Path

import matplotlib
import pytest
import sympy

README = Path(__file__).resolve().parents[1] / "README.md"
_BLOCK = re.compile(r"^```python\n(.*?)^```", re.MULTILINE | re.DOTALL)


def python_blocks() -> list[str]:
    return _BLOCK.findall(README.read_text(encoding="utf-8"))


def test_the_readme_has_python_snippets():
    assert len(python_blocks()) >= 3


def test_the_readme_snippets_run_top_to_bottom(tmp_path, monkeypatch):
    matplotlib.use("Agg")
    monkeypatch.chdir(tmp_path)  # snippets may write files
    namespace: dict = {}
    for number, block in enumerate(python_blocks(), start=1):
        try:
            exec(compile(block, f"README.md python block {number}", "exec"), namespace)  # our own README
        except Exception as error:  # report which snippet broke
            pytest.fail(f"README python block {number} fails: {type(error).__name__}: {error}\n{block}")
    ls = namespace["ls"]
    # spot checks of what the snippets' comments promise, against textbook formulas
    s, t = ls.s, ls.t
    assert ls.inverse_laplace(1 / (s**2 + 2 * s + 5), s, t) == sympy.exp(-t) * sympy.sin(2 * t) / 2
    assert sympy.simplify(ls.laplace("t*sin(2*t) + Heaviside(t - 1)")
                          - (4 * s / (s**2 + 4) ** 2 + sympy.exp(-s) / s)) == 0
    scene = namespace["scene"]  # the last scene of the README: the one with parameters c, k
    assert [symbol.name for symbol in scene.parameters] == ["c", "k"]
    critical = ls.solve(scene.subs({"c": 2, "k": 1})).x[0]
    assert sympy.simplify(critical - (1 + t) * sympy.exp(-t)) == 0
    # base excitation: the textbook single-mass transmissibility at r = 1.5/2, ζ = 0.1
    r, zeta = 0.75, 0.1
    textbook = ((1 + (2 * zeta * r) ** 2) / ((1 - r * r) ** 2 + (2 * zeta * r) ** 2)) ** 0.5
    assert abs(float(ls.transmissibility(namespace["shaken"], [1.5]).ravel()[0]) - textbook) < 1e-13
    assert namespace["x"].shape == (400, 2, 50)
