"""Quantities users sweep for: peak amplitude, RMS, settling time, steady-state amplitude
under a harmonic force, transmissibility, modal quantities per set, and the force the
springs and dashpots pass to the supports.

The amplitude functions take a sweep's values; for sweeps too large to hold, the same
quantities are reduced chunk by chunk with ``sweep(..., quantities=[...])``
(:mod:`laplace_springs.sweeps.reduce`). The frequency-domain ones
(:func:`steady_state_amplitudes`, :func:`sweep_transmissibility`, :func:`modal_quantities`)
work on any size: batched linear solves and eigenvalue problems of the sets' matrices in
float64 (no error bound: their accuracy is that of a backward-stable solve, about
u·cond of each set's dynamic stiffness).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import sympy as sp

from ..exact.resolvent import resolvent
from ..model.errors import SceneError
from ..model.names import coordinate_index
from ..model.numbers import shown, to_exact
from ..model.scene import Scene
from ..model.supports import is_support, support_columns
from ..model.symbols import lam
from .compile import compile_refusal, compile_scene, parameter_rows
from .parameters import check_flat, parameter_sets
from .reduce import check_increasing
from .run import plan_sweep, sweep
from .validate import validate_sets

__all__ = ["peak_amplitude", "rms_amplitude", "settling_time", "steady_state_amplitudes",
           "sweep_transmissibility", "modal_quantities", "ModalQuantities", "support_force",
           "peak_support_force"]


def _values(values: Any, what: str) -> np.ndarray:
    array = np.asarray(getattr(values, "values", values), dtype=float)
    if array.ndim < 1:
        raise SceneError(f"{what}: expected sweep values (sets, coordinates, times), got "
                         f"{shown(values)}")
    if array.shape[-1] == 0:
        raise SceneError(f"{what}: expected values at one time or more, got shape {array.shape}")
    return array


def peak_amplitude(values: Any) -> np.ndarray:
    """max over the times of |x_i(t)|: shape (P, n) from a sweep's (P, n, T) values.

    Examples
    --------
    >>> peak_amplitude(np.array([[[0.5, -2.0, 1.0]]])).tolist()
    [[2.0]]
    """
    return np.max(np.abs(_values(values, "peak_amplitude")), axis=-1)


def rms_amplitude(values: Any) -> np.ndarray:
    """√(mean over the times of x_i(t)²): shape (P, n) from a sweep's (P, n, T) values (the
    discrete RMS over the times given; uniform times give the time average).

    Examples
    --------
    >>> rms_amplitude(np.array([[[3.0, -4.0, 0.0, 0.0]]])).tolist()
    [[2.5]]
    """
    array = _values(values, "rms_amplitude")
    return np.sqrt(np.mean(array**2, axis=-1))


def settling_time(values: Any, times: Any, tolerance: float) -> np.ndarray:
    """The last time at which |x_i| exceeds ``tolerance``: shape (P, n).

    0 where |x_i| never exceeds it; ``inf`` where it still does at the last time (not
    settled within the times given); NaN where a value is NaN (a set the sweep could not
    serve). Resolution is that of ``times``, which must increase.

    Examples
    --------
    >>> t = np.array([0.0, 1.0, 2.0, 3.0])
    >>> settling_time(np.array([[[1.0, 0.5, 0.05, 0.01], [0.0, 0.0, 0.0, 0.2]]]), t, 0.1).tolist()
    [[1.0, inf]]
    """
    array = _values(values, "settling_time")
    check_flat(times, "settling_time: times")
    grid = np.atleast_1d(np.asarray(times, dtype=float))
    if grid.size != array.shape[-1]:
        raise SceneError(f"settling_time: {grid.size} times for values with {array.shape[-1]} times")
    if not (isinstance(tolerance, (int, float)) and tolerance >= 0):
        raise SceneError(f"settling_time: tolerance must be a nonnegative number, got {shown(tolerance)}")
    check_increasing(grid, "settling_time")
    outside = np.abs(array) > tolerance
    last = grid.size - 1 - np.argmax(outside[..., ::-1], axis=-1)
    result = np.where(outside.any(axis=-1), grid[last], 0.0)
    result = np.where(outside[..., -1], np.inf, result)
    return np.where(np.isnan(array).any(axis=-1), np.nan, result)


def steady_state_amplitudes(scene: Scene, values: Mapping[Any, Any], force: Sequence[Any],
                            omegas: Any) -> np.ndarray:
    """|(H(iω) F)_i|, the steady amplitude under F cos ωt, for every parameter set.

    H(iω) = adj(iω)/Δ(iω) with the adjugate and Δ compiled once as polynomials in λ
    whose coefficients are functions of the parameters (the exact
    :func:`laplace_springs.steady_state_amplitude`, vectorised); beyond
    :attr:`~laplace_springs.limits.Limits.sweep_max_coordinates` coordinates, batched
    solves of (K − ω²M + iωC) X = F per set.

    Parameters
    ----------
    scene : Scene
        With declared parameters (forces and initial data do not matter).
    values : mapping
        Parameter -> values, as for :func:`laplace_springs.sweeps.sweep`.
    force : sequence
        Force amplitudes F_j, one per coordinate (numbers).
    omegas : float or array_like
        Driving frequencies: a number, a 1-D array (the same for every set) or a
        (P, W) array (per set).

    Returns
    -------
    ndarray
        (P, n) for a single frequency, else (P, n, W).

    Examples
    --------
    Textbook 1-DOF: X = F/√((k − mω²)² + (cω)²):

    >>> import laplace_springs as ls
    >>> scene = ls.Scene.from_matrices(M=[[1]], C=[["c"]], K=[["k"]], x0=[0], v0=[0],
    ...                                parameters=["c", "k"])
    >>> a = steady_state_amplitudes(scene, {"c": [0.1, 0.2], "k": [4, 4]}, [1], 2.0)
    >>> np.allclose(a[:, 0], [1 / 0.2, 1 / 0.4], rtol=1e-14)
    True
    """
    F = [to_exact(f, f"force[{j}]") for j, f in enumerate(force)] \
        if isinstance(force, Sequence) and not isinstance(force, str) else None
    if F is None or len(F) != scene.n:
        raise SceneError(f"steady_state_amplitudes: force must have {scene.n} entries, got {shown(force)}")
    if compile_refusal(scene.with_forcing(None)) is not None:  # beyond the symbolic limit
        sets, M, C, K = _matrices(scene, values)
        w, single = _frequencies(omegas, len(sets), "steady_state_amplitudes")
        drive = np.broadcast_to(np.array([float(f) for f in F], dtype=complex)[None, :, None],
                                (len(sets), scene.n, w.shape[1]))
        amplitude = np.abs(_responses(M, C, K, drive, w))
        return amplitude[..., 0] if single else amplitude
    compiled = compile_scene(scene.with_forcing(None))
    rows = parameter_rows(compiled, values)
    P = len(rows)
    R = resolvent(scene.with_forcing(None))
    columns = [sp.Poly(sp.expand(sum((R.adjugate[i, j] * F[j] for j in range(scene.n)), sp.S.Zero)),
                       lam) for i in range(scene.n)]
    width = R.determinant.degree() + 1
    exprs = list(R.determinant.all_coeffs())
    for poly in columns:
        coeffs = [] if poly.is_zero else poly.all_coeffs()
        exprs += [sp.S.Zero] * (width - len(coeffs)) + coeffs
    function = sp.lambdify(list(compiled.symbols), exprs, modules="numpy")
    table = np.empty((P, len(exprs)))
    for k, value in enumerate(function(*[rows[:, c] for c in range(rows.shape[1])])):
        table[:, k] = value
    w = np.asarray(omegas, dtype=float)
    single = w.ndim == 0
    w = np.broadcast_to(np.atleast_1d(w), (P, np.atleast_1d(w).shape[-1])) if w.ndim <= 1 else w
    if w.shape[0] != P or not np.all(np.isfinite(w)):
        raise SceneError(f"steady_state_amplitudes: omegas must be finite, one row per set; got shape {w.shape}")
    s = 1j * w  # (P, W)
    den = _horner(table[:, :width], s)
    num = np.stack([_horner(table[:, width * (i + 1):width * (i + 2)], s) for i in range(scene.n)], axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        amplitude = np.abs(num / den[:, None, :])
    return amplitude[..., 0] if single else amplitude


def _horner(coeffs: np.ndarray, z: np.ndarray) -> np.ndarray:
    value = np.zeros(z.shape, dtype=complex) + coeffs[:, :1]
    for k in range(1, coeffs.shape[1]):
        value = value * z + coeffs[:, k:k + 1]
    return value


def _support_terms(scene: Scene) -> list[tuple[str, int, sp.Expr]]:
    if not scene.components:
        raise SceneError("support_force: the scene has no components (build it with "
                         "Scene.from_components to name springs and dashpots)")
    terms = []
    for component in scene.components:
        ends = [component.a, component.b]
        supports = [end for end in ends if is_support(end)]
        if len(supports) != 1:
            continue
        mass = ends[1] if is_support(ends[0]) else ends[0]
        terms.append((component.kind, scene.mass_names.index(mass), component.value))
    if not terms:
        raise SceneError("support_force: no spring or dashpot connects a mass to a support")
    return terms


def support_force(scene: Scene, values: Mapping[Any, Any], times: Any, **options: Any) -> np.ndarray:
    """The force the springs and dashpots pass to the supports: Σ k x_m + Σ c x_m'.

    Summed over the components between a support and a mass, positive along the
    coordinates; shape (P, T). ``options`` go to :func:`laplace_springs.sweeps.sweep`
    (e.g. ``client=``).

    Examples
    --------
    >>> import laplace_springs as ls
    >>> scene = ls.Scene.from_components(masses={"m": 1}, springs={"k": ("wall", "m", "k")},
    ...                                  x0=[1], v0=[0], parameters=["k"])
    >>> f = support_force(scene, {"k": [4.0]}, [0.0, np.pi / 4])
    >>> np.allclose(f, [[4.0, 0.0]], atol=1e-14)
    True
    """
    terms = _support_terms(scene)
    compiled = compile_scene(scene)
    rows = parameter_rows(compiled, values)
    symbols = list(compiled.symbols)
    columns = [rows[:, c] for c in range(rows.shape[1])]
    x = np.asarray(sweep(scene, values, times, **options))
    needs_velocity = any(kind == "dashpot" for kind, _, _ in terms)
    v = np.asarray(sweep(scene, values, times, derivative=1, **options)) if needs_velocity else x
    total = np.zeros((rows.shape[0], x.shape[-1]))
    for kind, index, value in terms:
        coefficient = np.broadcast_to(np.asarray(sp.lambdify(symbols, value, modules="numpy")(*columns),
                                                 dtype=float), (rows.shape[0],))
        total += coefficient[:, None] * (v if kind == "dashpot" else x)[:, index, :]
    return total


def peak_support_force(scene: Scene, values: Mapping[Any, Any], times: Any, **options: Any) -> np.ndarray:
    """max over the times of |support force|: shape (P,). See :func:`support_force`.

    Examples
    --------
    >>> import laplace_springs as ls
    >>> scene = ls.Scene.from_components(masses={"m": 1}, springs={"k": ("wall", "m", "k")},
    ...                                  x0=[1], v0=[0], parameters=["k"])
    >>> peak_support_force(scene, {"k": [4.0, 9.0]}, np.linspace(0, 3, 31)).tolist()
    [4.0, 9.0]
    """
    return np.max(np.abs(support_force(scene, values, times, **options)), axis=-1)


# ----------------------------------------------------------------------------- any size


def _matrices(scene: Scene, values: Mapping[Any, Any]) -> tuple[Any, np.ndarray, np.ndarray, np.ndarray]:
    """The parameter sets (checked as ``Scene.subs`` checks them) and each set's M, C, K
    in float64, (P, n, n)."""
    plan = plan_sweep(scene)
    sets = parameter_sets(plan.names, plan.symbols, values)
    validate_sets(scene, plan.entries, sets)
    n, P = scene.n, len(sets)
    out = []
    for name in ("M", "C", "K"):
        dense = np.zeros((P, n, n))
        floats = plan.entries.floats(name, sets.rows)
        for k, (i, j) in enumerate(plan.entries.pattern[name]):
            dense[:, i, j] = floats[:, k]
        out.append(dense)
    return sets, out[0], out[1], out[2]


def _frequencies(omegas: Any, P: int, name: str) -> tuple[np.ndarray, bool]:
    w = np.asarray(omegas, dtype=float)
    single = w.ndim == 0
    w = np.broadcast_to(np.atleast_1d(w), (P, np.atleast_1d(w).shape[-1])) if w.ndim <= 1 else w
    if w.ndim != 2 or w.shape[0] != P or not np.all(np.isfinite(w)) or np.any(w < 0):
        raise SceneError(f"{name}: omegas must be finite and nonnegative: a number, a 1-D array "
                         f"or one row per set; got shape {np.shape(omegas)}")
    return w, single


def _responses(M: np.ndarray, C: np.ndarray, K: np.ndarray, drive: np.ndarray,
               omegas: np.ndarray) -> np.ndarray:
    """(K − ω²M + iωC)⁻¹·drive(ω) for every set and frequency: (P, n, W) complex.

    ``drive`` (P, n, W) complex. Solved in blocks of sets (batched LAPACK)."""
    P, n, _ = M.shape
    W = omegas.shape[1]
    out = np.empty((P, n, W), dtype=complex)
    block = max(1, int(2**24 // max(16 * n * n, 1)))
    for start in range(0, P, block):
        rows = slice(start, start + block)
        for k in range(W):
            w = omegas[rows, k][:, None, None]
            A = K[rows] - w * w * M[rows] + 1j * w * C[rows]
            with np.errstate(all="ignore"):
                out[rows, :, k] = np.linalg.solve(A, drive[rows, :, k][:, :, None])[:, :, 0]
    return out


def sweep_transmissibility(scene: Scene, values: Mapping[Any, Any], omegas: Any,
                           support: str | None = None, outputs: Sequence[Any] | None = None
                           ) -> np.ndarray:
    """|X_i(iω)/U(iω)| per parameter set: motion amplitude per unit amplitude of a
    support's harmonic motion, (K − ω²M + iωC)⁻¹(K_s + iωC_s), any scene size.

    Parameters
    ----------
    scene : Scene
        Built from components, with declared parameters.
    values : mapping
        Parameter -> values, as for :func:`laplace_springs.sweeps.sweep`.
    omegas : float or array_like
        A number, a 1-D array (every set) or (P, W) (per set), in rad/s.
    support : str, optional
        The support that moves (default: the scene's moving support, or its only one).
    outputs : sequence, optional
        Coordinates (names or indices); all by default.

    Returns
    -------
    ndarray
        (P, outputs) for a single frequency, else (P, outputs, W).

    Examples
    --------
    A mass on a spring k and dashpot c on moving ground, 1-DOF textbook:
    T = √((k² + (cω)²)/((k − ω²)² + (cω)²)).

    >>> import laplace_springs as ls
    >>> scene = ls.Scene.from_components(masses={"m": 1}, springs={"k": ("ground", "m", "k")},
    ...                                  dashpots={"c": ("ground", "m", "c")}, parameters=["k", "c"])
    >>> T = sweep_transmissibility(scene, {"k": [4.0, 9.0], "c": [0.4, 0.6]}, 1.5)
    >>> k, c, w = np.array([4.0, 9.0]), np.array([0.4, 0.6]), 1.5
    >>> bool(np.allclose(T[:, 0], np.sqrt((k**2 + (c*w)**2) / ((k - w**2)**2 + (c*w)**2)), rtol=1e-13))
    True
    """
    sets, M, C, K = _matrices(scene, values)
    P, n = len(sets), scene.n
    Ks, Cs = support_columns(scene, support)
    symbols = list(sets.symbols)
    columns = [sets.rows[:, c] for c in range(sets.rows.shape[1])]
    stiff = np.zeros((P, n))
    damp = np.zeros((P, n))
    for target, column in ((stiff, Ks), (damp, Cs)):
        for i, value in enumerate(column):
            if value != 0:
                target[:, i] = np.broadcast_to(np.asarray(
                    sp.lambdify(symbols, value, modules="numpy")(*columns), dtype=float), (P,))
    w, single = _frequencies(omegas, P, "sweep_transmissibility")
    drive = stiff[:, :, None] + 1j * w[:, None, :] * damp[:, :, None]
    chosen = list(range(n)) if outputs is None else [
        item if isinstance(item, int) else coordinate_index(
            item, "outputs", names=scene.names, mass_names=scene.mass_names)
        for item in outputs]
    amplitude = np.abs(_responses(M, C, K, drive, w))[:, chosen]
    return amplitude[..., 0] if single else amplitude


@dataclass
class ModalQuantities:
    """Modal quantities of each parameter set, modes ordered by natural frequency.

    Attributes
    ----------
    natural_frequency : ndarray
        (P, modes) ω_n = |λ| (rad/s) of each pole with Im λ ≥ 0 (an overdamped mode gives
        two real poles, each listed).
    damping_ratio : ndarray
        (P, modes) ζ = −Re λ/|λ|.
    damped_frequency : ndarray
        (P, modes) ω_d = Im λ.
    """

    natural_frequency: np.ndarray
    damping_ratio: np.ndarray
    damped_frequency: np.ndarray


def modal_quantities(scene: Scene, values: Mapping[Any, Any]) -> ModalQuantities:
    """Natural frequencies, damping ratios and damped frequencies of every parameter set:
    the eigenvalues of each set's first-order matrix [[0, I], [−M⁻¹K, −M⁻¹C]] (batched
    LAPACK, float64), any scene size with an invertible M.

    Examples
    --------
    One mass: ω_n = √k, ζ = c/(2√k).

    >>> import laplace_springs as ls
    >>> scene = ls.Scene.from_matrices(M=[[1]], C=[["c"]], K=[["k"]], x0=[1], v0=[0],
    ...                                parameters=["c", "k"])
    >>> q = modal_quantities(scene, {"k": [4.0, 9.0], "c": [0.4, 0.6]})
    >>> q.natural_frequency.round(12).tolist(), q.damping_ratio.round(12).tolist()
    ([[2.0], [3.0]], [[0.1], [0.1]])
    """
    sets, M, C, K = _matrices(scene, values)
    P, n = len(sets), scene.n
    try:
        Minv = np.linalg.inv(M)
    except np.linalg.LinAlgError:
        raise SceneError("modal_quantities: some set's M is singular (massless nodes); "
                         "use ls.modes(scene.subs(set)) for such sets") from None
    Z = np.zeros((P, 2 * n, 2 * n))
    Z[:, np.arange(n), n + np.arange(n)] = 1.0
    Z[:, n:, :n] = -Minv @ K
    Z[:, n:, n:] = -Minv @ C
    poles = np.linalg.eigvals(Z)
    scale = np.max(np.abs(poles), axis=1, keepdims=True)
    poles = np.where(np.abs(poles.imag) <= 1e-12 * scale, poles.real + 0j, poles)
    kept = poles.imag >= 0
    count = int(np.max(np.sum(kept, axis=1)))
    omega = np.where(kept, np.abs(poles), np.inf)
    order = np.argsort(omega, axis=1)[:, :count]
    chosen = np.take_along_axis(poles, order, axis=1)
    valid = np.take_along_axis(kept, order, axis=1)
    natural = np.where(valid, np.abs(chosen), np.nan)
    with np.errstate(divide="ignore", invalid="ignore"):
        zeta = np.where(valid, -chosen.real / natural, np.nan)
    return ModalQuantities(natural, zeta, np.where(valid, chosen.imag, np.nan))
