"""Frequency response H(iω) = (K − ω²M + iωC)⁻¹: exact, numeric, amplitudes and plots.

A harmonic force f(t) = F cos ωt drives a stable scene into the steady oscillation
x(t) = Re[H(iω) F e^{iωt}]: mass j moves with amplitude |(H F)_j| and phase lag
−arg (H F)_j. The exact H comes from the resolvent's adjugate, H = adj(iω)/Δ(iω).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Sequence

import numpy as np
import sympy as sp

from .errors import SceneError
from .numbers import to_exact
from .resolvent import lam, resolvent

if TYPE_CHECKING:
    from .scene import Scene

__all__ = ["omega", "frequency_response", "steady_state_amplitude", "plot_frequency_response"]

#: The driving frequency ω of exact frequency responses (rad per unit time).
omega = sp.Symbol("omega", positive=True)


def frequency_response(scene: Scene, omegas: Any = None):
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
    M, C, K = (_float_matrix(scene, name) for name in ("M", "C", "K"))
    w = np.atleast_1d(np.asarray(omegas, dtype=float))
    pencils = K[None] - (w**2)[:, None, None] * M[None] + 1j * w[:, None, None] * C[None]
    eye = np.broadcast_to(np.eye(scene.n, dtype=complex), pencils.shape)
    return np.linalg.solve(pencils, eye)


def _float_matrix(scene: Scene, name: str) -> np.ndarray:
    matrix = getattr(scene, name)
    if matrix.free_symbols:
        raise SceneError(f"{name} has symbolic entries {sorted(map(str, matrix.free_symbols))}; "
                         "give numbers to evaluate the frequency response numerically")
    return np.array(matrix.tolist(), dtype=float)


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
    phase = response.applyfunc(lambda z: _phase_lag(z))
    return sp.ImmutableMatrix(amplitude), sp.ImmutableMatrix(phase)


def _phase_lag(z: sp.Expr) -> sp.Expr:
    re, im = sp.expand_complex(z).as_real_imag()
    if re == 0 and im == 0:
        return sp.S.Zero
    return sp.simplify(-sp.atan2(sp.simplify(im), sp.simplify(re)))


def plot_frequency_response(scene: Scene, omegas: Any = None, *, force: int = 0,
                            outputs: Sequence[int] | None = None, ax=None):
    """Amplitude and phase of the response to a unit harmonic force, on log axes.

    Parameters
    ----------
    scene : Scene
        Numeric entries.
    omegas : array_like, optional
        Frequencies; by default 4000 log-spaced points spanning the natural frequencies
        from a tenth of the lowest to ten times the highest.
    force : int
        The coordinate the unit force acts on.
    outputs : sequence of int, optional
        Coordinates to draw (default all).
    ax : pair of matplotlib Axes, optional
        (amplitude axes, phase axes); a new figure by default.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> from laplace_springs import load_scene
    >>> fig = plot_frequency_response(load_scene("vertical-pair-damped"))
    >>> [a.get_xscale() for a in fig.axes]
    ['log', 'log']
    """
    import matplotlib.pyplot as plt

    from .modes import modes

    found = modes(scene)
    peaks = sorted(float(m.damped_frequency) for m in found if m.kind == "oscillatory")
    if omegas is None:
        positive = [float(m.natural_frequency) for m in found if m.kind != "rigid"]
        low, high = (min(positive) / 10, max(positive) * 10) if positive else (0.01, 100)
        omegas = np.union1d(np.geomspace(low, high, 4000), peaks)
    w = np.asarray(omegas, dtype=float)
    H = frequency_response(scene, w)[:, :, force]
    if ax is None:
        fig, (amp_ax, phase_ax) = plt.subplots(2, 1, sharex=True, figsize=(7, 6))
    else:
        amp_ax, phase_ax = ax
        fig = amp_ax.figure
    rows = range(scene.n) if outputs is None else outputs
    for i in rows:
        label = scene.names[i]
        line, = amp_ax.loglog(w, np.abs(H[:, i]), label=f"|{label}| / F")
        phase_ax.semilogx(w, np.degrees(np.unwrap(np.angle(H[:, i]))), color=line.get_color(),
                          label=label)
    for peak in peaks:  # resonance peaks: the damped natural frequencies
        for axis in (amp_ax, phase_ax):
            axis.axvline(peak, color="0.6", linestyle="--", linewidth=0.8)
        k = int(np.argmin(np.abs(w - peak)))
        amp_ax.plot([peak] * len(rows), np.abs(H[k, list(rows)]), "o", color="0.25", markersize=4)
        amp_ax.text(peak, 0.03, f" ω = {peak:.4g}", transform=amp_ax.get_xaxis_transform(),
                    rotation=90, va="bottom", ha="right", fontsize=8, color="0.3")
    amp_ax.set_ylabel("amplitude per unit force (m/N)")
    phase_ax.set_ylabel("phase (degrees)")
    phase_ax.set_xlabel("driving frequency ω (rad/s)")
    amp_ax.set_title(f"Frequency response, unit force on {scene.names[force]}")
    amp_ax.legend(loc="best", fontsize=8)
    amp_ax.grid(True, which="both", alpha=0.3)
    phase_ax.grid(True, which="both", alpha=0.3)
    return fig
