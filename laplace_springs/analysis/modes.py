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

from ..exact.algebraic import AlgebraicRoot, numeric_value
from ..exact.resolvent import resolvent
from ..model.errors import SceneError
from ..model.numbers import generic_values
from ..model.scene import Scene
from ..model.symbols import lam

__all__ = ["Mode", "modes"]

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
        ω_n = |λ| (rad per unit time).
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

    def __repr__(self) -> str:
        wn = float(self.natural_frequency)
        zeta = "" if self.damping_ratio is None else f", zeta={float(self.damping_ratio):.6g}"
        return f"<Mode {self.kind}: omega_n={wn:.6g}{zeta}, multiplicity {self.multiplicity}>"


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
    R = resolvent(scene)
    if not scene.is_damped:
        out = _undamped_modes(scene, R.determinant)
    else:
        out = _damped_modes(scene, R.determinant)
    generic = generic_values(scene.free_symbols)
    return tuple(sorted(out, key=lambda m: float(numeric_value(
        m.natural_frequency.xreplace(generic), 20))))


_MU = sp.Symbol("mu")


def _undamped_modes(scene: Scene, determinant: sp.Poly) -> list[Mode]:
    """Δ(λ) = p(−λ²): ω² = μ runs over the roots of p, λ = iω; no damping, ζ = 0."""
    coeffs = determinant.all_coeffs()[::-1]  # ascending powers of λ
    p = sp.Poly(sum(c * (-_MU) ** (k // 2) for k, c in enumerate(coeffs) if k % 2 == 0), _MU)
    out = []
    for factor, multiplicity in p.factor_list()[1]:
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
    return [AlgebraicRoot(factor, i) for i in range(factor.degree())]


def _damped_modes(scene: Scene, determinant: sp.Poly) -> list[Mode]:
    out = []
    for factor, multiplicity in determinant.factor_list()[1]:
        for root in _upper_roots(factor, scene):
            out.append(_mode(scene, root, multiplicity))
    return out


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
    """Null vectors of the pencil at ``root``, from an SVD of its accurately rounded value."""
    generic = generic_values(scene.free_symbols)
    at = root.xreplace(generic)
    pencil = (lam**2 * scene.M + lam * scene.C + scene.K).xreplace(generic)
    P = np.array([[complex(numeric_value(e.subs(lam, at), dps)) for e in row]
                  for row in pencil.tolist()])
    _, sigma, vh = np.linalg.svd(P)
    scale = max(sigma[0], 1e-300)
    null = [vh[k].conj() for k in range(len(sigma)) if sigma[k] <= 1e-9 * scale] or [vh[-1].conj()]
    return tuple(_normalise(v) for v in null)


def _normalise(v: np.ndarray) -> np.ndarray:
    v = v / v[np.argmax(np.abs(v))]
    v[np.abs(v) < 1e-14] = 0
    if np.all(np.abs(v.imag) < 1e-13):
        v = v.real.astype(complex)
    return v
