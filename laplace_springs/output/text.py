"""Plain text and Unicode: x(t) with the named structure of the LaTeX, and modal summaries.

What the command line prints and what ``str(solution)`` is.

- :func:`formula_lines` writes each x_i(t) the way :mod:`laplace_springs.output.latex`
  does (the same names, from :mod:`laplace_springs.output.named_terms`): exponential
  rates α_j, frequencies β_j, real roots r_j and coefficients c_j, listed under "where"
  with their values and exact definitions. Plain text uses SymPy's syntax (``alpha_1``,
  ``**``, ``exp(...)``), so every line reads back with ``sympy.sympify``; ``pretty=True``
  uses Unicode (α₁, β₁, e^(α₁·t), c₁, subscripts, superscripts).
- :func:`summary_lines` is a modal summary: natural frequencies, damping ratios and how
  much each mode takes part in the initial data (its amplitude, its share of the initial
  energy); for a large scene the first modes and the count.
- :func:`modal_formula_lines` writes x_i(t) of chosen coordinates of a large scene from
  the float64 modes, with the rates and frequencies named.

Where the modes come from: :func:`laplace_springs.modes` (exact) up to
:attr:`~laplace_springs.limits.Limits.exact_modes_max_coordinates` coordinates, else :func:`float_modes`, a float64
eigen-decomposition (``numpy.linalg.eigh`` after a Cholesky reduction for undamped
symmetric scenes, the eigenvalues of the first-order matrix otherwise).

Examples
--------
>>> import laplace_springs as ls
>>> sol = ls.solve(ls.load_scene("three-dashpots"), method="exact")
>>> lines = formula_lines(sol.scene, sol.x)
>>> print(lines[0])
x1(t) = (c_1*cos(beta_1*t) + c_2*sin(beta_1*t))*exp(alpha_1*t) + (c_3*cos(beta_2*t) + c_4*sin(beta_2*t))*exp(alpha_2*t)
>>> print(lines[3])
  alpha_1 ≈ -0.479001077361, beta_1 ≈ 15.9881995289
>>> print(formula_lines(sol.scene, sol.x, pretty=True)[0])
x₁(t) = (c₁·cos(β₁·t) + c₂·sin(β₁·t))·e^(α₁·t) + (c₃·cos(β₂·t) + c₄·sin(β₂·t))·e^(α₂·t)
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import sympy as sp
from sympy.printing.str import StrPrinter

from ..analysis.modes import Mode, float_modes, modes
from ..exact.named import NamedQuantity
from ..limits import limits
from ..model.errors import SceneError
from ..model.scene import Scene
from ..model.symbols import lam
from ..numeric.first_order import scene_arrays
from ..numeric.mp_expr import numeric_value
from .named_terms import NamedTerms, reading_order

__all__ = ["DIGITS", "SUMMARY_MODES", "MAX_DEFINITION_TERMS",
           "formula_lines", "summary_lines", "modal_formula_lines", "formula_terms",
           "mode_list_of", "participation", "Participation", "unicode_name"]

#: Significant digits of the values in the "where" lists and tables.
DIGITS = 12
#: Modes a summary lists (by natural frequency) before it gives the count of the rest.
SUMMARY_MODES = 10
#: A coefficient's exact definition is written out up to this many terms; a longer one is
#: described (its degree and number of terms) and left to the LaTeX output.
MAX_DEFINITION_TERMS = 8

_GREEK = {"alpha": "α", "beta": "β", "gamma": "γ", "delta": "δ", "epsilon": "ε", "zeta": "ζ",
          "eta": "η", "theta": "θ", "kappa": "κ", "lambda": "λ", "mu": "μ", "nu": "ν", "xi": "ξ",
          "rho": "ρ", "sigma": "σ", "tau": "τ", "phi": "φ", "chi": "χ", "psi": "ψ",
          "omega": "ω", "Omega": "Ω", "Delta": "Δ"}
_SUB = str.maketrans("0123456789", "₀₁₂₃₄₅₆₇₈₉")
_SUP = str.maketrans("0123456789-", "⁰¹²³⁴⁵⁶⁷⁸⁹⁻")
_INDEXED = re.compile(r"^([A-Za-z]+?)_?(\d+)$")


def unicode_name(name: str) -> str:
    """A name in Unicode: ``alpha_1`` → ``α₁``, ``k12`` → ``k₁₂``, ``omega`` → ``ω``.

    >>> unicode_name("alpha_1"), unicode_name("x12"), unicode_name("mu"), unicode_name("F0")
    ('α₁', 'x₁₂', 'μ', 'F₀')
    """
    match = _INDEXED.match(name)
    if match:
        base, index = match.groups()
        return _GREEK.get(base, base) + index.translate(_SUB)
    return _GREEK.get(name, name)


# ---------------------------------------------------------------------------
# printers
# ---------------------------------------------------------------------------
class _PlainPrinter(StrPrinter):
    """SymPy's str printer with terms in reading order (Heaviside stays SymPy's name)."""

    def _as_ordered_terms(self, expr, order=None):
        return sorted(super()._as_ordered_terms(expr, order=order), key=reading_order)


class _UnicodePrinter(_PlainPrinter):
    """One-line Unicode: α₁, c₁, a·b, x², e^(…), √, θ(…)."""

    def _print(self, expr, **kwargs):
        if isinstance(expr, NamedQuantity):
            return unicode_name(expr.name)
        return super()._print(expr, **kwargs)

    def _print_Symbol(self, expr):
        return unicode_name(expr.name)

    _print_Dummy = _print_Symbol

    def _print_Heaviside(self, expr):
        return f"θ({self._print(expr.args[0])})"

    def _print_exp(self, expr):
        arg = expr.args[0]
        shown = self._print(arg)
        return f"e^{shown}" if arg.is_Atom and not arg.could_extract_minus_sign() else f"e^({shown})"

    def _print_Pow(self, expr, rational=False):
        base, exponent = expr.args
        if exponent is sp.S.Half:
            inner = self._print(base)
            return f"√{inner}" if base.is_Atom else f"√({inner})"
        if exponent.is_Integer and exponent > 1:
            return self.parenthesize(base, sp.printing.precedence.PRECEDENCE["Pow"]) \
                + str(exponent).translate(_SUP)
        return super()._print_Pow(expr, rational=rational).replace("**", "^")

    def _print_Mul(self, expr):
        # a lone * is a product; ** (a power printed by the plain printer) is not
        return re.sub(r"(?<!\*)\*(?!\*)", "·", super()._print_Mul(expr)).replace("**", "^")


def _printer(pretty: bool) -> StrPrinter:
    return _UnicodePrinter() if pretty else _PlainPrinter()


def _number(value: Any, digits: int = DIGITS) -> str:
    """A real number with ``digits`` significant digits (Python's float syntax)."""
    if isinstance(value, (int, float, np.floating, np.integer)):
        x = float(value)
    else:
        x = float(sp.re(numeric_value(value, digits + 5)))
    return f"{x:.{digits}g}"


def _name(symbol: sp.Symbol, pretty: bool) -> str:
    return unicode_name(symbol.name) if pretty else symbol.name


# ---------------------------------------------------------------------------
# the formula with its "where" list
# ---------------------------------------------------------------------------
def formula_lines(scene: Scene, exprs: Sequence[sp.Expr], conditions: Sequence[Any] = (), *,
                  pretty: bool = False, coordinates: Sequence[int] | None = None) -> list[str]:
    """``x1(t) = ...`` per coordinate and a "where" list of every name used.

    Parameters
    ----------
    scene : Scene
        Gives the coordinate names.
    exprs : sequence of sympy.Expr
        x_i(t) in :data:`laplace_springs.t`, one per coordinate (``solution.x``).
    conditions : sequence
        Where the formula holds (objects with a ``meaning``), listed last.
    pretty : bool
        Unicode (α₁, e^(…), ·) instead of SymPy's syntax.
    coordinates : sequence of int, optional
        Indices of the coordinates to write (all by default).

    Returns
    -------
    list of str

    Examples
    --------
    >>> import laplace_springs as ls
    >>> scene = ls.Scene.from_matrices(M=[[1]], C=[["c"]], K=[["k"]], x0=[1], v0=[0],
    ...                                parameters=["c", "k"])
    >>> print("\\n".join(formula_lines(scene, ls.solve(scene).x, pretty=True)))
    x₁(t) = (cos(t·ω₁) + γ₁·sin(t·ω₁)/ω₁)·e^(-t·γ₁)
    where
      γ₁ = c/2   (damping rate)
      ω₁ = √(k - γ₁²)   (damped frequency, underdamped assumed (positive radicand))
    """
    printer = _printer(pretty)
    chosen = range(scene.n) if coordinates is None else coordinates
    terms = NamedTerms()
    shown = terms.prepare([exprs[i] for i in chosen])
    lines = []
    for i, expr in zip(chosen, shown):
        name = _name(sp.Symbol(scene.names[i]), pretty)
        lines.append(f"{name}(t) = {printer.doprint(expr)}")
    where = _where_lines(terms, printer, pretty)
    if where:
        lines += ["where", *where]
    lines += [f"valid where {condition.meaning}" for condition in conditions]
    return lines


def _where_lines(terms: NamedTerms, printer: StrPrinter, pretty: bool) -> list[str]:
    lines = []
    for quantity, definition in terms.definitions().items():
        meaning = f"   ({quantity.meaning})" if quantity.meaning else ""
        lines.append(f"  {printer.doprint(quantity)} = {printer.doprint(definition)}{meaning}")
    lines += _constant_lines(terms, printer, pretty)
    if terms.has_step:
        step = "θ" if pretty else "Heaviside"
        geq = "≥" if pretty else ">="
        lines.append(f"  {step}(s) = 1 for s {geq} 0, 0 for s < 0   (unit step)")
    return lines


def _constant_lines(terms: NamedTerms, printer: StrPrinter, pretty: bool) -> list[str]:
    """α_j, β_j with the factor they come from; r_j; then each c_j: value, exact value."""
    constants = terms.constants
    variable = "λ" if pretty else "lambda"
    lines = []
    for root, names in constants.roots.items():
        poly = printer.doprint(sp.Poly(root.poly.as_expr(), root.poly.gen).as_expr().xreplace(
            {root.poly.gen: lam}))
        if len(names) == 1:
            lines.append(f"  {_name(names[0], pretty)} ≈ {_number(root)}   (a root of {poly})")
            continue
        alpha, beta = (_name(s, pretty) for s in names)
        lines.append(f"  {alpha} ≈ {_number(sp.re(root))}, {beta} ≈ {_number(sp.im(root))}")
        square = "²" if pretty else "**2"
        lines.append(f"      ({variable} - {alpha}){square} + {beta}{square} is a factor of {poly}")
    indent = " " * 4
    for expr, name in constants.coefficients.items():
        lines.append(f"  {_name(name, pretty)} ≈ {_number(expr)}")
        lines.append(f"  {indent}= {_exact_text(constants.definition(name), printer, pretty)}")
    return lines


def _exact_text(expr: sp.Expr, printer: StrPrinter, pretty: bool) -> str:
    """A polynomial in the root names over one common denominator: (…)/D; described when long."""
    expr = sp.expand(expr)
    terms = sp.Add.make_args(expr)
    if len(terms) > MAX_DEFINITION_TERMS:
        names = sorted(expr.free_symbols, key=lambda s: s.name)
        degree = sp.Poly(expr, *names).total_degree()
        shown = ", ".join(_name(s, pretty) for s in names)
        return (f"a polynomial of degree {degree} in {shown} with {len(terms)} rational "
                f"coefficients (written out by --latex)")
    numerator, denominator = sp.fraction(sp.together(expr))
    top = printer.doprint(sp.expand(numerator))
    if denominator == 1:
        return top
    return f"({top})/{printer.doprint(denominator)}"


# ---------------------------------------------------------------------------
# modes: float64 where the exact ones are too slow, and their participation
# ---------------------------------------------------------------------------
def _complex(value: Any) -> complex:
    if isinstance(value, (int, float, complex, np.number)):
        return complex(value)
    return complex(numeric_value(value, 20))


@dataclass(frozen=True)
class Participation:
    """How much each mode takes part in the initial data x0, v0.

    Attributes
    ----------
    weights : list of numpy.ndarray
        g_k with x(t) = Σ_k Re(g_k e^{λ_k t}) for the free motion (for a rigid mode the
        constant part; its drift is in ``drifts``).
    drifts : list of numpy.ndarray or None
        The velocity of the drift b t of a rigid mode (None for other modes).
    amplitude : numpy.ndarray
        max_i |g_k,i|: the mode's largest amplitude (at t = 0) over the coordinates.
    energy : numpy.ndarray
        The mode's share of the initial energy ½(v0ᵀMv0 + x0ᵀKx0), NaN when that is 0.
    """

    weights: list
    drifts: list
    amplitude: np.ndarray
    energy: np.ndarray


def participation(scene: Scene, mode_list: Sequence[Any]) -> Participation | None:
    """The part each mode plays in the initial data, or None where the shapes cannot say.

    The initial state [x0; v0] is written in the basis of the modes' states
    [φ; λφ] (real and imaginary parts for a complex pair; [φ; 0] and [0; φ] for a
    rigid mode of multiplicity 2) by least squares; None when that basis is singular
    (a defective eigenvalue, massless nodes) or misses the state.

    Parameters
    ----------
    scene : Scene
        Numeric.
    mode_list : sequence of Mode
        From :func:`laplace_springs.modes` or :func:`float_modes`.

    Examples
    --------
    Two unit masses between walls, x0 = (1, 0): each mode carries half the energy of
    its own frequency, ω₁² and ω₂² = 3 weigh in as 1 : 3.

    >>> import laplace_springs as ls
    >>> scene = ls.Scene.from_matrices(M=[[1, 0], [0, 1]], K=[[2, -1], [-1, 2]],
    ...                                x0=[1, 0], v0=[0, 0])
    >>> share = participation(scene, float_modes(scene))
    >>> share.energy.round(12), share.amplitude.round(12)
    (array([0.25, 0.75]), array([0.5, 0.5]))
    """
    M, C, K, x0, v0 = scene_arrays(scene)
    n = scene.n
    columns, owners = [], []  # owner: (mode, part, shape); part "re", "im", "x" or "drift"
    for k, mode in enumerate(mode_list):
        value = _complex(mode.eigenvalue)
        for shape in mode.shapes:
            phi = np.asarray(shape, dtype=complex)
            if mode.kind == "rigid":
                columns.append(np.concatenate([phi.real, np.zeros(n)]))
                owners.append((k, "x", phi.real))
                if mode.multiplicity >= 2:
                    columns.append(np.concatenate([np.zeros(n), phi.real]))
                    owners.append((k, "drift", phi.real))
                continue
            state = np.concatenate([phi, value * phi])
            columns.append(state.real)
            owners.append((k, "re", phi))
            if value.imag != 0:
                columns.append(state.imag)
                owners.append((k, "im", phi))
    if len(columns) != 2 * n:
        return None
    B = np.array(columns).T
    start = np.concatenate([x0, v0])
    if np.linalg.cond(B) > 1e10:
        return None
    coefficients = np.linalg.solve(B, start)
    if np.linalg.norm(B @ coefficients - start) > 1e-8 * max(float(np.linalg.norm(start)), 1e-300):
        return None
    count = len(mode_list)
    weights = [np.zeros(n, dtype=complex) for _ in range(count)]
    drifts: list = [None] * count
    states = [np.zeros(2 * n) for _ in range(count)]
    for (k, part, phi), column, a in zip(owners, B.T, coefficients):
        # the state column is that of Re(φ e^{λt}) or Im(φ e^{λt}) = Re(−i φ e^{λt})
        states[k] += a * column
        if part == "drift":
            drifts[k] = a * phi
        else:
            weights[k] = weights[k] + (-1j if part == "im" else 1) * a * phi
    total = 0.5 * (v0 @ M @ v0 + x0 @ K @ x0)
    energy = np.array([0.5 * (s[n:] @ M @ s[n:] + s[:n] @ K @ s[:n]) for s in states])
    energy = energy / total if total > 0 else np.full(count, np.nan)
    amplitude = np.array([float(np.max(np.abs(w), initial=0.0)) for w in weights])
    return Participation(weights, drifts, amplitude, energy)


def mode_list_of(scene: Scene) -> tuple[Mode, ...]:
    """The modes a summary uses: exact up to Limits.exact_modes_max_coordinates, else float64.

    Examples
    --------
    >>> import laplace_springs as ls
    >>> mode_list_of(ls.load_scene("vertical-pair"))
    (Mode(ω_n=1, ζ=0, oscillatory), Mode(ω_n=2, ζ=0, oscillatory))
    """
    if scene.n <= limits().exact_modes_max_coordinates:
        return modes(scene)
    return float_modes(scene)


# ---------------------------------------------------------------------------
# the summary
# ---------------------------------------------------------------------------
def summary_lines(scene: Scene, mode_list: Sequence[Any] | None = None, *, pretty: bool = False,
                  limit: int = SUMMARY_MODES) -> list[str]:
    """A table of the modes: ω_n, ζ, ω_d, amplitude and share of the initial energy.

    Parameters
    ----------
    scene : Scene
        Numeric.
    mode_list : sequence of Mode, optional
        The modes (by default exact ones up to :attr:`~laplace_springs.limits.Limits.exact_modes_max_coordinates`
        coordinates, else :func:`float_modes`).
    pretty : bool
        Unicode headers (ω_n, ζ, ω_d).
    limit : int
        The number of modes listed; the rest are counted, and those with the largest
        energy shares named.

    Returns
    -------
    list of str

    Examples
    --------
    >>> import laplace_springs as ls
    >>> print("\\n".join(summary_lines(ls.load_scene("vertical-pair"))))
    2 coordinates, 2 modes (undamped)
    mode           omega_n         zeta           omega_d    amplitude     energy
       1                 1            0                 1     0.942809     19.05%
       2                 2            0                 2     0.687184     80.95%
    amplitude: the mode's largest amplitude over the coordinates; energy: its share of the initial energy
    """
    mode_list = mode_list_of(scene) if mode_list is None else tuple(mode_list)
    share = participation(scene, mode_list)
    damped = any(m.kind == "real" or (m.damping_ratio is not None and _complex(m.damping_ratio) != 0)
                 for m in mode_list)
    kinds = "damped" if damped else "undamped"
    header = (f"{'mode':>4}  {'ω_n' if pretty else 'omega_n':>16}  {'ζ' if pretty else 'zeta':>11}  "
              f"{'ω_d' if pretty else 'omega_d':>16}  {'amplitude':>11}  {'energy':>9}")
    plural = "" if len(mode_list) == 1 else "s"
    first = f"{scene.n} coordinate{'s' if scene.n != 1 else ''}, {len(mode_list)} mode{plural} ({kinds})"
    if len(mode_list) > limit:
        first += f"; the first {limit} by natural frequency"
    lines = [first, header]
    for k, mode in enumerate(mode_list[:limit]):
        lines.append(_mode_row(k, mode, share))
    if len(mode_list) > limit:
        rest = mode_list[limit:]
        top = float(_complex(rest[-1].natural_frequency).real)
        low = float(_complex(rest[0].natural_frequency).real)
        lines.append(f"... and {len(rest)} more modes, {'ω_n' if pretty else 'omega_n'} from "
                     f"{low:.6g} to {top:.6g}")
    if share is not None:
        if len(mode_list) > limit and np.all(np.isfinite(share.energy)):
            order = np.argsort(-share.energy)[:3]
            named = ", ".join(f"mode {k + 1} ({100 * share.energy[k]:.3g}%)" for k in order)
            lines.append(f"largest shares of the initial energy: {named}")
        lines.append("amplitude: the mode's largest amplitude over the coordinates; "
                     "energy: its share of the initial energy")
    else:
        lines.append("(no participation: the mode shapes do not span the initial state)")
    if scene.is_forced:
        lines.append("the scene is forced: these are its free modes, and the participation "
                     "is that of the initial data")
    return lines


def _mode_row(k: int, mode: Any, share: Participation | None) -> str:
    wn = float(_complex(mode.natural_frequency).real)
    wd = float(_complex(mode.damped_frequency).real)
    zeta = "-" if mode.damping_ratio is None else f"{float(_complex(mode.damping_ratio).real):.6g}"
    amplitude = energy = "-"
    if share is not None:
        amplitude = f"{share.amplitude[k]:.6g}"
        if np.isfinite(share.energy[k]):
            percent = 100 * share.energy[k]
            energy = f"{percent:.2f}%" if percent >= 0.01 or percent == 0 else f"{percent:.3g}%"
    kind = "" if mode.kind == "oscillatory" else f"  ({mode.kind})"
    return (f"{k + 1:>4}  {wn:>16.{DIGITS}g}  {zeta:>11}  {wd:>16.{DIGITS}g}  {amplitude:>11}  "
            f"{energy:>9}{kind}")


# ---------------------------------------------------------------------------
# the formula of a large scene, from its float64 modes
# ---------------------------------------------------------------------------
def formula_terms(scene: Scene, mode_list: Sequence[Any] | None = None) -> int:
    """The number of terms :func:`modal_formula_lines` writes per coordinate (at most).

    Two per oscillatory or rigid mode (cos and sin, or constant and drift), one per real one.

    Examples
    --------
    >>> import laplace_springs as ls
    >>> formula_terms(ls.load_scene("three-dashpots"))
    4
    """
    mode_list = float_modes(scene) if mode_list is None else mode_list
    return sum(2 if m.kind in ("oscillatory", "rigid") else 1 for m in mode_list)


def modal_formula_lines(scene: Scene, coordinates: Sequence[int] | None = None, *,
                        pretty: bool = False, mode_list: Sequence[Any] | None = None) -> list[str]:
    """x_i(t) of the chosen coordinates as a sum over the float64 modes.

    Mode k (by natural frequency) contributes e^(α_k t)(a cos(β_k t) + b sin(β_k t));
    α_k, β_k are listed under "where" with their values (α_k only where it is not 0).
    Coefficients below 1e-13 of the largest are left out.

    Raises
    ------
    SceneError
        When the modes do not span the initial state (a defective eigenvalue).

    Examples
    --------
    >>> import laplace_springs as ls
    >>> scene = ls.Scene.from_matrices(M=[[1]], C=[["0.4"]], K=[[4]], x0=[1], v0=[0])
    >>> print("\\n".join(modal_formula_lines(scene)))
    x1(t) = (cos(beta_1*t) + 0.100503781526*sin(beta_1*t))*exp(alpha_1*t)
    where
      alpha_1 ≈ -0.2, beta_1 ≈ 1.98997487421
    """
    mode_list = float_modes(scene) if mode_list is None else tuple(mode_list)
    share = participation(scene, mode_list)
    if share is None:
        raise SceneError("no modal formula: the float64 mode shapes do not span the initial "
                         "state (a defective or nearly defective eigenvalue)")
    chosen = list(range(scene.n)) if coordinates is None else list(coordinates)
    largest = max((float(np.max(np.abs(w), initial=0.0)) for w in share.weights), default=0.0)
    largest = max([largest] + [float(np.max(np.abs(d))) for d in share.drifts if d is not None])
    tiny = 1e-13 * largest
    used: dict[int, tuple[bool, bool]] = {}
    lines = []
    for i in chosen:
        parts = []
        for k, mode in enumerate(mode_list):
            g = complex(share.weights[k][i])
            drift = share.drifts[k]
            piece, has_rate, has_wave = _mode_terms(k, mode, g, None if drift is None else drift[i],
                                                    tiny, pretty)
            if piece:
                parts.append(piece)
                seen = used.get(k, (False, False))
                used[k] = (seen[0] or has_rate, seen[1] or has_wave)
        body = " + ".join(parts).replace("+ -", "- ") if parts else "0"
        lines.append(f"{_name(sp.Symbol(scene.names[i]), pretty)}(t) = {body}")
    where = []
    for k in sorted(used):
        has_rate, has_wave = used[k]
        value = _complex(mode_list[k].eigenvalue)
        items = []
        if has_rate:
            items.append(f"{_indexed('alpha', k, pretty)} ≈ {value.real:.{DIGITS}g}")
        if has_wave:
            items.append(f"{_indexed('beta', k, pretty)} ≈ {value.imag:.{DIGITS}g}")
        if items:
            where.append("  " + ", ".join(items))
    return lines + (["where", *where] if where else [])


def _indexed(base: str, k: int, pretty: bool) -> str:
    return unicode_name(f"{base}_{k + 1}") if pretty else f"{base}_{k + 1}"


def _coefficient(value: float, tail: str, times: str) -> str:
    """``value*tail`` with 1 and -1 left implicit."""
    text = f"{value:.{DIGITS}g}"
    if text == "1":
        return tail
    if text == "-1":
        return f"-{tail}"
    return f"{text}{times}{tail}"


def _mode_terms(k: int, mode: Any, g: complex, drift: float | None, tiny: float,
                pretty: bool) -> tuple[str, bool, bool]:
    """The terms of mode k in one coordinate, and whether they use α_k, β_k."""
    times = "·" if pretty else "*"
    t = "t"
    alpha, beta = _indexed("alpha", k, pretty), _indexed("beta", k, pretty)
    if mode.kind == "rigid":
        items = []
        if abs(g.real) > tiny:
            items.append(f"{g.real:.{DIGITS}g}")
        if drift is not None and abs(drift) > tiny:
            items.append(_coefficient(float(drift), t, times))
        return " + ".join(items), False, False
    value = _complex(mode.eigenvalue)
    rate = value.real != 0
    growth = (f"e^({alpha}{times}{t})" if pretty else f"exp({alpha}{times}{t})") if rate else ""
    if mode.kind == "real":
        if abs(g.real) <= tiny:
            return "", False, False
        return _coefficient(g.real, growth, times), True, False
    a, b = g.real, -g.imag
    waves = []
    if abs(a) > tiny:
        waves.append(_coefficient(a, f"cos({beta}{times}{t})", times))
    if abs(b) > tiny:
        waves.append(_coefficient(b, f"sin({beta}{times}{t})", times))
    if not waves:
        return "", False, False
    inner = " + ".join(waves).replace("+ -", "- ")
    if not rate:
        return inner, False, True
    if len(waves) > 1:
        inner = f"({inner})"
    return f"{inner}{times}{growth}", True, True
