"""What a worked example says about a scene, independent of HTML or LaTeX.

:func:`sections` walks through a scene the way the seed's course page works its examples:
the system (diagram, the components, the equations of motion, M, C, K and the seed's
A = M⁻¹K, B = M⁻¹C, the initial data), the characteristic polynomial Δ(λ) and the
resolvent R(λ) = (λ²I + λB + A)⁻¹, the partial fractions of X(λ) where Δ factors over ℚ,
the g-functions g_k(t) = L⁻¹[λ^k/Δ(λ)] of a free motion, the solution in its named form,
``verify()``'s residuals and the motion plotted. A section is text (with inline math between
``\\(`` and ``\\)``), display formulas (LaTeX of amsmath, as MathJax and pdflatex both read
it), and images (PNG): :mod:`~laplace_springs.publish.page` renders them as HTML,
:mod:`~laplace_springs.publish.document` as a LaTeX document.

A scene with parameters is worked symbolically; its plots use ``values`` (1 for any
parameter not given, and the page says so). A scene beyond
:attr:`~laplace_springs.limits.Limits.exact_form_max_coordinates` coordinates has no exact
form: its page gives the modal summary instead of the formulas.
"""

from __future__ import annotations

import io
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import sympy as sp

from ..exact.partial_fractions import partial_fractions
from ..exact.resolvent import resolvent
from ..limits import limits
from ..model.errors import SceneError
from ..model.scene import Scene
from ..model.symbols import lam
from ..output.chain import chain_of, latex_symbol
from ..output.drawing import fit_figure
from ..output.latex import resolvent_latex
from ..output.plots import default_t_end, plot_energy, plot_motion
from ..output.text import summary_lines
from ..solution import Solution
from ..solving import solve

__all__ = ["Section", "sections", "figure_png", "plot_values", "page_t_end"]


@dataclass(frozen=True)
class Section:
    """One part of a worked example.

    Attributes
    ----------
    key : str
        A short identifier (``system``, ``resolvent``, ...), the HTML anchor.
    title : str
    text : tuple of str
        Paragraphs; inline math between ``\\(`` and ``\\)``.
    math : tuple of str
        Display formulas (each an amsmath ``aligned`` block or a single formula).
    images : tuple of (str, bytes)
        (caption, PNG bytes).
    notes : tuple of str
        Paragraphs after the formulas.
    preformatted : str
        Monospaced text (a large scene's modal summary).
    images_first : bool
        Show the images after the first paragraph, before the formulas.
    """

    key: str
    title: str
    text: tuple[str, ...] = ()
    math: tuple[str, ...] = ()
    images: tuple[tuple[str, bytes], ...] = ()
    notes: tuple[str, ...] = ()
    preformatted: str = ""
    images_first: bool = False


def figure_png(figure: Any, dpi: float = 110) -> bytes:
    """A matplotlib figure as PNG bytes (tight bounding box)."""
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=dpi, bbox_inches="tight")
    return buffer.getvalue()


def plot_values(scene: Scene, values: Mapping[str, Any] | None) -> tuple[Scene, dict[str, Any]]:
    """The scene with numbers for its parameters (``values``, else 1), and those numbers."""
    given = {str(k): v for k, v in (values or {}).items()}
    unknown = set(given) - {s.name for s in scene.parameters}
    if unknown:
        raise SceneError(f"values: {', '.join(sorted(unknown))} is not a parameter of the scene "
                         f"(its parameters: {', '.join(s.name for s in scene.parameters) or 'none'})")
    chosen = {s.name: given.get(s.name, 1) for s in scene.parameters}
    return (scene.subs(chosen) if chosen else scene), chosen


def page_t_end(solution: Solution, t_end: float | None) -> float:
    """The span a page plots: ``t_end``, else the plots' default shortened so that 40 samples
    per fastest period stay within :attr:`~laplace_springs.limits.Limits.page_max_plot_samples`."""
    if t_end is not None:
        return float(t_end)
    end = default_t_end(solution)
    fastest = float(np.max(np.abs(np.asarray(solution.poles, dtype=complex).imag), initial=0.0))
    most = limits().page_max_plot_samples
    if 40 * end * fastest / (2 * np.pi) > most:
        end = most * 2 * np.pi / (40 * fastest)
    return end


def _tex_matrix(matrix: Any) -> str:
    return str(sp.latex(sp.Matrix(matrix), mat_delim="[", mat_str="matrix"))


def _vector_tex(names: tuple[str, ...], dots: int = 0) -> str:
    accent = {0: "{}", 1: "\\dot{{{}}}", 2: "\\ddot{{{}}}"}[dots]
    return ", ".join(accent.format(latex_symbol(name)) for name in names)


def _signed_terms(terms: list[tuple[sp.Expr, str]]) -> str:
    """``c₁ s₁ + c₂ s₂ ...`` in the given order (SymPy would sort them), zero terms left out."""
    out = ""
    for coefficient, symbol in terms:
        if coefficient == 0:
            continue
        negative = coefficient.could_extract_minus_sign()
        magnitude = -coefficient if negative else coefficient
        factor = "" if magnitude == 1 else sp.latex(magnitude) + (" " if magnitude.is_Atom else "")
        if not magnitude.is_Atom and not magnitude.is_Mul and not magnitude.is_Rational:
            factor = f"\\left({sp.latex(magnitude)}\\right) "
        sign = " - " if negative else " + "
        out += (("-" if negative else "") if not out else sign) + factor + symbol
    return out or "0"


def _latex_sum(terms: Sequence[str]) -> str:
    r"""LaTeX terms joined by their signs: ``a - b``, never ``a + -b``.

    >>> _latex_sum([r"\frac{1}{2}", r"- \frac{1}{3}", "x"])
    '\\frac{1}{2} - \\frac{1}{3} + x'
    """
    out = ""
    for term in terms:
        if not out:
            out = term
        elif term.startswith("-"):
            out += " - " + term[1:].lstrip()
        else:
            out += " + " + term
    return out


def _equations(scene: Scene) -> str:
    """The scalar equations of motion, one row per coordinate, in the order M, C, K:
    Σ_j M_ij ẍ_j + C_ij ẋ_j + K_ij x_j = f_i."""
    n = scene.n
    names = [latex_symbol(name) for name in scene.names]
    forcing = scene.forcing if scene.forcing is not None else sp.zeros(n, 1)
    rows = []
    for i in range(n):
        terms = [(scene.M[i, j], f"\\ddot{{{names[j]}}}") for j in range(n)]
        terms += [(scene.C[i, j], f"\\dot{{{names[j]}}}") for j in range(n)]
        terms += [(scene.K[i, j], names[j]) for j in range(n)]
        right = forcing[i] if scene.sampled is None or scene.sampled[i] is None else sp.Symbol(
            f"f_{{{i + 1}}}(t)")
        rows.append(f"{_signed_terms(terms)} &= {sp.latex(right)}")
    return "\\begin{aligned}\n" + " \\\\\n".join(rows) + "\n\\end{aligned}"


def _system(scene: Scene, diagram: bytes | None, diagram_note: str) -> Section:
    text = [f"{scene.n} coordinate{'s' if scene.n != 1 else ''} "
            f"\\({_vector_tex(scene.names)}\\), "
            + ("damped" if scene.is_damped else "undamped")
            + (", driven" if scene.is_forced else ", free motion") + "."]
    if scene.components:
        parts = []
        for c in scene.components:
            what = "spring" if c.kind == "spring" else "dashpot"
            parts.append(f"a {what} \\({latex_symbol(c.label)} = {sp.latex(c.value)}\\) "
                         f"between {c.a} and {c.b}")
        text.append("Components: " + "; ".join(parts) + ".")
    if scene.support_motion:
        moving = ", ".join(f"\\(u_{{\\text{{{name}}}}}(t) = {sp.latex(u)}\\)"
                           for name, u in scene.support_motion)
        text.append(f"Moving supports: {moving}; their motion drives the masses through the "
                    "springs and dashpots attached to them.")
    text.append("The equations of motion, \\(M\\ddot x + C\\dot x + Kx = f(t)\\), coordinate by coordinate:")
    math = [_equations(scene)]
    matrices = [f"M &= {_tex_matrix(scene.M)}", f"C &= {_tex_matrix(scene.C)}",
                f"K &= {_tex_matrix(scene.K)}"]
    if scene.n <= limits().exact_form_max_coordinates:
        A, B = scene.normalized()
        matrices += [f"A = M^{{-1}}K &= {_tex_matrix(A)}", f"B = M^{{-1}}C &= {_tex_matrix(B)}"]
    math.append("\\begin{aligned}\n" + " \\\\\n".join(matrices) + "\n\\end{aligned}")
    math.append(f"x(0) = {_tex_matrix(scene.x0)}, \\qquad \\dot x(0) = {_tex_matrix(scene.v0)}")
    images = (("The scene", diagram),) if diagram is not None else ()
    notes = (diagram_note,) if diagram_note else ()
    return Section("system", "The system", tuple(text), tuple(math), images, notes, images_first=True)


def _resolvent_section(scene: Scene) -> Section:
    R = resolvent(scene)
    text = ("Taking the Laplace transform of the equations with the initial data gives "
            "\\((\\lambda^2 M + \\lambda C + K)X(\\lambda) = M(\\lambda x_0 + v_0) + C x_0 + F(\\lambda)\\). "
            "Its determinant is the characteristic polynomial \\(\\Delta(\\lambda)\\); the seed "
            "writes the inverse through \\(R(\\lambda) = (\\lambda^2 I + \\lambda B + A)^{-1}\\):",)
    return Section("resolvent", "The characteristic polynomial and the resolvent", text,
                    (resolvent_latex(R),))


def _partial_fractions(scene: Scene) -> Section | None:
    """X_i(λ) as partial fractions over ℚ, where Δ(λ) factors (else None)."""
    if scene.free_symbols or scene.is_forced:
        return None
    X = resolvent(scene).transform()
    rows, factored = [], False
    for i, name in enumerate(scene.names):
        pf = partial_fractions(X[i], lam)
        if len(pf.groups) > 1 or any(group.multiplicity > 1 for group in pf.groups):
            factored = True
        parts = [group.as_expr() for group in pf.groups]
        if pf.polynomial.as_expr() != 0:
            parts.insert(0, pf.polynomial.as_expr())
        shown = _latex_sum([sp.latex(sp.factor(part)) for part in parts])
        rows.append(f"X_{{{latex_symbol(name).split('_', 1)[-1].strip('{}')}}}(\\lambda) &= {shown}")
    if not factored:
        return Section("partial-fractions", "Partial fractions",
                       ("\\(\\Delta(\\lambda)\\) is irreducible over the rationals, so each "
                        "\\(X_i(\\lambda)\\) is its own partial fraction; its roots enter the "
                        "solution below as named constants.",))
    return Section("partial-fractions", "Partial fractions",
                   ("Over the rationals, \\(\\Delta(\\lambda)\\) factors and each transform splits "
                    "into one fraction per factor:",),
                   ("\\begin{aligned}\n" + " \\\\\n".join(rows) + "\n\\end{aligned}",))


#: Longest g-function block a page shows (LaTeX characters); beyond, the page says where it is.
G_FORM_MAX_CHARS = 6000


def _g_functions(solution: Solution) -> Section | None:
    if solution.scene.is_forced:
        return None
    intro = ("The seed writes each coordinate through the basis "
             "\\(g_k(t) = \\mathcal{L}^{-1}[\\lambda^k/\\Delta(\\lambda)]\\), "
             "\\(x_i(t) = \\sum_k c_{ik} g_k(t)\\)")
    block = solution.latex(form="g")
    if len(block) > G_FORM_MAX_CHARS:
        return Section("g-functions", "The g-functions",
                       (intro + f". Here their coefficients are long polynomials in the roots of "
                        f"\\(\\Delta(\\lambda)\\) ({len(block):,} characters of LaTeX): "
                        "solution.latex(form='g') gives them.",))
    return Section("g-functions", "The g-functions", (intro + ":",), (block,))


def _solution_section(solution: Solution) -> Section:
    if solution.scene.sampled is not None:
        return Section("solution", "The solution", (
            f"Solved by the {solution.method} route ({solution.reason}). A measured force has no "
            "closed form: the motion is exact for the interpolant of the samples, evaluated "
            "segment by segment (see the plots).",))
    text = (f"Solved by the {solution.method} route ({solution.reason}). The motion, "
            "for \\(t \\ge 0\\):",)
    return Section("solution", "The solution", text, (solution.latex(),))


def _check_section(solution: Solution, plotted: Solution) -> Section:
    check = plotted.verify()
    symbolic = solution.scene.free_symbols
    text = (("At the plotted values, " if symbolic else "")
            + "substituting the solution back: the residual of "
            "\\(M\\ddot x + C\\dot x + Kx - f\\), relative to the size of its terms, is "
            f"{check.ode_residual:.1e}, and the initial data are met to {check.initial_residual:.1e} "
            f"(tolerance {check.tolerance:g}): {'passed' if check else 'FAILED'}.",)
    return Section("check", "Check", text)


def _large_section(solution: Solution) -> Section:
    return Section("summary", "The motion, mode by mode",
                   (f"With {solution.scene.n} coordinates the exact form is not built (more than "
                    f"{limits().exact_form_max_coordinates}); the {solution.method} route's modal "
                    "summary:",), preformatted="\n".join(summary_lines(solution.scene)))


def _plots(plotted: Solution, t_end: float | None) -> Section:
    from matplotlib.figure import Figure

    motion = Figure(figsize=(8.0, 4.2), layout="constrained")
    plot_motion(plotted, motion.subplots(), t_end=t_end, title="Mass Position vs. Time")
    images = [("Mass position against time", figure_png(motion))]
    if not plotted.scene.is_forced:
        energy = Figure(figsize=(8.0, 3.6), layout="constrained")
        plot_energy(plotted, energy.subplots(), t_end=t_end, title="Energy")
        images.append(("Kinetic and potential energy, and what the dashpots dissipated", figure_png(energy)))
    return Section("plots", "The motion", (), (), tuple(images))


def _diagram(scene: Scene) -> tuple[bytes | None, str]:
    from matplotlib.figure import Figure

    try:
        chain_of(scene)
    except SceneError as exc:
        return None, f"(No diagram: {exc}.)"
    if scene.n > 24:
        return None, f"(No diagram: {scene.n} masses are too many to draw readably.)"
    figure = Figure()
    ax = figure.add_axes((0.0, 0.0, 1.0, 1.0))
    scene.draw(ax, show_values=True)
    fit_figure(figure, ax)
    return figure_png(figure, dpi=100), ""


def sections(scene: Scene, *, values: Mapping[str, Any] | None = None,
             t_end: float | None = None) -> tuple[list[Section], Solution, Solution]:
    """The sections of a worked example, the solution and the solution that is plotted.

    Parameters
    ----------
    scene : Scene
    values : mapping, optional
        Numbers for the plots of a scene with parameters (default 1 for each).
    t_end : float, optional
        Last time of the plots.

    Returns
    -------
    (list of Section, Solution, Solution)
        The plotted solution is the solution itself for a scene of numbers.

    Examples
    --------
    >>> import laplace_springs as ls
    >>> parts, solution, plotted = sections(ls.load_scene("vertical-pair"))
    >>> [part.key for part in parts]
    ['system', 'resolvent', 'partial-fractions', 'g-functions', 'solution', 'check', 'plots']
    """
    numbers, chosen = plot_values(scene, values)
    solution = solve(scene)
    plotted = solution if not chosen else solve(numbers)
    diagram, note = _diagram(scene)
    parts: list[Section] = [_system(scene, diagram, note)]
    if scene.n <= limits().exact_form_max_coordinates:
        parts.append(_resolvent_section(scene))
        partial = _partial_fractions(scene)
        if partial is not None:
            parts.append(partial)
        g = _g_functions(solution)
        if g is not None:
            parts.append(g)
        parts.append(_solution_section(solution))
    else:
        parts.append(_large_section(solution))
    parts.append(_check_section(solution, plotted))
    plots = _plots(plotted, page_t_end(plotted, t_end))
    if chosen:
        listed = ", ".join(f"\\({latex_symbol(k)} = {sp.latex(sp.nsimplify(v))}\\)" for k, v in chosen.items())
        plots = Section(plots.key, plots.title, (f"Plotted at {listed}.",), plots.math, plots.images)
    parts.append(plots)
    return parts, solution, plotted
