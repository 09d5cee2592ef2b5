"""Modal data: eigenvalues of the pencil λ²M + λC + K, frequencies, damping ratios, shapes.

The eigenvalues are the roots of Δ(λ) = det(λ²M + λC + K), taken exactly from its
factorisation over the rationals (radicals up to degree 2, certified algebraic numbers
beyond). Each complex pair λ = −ζω_n ± iω_d gives one mode with natural frequency
ω_n = |λ|, damped frequency ω_d = Im λ and damping ratio ζ = −Re λ/|λ|; a real
eigenvalue (overdamped motion, a dashpot-only coordinate) or λ = 0 (a rigid-body mode)
gives a mode without oscillation. Shapes are null vectors of the pencil at λ.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
import sympy as sp

from ..exact.algebraic import AlgebraicRoot
from ..exact.partial_fractions import exact_factors, isolation_obstacle
from ..exact.resolvent import resolvent
from ..limits import limits
from ..model.errors import LimitError, SceneError
from ..model.numbers import generic_values
from ..model.scene import Scene
from ..model.symbols import lam
from ..numeric.classical import float_eigenpairs
from ..numeric.first_order import is_rational
from ..numeric.mp_expr import numeric_value
from .multiple_roots import multiple_roots

__all__ = ["Mode", "modes", "float_modes"]


ModeKind = Literal["oscillatory", "real", "rigid"]


@dataclass(frozen=True)
class Mode:
    """One eigenvalue of the pencil and what it means physically.

    Attributes
    ----------
    eigenvalue : sympy.Expr
        λ, exact; for a complex pair the member with Im λ > 0.
    kind : {"oscillatory", "real", "rigid"}
        A complex pair; a real nonzero eigenvalue; λ = 0.
    natural_frequency : sympy.Expr
        ω_n = |λ| (rad per unit time: rad/s for a scene with units; in Hz,
        :attr:`natural_frequency_hz`).
    damped_frequency : sympy.Expr
        ω_d = Im λ (0 for real eigenvalues).
    damping_ratio : sympy.Expr or None
        ζ = −Re λ/|λ| for an oscillatory mode; ``None`` for real eigenvalues.
    multiplicity : int
        Algebraic multiplicity of λ as a root of Δ.
    shapes : tuple of numpy.ndarray
        Null vectors of λ²M + λC + K (as many as the geometric multiplicity), complex,
        scaled so the largest entry is 1: real for undamped and proportionally damped
        scenes.
    """

    eigenvalue: sp.Expr
    kind: ModeKind
    natural_frequency: sp.Expr
    damped_frequency: sp.Expr
    damping_ratio: sp.Expr | None
    multiplicity: int
    shapes: tuple[np.ndarray, ...]

    @property
    def shape(self) -> np.ndarray:
        """The first mode shape."""
        return self.shapes[0]

    @property
    def natural_frequency_hz(self) -> sp.Expr:
        """f_n = ω_n/(2π), exact: cycles per second (Hz) when time is in seconds.

        >>> Mode(sp.I * 2, "oscillatory", sp.Integer(2), sp.Integer(2), sp.S.Zero, 1, ()).natural_frequency_hz
        1/pi
        """
        return self.natural_frequency / (2 * sp.pi)

    @property
    def damped_frequency_hz(self) -> sp.Expr:
        """f_d = ω_d/(2π), exact: cycles per second (Hz) when time is in seconds."""
        return self.damped_frequency / (2 * sp.pi)

    def __repr__(self) -> str:
        """``Mode(ω_n=2, ζ=1/10, oscillatory)``: short exact values as they are, others ≈ 6 digits.

        >>> Mode(sp.I * 2, "oscillatory", sp.Integer(2), sp.Integer(2), sp.S.Zero, 1, ())
        Mode(ω_n=2, ζ=0, oscillatory)
        >>> Mode(-1.0, "real", 1.0, 0.0, None, 2, ())
        Mode(λ=-1, real, multiplicity 2)
        >>> c, k, m = sp.symbols("c k m")
        >>> Mode(None, "oscillatory", sp.sqrt(k / m), None, c / (2 * sp.sqrt(k * m)), 1, ())
        Mode(ω_n=sqrt(k/m), ζ=c/(2*sqrt(k*m)), oscillatory)
        """
        if self.kind == "oscillatory":
            parts = [f"ω_n{Mode._compact(self.natural_frequency)}"]
            if self.damping_ratio is not None:
                parts.append(f"ζ{Mode._compact(self.damping_ratio)}")
        else:
            parts = [f"λ{Mode._compact(self.eigenvalue)}"]
        parts.append(self.kind)
        if self.multiplicity > 1:
            parts.append(f"multiplicity {self.multiplicity}")
        return f"Mode({', '.join(parts)})"

    @staticmethod
    def _compact(value: sp.Expr | complex | float) -> str:
        """``=2``, ``=sqrt(3)`` for short exact values, ``≈15.9954`` for long or float ones."""
        if isinstance(value, sp.Basic) and not value.has(sp.Float):
            text = sp.sstr(value)
            if value.free_symbols or (len(text) <= 14 and not value.has(sp.CRootOf, AlgebraicRoot)):
                return f"={text}"   # a formula in the parameters has no value to show
        number = complex(numeric_value(value, 15)) if isinstance(value, sp.Basic) else complex(value)
        shown = f"{number.real:.6g}" if number.imag == 0 else f"{number:.6g}"
        exact = not isinstance(value, sp.Basic) and complex(shown.strip("()")) == number
        return f"={shown}" if exact else f"≈{shown}"


def modes(scene: Scene) -> tuple[Mode, ...]:
    """The modes of a scene, ordered by natural frequency.

    Parameters
    ----------
    scene : Scene
        Numeric entries (symbolic scenes: only when Δ splits into quadratics in λ or λ²).

    Returns
    -------
    tuple of Mode

    Raises
    ------
    SceneError
        When the eigenvalues have no closed form (symbolic entries, high degree).

    Notes
    -----
    Rational scenes up to Limits.modes_exact_max_coordinates coordinates are exact. A
    scene with irrational entries takes its modes from float64 eigenpairs
    (:func:`float_modes`), except that up to Limits.modes_multiple_root_max_coordinates
    coordinates, where two eigenvalues lie within 1e-3 of each other, the squarefree
    decomposition of Δ decides exactly whether they are one multiple root
    (:mod:`laplace_springs.analysis.multiple_roots`); such a root is one mode of its
    multiplicity, exact, as for a rational scene (m = 1, c = 2√2, k = 2: λ = −√2 twice).
    Beyond that size (or where Δ is too large to expand) a multiple root of an irrational
    scene is listed as the float64 eigenvalues rounding split it into.

    Examples
    --------
    The seed's Example 1 (undamped; A has eigenvalues 1 and 4):

    >>> from laplace_springs import load_scene
    >>> for mode in modes(load_scene("vertical-pair")):
    ...     print(mode.natural_frequency, mode.damping_ratio, mode.shape.real.round(4))
    1 0 [0.5 1. ]
    2 0 [-1.  1.]

    A damped single mass, x'' + 0.4x' + 4x = 0 (ζ = 0.1, ω_n = 2):

    >>> from laplace_springs import Scene
    >>> (mode,) = modes(Scene.from_matrices(M=[[1]], C=[["0.4"]], K=[[4]], x0=[1], v0=[0]))
    >>> mode.natural_frequency, mode.damping_ratio, mode.damped_frequency
    (2, 1/10, 3*sqrt(11)/5)
    """
    if not scene.free_symbols and (scene.n > limits().modes_exact_max_coordinates or not is_rational(scene)):
        found = float_modes(scene)
        if scene.n <= limits().modes_exact_max_coordinates and _clustered(found):
            return _merge_multiple(scene, found)
        return found
    R = resolvent(scene)
    if not scene.is_damped:
        out = _undamped_modes(scene, R.determinant)
    else:
        out = _damped_modes(scene, R.determinant)
    generic = generic_values(scene.free_symbols)
    return tuple(sorted(out, key=lambda m: float(numeric_value(
        m.natural_frequency.xreplace(generic), 20))))


_MU = sp.Symbol("mu")


def float_modes(scene: Scene) -> tuple[Mode, ...]:
    """The modes of a numeric scene from float64 eigenpairs, ordered by natural frequency.

    What :func:`modes` returns beyond :attr:`~laplace_springs.limits.Limits.modes_exact_max_coordinates` coordinates or for
    irrational entries: the symmetric eigenproblem of size n where the damping is classical
    (real shapes), else the 2n x 2n first-order matrix. Values are SymPy Floats (15 digits).
    A zero eigenvalue of the symmetric problem (|λ|² ≤ 1e-13 of the largest) is one rigid
    mode of multiplicity 2 (a drift and a position), shapes scaled so the largest entry is 1.

    Examples
    --------
    A chain of three unit masses and springs: ω_k = 2 sin(kπ/8).

    >>> scene = Scene.from_matrices(M=[[1, 0, 0], [0, 1, 0], [0, 0, 1]],
    ...                             K=[[2, -1, 0], [-1, 2, -1], [0, -1, 2]], x0=[1, 0, 0], v0=[0, 0, 0])
    >>> [round(float(m.natural_frequency), 12) for m in float_modes(scene)]
    [0.76536686473, 1.414213562373, 1.847759065023]
    """
    pairs = float_eigenpairs(scene)
    symmetric = scene.M.is_symmetric() and scene.K.is_symmetric()
    top = max((abs(value) for value, _ in pairs), default=0.0)
    out: list[Mode] = []
    seen_rigid: list[np.ndarray] = []
    for value, shape in pairs:
        if abs(value) ** 2 <= 1e-13 * top**2:
            if any(np.array_equal(shape, other) for other in seen_rigid):
                continue  # the symmetric route lists a rigid mode once per root of λ² = 0
            seen_rigid.append(shape)
            real = shape.real.astype(complex) if np.all(shape.imag == 0) else shape
            out.append(Mode(sp.S.Zero, "rigid", sp.S.Zero, sp.S.Zero, None, 2, (real,)))
            continue
        if not scene.is_damped and symmetric:  # λ² is real: λ = ±iω or real, never ζ ≠ 0
            value = _undamped(value)  # noqa: PLW2901
        wn = abs(value)
        kind: ModeKind = "real" if value.imag == 0 else "oscillatory"
        zeta = (sp.S.Zero if value.real == 0 else sp.Float(-value.real / wn, 15)) \
            if kind == "oscillatory" else None
        eigenvalue = sp.Float(value.real, 15) + sp.I * sp.Float(value.imag, 15)
        out.append(Mode(eigenvalue, kind, sp.Float(wn, 15), sp.Float(value.imag, 15), zeta, 1,
                        (shape,)))
    return tuple(sorted(out, key=lambda m: (float(m.natural_frequency), float(m.damped_frequency))))


#: Float eigenvalues this close (relative) may be one multiple root split by rounding
#: (a double root splits by about √u = 1.5e-8, a triple by u^(1/3) = 6e-6 of its size).
_CLUSTER = 1e-3


def _clustered(found: tuple[Mode, ...]) -> bool:
    """Whether two float eigenvalues (a complex one and its conjugate included) other
    than 0 lie within _CLUSTER of each other, relative to the larger."""
    values: list[complex] = []
    for mode in found:
        if mode.kind == "rigid":
            continue
        z = complex(mode.eigenvalue)
        values += [z, z.conjugate()] if mode.kind == "oscillatory" else [z]
    return any(abs(a - b) <= _CLUSTER * max(abs(a), abs(b))
               for i, a in enumerate(values) for b in values[i + 1:])


def _merge_multiple(scene: Scene, found: tuple[Mode, ...]) -> tuple[Mode, ...]:
    """Float modes with each multiple root of Δ (decided exactly: :mod:`.multiple_roots`)
    as one mode of its multiplicity, exact as :func:`modes` gives it for a rational
    scene, in place of the float modes rounding split it into."""
    if scene.n > limits().modes_multiple_root_max_coordinates:
        return found
    try:
        determinant = resolvent(scene).determinant
    except LimitError:  # Δ too large to expand (max_resolvent_terms): the float modes stand
        return found
    roots = multiple_roots(determinant, scene.n)
    if not roots:
        return found
    kept = list(found)
    merged = []
    for root, multiplicity in roots:
        z = complex(numeric_value(root, 20))
        # the float modes nearest to the root, until they hold its multiplicity: a real
        # root split into a complex pair is one oscillatory float mode holding two
        order = sorted((m for m in kept if m.kind != "rigid"), key=lambda m: abs(complex(m.eigenvalue) - z))
        held = 0
        for mode in order:
            if held >= multiplicity:
                break
            if abs(complex(mode.eigenvalue) - z) > _CLUSTER * abs(z):
                return found  # no cluster there: leave the float modes as they are
            kept.remove(mode)
            held += 2 if (mode.kind == "oscillatory" and z.imag == 0) else 1
        if held != multiplicity:
            return found
        merged.append(_mode(scene, root, multiplicity) if not root.has(sp.Float) else
                      _float_mode(scene, z, multiplicity))
    return tuple(sorted(kept + merged, key=lambda m: (float(numeric_value(m.natural_frequency, 20)),
                                                     float(numeric_value(m.damped_frequency, 20)))))


def _float_mode(scene: Scene, value: complex, multiplicity: int) -> Mode:
    """A mode at a multiple root known to 15 digits."""
    wn = abs(value)
    kind: ModeKind = "real" if value.imag == 0 else "oscillatory"
    zeta = sp.Float(-value.real / wn, 15) if kind == "oscillatory" else None
    eigenvalue = sp.Float(value.real, 15) + sp.I * sp.Float(value.imag, 15)
    return Mode(eigenvalue, kind, sp.Float(wn, 15), sp.Float(value.imag, 15), zeta, multiplicity,
                _shapes(scene, eigenvalue))


def _undamped(value: complex) -> complex:
    """An eigenvalue of an undamped symmetric scene (λ² real) without the rounding that
    gave it a real part next to its imaginary one (ζ = −2.3e-17) or the reverse."""
    if abs(value.imag) >= abs(value.real):
        return complex(0.0, abs(value.imag))
    return complex(value.real, 0.0)


def _undamped_modes(scene: Scene, determinant: sp.Poly) -> list[Mode]:
    """Δ(λ) = p(−λ²): ω² = μ runs over the roots of p, λ = iω; no damping, ζ = 0."""
    coeffs = determinant.all_coeffs()[::-1]  # ascending powers of λ
    p = sp.Poly(sum(c * (-_MU) ** (k // 2) for k, c in enumerate(coeffs) if k % 2 == 0), _MU)
    out = []
    for factor, multiplicity in exact_factors(p):
        for mu in _all_roots(factor, scene):
            if mu == 0:
                out.append(Mode(sp.S.Zero, "rigid", sp.S.Zero, sp.S.Zero, None, 2 * multiplicity,
                                _shapes(scene, sp.S.Zero)))
                continue
            omega = _simplify(sp.sqrt(mu))
            out.append(Mode(sp.I * omega, "oscillatory", omega, omega, sp.S.Zero, multiplicity,
                            _shapes(scene, sp.I * omega)))
    return out


def _all_roots(factor: sp.Poly, scene: Scene) -> list[sp.Expr]:
    """All roots of an irreducible factor: radicals up to degree 2, else AlgebraicRoot."""
    factor = factor.monic()
    if factor.degree() <= 2 or factor.free_symbols - set(factor.gens):
        found = sp.roots(factor, factor.gen)
        if sum(found.values()) != factor.degree():
            raise SceneError(f"the eigenvalues of {scene!r} have no closed form: "
                             f"cannot solve {factor.as_expr()} = 0")
        return list(found)
    if (why := isolation_obstacle(factor.all_coeffs())) is not None:
        raise LimitError(f"the exact modes of this scene: Δ(λ) has an {why}. Its poles, "
                         "certified: ls.solve(scene, method='certified').poles")
    return [AlgebraicRoot(factor, i) for i in range(factor.degree())]


def _damped_modes(scene: Scene, determinant: sp.Poly) -> list[Mode]:
    out = []
    for factor, multiplicity in exact_factors(determinant):
        pair = _symbolic_pair(scene, factor, multiplicity)
        if pair is not None:
            out.append(pair)
            continue
        for root in _upper_roots(factor, scene):
            out.append(_mode(scene, root, multiplicity))
    return out


def _symbolic_pair(scene: Scene, factor: sp.Poly, multiplicity: int) -> Mode | None:
    """a λ² + b λ + c with symbolic coefficients whose roots are not known to be real: the
    underdamped pair, as the exact route writes it (4ac > b² assumed): ω_n = √(c/a),
    ζ = b/(2√(ac)), ω_d = √(4ac − b²)/(2a). SymPy's roots of a symbolic quadratic would
    give |λ| through re(), im() and atan2 of the parameters (they may be complex to it).
    None for other factors."""
    if factor.degree() != 2 or not factor.free_symbols - set(factor.gens):
        return None
    a, b, c = factor.all_coeffs()
    if b == 0 or sp.factor(b**2 - 4 * a * c).is_nonnegative:
        return None  # undamped (ζ = 0 by the general path) or known real roots
    damped = sp.factor(sp.sqrt(sp.factor(4 * a * c - b**2)) / (2 * a))
    root = -b / (2 * a) + sp.I * damped
    natural = _simplify(sp.sqrt(c / a))
    ratio = b / (2 * sp.sqrt(a * c))
    return Mode(root, "oscillatory", natural, damped, ratio, multiplicity, _shapes(scene, root))


def _upper_roots(factor: sp.Poly, scene: Scene) -> list[sp.Expr]:
    """Roots of an irreducible factor: real ones, and complex ones with Im > 0."""
    roots = _all_roots(factor, scene)
    kept = []
    for root in roots:
        im = sp.im(root)
        if im.is_number:  # radicals or algebraic numbers (possibly rescaled, 2*CRootOf(...))
            if im == 0 or numeric_value(im, 20) > 0:
                kept.append(root)
        elif im.is_positive or (im.is_positive is None
                                and not sp.expand_complex(im).could_extract_minus_sign()):
            kept.append(root)  # symbolic: the conjugate pair's member written with +
    return kept


def _simplify(expr: sp.Expr) -> sp.Expr:
    return sp.radsimp(sp.sqrtdenest(sp.simplify(expr))) if not expr.has(sp.CRootOf) else expr


def _mode(scene: Scene, root: sp.Expr, multiplicity: int) -> Mode:
    if root.has(sp.CRootOf):  # expand_complex cannot take CRootOf apart
        re, im = sp.re(root), sp.im(root)
    else:
        re, im = (_simplify(part) for part in sp.expand_complex(root).as_real_imag())
    kind: ModeKind
    zeta: sp.Expr | None
    if root == 0:
        kind, wn, zeta = "rigid", sp.S.Zero, None
    elif im == 0:
        kind, wn, zeta = "real", sp.Abs(re), None
    else:
        kind = "oscillatory"
        wn = _simplify(sp.sqrt(re**2 + im**2))
        zeta = _simplify(-re / wn)
    return Mode(root, kind, wn, im, zeta, multiplicity, _shapes(scene, root))


def _shapes(scene: Scene, root: sp.Expr, dps: int = 30) -> tuple[np.ndarray, ...]:
    """Null vectors of the pencil at ``root``, from an SVD of its accurately rounded value.

    A singular value counts as zero relative to the size of the pencil's parts,
    |λ|²‖M‖ + |λ|‖C‖ + ‖K‖, not to the pencil's own largest one: where the whole pencil
    vanishes (M = I, C = I/5, K = 4I: every vector is a shape) that one is rounding too.
    """
    generic = generic_values(scene.free_symbols)
    at = root.xreplace(generic)
    pencil = (lam**2 * scene.M + lam * scene.C + scene.K).xreplace(generic)
    P = np.array([[complex(numeric_value(e.subs(lam, at), dps)) for e in row]
                  for row in pencil.tolist()])
    _, sigma, vh = np.linalg.svd(P)
    size = abs(complex(numeric_value(at, dps)))
    parts = [float(np.linalg.norm(np.array(m.xreplace(generic).tolist(), dtype=complex), 2))
             for m in (scene.M, scene.C, scene.K)]
    scale: float = max(size**2 * parts[0] + size * parts[1] + parts[2], 1e-300)
    null = [vh[k].conj() for k in range(len(sigma)) if sigma[k] <= 1e-9 * scale] or [vh[-1].conj()]
    return tuple(_normalise(v) for v in null)


def _normalise(v: np.ndarray) -> np.ndarray:
    v = v / v[np.argmax(np.abs(v))]
    v[np.abs(v) < 1e-14] = 0
    if np.all(np.abs(v.imag) < 1e-13):
        v = v.real.astype(complex)
    return v
