"""Quantities users sweep for: peak amplitude, settling time, steady-state amplitude under
a harmonic force, and the force the springs and dashpots pass to the supports."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import sympy as sp

from ..exact.resolvent import resolvent
from ..model.errors import SceneError
from ..model.numbers import shown, to_exact
from ..model.scene import Scene
from ..model.supports import is_support
from ..model.symbols import lam
from .compile import compile_scene, parameter_rows
from .run import sweep

__all__ = ["peak_amplitude", "settling_time", "steady_state_amplitudes", "support_force",
           "peak_support_force"]


def _values(values: Any) -> np.ndarray:
    array = np.asarray(getattr(values, "values", values), dtype=float)
    if array.ndim < 1:
        raise SceneError(f"expected sweep values (sets, coordinates, times), got {shown(values)}")
    return array


def peak_amplitude(values: Any) -> np.ndarray:
    """max over the times of |x_i(t)|: shape (P, n) from a sweep's (P, n, T) values.

    Examples
    --------
    >>> peak_amplitude(np.array([[[0.5, -2.0, 1.0]]])).tolist()
    [[2.0]]
    """
    return np.max(np.abs(_values(values)), axis=-1)


def settling_time(values: Any, times: Any, tolerance: float) -> np.ndarray:
    """The last time at which |x_i| exceeds ``tolerance``: shape (P, n).

    0 where |x_i| never exceeds it; ``inf`` where it still does at the last time (not
    settled within the times given). Resolution is that of ``times``.

    Examples
    --------
    >>> t = np.array([0.0, 1.0, 2.0, 3.0])
    >>> settling_time(np.array([[[1.0, 0.5, 0.05, 0.01], [0.0, 0.0, 0.0, 0.2]]]), t, 0.1).tolist()
    [[1.0, inf]]
    """
    array = _values(values)
    grid = np.asarray(times, dtype=float).ravel()
    if grid.size != array.shape[-1]:
        raise SceneError(f"settling_time: {grid.size} times for values with {array.shape[-1]} times")
    if not (isinstance(tolerance, (int, float)) and tolerance >= 0):
        raise SceneError(f"settling_time: tolerance must be a nonnegative number, got {shown(tolerance)}")
    outside = np.abs(array) > tolerance
    last = grid.size - 1 - np.argmax(outside[..., ::-1], axis=-1)
    result = np.where(outside.any(axis=-1), grid[last], 0.0)
    return np.where(outside[..., -1], np.inf, result)


def steady_state_amplitudes(scene: Scene, values: Mapping[Any, Any], force: Sequence[Any],
                            omegas: Any) -> np.ndarray:
    """|(H(iω) F)_i|, the steady amplitude under F cos ωt, for every parameter set.

    H(iω) = adj(iω)/Δ(iω) with the adjugate and Δ compiled once as polynomials in λ
    whose coefficients are functions of the parameters (the exact
    :func:`laplace_springs.steady_state_amplitude`, vectorised).

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
    compiled = compile_scene(scene.with_forcing(None))
    rows = parameter_rows(compiled, values)
    P = len(rows)
    F = [to_exact(f, f"force[{j}]") for j, f in enumerate(force)] \
        if isinstance(force, Sequence) and not isinstance(force, str) else None
    if F is None or len(F) != scene.n:
        raise SceneError(f"steady_state_amplitudes: force must have {scene.n} entries, got {shown(force)}")
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
