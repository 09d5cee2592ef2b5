"""Frequency response H(iω) = (K − ω²M + iωC)⁻¹: exact, numeric, and steady amplitudes.

A harmonic force f(t) = F cos ωt drives a stable scene into the steady oscillation
x(t) = Re[H(iω) F e^{iωt}]: mass j moves with amplitude |(H F)_j| and phase lag
−arg (H F)_j. The exact H comes from the resolvent's adjugate, H = adj(iω)/Δ(iω).
The plot of |H| and arg H is :func:`laplace_springs.output.plots.plot_frequency_response`.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, overload

import numpy as np
import sympy as sp
from numpy.typing import ArrayLike

from ..exact.resolvent import resolvent
from ..model.errors import SceneError
from ..model.numbers import to_exact
from ..model.scene import Scene
from ..model.symbols import lam
from ..numeric.first_order import float_matrix

__all__ = ["omega", "frequency_response", "steady_state_amplitude"]

#: The driving frequency ω of exact frequency responses (rad per unit time).
omega = sp.Symbol("omega", positive=True)


@overload
def frequency_response(scene: Scene, omegas: None = None) -> sp.ImmutableMatrix: ...


@overload
def frequency_response(scene: Scene, omegas: ArrayLike) -> np.ndarray: ...


def frequency_response(scene: Scene, omegas: ArrayLike | None = None) -> sp.ImmutableMatrix | np.ndarray:
    """The receptance matrix H(iω) = (K − ω²M + iωC)⁻¹, exactly or at given frequencies.

    Parameters
    ----------
    scene : Scene
    omegas : array_like, optional
        Driving frequencies. Without them the exact matrix is returned as a function of
        the symbol :data:`omega`.

    Returns
    -------
    sympy.ImmutableMatrix or numpy.ndarray
        The exact n x n matrix in ``omega``; or a complex array of shape
        (len(omegas), n, n) with ``H[k, i, j]`` the response of coordinate i to a unit
        harmonic force on coordinate j at ``omegas[k]``.

    Examples
    --------
    A single mass, spring and dashpot: H = 1/(k − mω² + icω):

    >>> from laplace_springs import Scene
    >>> scene = Scene.from_matrices(M=[[1]], C=[["0.2"]], K=[[4]], x0=[0], v0=[0])
    >>> frequency_response(scene)[0, 0]
    1/(-omega**2 + I*omega/5 + 4)
    >>> float(abs(frequency_response(scene, [2.0])[0, 0, 0]))  # at resonance: 1/(cω) = 2.5
    2.5
    """
    if omegas is None:
        R = resolvent(scene)
        at = {lam: sp.I * omega}
        delta = sp.expand(R.determinant.as_expr().xreplace(at))
        return sp.ImmutableMatrix(R.adjugate.applyfunc(lambda e: sp.expand(e.xreplace(at)) / delta))
    M, C, K = (float_matrix(getattr(scene, name), name) for name in ("M", "C", "K"))
    w = np.atleast_1d(np.asarray(omegas, dtype=float))
    pencils = K[None] - (w**2)[:, None, None] * M[None] + 1j * w[:, None, None] * C[None]
    eye = np.broadcast_to(np.eye(scene.n, dtype=complex), pencils.shape)
    return np.linalg.solve(pencils, eye)


def steady_state_amplitude(scene: Scene, force: Sequence[Any], frequency: Any
                           ) -> tuple[sp.ImmutableMatrix, sp.ImmutableMatrix]:
    """Exact steady-state amplitude and phase lag of each coordinate under F cos ωt.

    Parameters
    ----------
    scene : Scene
        A damped scene (or an undamped one driven off its natural frequencies).
    force : sequence
        Force amplitudes F_j, one per coordinate.
    frequency : number or sympy.Expr
        The driving frequency ω.

    Returns
    -------
    amplitude, phase : sympy.ImmutableMatrix
        x_j(t) → amplitude_j · cos(ωt − phase_j) once transients have died out.

    Raises
    ------
    SceneError
        When ω is a natural frequency of an undamped scene (no steady state: resonance).

    Examples
    --------
    Textbook single degree of freedom: X = F0/√((k − mω²)² + (cω)²), tan φ = cω/(k − mω²):

    >>> from laplace_springs import Scene
    >>> scene = Scene.from_matrices(M=[[2]], C=[[1]], K=[[8]], x0=[0], v0=[0])
    >>> amplitude, phase = steady_state_amplitude(scene, [3], 1)
    >>> amplitude[0], phase[0]
    (3*sqrt(37)/37, atan(1/6))
    """
    w = to_exact(frequency, "frequency")
    F = sp.Matrix([to_exact(f, f"force[{j}]") for j, f in enumerate(force)])
    if F.rows != scene.n:
        raise SceneError(f"force has {F.rows} entries, expected {scene.n}")
    R = resolvent(scene)
    at = {lam: sp.I * w}
    delta = sp.expand(R.determinant.as_expr().xreplace(at))
    if delta == 0:
        raise SceneError(f"omega = {w} is a natural frequency of an undamped scene: "
                         "the response grows without bound (resonance), no steady state")
    response = (R.adjugate.xreplace(at) * F).applyfunc(lambda e: sp.expand(e / delta))
    amplitude = response.applyfunc(lambda z: sp.simplify(sp.sqrt(sp.expand(z * sp.conjugate(z)))))
    phase = response.applyfunc(_phase_lag)
    return sp.ImmutableMatrix(amplitude), sp.ImmutableMatrix(phase)


def _phase_lag(z: sp.Expr) -> sp.Expr:
    re, im = sp.expand_complex(z).as_real_imag()
    if re == 0 and im == 0:
        return sp.S.Zero
    return sp.simplify(-sp.atan2(sp.simplify(im), sp.simplify(re)))
