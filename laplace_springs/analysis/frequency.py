"""Frequency response H(iω) = (K − ω²M + iωC)⁻¹: exact, numeric, and steady amplitudes.

A harmonic force f(t) = F cos ωt drives a stable scene into the steady oscillation
x(t) = Re[H(iω) F e^{iωt}]: mass j moves with amplitude |(H F)_j| and phase lag
−arg (H F)_j. The exact H comes from the resolvent's adjugate, H = adj(iω)/Δ(iω).
The plot of |H| and arg H is :func:`laplace_springs.output.plots.plot_frequency_response`.

A moving support (base excitation, :mod:`laplace_springs.model.supports`) with
displacement u(t) drives the masses with K_s u + C_s u', where K_s and C_s hold the
springs and dashpots tying each mass to that support. The transmissibility is the ratio
of the masses' motion to the support's, X(λ)/U(λ) = (λ²M + λC + K)⁻¹ (K_s + λC_s)
(:func:`transmissibility_function`); its modulus on λ = iω is :func:`transmissibility`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, overload

import mpmath as mp
import numpy as np
import sympy as sp
from numpy.typing import ArrayLike

from ..exact.resolvent import resolvent
from ..kernels.dd import dd_add, dd_mul, dd_mul_float, from_exact, two_prod, two_sum
from ..kernels.precision import workdps
from ..limits import limits
from ..model.errors import LimitError, SceneError
from ..model.names import coordinate_index
from ..model.numbers import shown, to_exact
from ..model.scene import Scene
from ..model.supports import support_columns
from ..model.symbols import OMEGA, lam
from ..model.units import frequencies_to_rad_per_second
from ..numeric.first_order import float_matrix
from ..numeric.mp_expr import numeric_value
from .exact_pencil import ExactPencil

__all__ = ["omega", "frequency_response", "steady_state_amplitude", "transmissibility",
           "transmissibility_function"]

#: The driving frequency ω of exact frequency responses (rad per unit time); no parameter
#: may have its name (model/symbols.py, RESERVED_NAMES).
omega = OMEGA


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
        Driving frequencies in rad/s, or with units (``"2 Hz"`` is 4π rad/s, pint
        Quantities). Without them the exact matrix is returned as a function of the
        symbol :data:`omega`.

    Returns
    -------
    sympy.ImmutableMatrix or numpy.ndarray
        The exact n x n matrix in ``omega``; or a complex array of shape
        (len(omegas), n, n) with ``H[k, i, j]`` the response of coordinate i to a unit
        harmonic force on coordinate j at ``omegas[k]``.

    Raises
    ------
    SceneError
        At ω = 0 on a scene with a rigid-body mode (K singular), or at ω exactly a natural
        frequency of an undamped mode: the pencil is singular, the response unbounded.
    LimitError
        Where |H| is beyond the float64 range.

    Notes
    -----
    Values are within a few units of float64 rounding of max |H(iω)| (normwise). Where
    the pencil is singular at float64 precision but not exactly (near ω = 0 on a free
    scene, at a float64 number next to an undamped natural frequency) it is solved
    exactly (:mod:`laplace_springs.analysis.exact_pencil`).

    Examples
    --------
    A single mass, spring and dashpot: H = 1/(k − mω² + icω):

    >>> from laplace_springs import Scene
    >>> scene = Scene.from_matrices(M=[[1]], C=[["0.2"]], K=[[4]], x0=[0], v0=[0])
    >>> frequency_response(scene)[0, 0]
    1/(-omega**2 + I*omega/5 + 4)
    >>> float(abs(frequency_response(scene, [2.0])[0, 0, 0]))  # at resonance: 1/(cω) = 2.5
    2.5

    Two free masses joined by a spring k = 1/10 (a rigid-body mode): at ω = 1e-12,
    H₀₀ = (k − ω²)/(ω²(ω² − 2k)) ≈ −1/(2ω²):

    >>> free = Scene.from_matrices(M=[[1, 0], [0, 1]], K=[["0.1", "-0.1"], ["-0.1", "0.1"]],
    ...                            x0=[0, 0], v0=[0, 0])
    >>> float(frequency_response(free, [1e-12])[0, 0, 0].real)
    -5e+23
    """
    if omegas is None:
        R = resolvent(scene)
        at = {lam: sp.I * omega}
        delta = sp.expand(R.determinant.as_expr().xreplace(at))
        return sp.ImmutableMatrix(R.adjugate.applyfunc(lambda e: sp.expand(e.xreplace(at)) / delta))
    w = _frequencies(frequencies_to_rad_per_second(omegas), "frequency_response", scene.n * scene.n)
    eye = np.eye(scene.n, dtype=complex)
    return _solve_pencils(scene, w, scene.n, lambda part: np.broadcast_to(eye, (part.size, *eye.shape)),
                          "frequency_response")


def _check_size(count: int, per_frequency: int, caller: str) -> None:
    """Refuse more than Limits.max_evaluation_values values before any work."""
    most = limits().max_evaluation_values
    if count * per_frequency > most:
        raise LimitError(f"{caller}: {count:,} frequencies x {per_frequency:,} values each = "
                         f"{count * per_frequency:,} values, more than Limits.max_evaluation_values = "
                         f"{most:,}; give at most {max(most // per_frequency, 1):,} frequencies per call")


def _frequencies(omegas: Any, caller: str, per_frequency: int) -> np.ndarray:
    """Driving frequencies as a flat float64 array, each finite (a SceneError naming the
    first that is not, or that is not a real number); their number is held to
    Limits.max_evaluation_values / ``per_frequency`` before they are converted."""
    size = getattr(omegas, "size", None)
    if isinstance(size, (int, np.integer)):
        _check_size(int(size), per_frequency, caller)
    elif isinstance(omegas, (list, tuple)):
        _check_size(len(omegas), per_frequency, caller)
    try:
        w = np.atleast_1d(np.asarray(omegas, dtype=float))
    except (TypeError, ValueError, OverflowError):
        raise SceneError(f"{caller}: omegas must be real numbers (rad per unit time), got "
                         f"{shown(omegas)}") from None
    if w.ndim != 1:
        raise SceneError(f"{caller}: omegas must be a flat sequence of frequencies, got shape {w.shape}")
    bad = np.flatnonzero(~np.isfinite(w))
    if bad.size:
        raise SceneError(f"{caller}: omegas[{int(bad[0])}] = {float(w[bad[0]])!r} is not a finite frequency")
    return w


def _solve_pencils(scene: Scene, w: np.ndarray, columns: int,
                   rhs: Callable[[np.ndarray], np.ndarray], caller: str) -> np.ndarray:
    """(K − ω²M + iωC)⁻¹ B(ω) for each ω = w[k], in float64, with ω² never rounded;
    ``rhs(part)`` gives the n x ``columns`` right-hand sides B of the frequencies ``part``.

    Above ω = 1 the pencil is divided by s², s the power of two at or above ω (K/s² −
    (ω/s)²M + i(ω/s²)C, each exactly or in double-double), and the solution by s twice, so
    ω up to the float64 range gives finite values. The pencil is formed in double-double
    from the exact entries (near a natural frequency K − ω²M cancels: rounded ω² or
    entries would leave an error of u‖K‖ against a pencil of size ζ‖K‖), solved in
    float64 and refined with residuals summed in double-double until the correction is
    below the float64 rounding. Where refinement does not converge (the pencil is singular
    at float64 precision: near ω = 0 on a scene with a rigid-body mode, at an undamped
    natural frequency rounded to float64) the pencil is solved exactly instead
    (:class:`~laplace_springs.analysis.exact_pencil.ExactPencil`: over the rationals, or in
    certified balls for irrational entries). A pencil that is exactly singular (ω = 0 with
    a rigid-body mode, ω exactly an undamped natural frequency) is a SceneError naming the
    frequency, and a value beyond the float64 range (|H| above about 1e308, or below about
    1e-308 where the solution is not zero) a LimitError, never NaN, a silent zero or a
    value ruled by rounding. The result (frequencies x n x columns) is
    held to Limits.max_evaluation_values before any work, and the pencils are formed and
    solved in chunks of about Limits.evaluation_chunk_values numbers.
    """
    n = scene.n
    _check_size(w.size, n * columns, caller)
    parts = [_dd_matrix(getattr(scene, name), name) for name in ("M", "C", "K")]
    exact: list[ExactPencil] = []  # built the first time float64 cannot resolve a pencil

    def solve_exactly(k: float, B: np.ndarray) -> np.ndarray:
        if not exact:
            exact.append(ExactPencil(scene.M, scene.C, scene.K))
        return exact[0].solve(k, B, caller)

    out = np.empty((w.size, n, columns), dtype=complex)
    step = max(1, limits().evaluation_chunk_values // (n * max(n, columns)))
    for start in range(0, w.size, step):
        part = slice(start, start + step)
        out[part] = _solve_chunk(parts, w[part], rhs(w[part]), solve_exactly, caller)
    return out


def _dd_matrix(matrix: sp.MatrixBase, name: str) -> tuple[np.ndarray, np.ndarray]:
    """An exact numeric matrix as hi + lo float64 arrays (|error| ≤ u²|entry|)."""
    hi = float_matrix(matrix, name)  # refuses symbols and entries beyond float64
    lo = np.zeros_like(hi)
    for (i, j), entry in matrix.todok().items():
        if entry.is_Rational:
            hi[i, j], lo[i, j] = from_exact(entry)
        else:
            with workdps(40):
                hi[i, j], lo[i, j] = from_exact(mp.mpf(str(numeric_value(entry, 40))))
    return hi, lo


def _pencil(parts: list[tuple[np.ndarray, np.ndarray]], w: np.ndarray
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The scaled pencils K/s² − (ω/s)²M + i(ω/s²)C (F, n, n) as double-doubles (real hi,
    real lo, imaginary hi, imaginary lo) and the scales s (powers of two)."""
    (Mh, Ml), (Ch, Cl), (Kh, Kl) = parts
    exponent = np.where(np.abs(w) > 1, np.ceil(np.log2(np.maximum(np.abs(w), 1.0))), 0.0)
    scale = np.ldexp(1.0, exponent.astype(int))
    r = (w / scale)[:, None, None]  # exact: a power-of-two scaling
    with np.errstate(under="ignore"):
        g = ((w / scale) / scale)[:, None, None]  # ω/s², exact unless it underflows
        square, square_lo = two_prod(r, r)  # (ω/s)² exactly
        mh, ml = dd_mul(square, square_lo, Mh[None], Ml[None])
        s = scale[:, None, None]
        kh, kl = Kh[None] / s / s, Kl[None] / s / s  # exact unless it underflows
        real_h, real_l = dd_add(kh, kl, -mh, -ml)
        imag_h, imag_l = dd_mul_float(Ch[None], Cl[None], g)
    return real_h, real_l, imag_h, imag_l, scale


def _residual(B: np.ndarray, pencil: tuple[np.ndarray, ...], X: np.ndarray) -> np.ndarray:
    """B − P X (F, n, m) for double-double P = (real hi, real lo, imaginary hi, imaginary
    lo), the products error-free and the sums compensated (Ogita, Rump & Oishi's Dot2)."""
    real_h, real_l, imag_h, imag_l = pencil
    out = []
    for target, terms in ((B.real, ((real_h, real_l, X.real, -1.0), (imag_h, imag_l, X.imag, 1.0))),
                          (B.imag, ((real_h, real_l, X.imag, -1.0), (imag_h, imag_l, X.real, -1.0)))):
        total = np.array(target, dtype=float)
        err = np.zeros_like(total)
        for Ah, Al, Y, sign in terms:
            for j in range(Ah.shape[2]):
                p, e = two_prod(Ah[:, :, j, None], Y[:, None, j, :])
                total, f = two_sum(total, sign * p)
                err += f + sign * (e + Al[:, :, j, None] * Y[:, None, j, :])
        out.append(total + err)
    return out[0] + 1j * out[1]


def _solve_chunk(parts: list[tuple[np.ndarray, np.ndarray]], w: np.ndarray, rhs: np.ndarray,
                 solve_exactly: Callable[[float, np.ndarray], np.ndarray], caller: str) -> np.ndarray:
    """One chunk of :func:`_solve_pencils`."""
    real_h, real_l, imag_h, imag_l, scale = _pencil(parts, w)
    pencils = real_h + 1j * imag_h
    B = np.asarray(rhs, dtype=complex)
    unresolved = np.zeros(w.size, dtype=bool)
    try:
        scaled = np.linalg.solve(pencils, B)
    except np.linalg.LinAlgError:  # some pencil is singular in float64: solve the others
        scaled = np.zeros_like(B)
        for k in range(w.size):
            try:
                scaled[k] = np.linalg.solve(pencils[k], B[k])
            except np.linalg.LinAlgError:
                unresolved[k] = True
    scaled, stalled = _refine(pencils, (real_h, real_l, imag_h, imag_l), B, scaled, ~unresolved)
    unresolved |= stalled
    with np.errstate(under="ignore"):
        value = scaled / scale[:, None, None] / scale[:, None, None]
    largest = np.max(np.abs(value), axis=(1, 2), initial=0.0)
    lost = (largest < np.finfo(float).tiny) & np.any(scaled != 0, axis=(1, 2))  # all of it underflowed
    bad = np.flatnonzero((~np.all(np.isfinite(value), axis=(1, 2)) | lost) & ~unresolved)
    for index in np.flatnonzero(unresolved):  # in order, so the first refusal is named
        if bad.size and bad[0] < index:
            break
        value[index] = solve_exactly(float(w[index]), B[index])
    if bad.size:
        k = int(bad[0])
        raise LimitError(f"{caller}: at omega = {float(w[k])!r} the response is beyond the float64 "
                         f"range (|H| about {_magnitude(scaled[k], w[k])}); float64 values exist "
                         "only between about 1e-308 and 1e308")
    return value


def _refine(pencils: np.ndarray, pencil: tuple[np.ndarray, ...], B: np.ndarray, X: np.ndarray,
            todo_mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Iterative refinement of P X = B with double-double residuals for the pencils in
    ``todo_mask``: each step divides the error by about u·cond(P). Returns X and a mask of
    the pencils whose correction did not shrink below u‖X‖ within _REFINE_STEPS steps
    (cond(P) ≳ 1/(10u): the pencil is singular at float64 precision)."""
    size = np.max(np.abs(X), axis=(1, 2), initial=0.0)
    stalled = todo_mask & ~np.isfinite(size)  # float64 solving overflowed
    done = ~todo_mask | stalled | (size == 0)
    previous = np.full(X.shape[0], np.inf)
    for _ in range(_REFINE_STEPS):
        todo = np.flatnonzero(~done)
        if not todo.size:
            break
        residual = _residual(B[todo], tuple(p[todo] for p in pencil), X[todo])
        with np.errstate(over="ignore", invalid="ignore"):
            correction = np.linalg.solve(pencils[todo], residual)
        X[todo] = X[todo] + correction
        change = np.max(np.abs(correction), axis=(1, 2), initial=0.0)
        size = np.max(np.abs(X[todo]), axis=(1, 2), initial=0.0)
        with np.errstate(invalid="ignore"):
            stuck = ~(change <= 0.5 * previous[todo]) | ~np.isfinite(size)
        converged = change <= 4 * _U * size
        stalled[todo[stuck & ~converged]] = True
        previous[todo] = change
        done[todo] = converged | stuck
    return X, stalled | ~done


#: Refinement steps of :func:`_refine` (each gains about log10(1/(u·cond)) digits).
_REFINE_STEPS = 6
_U = 2.0**-53


def _magnitude(scaled: np.ndarray, omega: float) -> str:
    """|scaled|/ω² written as a power of ten (it need not be a float64 number)."""
    largest = float(np.max(np.abs(scaled))) if scaled.size else 0.0
    if largest == 0 or not np.isfinite(largest):
        return "not finite"
    exponent = np.log10(largest) - 2 * np.log10(max(abs(omega), 1.0))
    return f"1e{round(exponent):+d}"


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


def transmissibility_function(scene: Scene, support: str | None = None) -> sp.ImmutableMatrix:
    """X(λ)/U(λ): the transform of each mass's motion per unit motion of a support, exact.

    G(λ) = (λ²M + λC + K)⁻¹ (K_s + λC_s), with K_s and C_s the stiffness and damping tying
    each mass to the support (:func:`laplace_springs.model.supports.support_columns`).

    Parameters
    ----------
    scene : Scene
        Built from components (the supports are known by name).
    support : str, optional
        The support that moves: by default the scene's moving support
        (``support_motion``), or its only support.

    Returns
    -------
    sympy.ImmutableMatrix
        n x 1, rational functions of :data:`laplace_springs.lam`.

    Examples
    --------
    A mass on a spring and dashpot standing on the ground: G = (k + cλ)/(mλ² + cλ + k).

    >>> from laplace_springs import Scene
    >>> scene = Scene.from_components(masses={"m": "m"}, springs={"k": ("ground", "m", "k")},
    ...                               dashpots={"c": ("ground", "m", "c")}, parameters=["m", "k", "c"])
    >>> transmissibility_function(scene)[0]
    (c*lambda + k)/(c*lambda + k + lambda**2*m)
    """
    Ks, Cs = support_columns(scene, support)
    R = resolvent(scene)
    delta = R.determinant.as_expr()
    drive = sp.Matrix(Ks + lam * Cs)
    column = (R.adjugate * drive).applyfunc(lambda e: sp.cancel(sp.expand(e) / delta))
    return sp.ImmutableMatrix(column)


def _output_rows(scene: Scene, outputs: Sequence[Any] | None) -> list[int]:
    """Coordinates to report: indices (0-based), mass names or coordinate names."""
    if outputs is None:
        return list(range(scene.n))
    rows = []
    for item in outputs:
        if isinstance(item, str):
            rows.append(coordinate_index(item, "outputs", names=scene.names, mass_names=scene.mass_names))
        elif isinstance(item, (int, np.integer)) and not isinstance(item, bool) and 0 <= item < scene.n:
            rows.append(int(item))
        else:
            raise SceneError(f"outputs: {item!r} is not a coordinate (0 to {scene.n - 1}, or a name)")
    return rows


@overload
def transmissibility(scene: Scene, omegas: None = None, support: str | None = None,
                     outputs: Sequence[Any] | None = None, *, exact: bool = False
                     ) -> sp.ImmutableMatrix: ...


@overload
def transmissibility(scene: Scene, omegas: ArrayLike, support: str | None = None,
                     outputs: Sequence[Any] | None = None, *, exact: bool = False
                     ) -> np.ndarray | sp.ImmutableMatrix: ...


def transmissibility(scene: Scene, omegas: ArrayLike | None = None, support: str | None = None,
                     outputs: Sequence[Any] | None = None, *, exact: bool = False
                     ) -> sp.ImmutableMatrix | np.ndarray:
    """The transmissibility |X_i(iω)/U(iω)|: motion amplitude of each mass per unit
    amplitude of a support's harmonic motion.

    |(−ω²M + iωC + K)⁻¹ (K_s + iωC_s)|, entry by entry (see
    :func:`transmissibility_function`). For one mass on a spring k and a dashpot c it is
    the textbook T = √((1 + (2ζr)²)/((1 − r²)² + (2ζr)²)), r = ω/ωₙ, ωₙ = √(k/m),
    ζ = c/(2√(km)).

    Parameters
    ----------
    scene : Scene
        Built from components.
    omegas : array_like, optional
        Frequencies ω ≥ 0. Without them the exact transmissibility is returned as a
        function of the symbol :data:`omega`.
    support : str, optional
        The support that moves: by default the scene's moving support
        (``support_motion``), or its only support.
    outputs : sequence of int or str, optional
        Coordinates (0-based) or mass names; all by default.
    exact : bool, optional
        With ``omegas``: exact values (a SymPy matrix) instead of floats.

    Returns
    -------
    sympy.ImmutableMatrix or numpy.ndarray
        Without ``omegas``: a column (one entry per output) in ``omega``. With them: a
        float array of shape (len(omegas), len(outputs)), or with ``exact=True`` a SymPy
        matrix of that shape.

    Raises
    ------
    SceneError
        For a scene without components, an unknown support or output, symbols in a
        numeric evaluation, or a frequency where an undamped scene resonates.

    Examples
    --------
    >>> from laplace_springs import Scene
    >>> scene = Scene.from_components(masses={"m": 1}, springs={"k": ("ground", "m", 4)},
    ...                               dashpots={"c": ("ground", "m", "2/5")})
    >>> transmissibility(scene)[0]
    sqrt(4*omega**2 + 400)/sqrt(25*omega**4 - 196*omega**2 + 400)
    >>> transmissibility(scene, [3], exact=True)[0, 0]   # r = 3/2, ζ = 1/10: √(1.09/1.6525) = 2√(109/661)
    2*sqrt(72049)/661

    The textbook formula at r = 3/2, ζ = 1/10:

    >>> import math
    >>> r, zeta = 1.5, 0.1
    >>> textbook = math.sqrt((1 + (2 * zeta * r)**2) / ((1 - r**2)**2 + (2 * zeta * r)**2))
    >>> bool(abs(transmissibility(scene, [3.0])[0, 0] - textbook) < 1e-15 * textbook)
    True
    """
    rows = _output_rows(scene, outputs)
    if omegas is None or exact:
        G = transmissibility_function(scene, support)
        squares = _squared_moduli([G[i] for i in rows])
        if omegas is None:
            return sp.ImmutableMatrix([sp.sqrt(P) / sp.sqrt(Q) for P, Q in squares])
        table = []
        for k, value in enumerate(np.atleast_1d(np.asarray(omegas, dtype=object))):
            w = to_exact(value, f"omegas[{k}]")
            row = []
            for P, Q in squares:
                denominator = sp.expand(Q.xreplace({omega: w}))
                if denominator == 0:
                    raise SceneError(f"omega = {w} is a natural frequency of an undamped scene: "
                                     "the response grows without bound (resonance)")
                row.append(sp.sqrt(sp.cancel(sp.expand(P.xreplace({omega: w})) / denominator)))
            table.append(row)
        return sp.ImmutableMatrix(table)
    w = _frequencies(frequencies_to_rad_per_second(omegas), "transmissibility", scene.n)  # "2 Hz" is 4π rad/s
    Ks, Cs = (float_matrix(column, name).ravel() for column, name in
              zip(support_columns(scene, support), ("K_s", "C_s")))
    def drives(part: np.ndarray) -> np.ndarray:
        return (Ks[None, :] + 1j * part[:, None] * Cs[None, :])[:, :, None]

    X = _solve_pencils(scene, w, 1, drives, "transmissibility")[:, :, 0]
    return np.abs(X[:, rows])


def _squared_moduli(ratios: Sequence[sp.Expr]) -> list[tuple[sp.Expr, sp.Expr]]:
    """|G(iω)|² = P(iω)P(−iω) / (Q(iω)Q(−iω)) for real rational G = P/Q, as (numerator,
    denominator) polynomials in ω."""
    out = []
    for ratio in ratios:
        P, Q = sp.fraction(sp.cancel(ratio))
        squares = [sp.expand(F.xreplace({lam: sp.I * omega}) * F.xreplace({lam: -sp.I * omega}))
                   for F in (P, Q)]
        out.append((squares[0], squares[1]))
    return out
