"""Plots of a solution: motion, phase portraits, energy, frequency response.

:func:`plot_motion` is the seed's "Mass Position vs. Time" figure (Example 5): one
line per mass, a legend, axis labels with units. :func:`plot_phase` draws each
coordinate's phase portrait (x_i against v_i). :func:`plot_energy` draws kinetic
energy ½vᵀMv, potential energy ½xᵀKx, the energy dissipated by the dashpots
∫vᵀCv dt, and their sum, which stays at the initial energy: damping only removes
energy. :func:`plot_frequency_response` draws amplitude and phase of the response to a unit
harmonic force, on log axes.

Velocities come from the solution itself (``evaluate(times, derivative=1)``: exact
derivatives of the terms on the exact route, λ·weights on the others), so no finite
differences enter the phase portraits or the energies. The dissipated energy is integrated with
three-point Gauss-Legendre on each sampling interval (sixth order).

All functions draw on given axes or, without them, on a new pyplot figure; the
command line uses :func:`overview_figure`, which needs no pyplot backend.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np
import sympy as sp

from ..analysis.frequency import frequency_response
from ..analysis.interop import poles_and_zeros
from ..analysis.modes import modes
from ..model.errors import SceneError
from ..model.scene import Scene
from ..model.symbols import TIME
from ..model.units import axis_label
from ..numeric.first_order import float_matrix
from .chain import math_label, physical_matrices
from .drawing import draw_scene

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure


class Motion(Protocol):
    """What the plots read of a solution (every :class:`laplace_springs.Solution` has it)."""

    scene: Scene

    @property
    def poles(self) -> np.ndarray: ...

    def evaluate(self, times: Any, *, derivative: int = 0) -> Any: ...


__all__ = [
    "Motion", "time_grid", "default_t_end", "motion", "Energy", "energy",
    "plot_motion", "plot_phase", "plot_energy", "plot_frequency_response", "overview_figure",
    "plot_bode", "plot_pole_zero", "bode_data",
]

LINE_WIDTH = 2.2


# ----------------------------------------------------------------------------
# Numbers behind the plots
# ----------------------------------------------------------------------------


def _check_numeric(scene: Scene) -> None:
    if scene.free_symbols:
        names = ", ".join(sorted(symbol.name for symbol in scene.free_symbols))
        raise SceneError(f"plots need numbers, but the scene has symbols {names}; "
                         "substitute values first")


def _rates_and_frequencies(solution: Motion) -> tuple[np.ndarray, np.ndarray]:
    """Exponential rates α and angular frequencies |β| of the solution's poles α ± iβ."""
    _check_numeric(solution.scene)
    poles = np.asarray(solution.poles, dtype=complex)
    return poles.real.copy(), np.abs(poles.imag)


def _nice(value: float) -> float:
    """The smallest of 1, 1.5, 2, 2.5, 3, 4, 5, 6, 8 × 10^k that is ≥ value."""
    exponent = math.floor(math.log10(value))
    for mantissa in (1, 1.5, 2, 2.5, 3, 4, 5, 6, 8, 10):
        if mantissa * 10.0**exponent >= value * (1 - 1e-12):
            return mantissa * 10.0**exponent
    return 10.0 ** (exponent + 1)  # pragma: no cover


def default_t_end(solution: Motion) -> float:
    """A time span that shows the motion: a few slow periods, or until it has decayed.

    Read off the solution's poles α ± iβ. Undamped: four
    periods of the slowest oscillation. Damped: three decay times 1/|α| of the
    slowest-decaying term, but at most twelve periods of the slowest oscillation.
    Rounded up to a round number (1, 1.5, 2, 2.5, 3, 4, 5, 6 or 8 times a power of ten).

    Examples
    --------
    >>> import laplace_springs as ls
    >>> default_t_end(ls.solve(ls.load_scene("three-dashpots")))  # the seed plots 0 to 4 s
    5.0
    """
    rates, frequencies = _rates_and_frequencies(solution)
    scale = max(1.0, float(np.max(np.hypot(rates, frequencies), initial=0.0)))
    oscillating = frequencies > 1e-9 * scale
    slowest_period = 2 * math.pi / frequencies[oscillating].min() if oscillating.any() else None
    decaying = rates < -1e-9 * scale
    if rates.size and decaying.all():
        span = 3.0 / -rates.max()
        if slowest_period is not None:
            span = min(span, 12 * slowest_period)
    elif slowest_period is not None:
        span = 4 * slowest_period
    else:
        span = 10.0
    return _nice(span)


def time_grid(solution: Motion, t_end: float | None = None, samples: int = 800) -> np.ndarray:
    """Sample times from 0 to ``t_end``: at least ``samples``, and 40 per fastest period.

    Parameters
    ----------
    solution : Motion
        A solution (any route); its poles give the default span and the fastest period.
    t_end : float, optional
        Last time; :func:`default_t_end` when omitted.
    samples : int
        Minimum number of times (at most 200 000 are returned).

    Returns
    -------
    numpy.ndarray
        Equally spaced times, from 0 to ``t_end``.

    Examples
    --------
    Example 5 oscillates at up to 33.4 rad/s, so its 5 s need more than 800 samples:

    >>> import laplace_springs as ls
    >>> times = time_grid(ls.solve(ls.load_scene("three-dashpots")))
    >>> len(times), float(times[0]), float(times[-1])
    (1065, 0.0, 5.0)
    """
    t_end = default_t_end(solution) if t_end is None else float(t_end)
    if not t_end > 0:
        raise ValueError(f"t_end must be positive, got {t_end}")
    _, frequencies = _rates_and_frequencies(solution)
    fastest = float(np.max(frequencies, initial=0.0))
    per_period = int(40 * t_end * fastest / (2 * math.pi)) + 1
    return np.linspace(0.0, t_end, min(max(samples, per_period), 200_000))


def motion(solution: Motion, times: Any) -> tuple[np.ndarray, np.ndarray]:
    """Positions and velocities at ``times`` in float64, each of shape (n, len(times)).

    Both come from ``solution.evaluate`` (velocities with ``derivative=1``), so the
    solution's error contract holds for them; no finite differences are taken.

    Examples
    --------
    >>> import laplace_springs as ls
    >>> sol = ls.solve(ls.Scene.from_matrices(M=[[1]], K=[[1]], x0=[0], v0=[1]))
    >>> x, v = motion(sol, [0.0, math.pi / 2])
    >>> np.round(x, 12).tolist(), np.round(v, 12).tolist()
    ([[0.0, 1.0]], [[1.0, 0.0]])
    """
    _check_numeric(solution.scene)
    times = np.atleast_1d(np.asarray(times, dtype=float))
    return solution.evaluate(times), solution.evaluate(times, derivative=1)


@dataclass(frozen=True)
class Energy:
    """Energies along a solution, arrays over :attr:`times`.

    Attributes
    ----------
    times : numpy.ndarray
    kinetic : numpy.ndarray
        ½ vᵀ M v.
    potential : numpy.ndarray
        ½ xᵀ K x.
    dissipated : numpy.ndarray
        ∫₀ᵗ vᵀ C v dt, the work done against the dashpots (non-decreasing).
    work : numpy.ndarray
        ∫₀ᵗ fᵀ v dt, the work done by the external forces (zeros for a free motion).
    """

    times: np.ndarray
    kinetic: np.ndarray
    potential: np.ndarray
    dissipated: np.ndarray
    work: np.ndarray

    @property
    def mechanical(self) -> np.ndarray:
        """Kinetic plus potential energy (non-increasing under damping)."""
        return self.kinetic + self.potential

    @property
    def total(self) -> np.ndarray:
        """Mechanical plus dissipated energy minus the work of the forces: the initial energy."""
        return self.mechanical + self.dissipated - self.work


_GAUSS_NODES, _GAUSS_WEIGHTS = np.polynomial.legendre.leggauss(3)


def _quadratic(matrix: np.ndarray, vectors: np.ndarray) -> np.ndarray:
    """vᵀ A v for each column v."""
    return np.einsum("it,ij,jt->t", vectors, matrix, vectors)


def energy(solution: Motion, times: Any) -> Energy:
    """Kinetic, potential and dissipated energy at ``times`` (increasing, from 0).

    A scene given in the seed's normalised form with a non-symmetric A is first
    rescaled to symmetric M, K (see :func:`laplace_springs.output.chain.physical_matrices`),
    so that the energy is the physical one up to a common factor.

    Examples
    --------
    The seed's Example 5 loses energy to its three dashpots but none goes missing:

    >>> import laplace_springs as ls
    >>> sol = ls.solve(ls.load_scene("three-dashpots"))
    >>> e = energy(sol, np.linspace(0, 4, 401))
    >>> bool(np.all(np.diff(e.mechanical) <= 1e-12))
    True
    >>> float(abs(e.total - e.total[0]).max() / e.total[0]) < 1e-9
    True
    """
    times = np.atleast_1d(np.asarray(times, dtype=float))
    if times[0] != 0 or np.any(np.diff(times) <= 0):
        raise ValueError("energy needs increasing times starting at 0")
    M, C, K = (float_matrix(m, name) for m, name in zip(physical_matrices(solution.scene), "MCK"))
    x, v = motion(solution, times)
    starts, widths = times[:-1], np.diff(times)
    nodes = (starts[:, None] + 0.5 * widths[:, None] * (1 + _GAUSS_NODES[None, :])).ravel()
    _, v_nodes = motion(solution, nodes)

    def integral(power: np.ndarray) -> np.ndarray:
        steps = 0.5 * widths * (power.reshape(len(starts), 3) @ _GAUSS_WEIGHTS)
        return np.concatenate([[0.0], np.cumsum(steps)])

    dissipated = integral(_quadratic(C, v_nodes))
    work = np.zeros_like(times)
    force = _force_values(solution.scene, nodes)
    if force is not None:
        weights = _force_weights(solution.scene)
        work = integral(np.einsum("it,ij,jt->t", force, weights, v_nodes))
    return Energy(times, 0.5 * _quadratic(M, v), 0.5 * _quadratic(K, x), dissipated, work)


def _force_weights(scene: Scene) -> np.ndarray:
    """diag(d) of :func:`physical_matrices` (the identity for a symmetric scene)."""
    M, _, _ = physical_matrices(scene)
    if M == scene.M:
        return np.eye(scene.n)
    return float_matrix(M, "M") @ np.linalg.inv(float_matrix(scene.M, "M"))


def _force_values(scene: Scene, times: np.ndarray) -> np.ndarray | None:
    """f(t) at ``times``, shape (n, len(times)); None for a free motion."""
    forcing = scene.forcing
    if forcing is None or not scene.is_forced:
        return None
    if any(entry.has(sp.DiracDelta) for entry in forcing):
        raise SceneError("energy: impulsive forces (DiracDelta) deliver their work in an instant; "
                         "the energy balance is not drawn for them")
    step = {"Heaviside": lambda value, *_: np.heaviside(value, 1.0)}
    values = np.empty((scene.n, times.size))
    for i, entry in enumerate(forcing):
        function = sp.lambdify(TIME, entry, modules=[step, "numpy"])
        values[i] = np.broadcast_to(np.asarray(function(times), dtype=float), times.shape)
    return values


# ----------------------------------------------------------------------------
# Plots
# ----------------------------------------------------------------------------


def _axes(ax: Axes | None, size: tuple[float, float] = (8.0, 4.5)) -> Axes:
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt

    return plt.subplots(figsize=size)[1]


def _legend_names(scene: Scene) -> list[str]:
    """``Mass 1: x₁(t)`` for each coordinate, as in the seed's legend ("Mass 1")."""
    return [f"Mass {i + 1}: {math_label(coordinate)[:-1]}(t)$"
            for i, coordinate in enumerate(scene.names)]


def _legend(ax: Axes) -> None:
    """The legend inside the axes, where it hides the least of the curves (outside, it was cut
    off at the edge of a subplot); beyond six entries in two columns."""
    count = len(ax.get_legend_handles_labels()[1])
    ax.legend(loc="best", framealpha=0.85, ncols=2 if count > 6 else 1,
              fontsize="small" if count > 3 else None)


def _title(ax: Axes, heading: str, scene: Scene, title: str | bool) -> None:
    if title is True:
        text = heading + (f"\n{scene.title}" if scene.title else "")
    else:
        text = title or ""
    ax.set_title(text)


def plot_motion(solution: Motion, ax: Axes | None = None, *, t_end: float | None = None,
                samples: int = 800, time_unit: str | None = None, length_unit: str | None = None,
                title: str | bool = True) -> Axes:
    """The seed's "Mass Position vs. Time" plot: x_i(t) for each mass.

    Parameters
    ----------
    solution : Motion
        A solution (any route).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; a new figure when omitted.
    t_end : float, optional
        Last time; :func:`default_t_end` when omitted.
    samples : int
        Minimum number of sample times (more for fast oscillations).
    time_unit, length_unit : str, optional
        Units in the axis labels ("Time (s)", "Position (m)"). By default those of a
        scene with units (:func:`laplace_springs.model.units.axis_label`); a scene
        without units gets none ("Time", "Position").
    title : str or bool
        True for "Mass Position vs. Time" and the scene's title.

    Returns
    -------
    matplotlib.axes.Axes

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> import laplace_springs as ls
    >>> ax = plot_motion(ls.solve(ls.load_scene("three-dashpots")), Figure().subplots())
    >>> ax.get_xlabel(), ax.get_ylabel(), [t.get_text() for t in ax.get_legend().texts]
    ('Time', 'Position', ['Mass 1: $x_{1}(t)$', 'Mass 2: $x_{2}(t)$'])
    >>> in_units = ls.Scene.from_matrices(M=[["1 kg"]], K=[["4 N/m"]], x0=["5 cm"], v0=[0])
    >>> ax = plot_motion(ls.solve(in_units), Figure().subplots())
    >>> ax.get_xlabel(), ax.get_ylabel()
    ('Time (s)', 'Position (m)')
    """
    ax = _axes(ax)
    times = time_grid(solution, t_end, samples)
    positions = solution.evaluate(times)
    for row, name in zip(positions, _legend_names(solution.scene)):
        ax.plot(times, row, linewidth=LINE_WIDTH, label=name)
    ax.axhline(0.0, color="0.6", linewidth=0.8, zorder=0)
    ax.set_xlim(times[0], times[-1])
    ax.set_xlabel(axis_label("time", solution.scene, time_unit))
    ax.set_ylabel(axis_label("position", solution.scene, length_unit))
    _legend(ax)
    ax.grid(alpha=0.3)
    _title(ax, "Mass Position vs. Time", solution.scene, title)
    return ax


def plot_phase(solution: Motion, ax: Axes | None = None, *, t_end: float | None = None,
               samples: int = 800, coordinates: Sequence[int] | None = None,
               time_unit: str | None = None, length_unit: str | None = None,
               title: str | bool = True) -> Axes:
    """Phase portraits: velocity x_i'(t) against position x_i(t), from a dot at t = 0.

    The parameters other than ``coordinates`` are those of :func:`plot_motion`.

    Parameters
    ----------
    coordinates : sequence of int, optional
        Which coordinates (0-based); all when omitted.

    Returns
    -------
    matplotlib.axes.Axes

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> import laplace_springs as ls
    >>> ax = plot_phase(ls.solve(ls.load_scene("wall-pair-dashpot")), Figure().subplots())
    >>> ax.get_xlabel(), ax.get_ylabel()
    ('Position', 'Velocity')
    """
    ax = _axes(ax, (6.0, 5.0))
    times = time_grid(solution, t_end, samples)
    x, v = motion(solution, times)
    names = _legend_names(solution.scene)
    chosen = range(solution.scene.n) if coordinates is None else coordinates
    for i in chosen:
        (line,) = ax.plot(x[i], v[i], linewidth=1.6, label=names[i])
        ax.plot(x[i, 0], v[i, 0], "o", color=line.get_color(), markersize=7)
    ax.axhline(0.0, color="0.6", linewidth=0.8, zorder=0)
    ax.axvline(0.0, color="0.6", linewidth=0.8, zorder=0)
    record = solution.scene.units
    length = length_unit or (record.length if record is not None else "m")
    velocity = None if time_unit is None and length_unit is None else f"{length}/{time_unit or 's'}"
    ax.set_xlabel(axis_label("position", solution.scene, length_unit))
    ax.set_ylabel(axis_label("velocity", solution.scene, velocity))
    _legend(ax)
    ax.grid(alpha=0.3)
    _title(ax, "Phase portrait (dot: t = 0)", solution.scene, title)
    return ax


def plot_energy(solution: Motion, ax: Axes | None = None, *, t_end: float | None = None,
                samples: int = 800, time_unit: str | None = None, energy_unit: str | None = None,
                title: str | bool = True) -> Axes:
    """Kinetic, potential and dissipated energy over time, and their constant sum.

    For a driven scene the work of the forces is drawn too, and the dashed line is the
    total minus that work (the initial energy again). The parameters are those of
    :func:`plot_motion` (``energy_unit`` labels the energy axis); the numbers are those
    of :func:`energy`.

    Returns
    -------
    matplotlib.axes.Axes

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> import laplace_springs as ls
    >>> ax = plot_energy(ls.solve(ls.load_scene("vertical-pair-damped")), Figure().subplots())
    >>> [t.get_text() for t in ax.get_legend().texts]
    ['kinetic ½vᵀMv', 'potential ½xᵀKx', 'dissipated ∫vᵀCv dt', 'total']
    """
    ax = _axes(ax)
    times = time_grid(solution, t_end, samples)
    e = energy(solution, times)
    ax.plot(times, e.kinetic, linewidth=1.4, label="kinetic ½vᵀMv")
    ax.plot(times, e.potential, linewidth=1.4, label="potential ½xᵀKx")
    ax.plot(times, e.dissipated, linewidth=LINE_WIDTH, label="dissipated ∫vᵀCv dt")
    forced = bool(np.any(e.work))
    if forced:
        ax.plot(times, e.work, linewidth=LINE_WIDTH, label="work of the forces ∫fᵀv dt")
    ax.plot(times, e.total, "k--", linewidth=LINE_WIDTH, label="total − work" if forced else "total")
    ax.set_xlim(times[0], times[-1])
    if not forced:
        ax.set_ylim(bottom=0.0)
    ax.set_xlabel(axis_label("time", solution.scene, time_unit))
    ax.set_ylabel(axis_label("energy", solution.scene, energy_unit))
    _legend(ax)
    ax.grid(alpha=0.3)
    _title(ax, "Energy", solution.scene, title)
    return ax


def _root_figure(ax: Axes) -> Figure:
    """The figure that holds ``ax``, through any subfigures (matplotlib 3.8 to 3.11)."""
    from matplotlib.figure import Figure, SubFigure

    parent = ax.get_figure()
    while isinstance(parent, SubFigure):
        parent = parent.get_figure()
    if not isinstance(parent, Figure):
        raise ValueError("the axes belong to no figure")
    return parent


def plot_frequency_response(scene: Scene, omegas: Any = None, *, force: int = 0,
                            outputs: Sequence[int] | None = None,
                            ax: tuple[Axes, Axes] | None = None) -> Figure:
    """Amplitude and phase of the response to a unit harmonic force, on log axes.

    The amplitude of coordinate i is |H(iω)[i, force]| with H(iω) = (K − ω²M + iωC)⁻¹
    (:func:`laplace_springs.analysis.frequency.frequency_response`); the phase is
    arg H in degrees, unwrapped along ω. Dashed vertical lines and dots mark the damped
    natural frequencies of the oscillatory modes (the resonance peaks).

    Parameters
    ----------
    scene : Scene
        Numeric entries.
    omegas : array_like, optional
        Positive frequencies (log axes); by default 4000 log-spaced points spanning the
        natural frequencies from a tenth of the lowest to ten times the highest.
    force : int
        The coordinate the unit force acts on (0-based).
    outputs : sequence of int, optional
        Coordinates to draw (0-based; default all).
    ax : pair of matplotlib Axes, optional
        (amplitude axes, phase axes); a new pyplot figure by default.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    SceneError
        When the scene has symbols.
    ValueError
        For a coordinate out of range, or frequencies that are not positive and finite.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> from laplace_springs.model.scene_files import load_scene
    >>> fig = plot_frequency_response(load_scene("vertical-pair-damped"))
    >>> [a.get_xscale() for a in fig.axes], [a.get_yscale() for a in fig.axes]
    (['log', 'log'], ['log', 'linear'])
    >>> [line.get_label() for line in fig.axes[0].get_lines() if line.get_label()[0] == "|"]
    ['|x1| / F', '|x2| / F']
    """
    _check_numeric(scene)
    rows = list(range(scene.n) if outputs is None else outputs)
    _check_coordinates(scene, [force, *rows])
    w, peaks = _response_frequencies(scene, omegas)
    H = _response_with_gaps(scene, w)[:, :, force]
    if ax is None:
        import matplotlib.pyplot as plt

        fig, (amp_ax, phase_ax) = plt.subplots(2, 1, sharex=True, figsize=(7, 6))
    else:
        amp_ax, phase_ax = ax
        fig = _root_figure(amp_ax)
    for i in rows:
        label = scene.names[i]
        (line,) = amp_ax.loglog(w, np.abs(H[:, i]), label=f"|{label}| / F")
        phase_ax.semilogx(w, np.degrees(np.unwrap(np.angle(H[:, i]))), color=line.get_color(),
                          label=label)
    at_peaks = np.abs(_response_with_gaps(scene, peaks)[:, rows, force])
    for peak, amplitudes in zip(peaks, at_peaks):  # resonance peaks: the damped natural frequencies
        for axis in (amp_ax, phase_ax):
            axis.axvline(peak, color="0.6", linestyle="--", linewidth=0.8)
        amp_ax.plot([peak] * len(rows), amplitudes, "o", color="0.25", markersize=4)
        amp_ax.text(peak, 0.03, f" ω = {peak:.4g}", transform=amp_ax.get_xaxis_transform(),
                    rotation=90, va="bottom", ha="right", fontsize=8, color="0.3")
    amp_ax.set_ylabel(axis_label("receptance", scene, title="amplitude per unit force"))
    phase_ax.set_ylabel("phase (degrees)")
    phase_ax.set_xlabel(axis_label("frequency", scene, title="driving frequency ω"))
    amp_ax.set_title(f"Frequency response, unit force on {scene.names[force]}")
    amp_ax.legend(loc="best", fontsize=8)
    amp_ax.grid(True, which="both", alpha=0.3)
    phase_ax.grid(True, which="both", alpha=0.3)
    return fig


def _response_with_gaps(scene: Scene, w: np.ndarray) -> np.ndarray:
    """H(iω) at the frequencies, NaN (a gap in the curve, no marker) at an undamped
    scene's natural frequencies, where the response has no finite value."""
    try:
        return frequency_response(scene, w)
    except SceneError:   # a resonance on the grid: the other frequencies one by one
        H = np.full((len(w), scene.n, scene.n), np.nan, dtype=complex)
        for k, omega in enumerate(w):
            try:
                H[k] = frequency_response(scene, [omega])[0]
            except SceneError as error:
                if "natural frequency" not in str(error):
                    raise
        return H


def overview_figure(solution: Motion, *, t_end: float | None = None) -> Figure:
    """A figure with the scene's diagram above its motion plot (the CLI's ``--plot``).

    Built on :class:`matplotlib.figure.Figure`, without pyplot, so it needs no
    display; save it with ``figure.savefig(path)``. A vertical scene's diagram goes
    beside the plot. Scenes that cannot be drawn get a note in place of the diagram.

    Parameters
    ----------
    solution : Motion
        A solution (any route).
    t_end : float, optional
        Last time of the motion plot; :func:`default_t_end` when omitted.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> import laplace_springs as ls
    >>> figure = overview_figure(ls.solve(ls.load_scene("wall-pair")))
    >>> [ax.get_title() for ax in figure.axes]
    ['Example 3: two masses between walls, three springs', 'Mass Position vs. Time']
    """
    from matplotlib.figure import Figure

    if solution.scene.layout == "vertical":  # a tall diagram beside the plot
        figure = Figure(figsize=(13.0, 6.0), layout="constrained")
        top, bottom = figure.subfigures(1, 2, squeeze=False, width_ratios=(1.0, 2.6)).ravel()
    else:
        figure = Figure(figsize=(9.0, 7.0), layout="constrained")
        top, bottom = figure.subfigures(2, 1, squeeze=False, height_ratios=(1.0, 2.2)).ravel()
    ax = top.subplots()
    try:
        draw_scene(solution.scene, ax, title=True, label_size=13)
    except SceneError as exc:
        ax.set_axis_off()
        ax.text(0.5, 0.5, f"(no diagram: {exc})", ha="center", va="center", wrap=True)
    plot_motion(solution, bottom.subplots(), t_end=t_end, title="Mass Position vs. Time")
    return figure


# ----------------------------------------------------------------------------
# Bode and pole-zero plots
# ----------------------------------------------------------------------------


def _check_matrices_numeric(scene: Scene, what: str) -> None:
    """M, C and K are numbers (initial data do not enter G(s))."""
    symbols = scene.M.free_symbols | scene.C.free_symbols | scene.K.free_symbols
    if symbols:
        names = ", ".join(sorted(symbol.name for symbol in symbols))
        raise SceneError(f"{what} needs numbers, but M, C, K have the parameters {names}; "
                         "give them values with scene.subs(...)")


def _check_coordinates(scene: Scene, indices: Sequence[int]) -> None:
    for index in indices:
        if isinstance(index, bool) or not isinstance(index, (int, np.integer)) \
                or not 0 <= index < scene.n:
            raise ValueError(f"coordinate {index!r} is out of range for a scene with {scene.n} "
                             "coordinates (0-based)")


def _response_frequencies(scene: Scene, omegas: Any) -> tuple[np.ndarray, np.ndarray]:
    """(frequencies, damped natural frequencies of the oscillatory modes).

    By default 4000 log-spaced points from a tenth of the lowest to ten times the highest
    natural frequency, with the resonance frequencies themselves added.
    """
    found = modes(scene)
    peaks = np.array(sorted(float(m.damped_frequency) for m in found if m.kind == "oscillatory"))
    if omegas is None:
        positive = [float(m.natural_frequency) for m in found if m.kind != "rigid"]
        low, high = (min(positive) / 10, max(positive) * 10) if positive else (0.01, 100)
        omegas = np.union1d(np.geomspace(low, high, 4000), peaks)
    w = np.atleast_1d(np.asarray(omegas, dtype=float))
    if w.ndim != 1 or w.size == 0 or not np.all(np.isfinite(w) & (w > 0)):
        raise ValueError("omegas must be positive and finite (they are drawn on a log axis)")
    return w, peaks


def bode_data(scene: Scene, omegas: Any = None, *, force: int = 0,
              outputs: Sequence[int] | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The numbers of :func:`plot_bode`: frequencies, magnitudes in dB, phases in degrees.

    Returns
    -------
    omegas : numpy.ndarray, shape (F,)
    magnitude_db : numpy.ndarray, shape (len(outputs), F)
        20·log10 |G(iω)[i, force]| (−inf where the entry is identically zero).
    phase_deg : numpy.ndarray, shape (len(outputs), F)
        arg G(iω)[i, force] in degrees, unwrapped along ω (so it runs continuously past
        −180°).

    Examples
    --------
    >>> from laplace_springs.model.scene import Scene
    >>> scene = Scene.from_matrices(M=[[1]], C=[["0.2"]], K=[[4]], x0=[0], v0=[0])
    >>> w, db, phase = bode_data(scene, [2.0])
    >>> round(float(db[0, 0]), 6), round(float(phase[0, 0]), 6)  # 20 log10(1/(cω)) = 20 log10 2.5
    (7.9588, -90.0)
    """
    w, _, magnitude, phase = _bode(scene, omegas, force, outputs)
    return w, magnitude, phase


def _bode(scene: Scene, omegas: Any, force: int, outputs: Sequence[int] | None
          ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Frequencies, resonance frequencies, magnitudes (dB) and phases (degrees)."""
    _check_matrices_numeric(scene, "a Bode plot")
    rows = list(range(scene.n) if outputs is None else outputs)
    _check_coordinates(scene, [force, *rows])
    w, peaks = _response_frequencies(scene, omegas)
    H = frequency_response(scene, w)[:, rows, force].T
    with np.errstate(divide="ignore"):
        magnitude = 20 * np.log10(np.abs(H))
    phase = np.degrees(np.unwrap(np.angle(H), axis=1))
    return w, peaks, magnitude, phase


def plot_bode(scene: Scene, omegas: Any = None, *, force: int = 0,
              outputs: Sequence[int] | None = None,
              ax: tuple[Axes, Axes] | None = None) -> Figure:
    """Bode plot of G(iω) = (K − ω²M + iωC)⁻¹: magnitude in dB and phase in degrees.

    One line per output coordinate i for a unit harmonic force on ``force``: the magnitude
    20·log10 |G(iω)[i, force]| in dB re 1 m/N, and the phase arg G in degrees, unwrapped
    along ω, against a log frequency axis. G(iω) comes from the exact matrices
    (:func:`laplace_springs.analysis.frequency.frequency_response`); the numbers are
    :func:`bode_data`. Dashed vertical lines mark the damped natural frequencies of the
    oscillatory modes.

    Parameters
    ----------
    scene : Scene
        Numeric M, C and K.
    omegas : array_like, optional
        Positive frequencies (rad/s); by default 4000 log-spaced points from a tenth of the
        lowest to ten times the highest natural frequency.
    force : int
        The coordinate the force acts on (0-based).
    outputs : sequence of int, optional
        Coordinates to draw (0-based; default all).
    ax : pair of matplotlib Axes, optional
        (magnitude axes, phase axes); a new pyplot figure by default.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    SceneError
        When M, C or K have symbols.
    ValueError
        For a coordinate out of range, or frequencies that are not positive and finite.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> from laplace_springs.model.scene_files import load_scene
    >>> fig = plot_bode(load_scene("three-dashpots"))
    >>> [a.get_xscale() for a in fig.axes], [a.get_ylabel() for a in fig.axes]
    (['log', 'log'], ['magnitude (dB)', 'phase (degrees)'])
    """
    w, peaks, magnitude, phase = _bode(scene, omegas, force, outputs)
    rows = list(range(scene.n) if outputs is None else outputs)
    if ax is None:
        import matplotlib.pyplot as plt

        fig, (mag_ax, phase_ax) = plt.subplots(2, 1, sharex=True, figsize=(7, 6))
    else:
        mag_ax, phase_ax = ax
        fig = _root_figure(mag_ax)
    source = scene.names[force]
    for i, db, degrees in zip(rows, magnitude, phase):
        label = f"{scene.names[i]} / f_{source}"
        (line,) = mag_ax.semilogx(w, db, label=label)
        phase_ax.semilogx(w, degrees, color=line.get_color(), label=label)
    for peak in peaks[(peaks >= w.min()) & (peaks <= w.max())]:
        for axis in (mag_ax, phase_ax):
            axis.axvline(peak, color="0.6", linestyle="--", linewidth=0.8)
    mag_ax.set_ylabel(axis_label("receptance_db", scene, title="magnitude"))
    phase_ax.set_ylabel("phase (degrees)")
    phase_ax.set_xlabel(axis_label("frequency", scene, title="frequency ω"))
    mag_ax.set_title(f"Bode plot, unit force on {source}")
    mag_ax.legend(loc="best", fontsize=8)
    for axis in (mag_ax, phase_ax):
        axis.grid(True, which="both", alpha=0.3)
    return fig


def plot_pole_zero(scene: Scene, *, force: int = 0, output: int = 0, ax: Axes | None = None) -> Figure:
    """The poles of the scene (×) and the zeros of G[output, force] (○) in the s-plane.

    The poles are the roots of Δ(s) = det(s²M + sC + K); the zeros the roots of the
    numerator adj(s)[output, force] of G[output, force] = adj/Δ. Both are computed by
    :func:`laplace_springs.analysis.interop.poles_and_zeros` from the exact polynomials
    (certified roots for rational scenes). A repeated root is marked with its
    multiplicity; a zero on a pole is a mode this pair of coordinates does not see.

    Parameters
    ----------
    scene : Scene
        Numeric M, C and K.
    force, output : int
        The coordinate the force acts on and the coordinate whose position is read (0-based).
    ax : matplotlib Axes, optional
        A new pyplot figure by default.

    Returns
    -------
    matplotlib.figure.Figure
        Its axes hold two lines labelled ``"poles"`` and ``"zeros"`` whose data are the
        real and imaginary parts.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> from laplace_springs.model.scene import Scene
    >>> scene = Scene.from_matrices(M=[[1]], C=[[2]], K=[[5]], x0=[0], v0=[0])
    >>> fig = plot_pole_zero(scene)
    >>> poles = [line for line in fig.axes[0].get_lines() if line.get_label() == "poles"][0]
    >>> poles.get_xdata().tolist(), poles.get_ydata().tolist()  # s² + 2s + 5: -1 ± 2i
    ([-1.0, -1.0], [-2.0, 2.0])
    """
    _check_matrices_numeric(scene, "a pole-zero plot")
    _check_coordinates(scene, [force, output])
    poles, zeros = poles_and_zeros(scene, force=force, output=output)
    ax = _axes(ax, (6.5, 5.5))
    fig = _root_figure(ax)
    ax.axhline(0.0, color="0.5", linewidth=0.8)
    ax.axvline(0.0, color="0.5", linewidth=0.8)
    ax.plot(poles.real, poles.imag, "x", color="C3", markersize=9, markeredgewidth=2, label="poles",
            linestyle="none")
    ax.plot(zeros.real, zeros.imag, "o", color="C0", markersize=9, markerfacecolor="none",
            markeredgewidth=1.8, label="zeros", linestyle="none")
    for points in (poles, zeros):
        values, counts = np.unique(np.round(points, 9), return_counts=True)
        for value, count in zip(values, counts):
            if count > 1:
                ax.annotate(f"{count}", (value.real, value.imag), textcoords="offset points",
                            xytext=(6, 6), fontsize=9)
    names = scene.names
    ax.set_xlabel(axis_label("rate", scene))
    ax.set_ylabel(axis_label("angular_rate", scene))
    ax.set_title(f"Poles and zeros of G[{names[output]}, {names[force]}]"
                 + (f"\n{scene.title}" if scene.title else ""))
    ax.legend(loc="best", fontsize=8)
    ax.grid(True, alpha=0.3)
    ax.margins(0.15)
    return fig
