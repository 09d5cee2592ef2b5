"""LaTeX for solutions and resolvents: fragments, Markdown snippets, standalone documents.

The solution is written the way the seed writes it: each x_i(t) as damped sines and
cosines (or, on request, through the g-functions g_k(t) = L⁻¹[λ^k/Δ(λ)]), followed by
a "where" list of everything named in it.

Conventions (what the output never contains, and what it uses instead):

- **No imaginary unit.** Results are real. A complex root of an irreducible factor of
  degree ≥ 3 appears through two real named constants α_j, β_j, stated as
  "(λ − α_j)² + β_j² is a factor of P(λ)" with their numeric values; a real one as r_j,
  "a root of P(λ)". Coefficients built from them are named c_j, with their exact
  value (a polynomial in α_j, β_j, r_j) and a numeric value. No ``CRootOf`` text.
- **Named quantities** of symbolic scenes (ω_j, γ_j, S_j, P_j, see
  :mod:`laplace_springs.exact.named`) are listed with their definitions.
- **Sums over roots.** Where Δ(λ) has a factor without closed-form roots (symbolic
  coefficients, degree ≥ 3) the formula is the textbook one,
  x_i(t) = Σ_{Δ(λ)=0} N_i(λ)/Δ'(λ) e^{λt} (with E(λ), the inputs' common denominator,
  beside Δ'(λ) for driven scenes), and the "where" list gives Δ(λ), each N_i(λ) and
  where the formula holds (Δ has simple roots: disc_λ Δ(λ) ≠ 0). Δ and N_i are scaled
  as in the resolvent block (:func:`resolvent_latex`).
- **Switched-on pieces.** Solutions hold for t ≥ 0, so a unit step at 0 is dropped; a
  step at τ > 0 prints as θ(t − τ), the unit step (θ(s) = 1 for s ≥ 0, 0 for s < 0),
  and the "where" list says so. Never ``\\operatorname{Heaviside}``.
- A symbol directly followed by a parenthesis gets an explicit ``\\cdot``
  (``d_{1} \\cdot \\left(...\\right)``), so that the formula cannot be read back as a
  function call d₁(...).

Three shapes of output: a math fragment (one ``aligned`` block per part, to put in
display math), a Markdown snippet (each block between ``$$`` lines) and a standalone
``article`` document that compiles with pdflatex (amsmath only).

Examples
--------
>>> import laplace_springs as ls
>>> print(solution_latex(ls.solve(ls.load_scene("vertical-pair"), method="exact").motion))
\\begin{aligned}
x_{1}(t) &= \\frac{\\cos{\\left(t \\right)}}{3} + \\frac{\\sin{\\left(t \\right)}}{3} + \\frac{2 \\cos{\\left(2 t \\right)}}{3} - \\frac{\\sin{\\left(2 t \\right)}}{6} \\\\
x_{2}(t) &= \\frac{2 \\cos{\\left(t \\right)}}{3} + \\frac{2 \\sin{\\left(t \\right)}}{3} - \\frac{2 \\cos{\\left(2 t \\right)}}{3} + \\frac{\\sin{\\left(2 t \\right)}}{6}
\\end{aligned}
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Literal

import sympy as sp
from sympy.printing.latex import LatexPrinter

from ..exact.assembly import ExactMotion
from ..exact.real_terms import RootSumTerm, Term
from ..exact.resolvent import Resolvent
from ..exact.sylvester import FunctionName, matrix_function_terms, sylvester_matrices
from ..model.scene import Scene
from ..model.symbols import TIME
from ..model.units import unit_note_latex
from ..numeric.mp_expr import numeric_value
from .named_terms import NamedConstants, NamedTerms, reading_order

__all__ = ["LatexWriter", "solution_latex", "resolvent_latex", "sylvester_latex", "matrix_latex",
           "as_markdown", "as_document", "latex_name"]

Output = Literal["fragment", "markdown", "document"]

#: Continue an equation on a new line once its right-hand side is this long.
LINE_WIDTH = 160
#: Significant digits of the numeric values in the "where" list.
DIGITS = 12

_STEP = sp.Function("theta")


# ---------------------------------------------------------------------------
# printing
# ---------------------------------------------------------------------------
class _Printer(LatexPrinter):
    """SymPy's LaTeX printer with the conventions of this module."""

    def _as_ordered_terms(self, expr, order=None):
        return sorted(super()._as_ordered_terms(expr, order=order), key=reading_order)

    def _print_Heaviside(self, expr, exp=None):
        tex = rf"\theta\left({self._print(expr.args[0])}\right)"
        return f"{tex}^{{{exp}}}" if exp else tex

    def _print_ImaginaryUnit(self, expr):  # only complex matrices (e^{Bt} projectors)
        return r"\mathrm{j}"


_CALL_LIKE = re.compile(r"(?<=[A-Za-z}])( +)\\left\(")


def latex_name(name: str) -> str:
    """A coordinate or parameter name in LaTeX: ``x1`` → ``x_{1}``, ``delta2`` → ``\\delta_{2}``.

    >>> latex_name("x1"), latex_name("delta2"), latex_name("m")
    ('x_{1}', '\\\\delta_{2}', 'm')
    """
    return sp.latex(sp.Symbol(name))


def _tex(expr) -> str:
    """One expression in LaTeX, with ``\\cdot`` before a parenthesis after a symbol."""
    text = _Printer({"mat_str": "bmatrix", "mat_delim": ""}).doprint(expr)
    return _CALL_LIKE.sub(r" \\cdot \\left(", text)


def _rhs_lines(expr: sp.Expr, width: int = LINE_WIDTH) -> list[str]:
    """The right-hand side split at top-level + and − into lines of about ``width``."""
    printer = _Printer()
    if not isinstance(expr, sp.Add):
        return [_tex(expr)]
    pieces = []
    for i, term in enumerate(printer._as_ordered_terms(expr)):
        sign = "+ " if i else ""
        shown = term
        if term.could_extract_minus_sign():
            sign, shown = "- ", -term
        text = _tex(shown)
        if printer._needs_add_brackets(shown):
            text = rf"\left({text}\right)"
        pieces.append(sign + text)
    lines, current = [], ""
    for piece in pieces:
        if current and len(current) + len(piece) > width:
            lines.append(current)
            current = piece
        else:
            current = f"{current} {piece}" if current else piece
    return lines + [current]


def _equation_rows(lhs: str, expr: sp.Expr) -> list[str]:
    """``lhs &= ...`` and ``&\\quad + ...`` continuation rows of an aligned block."""
    parts = _rhs_lines(expr)
    return [f"{lhs} &= {parts[0]}"] + [rf"&\quad {part}" for part in parts[1:]]


def _poly_tex(poly: sp.Poly) -> str:
    """A polynomial in descending powers of its variable, coefficients as simple fractions."""
    var = poly.gen
    terms = [sp.factor(c) * var**k for (k,), c in poly.as_expr().as_poly(var).terms()]
    return _Printer({"order": "none"}).doprint(sp.Add(*terms, evaluate=False))


@lru_cache(maxsize=64)
def _g_function(k: int) -> sp.Expr:
    """g_k(t) as an unevaluated function of t that prints as ``g_{k}(t)``."""
    cls = type(f"g_{k}", (sp.Function,), {"_latex": lambda self, printer, exp=None: f"g_{{{k}}}(t)"})
    return cls(TIME)


def _aligned(rows: Sequence[str]) -> str:
    return "\\begin{aligned}\n" + " \\\\\n".join(rows) + "\n\\end{aligned}"


# ---------------------------------------------------------------------------
# named constants for algebraic numbers
# ---------------------------------------------------------------------------
def _number(value: sp.Expr, digits: int = DIGITS) -> str:
    """A real number in LaTeX with ``digits`` significant digits (no exponent letters)."""
    x = float(sp.re(numeric_value(value, digits + 5)))
    text = f"{x:.{digits}g}"
    if "e" in text:
        mantissa, exponent = text.split("e")
        return rf"{mantissa} \cdot 10^{{{int(exponent)}}}"
    return text


def _constant_rows(constants: NamedConstants) -> list[str]:
    """The "where" rows of the named constants: roots first, then the coefficients."""
    rows = []
    for root, names in constants.roots.items():
        poly = _poly_tex(sp.Poly(root.poly.as_expr(), root.poly.gen))
        if len(names) == 1:
            rows.append(rf"{_tex(names[0])} &\approx {_number(root)} "
                        rf"\quad \text{{(a root of }} {poly}\text{{)}}")
        else:
            alpha, beta = names
            rows.append(rf"{_tex(alpha)} &\approx {_number(sp.re(root))}, \quad "
                        rf"{_tex(beta)} \approx {_number(sp.im(root))}")
            rows.append(rf"&\quad \text{{(}}\left(\lambda - {_tex(alpha)}\right)^{{2}} + "
                        rf"{_tex(beta)}^{{2}} \text{{ is a factor of }} {poly}\text{{)}}")
    mapping = constants.root_map()
    for expr, name in constants.coefficients.items():
        rows += _equation_rows(_tex(name), expr.xreplace(mapping))
        rows[-1] += rf" \approx {_number(expr)}"
    return rows


# ---------------------------------------------------------------------------
# the writer
# ---------------------------------------------------------------------------
@dataclass
class LatexWriter(NamedTerms):
    """Collects aligned blocks and the names they use; renders them in one of three shapes.

    The names (α_j, β_j, c_j, ω_j, ...) come from
    :class:`~laplace_springs.output.named_terms.NamedTerms`, shared with the plain text.
    """

    blocks: list[list[str]] = field(default_factory=list)
    defined_rows: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    def equation(self, lhs: str, expr: sp.Expr) -> list[str]:
        """Rows ``lhs &= expr`` (split over lines if long), names registered.

        Examples
        --------
        >>> import sympy as sp
        >>> from laplace_springs import t
        >>> writer = LatexWriter()
        >>> x = sp.Heaviside(t - 2) * sp.sin(t - 2) + sp.Heaviside(t) * sp.cos(t)
        >>> print(*writer.equation("x(t)", x))
        x(t) &= \\cos{\\left(t \\right)} + \\sin{\\left(t - 2 \\right)} \\theta\\left(t - 2\\right)
        >>> writer.where_rows()[0].endswith("{unit step}")
        True
        """
        (prepared,) = self.prepare([expr])
        return _equation_rows(lhs, prepared)

    def where_rows(self) -> list[str]:
        """Rows defining every named quantity and constant used so far."""
        rows = list(self.defined_rows)
        for q, shown in self.definitions().items():
            meaning = rf" && \text{{{q.meaning}}}" if q.meaning else ""
            rows.append(f"{_tex(q)} &= {_tex(shown)}{meaning}")
        rows += _constant_rows(self.constants)
        if self.has_step:
            rows.append(r"\theta(s) &= 1 \text{ for } s \geq 0, \quad \theta(s) = 0 "
                        r"\text{ for } s < 0 && \text{unit step}")
        if rows:
            rows[0] = r"\text{where}\quad " + rows[0]
        return rows + self.notes

    def render(self, output: Output = "fragment", *, title: str | None = None,
               text: str | None = None) -> str:
        """The collected blocks as a fragment, a Markdown snippet or a document."""
        blocks = [_aligned(rows) for rows in self.blocks if rows]
        if output == "fragment":
            return "\n\n".join(blocks)
        if output == "markdown":
            return as_markdown(blocks)
        if output == "document":
            return as_document(blocks, title=title, text=text)
        raise ValueError(f"output must be 'fragment', 'markdown' or 'document', got {output!r}")


def as_markdown(blocks: Sequence[str]) -> str:
    """Each block between ``$$`` lines (Markdown with KaTeX/MathJax display math).

    >>> print(as_markdown(["x &= 1"]), end="")
    $$
    x &= 1
    $$
    """
    return "\n\n".join(f"$$\n{block}\n$$" for block in blocks) + "\n"


_DOCUMENT = r"""\documentclass[11pt]{article}
\usepackage[utf8]{inputenc}
\usepackage{amsmath,amssymb}
\usepackage[margin=2cm,landscape]{geometry}
\allowdisplaybreaks
\begin{document}
%s
\end{document}
"""

_TEXT_ESCAPES = {"\\": r"\textbackslash{}", "&": r"\&", "%": r"\%", "$": r"\$", "#": r"\#",
                 "_": r"\_", "{": r"\{", "}": r"\}", "~": r"\textasciitilde{}",
                 "^": r"\textasciicircum{}"}


def _escape_text(text: str) -> str:
    return "".join(_TEXT_ESCAPES.get(ch, ch) for ch in text)


def as_document(blocks: Sequence[str], *, title: str | None = None, text: str | None = None) -> str:
    """A standalone ``article`` (amsmath, amssymb, geometry), each block an ``align*``.

    ``title`` becomes an unnumbered section and ``text`` a paragraph, both with LaTeX's
    special characters escaped.

    >>> print(as_document(["x &= 1"], title="A & B", text="Two  words."), end="")
    \\documentclass[11pt]{article}
    \\usepackage[utf8]{inputenc}
    \\usepackage{amsmath,amssymb}
    \\usepackage[margin=2cm,landscape]{geometry}
    \\allowdisplaybreaks
    \\begin{document}
    \\section*{A \\& B}
    <BLANKLINE>
    Two words.
    <BLANKLINE>
    x &= 1
    \\end{document}
    """
    parts = []
    if title:
        parts.append(rf"\section*{{{_escape_text(title)}}}")
    if text:
        parts.append(_escape_text(" ".join(text.split())))
    parts += [block.replace("{aligned}", "{align*}") for block in blocks]  # breaks across pages
    return _DOCUMENT % "\n\n".join(parts)


# ---------------------------------------------------------------------------
# sums over the roots of Δ(λ)
# ---------------------------------------------------------------------------
@lru_cache(maxsize=512)
def _shown_sum(text: str) -> sp.Expr:
    """An atom in t that prints as ``text``: a sum over roots written out by hand."""
    cls = type(f"SumOverRootsShown{len(text)}", (sp.Function,),
               {"_latex": lambda self, printer, exp=None: text})
    return cls(TIME)


@dataclass
class _RootSums:
    """Textbook LaTeX for the sums over roots of a motion, and their "where" rows.

    Δ(λ) is the resolvent block's (integer for numeric scenes, monic for symbolic ones),
    N_i(λ) the numerator over it, E(λ) the inputs' common denominator (monic): each sum
    prints as Σ_{Δ(λ)=0} N_i(λ)/(Δ'(λ) E(λ)) e^{λ(t−τ)}.
    """

    delta: sp.Poly
    determinant: sp.Poly
    delta_defined: bool = False
    delta_rows: list[str] = field(default_factory=list)
    factors: dict = field(default_factory=dict)
    inputs: dict = field(default_factory=dict)
    numerators: dict = field(default_factory=dict)
    others: dict = field(default_factory=dict)

    def _define_delta(self) -> None:
        if not self.delta_defined:
            self.delta_defined = True
            self.delta_rows.append(rf"\Delta(\lambda) &= {_readable_poly_tex(self.delta)} && "
                                   r"\text{characteristic polynomial}")

    def _factor_name(self, q: sp.Poly) -> str:
        """\\Delta when q is Δ up to a constant, else P_j (defined in a row)."""
        self._define_delta()
        if q.degree() == self.delta.degree():
            return r"\Delta"
        key = q.as_expr()
        if key not in self.factors:
            name = f"P_{{{len(self.factors) + 1}}}"
            self.factors[key] = (name, rf"{name}(\lambda) &= {_readable_poly_tex(q)} && "
                                       r"\text{a factor of } \Delta(\lambda)")
        return self.factors[key][0]

    def _input_name(self, E: sp.Poly) -> str:
        key = E.as_expr()
        if key not in self.inputs:
            name = "E" if not self.inputs else f"E_{{{len(self.inputs) + 1}}}"
            self.inputs[key] = (name, rf"{name}(\lambda) &= {_readable_poly_tex(E)} && \text{{common "
                                      r"denominator of the inputs' transforms}")
        return self.inputs[key][0]

    def _numerator_text(self, N: sp.Poly, coordinate: str, piece: int, var: str) -> str:
        """N itself when it is one term (λ^k), else its name N_i, defined in a row."""
        expr = N.as_expr()
        if len(sp.Add.make_args(expr)) == 1:
            return _raw_tex(expr.xreplace({N.gen: sp.Symbol(var)}))
        key = (coordinate, piece, expr)
        if key not in self.numerators:  # a second N for one coordinate and piece gets a prime
            index = coordinate if piece == 0 else f"{coordinate},{piece}"
            primes = "'" * sum(1 for c, p, _ in self.numerators if (c, p) == (coordinate, piece))
            name = f"N_{{{index}}}{primes}"
            self.numerators[key] = (name, rf"{name}(\lambda) &= {_readable_poly_tex(N)}")
        return rf"{self.numerators[key][0]}({var})"

    def text(self, term: RootSumTerm, coordinate: str, piece: int, delay: sp.Expr) -> str:
        """Σ_{Δ(λ)=0} N_i(λ)/Δ'(λ) e^{λt} for ``term`` (and its condition, noted)."""
        group = term.group
        q, N, D, m = group.factor, group.numerator, group.denominator, group.multiplicity
        var = q.gen
        qname = self._factor_name(_primitive(q))
        others = self.others.setdefault(qname, [])
        if qname != r"\Delta" and rf"\Delta(\lambda)/{qname}(\lambda)" not in others:
            others.append(rf"\Delta(\lambda)/{qname}(\lambda)")
        shifted = TIME - delay
        E = _inputs_denominator(D, self.determinant)
        if E is None:  # not Δ·E (cannot happen for a scene): the summand as it is
            summand = sp.Add(*(w * shifted**k for k, w in enumerate(term.weights))) * sp.exp(var * shifted)
            return rf"\sum_{{{qname}(\lambda) = 0}} {_raw_tex(summand)}"
        # D = Δ_R·E = Δ·(scale·E_monic) with Δ as displayed; N/(Δ_R'E) = (N/scale)/(Δ' E_monic)
        to_sympy = E.domain.to_sympy
        scale = to_sympy(E.LC()) * self.determinant.domain.to_sympy(self.determinant.LC()) \
            / self.delta.domain.to_sympy(self.delta.LC())
        N = N * (1 / scale)
        E = E.monic()
        ename = self._input_name(E) if E.degree() > 0 else None
        if ename and f"{ename}(\\lambda)" not in others:
            others.append(f"{ename}(\\lambda)")
        if m == 1:
            top = self._numerator_text(N, coordinate, piece, r"\lambda")
            bottom = r"\Delta'(\lambda)" + (rf" \, {ename}(\lambda)" if ename else "")
            body = rf"\frac{{{top}}}{{{bottom}}} \, {_raw_tex(sp.exp(var * shifted))}"
        else:
            top = self._numerator_text(N, coordinate, piece, "s")
            bottom = r"\Delta(s)" + (rf" \, {ename}(s)" if ename else "")
            wave = _raw_tex(sp.exp(sp.Symbol("s") * shifted))
            body = rf"\operatorname*{{Res}}_{{s = \lambda}} \frac{{{top} \, {wave}}}{{{bottom}}}"
        return rf"\sum_{{{qname}(\lambda) = 0}} {body}"

    def shown(self, expr: sp.Expr, rows: Sequence[tuple[Sequence[Term], sp.Expr, int]],
              coordinate: str) -> sp.Expr:
        """``expr`` with each sum over roots of ``rows`` (terms, delay, piece index) written
        out; bracketed unless it is the whole right-hand side."""
        plain: dict = {}
        for terms, delay, piece in rows:
            for term in terms:
                if isinstance(term, RootSumTerm):
                    atom = term.as_expr(TIME - delay)
                    plain[atom] = self.text(term, coordinate, piece, delay)
        if not plain:
            return expr
        if expr in plain:
            return _shown_sum(plain[expr])
        return expr.xreplace({atom: _shown_sum(rf"\left[{text}\right]")
                              for atom, text in plain.items()})

    def attach(self, writer: LatexWriter) -> None:
        """Δ, the factors, the inputs' denominators and the numerators into the writer's
        "where" list, and where the sums hold (each sum's roots must be simple)."""
        writer.defined_rows += self.delta_rows
        for table in (self.factors, self.inputs, self.numerators):
            writer.defined_rows += [row for _, row in table.values()]
        for qname, others in self.others.items():
            note = (rf"&\text{{valid where }} {qname}(\lambda) \text{{ has simple roots, "
                    rf"}} \operatorname{{disc}}_{{\lambda}} {qname}(\lambda) \neq 0")
            if others:
                note += r"\text{, none of them a root of } " + r" \text{ or } ".join(others)
            writer.notes.append(note)


def _inputs_denominator(D: sp.Poly, determinant: sp.Poly) -> sp.Poly | None:
    """E with D = determinant·E exactly (1 when D is the determinant), or None."""
    if D.degree() == determinant.degree():
        if D.monic() == determinant.set_domain(D.domain).monic():
            return sp.Poly(D.LC(), D.gen, domain=D.domain).quo_ground(
                D.domain.convert(determinant.set_domain(D.domain).LC()))
        return None
    domain = D.domain.unify(determinant.domain)
    quotient, remainder = D.set_domain(domain).div(determinant.set_domain(domain))
    return quotient if remainder.is_zero else None


def _readable_poly_tex(poly: sp.Poly) -> str:
    """A polynomial in descending powers, each coefficient tidied without factoring it
    (a symbolic chain's coefficients are too large to factor quickly)."""
    var = poly.gen
    to_sympy = poly.domain.to_sympy
    terms = [sp.factor_terms(to_sympy(c)) * var**k for (k,), c in poly.terms()]
    return _Printer({"order": "none"}).doprint(sp.Add(*terms, evaluate=False))


def _raw_tex(expr) -> str:
    """LaTeX of a piece of a hand-written formula (``_tex`` runs on the whole line later)."""
    return _Printer().doprint(expr)


def _primitive(poly: sp.Poly) -> sp.Poly:
    _, cleared = poly.clear_denoms(convert=True)
    return cleared.primitive()[1]


# ---------------------------------------------------------------------------
# solution, resolvent, Sylvester
# ---------------------------------------------------------------------------
def _motion_rows(writer: LatexWriter, motion: ExactMotion, form: str) -> list[str]:
    names = [latex_name(n) for n in motion.scene.names]
    if form == "terms":
        R = motion.resolvent
        sums = _RootSums(R.integer_characteristic_polynomial if motion.root_sums else R.determinant,
                         R.determinant)
        rows = []
        for i, (name, e) in enumerate(zip(names, motion.x)):
            pieces = [(piece.terms[i], piece.delay, k) for k, piece in enumerate(motion.pieces)]
            rows += writer.equation(f"{name}(t)", sums.shown(e, pieces, str(i + 1)))
        sums.attach(writer)
        return rows
    if form != "g":
        raise ValueError(f"form must be 'terms' or 'g', got {form!r}")
    C, basis = motion.g_coefficients, motion.g_basis
    rows = []
    coefficients = iter(writer.prepare([C[i, k] for i in range(C.rows) for k in motion.g_indices]))
    for name in names:
        total = sp.Add(*(next(coefficients) * _g_function(k) for k in motion.g_indices))
        rows += _equation_rows(f"{name}(t)", total)
    rows.append(rf"\Delta(\lambda) &= {_poly_tex(motion.g_denominator)}")
    sums = _RootSums(motion.g_denominator, motion.g_denominator, delta_defined=True)
    shown = [sums.shown(basis[k], [(motion.g_terms[k], sp.S.Zero, 0)], str(k))
             for k in motion.g_indices]
    for k, expr in zip(motion.g_indices, writer.prepare(shown)):
        lhs = (rf"g_{{{k}}}(t) = \mathcal{{L}}^{{-1}}\left[\frac{{\lambda^{{{k}}}}}"
               rf"{{\Delta(\lambda)}}\right]")
        rows += _equation_rows(lhs, expr)
    sums.attach(writer)
    return rows


def solution_latex(motion: ExactMotion, *, form: str = "terms", resolvent: bool = False,
                   sylvester: bool = False, output: Output = "fragment") -> str:
    """x(t) of an exact motion in LaTeX, with the definitions of everything named in it.

    Parameters
    ----------
    motion : ExactMotion
        The exact motion of a scene (``exact_motion(scene)``, or ``solution.motion`` of an
        :class:`~laplace_springs.ExactSolution`).
    form : {"terms", "g"}
        "terms": damped sines and cosines; "g": x_i(t) = Σ_k c_ik g_k(t) with the seed's
        g_k(t) = L⁻¹[λ^k/Δ(λ)] written out.
    resolvent : bool
        Also Δ(λ), the seed's R(λ) = (λ²I + λB + A)⁻¹ and X(λ).
    sylvester : bool
        Also Sylvester's matrices Z_λ of A = M⁻¹K and Ψ(t) = cos(√A t),
        Φ(t) = sin(√A t)/√A (undamped scenes with numeric A, the seed's Example 1).
    output : {"fragment", "markdown", "document"}
        A math fragment (``aligned`` blocks), a Markdown snippet (``$$`` blocks) or a
        standalone document.

    Returns
    -------
    str

    Examples
    --------
    The seed's Example 2 through its g-functions, as a Markdown snippet:

    >>> import laplace_springs as ls
    >>> motion = ls.solve(ls.load_scene("vertical-pair-damped"), method="exact").motion
    >>> print(solution_latex(motion, form="g", output="markdown").splitlines()[4])
    \\Delta(\\lambda) &= 25 \\lambda^{4} + 10 \\lambda^{3} + 126 \\lambda^{2} + 25 \\lambda + 100 \\\\
    """
    writer = LatexWriter()
    writer.blocks.append(_motion_rows(writer, motion, form))
    writer.notes += [rf"&\text{{valid for }} {condition.latex()}"
                     for condition in (*getattr(motion, "generic_conditions", ()),
                                       *getattr(motion, "input_conditions", ()))]
    writer.notes += unit_note_latex(motion.scene)  # "with x in m and t in s"
    if resolvent:
        writer.blocks.append(_resolvent_rows(motion.resolvent))
    if sylvester:
        writer.blocks.append(_sylvester_rows(writer, motion.scene))
    writer.blocks[0] += writer.where_rows()
    return writer.render(output, title=motion.scene.title or None)


def _resolvent_rows(R: Resolvent) -> list[str]:
    delta = R.integer_characteristic_polynomial.as_expr()
    normalized = R.normalized()
    scaled = normalized.applyfunc(lambda e: sp.factor_terms(sp.expand(sp.cancel(e * delta))))
    transform = [sp.factor_terms(sp.expand(sp.cancel(N.as_expr() * delta / R.determinant.as_expr())))
                 for N in R.numerators]
    rows = [rf"\Delta(\lambda) &= {_poly_tex(sp.Poly(delta, R.variable))}",
            r"R(\lambda) = \left(\lambda^{2} I + \lambda B + A\right)^{-1} &= "
            r"\frac{1}{\Delta(\lambda)} " + _tex(sp.Matrix(scaled))]
    for name, numerator in zip(R.scene.names, transform):
        rows.append(rf"{latex_name(name)}^{{L}}(\lambda) &= \frac{{{_tex(numerator)}}}{{\Delta(\lambda)}}")
    return rows


def resolvent_latex(R: Resolvent, *, output: Output = "fragment") -> str:
    """Δ(λ), R(λ) = (λ²I + λB + A)⁻¹ = adj(λ)M/Δ(λ) and X(λ) in LaTeX.

    Δ(λ) is scaled as the seed prints it (integer coefficients, content 1) for numeric
    scenes, monic for symbolic ones.

    Parameters
    ----------
    R : Resolvent
        The resolvent of a scene (:func:`laplace_springs.resolvent`).
    output : {"fragment", "markdown", "document"}
        An ``aligned`` block, a Markdown snippet or a standalone document.

    Returns
    -------
    str

    Examples
    --------
    >>> import laplace_springs as ls
    >>> print(resolvent_latex(ls.resolvent(ls.load_scene("vertical-pair-damped"))).splitlines()[1])
    \\Delta(\\lambda) &= 25 \\lambda^{4} + 10 \\lambda^{3} + 126 \\lambda^{2} + 25 \\lambda + 100 \\\\
    """
    writer = LatexWriter()
    writer.blocks.append(_resolvent_rows(R))
    return writer.render(output, title=R.scene.title or None)


def _sylvester_rows(writer: LatexWriter, scene: Scene) -> list[str]:
    if not scene.C.is_zero_matrix or scene.M.free_symbols or scene.K.free_symbols:
        raise ValueError("Sylvester's matrices need an undamped scene with numeric M and K")
    A, _ = scene.normalized()
    Z = sylvester_matrices(A)
    eigen = writer.prepare(list(Z))
    rows = [rf"A = M^{{-1}} K &= {_tex(sp.Matrix(A))}"]
    for value, shown in zip(Z, eigen):
        rows.append(rf"Z_{{{_tex(shown)}}} &= {_tex(sp.Matrix(Z[value]))}")
    functions: tuple[tuple[str, FunctionName], ...] = (
        (r"\Psi(t) = \cos\left(\sqrt{A}\, t\right)", "cos_sqrt"),
        (r"\Phi(t) = \frac{\sin\left(\sqrt{A}\, t\right)}{\sqrt{A}}", "sinc_sqrt"))
    for lhs, kind in functions:
        pairs = matrix_function_terms(A, kind, TIME)
        bases = writer.prepare([basis for basis, _ in pairs])
        body = " + ".join(rf"{_tex(b)} {_tex(sp.Matrix(M))}" for b, (_, M) in zip(bases, pairs))
        rows.append(f"{lhs} &= {body}")
    rows.append(r"x(t) &= \Psi(t)\, x_{0} + \Phi(t)\, v_{0}")
    return rows


def sylvester_latex(scene: Scene, *, output: Output = "fragment") -> str:
    """Sylvester's auxiliary matrices and Ψ(t), Φ(t) of an undamped numeric scene.

    Parameters
    ----------
    scene : Scene
        Undamped, with numeric M and K.
    output : {"fragment", "markdown", "document"}
        An ``aligned`` block, a Markdown snippet or a standalone document.

    Returns
    -------
    str

    Raises
    ------
    ValueError
        For a damped scene or symbolic M, K.

    Examples
    --------
    >>> import laplace_springs as ls
    >>> print(sylvester_latex(ls.load_scene("vertical-pair")).splitlines()[2])
    Z_{1} &= \\begin{bmatrix}\\frac{1}{3} & \\frac{1}{3}\\\\\\frac{2}{3} & \\frac{2}{3}\\end{bmatrix} \\\\
    """
    writer = LatexWriter()
    writer.blocks.append(_sylvester_rows(writer, scene))
    writer.blocks[0] += writer.where_rows()
    return writer.render(output, title=scene.title or None)


def matrix_latex(scene: Scene, x: sp.MatrixBase, *, standalone: bool = False,
                 markdown: bool = False) -> str:
    """x_i(t) = ... rows of a motion given as expressions (Float coefficients allowed).

    What solutions without an exact form print (large scenes on the modal or certified
    route): no named constants, no "where" list.

    Parameters
    ----------
    scene : Scene
        Gives the coordinate names and the document's title.
    x : sympy.Matrix
        One expression in :data:`laplace_springs.t` per coordinate.
    standalone, markdown : bool
        A standalone document, or a Markdown snippet, instead of an ``aligned`` block.

    Returns
    -------
    str

    Examples
    --------
    >>> import laplace_springs as ls
    >>> scene = ls.Scene.from_matrices(M=[[1]], K=[[4]], x0=[1], v0=[0])
    >>> print(matrix_latex(scene, sp.Matrix([sp.cos(2 * TIME)])).splitlines()[1])
    x_{1}(t) &= \\cos{\\left(2 t \\right)}
    """
    rows = [row for name, e in zip(scene.names, x)
            for row in _equation_rows(f"{latex_name(name)}(t)", sp.sympify(e, strict=True))]
    rows += unit_note_latex(scene)
    output: Output = "document" if standalone else "markdown" if markdown else "fragment"
    blocks = [_aligned(rows)]
    if output == "markdown":
        return as_markdown(blocks)
    if output == "document":
        return as_document(blocks, title=scene.title or None)
    return "\n".join(blocks)
