"""Vectorised evaluation of x(t) = Σ residues of N(λ) e^{λt}/D(λ) for many parameter sets.

For each set the roots of D come from the eigenvalues of its companion matrix (one
batched LAPACK call for the whole chunk) and are polished by Newton's method on the
exact-coefficient polynomial. Roots farther than :attr:`~laplace_springs.limits.Limits.cluster_gap` · ρ (ρ the largest
modulus of a root) from all others are *isolated*: their residue N(r)/D'(r), with D'(r) as the
product lead · Π(r − r_k), gives the term N(r)/D'(r) · e^{rt}; a complex pair is summed
as 2·Re of one of its roots. Closer roots form a *cluster* (critical damping, an
exceptional point, a forcing frequency at a natural frequency), and the residue formula
would lose digits as 1/separation. A cluster G = {z_0, ..., z_{m-1}} contributes the
divided difference of N(λ) e^{λt}/Q(λ) over G, Q = lead · Π_{k∉G}(λ − r_k), which by
Leibniz's rule is Σ_k g[z_0..z_k] · (e^{λt})[z_k..z_{m-1}] with g = N/Q. Both kinds of
divided difference are read off functions of the bidiagonal matrix T = diag(z) +
superdiagonal(1) (Opitz): g(T) from a matrix Horner scheme and one triangular solve;
exp(tT) from a Taylor series with scaling and squaring after shifting by the cluster's
centre. No difference of nearly equal numbers is formed, so exactly repeated roots need
no special case and nearly repeated ones lose nothing.

Each value comes with an error estimate: first order in the rounding errors, each of
them bounded in the worst case (the coefficients' own rounding, counted from their
expressions; Horner's bound for evaluating D and N_i; the Newton step, D'(r), the
exponentials and the sum), so an estimate that stays above the true error (the tests
check it against 40-digit evaluations, near-critical sets included) but not a rigorous
bound. The coefficients may come in extended precision (``numpy.longdouble``, see
:meth:`~laplace_springs.sweeps.compile.CompiledScene.coefficients_extended`). On sets whose
roots are all isolated the last Newton step uses residuals evaluated in extended
precision, and N_i(r_j) is too, and each root error δr_j enters
through ∂x/∂r_j(t). The cheap estimate bounds ∂x/∂r_j term by term; a set it rejects
gets the refined one (``refine=True``: ∂x/∂r_j summed as a complex number, so the 1/gap
terms of a close pair cancel, and the coefficients' rounding propagated as a
perturbation of the polynomials); sets whose estimate still misses the target are
recomputed by the exact solver.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..kernels.poles import cluster_labels
from ..limits import limits

__all__ = ["Block", "evaluate_block", "polynomial_roots"]

#: Unit roundoff of float64.
UNIT = 2.0**-53
#: Unit roundoff of numpy.longdouble (float64's on platforms without extended precision).
UNIT_EXTENDED = float(np.finfo(np.longdouble).eps) / 2
#: Terms of the Taylor series of exp on a matrix of 1-norm ≤ 1/2 (1/2^18/18! < 1e-21).
_TAYLOR_TERMS = 18
#: Newton steps on each isolated root.
_NEWTON_STEPS = 2
#: Absolute error, per unit of a term's coefficient, of an exponential that underflows
#: (e^{rt} below 2^-1022 is subnormal or 0: its error, and that of the products and sums
#: it enters, is up to 2^-1074 each, not relative to the value): 1e-300 covers it with room
#: (x = (1 + t)e^{-t} at t = 1e4 is 0 in float64; a bound of 0 there claims an exact 0).
_UNDERFLOW = 1e-300


@dataclass
class Block:
    """Values of one chunk of parameter sets.

    Attributes
    ----------
    values : ndarray
        (P, n, T) float64.
    error : ndarray
        (P, n, T) error estimates.
    roots : ndarray
        (P, N) complex roots of D.
    suspect : ndarray
        (P,) bool: a root or value is not finite, or the leading coefficient vanishes.
    """

    values: np.ndarray
    error: np.ndarray
    roots: np.ndarray
    suspect: np.ndarray


def _horner(coeffs: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Polynomials (..., K+1), highest first, at points (..., R) -> (..., R)."""
    value = np.broadcast_to(coeffs[..., :1], z.shape).astype(z.dtype)
    for k in range(1, coeffs.shape[-1]):
        value = value * z + coeffs[..., k:k + 1]
    return value


def _horner_derivative(coeffs: np.ndarray, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    value = np.broadcast_to(coeffs[..., :1], z.shape).astype(z.dtype)
    slope = np.zeros_like(value)
    for k in range(1, coeffs.shape[-1]):
        slope = slope * z + value
        value = value * z + coeffs[..., k:k + 1]
    return value, slope


def polynomial_roots(den: np.ndarray) -> np.ndarray:
    """Roots of the polynomials ``den`` (P, N+1), highest first: companion eigenvalues.

    Examples
    --------
    >>> np.sort_complex(polynomial_roots(np.array([[1.0, 0.0, -4.0]]))[0]).round(12).tolist()
    [(-2+0j), (2+0j)]
    """
    P, width = den.shape
    N = width - 1
    companion = np.zeros((P, N, N))
    with np.errstate(divide="ignore", invalid="ignore"):
        companion[:, 0, :] = -den[:, 1:] / den[:, :1]
    companion[:, np.arange(1, N), np.arange(N - 1)] = 1.0
    finite = np.all(np.isfinite(companion.reshape(P, -1)), axis=1)
    companion[~finite] = 0.0
    roots = np.linalg.eigvals(companion).astype(complex)
    roots[~finite] = np.nan
    return roots


def _clusters(roots: np.ndarray, radius: np.ndarray) -> np.ndarray:
    """Cluster labels (P, N) by the package's close-poles rule (kernels/poles.py) with the
    gap Limits.cluster_gap · radius."""
    return cluster_labels(roots, limits().cluster_gap * radius)


def _polish(den: np.ndarray, roots: np.ndarray, isolated: np.ndarray,
            gap: np.ndarray) -> np.ndarray:
    """Newton steps on the isolated roots, each kept only if it is small and helps."""
    roots = roots.copy()
    for _ in range(_NEWTON_STEPS):
        value, slope = _horner_derivative(den, roots)
        with np.errstate(divide="ignore", invalid="ignore"):
            step = value / slope
        moved = roots - step
        better = np.abs(_horner(den, moved)) <= np.abs(value)
        ok = isolated & np.isfinite(step) & (np.abs(step) < 0.25 * gap) & better
        roots = np.where(ok, moved, roots)
    return roots


def _expm_shifted(A: np.ndarray) -> np.ndarray:
    """exp of small matrices (..., m, m): Taylor series with scaling and squaring."""
    m = A.shape[-1]
    norm = float(np.max(np.sum(np.abs(A), axis=-2))) if A.size else 0.0
    squarings = max(0, int(np.ceil(np.log2(norm))) + 1) if norm > 0.5 else 0
    X = A / 2.0**squarings
    eye = np.broadcast_to(np.eye(m, dtype=complex), A.shape)
    term = eye.copy()
    total = eye.copy()
    for k in range(1, _TAYLOR_TERMS + 1):
        term = term @ X / k
        total = total + term
    with np.errstate(over="ignore", invalid="ignore"):  # inf/NaN: the caller's bound is inf
        for _ in range(squarings):
            total = total @ total
    return total


def _cluster_terms(z: np.ndarray, others: np.ndarray, lead: np.ndarray, num: np.ndarray,
                   num_abs: np.ndarray, den_abs: np.ndarray, times: np.ndarray, N: int
                   ) -> tuple[np.ndarray, np.ndarray]:
    """Contribution (B, n, T) of clusters z (B, m) and its error estimate.

    ``others`` (B, N-m) are the other roots, ``num`` (B, n, K) the numerators (highest
    first), ``num_abs``/``den_abs`` their absolute-coefficient bounds.
    """
    B, m = z.shape
    n = num.shape[1]
    T = np.zeros((B, m, m), dtype=complex)
    T[:, np.arange(m), np.arange(m)] = z
    T[:, np.arange(m - 1), np.arange(1, m)] = 1.0
    eye = np.eye(m, dtype=complex)
    # g(T) = N(T) Q(T)^{-1}, first row: g[z_0..z_k]
    Q = lead[:, None, None] * np.broadcast_to(eye, T.shape)
    for j in range(others.shape[1]):
        Q = Q @ (T - others[:, j, None, None] * eye)
    NT = np.broadcast_to(num[:, :, :1, None] * eye, (B, n, m, m)).astype(complex)
    for k in range(1, num.shape[2]):
        NT = NT @ T[:, None] + num[:, :, k, None, None] * eye
    rows = NT[:, :, 0, :]  # (B, n, m)
    QT = np.swapaxes(Q, -1, -2)
    G = np.linalg.solve(QT[:, None], rows[..., None])[..., 0]  # (B, n, m)
    # (e^{λt})[z_k..z_{m-1}] = t^{m-1-k} e^{μt} exp(t diag(z-μ) + superdiag)[k, m-1]
    mu = np.mean(z, axis=1)
    A = np.zeros((B, times.size, m, m), dtype=complex)
    A[:, :, np.arange(m), np.arange(m)] = times[None, :, None] * (z - mu[:, None])[:, None, :]
    A[:, :, np.arange(m - 1), np.arange(1, m)] = 1.0
    E = _expm_shifted(A)[..., :, m - 1]  # (B, T, m)
    powers = times[None, :, None] ** (m - 1 - np.arange(m))[None, None, :]
    H = np.exp(mu[:, None] * times[None, :])[:, :, None] * powers * E  # (B, T, m)
    value = np.einsum("bik,btk->bit", G, H)
    # error estimate
    size = np.einsum("bik,btk->bit", np.abs(G), np.abs(H))
    centre = np.abs(mu)
    dist = np.min(np.abs(mu[:, None] - others), axis=1) if others.shape[1] else np.full(B, np.inf)
    Qmu = np.abs(lead) * np.prod(np.abs(mu[:, None] - others), axis=1)
    num_bound = _horner(num_abs, np.broadcast_to(centre[:, None, None], (B, n, 1)))[..., 0]
    den_bound = _horner(den_abs[:, None, :], centre[:, None, None])[:, 0, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        shift = UNIT * den_bound / Qmu  # change of the cluster's factor
        reach = times[None, :] + (m + 1) / np.where(np.isfinite(dist), dist, np.inf)[:, None]
        scale_k = np.where(np.isfinite(dist), 1 / dist, 0.0)[:, None] ** np.arange(m)[None, :]
        numer = UNIT * (num_bound / Qmu[:, None])[:, :, None] \
            * np.einsum("bk,btk->bt", scale_k, np.abs(H))[:, None, :]
        # the rounding of N(T)'s first row (Horner on T): its k-th entry, a divided
        # difference of N, is off by about γ·c_k with c_k the k-th Taylor coefficient of
        # |N| at the cluster's radius, carried through Q(T)⁻¹ (first row ≲ s^j/|Q(μ)|); an
        # absolute term that does not vanish where N(T) cancels (x' of a near-critical
        # pair at t = 0: every root is in the cluster, so no other root's distance counts)
        radius = centre + np.max(np.abs(z - mu[:, None]), axis=1)
        spread = _divided_rounding(num_abs, radius, scale_k[:, 1] if m > 1 else None, (B, n, m))
        numer = numer + 4 * UNIT / Qmu[:, None, None] \
            * np.einsum("bik,btk->bit", spread, np.abs(H))
    error = UNIT * (2 * N + 4) * size * (1 + centre[:, None, None] * times[None, None, :]) \
        + size * (shift[:, None] * reach ** m)[:, None, :] + numer \
        + _UNDERFLOW * np.einsum("bik,btk->bit", np.abs(G), np.abs(powers * E))
    return value, np.where(np.isfinite(error), error, np.inf)


def _divided_rounding(num_abs: np.ndarray, radius: np.ndarray, s: np.ndarray | None,
                      shape: tuple[int, int, int]) -> np.ndarray:
    """Σ_{j≤k} c_j·s^{k−j} (shape (B, n, m)): c_j the Taylor coefficients of |N| (absolute
    coefficients ``num_abs``, highest first) at ``radius`` (B,), by repeated synthetic
    division; s (B,) the reciprocal distance to the other roots (None: one root)."""
    B, n, m = shape
    coeffs = np.broadcast_to(num_abs, (B, n, num_abs.shape[-1])).astype(float)
    r = radius[:, None, None]
    taylor = np.zeros((B, n, m))   # c_0 is counted by the caller's term (at the centre)
    for k in range(m):
        if coeffs.shape[-1] == 0:
            break
        partial = np.empty_like(coeffs)
        partial[..., 0] = coeffs[..., 0]
        for i in range(1, coeffs.shape[-1]):
            partial[..., i] = coeffs[..., i] + r[..., 0] * partial[..., i - 1]
        taylor[..., k] = partial[..., -1]
        coeffs = partial[..., :-1]
    taylor[..., 0] = 0.0
    out = taylor.copy()
    if s is not None:
        for k in range(1, m):
            out[..., k] = taylor[..., k] + s[:, None] * out[..., k - 1]
    return out


def evaluate_block(den: np.ndarray, num: np.ndarray, den_abs: np.ndarray, num_abs: np.ndarray,
                   times: np.ndarray, derivative: int = 0, *,
                   coefficient_error: tuple[np.ndarray, np.ndarray] | None = None,
                   refine: bool = False,
                   extended: tuple[np.ndarray, np.ndarray] | None = None) -> Block:
    """x_i(t) (or its derivative) for a block of parameter sets.

    Parameters
    ----------
    den : ndarray
        (P, N+1) coefficients of D(λ), highest first.
    num : ndarray
        (P, n, N) coefficients of the numerators N_i(λ), highest first.
    den_abs, num_abs : ndarray
        Absolute-coefficient bounds of the same shapes.
    times : ndarray
        (T,) nonnegative times.
    derivative : int
        0, 1 or 2: the numerators are multiplied by λ^derivative.
    coefficient_error : tuple of ndarray, optional
        Bounds (P, N+1) and (P, n, N) on the rounding errors of the coefficients
        themselves (default: two units in the last place of the absolute bounds).
    refine : bool
        Sum each ∂x/∂r_j(t) as a complex number before taking its modulus: a tighter
        estimate for sets with close roots (more work per set).
    extended : tuple of ndarray, optional
        The same coefficients in ``numpy.longdouble`` (``den`` and ``num`` being them
        rounded to float64); ``coefficient_error`` then bounds their errors. The last
        Newton step and N(r) use them.

    Returns
    -------
    Block

    Examples
    --------
    x'' + 2x' + x = 0, x(0) = 1, x'(0) = 0 (critical damping): x = (1 + t) e^{-t}.

    >>> den = np.array([[1.0, 2.0, 1.0]])
    >>> num = np.array([[[1.0, 2.0]]])
    >>> block = evaluate_block(den, num, den, num, np.array([0.0, 1.0]))
    >>> np.allclose(block.values[0, 0], [1.0, 2 * np.exp(-1)], rtol=1e-15, atol=0)
    True
    """
    P, width = den.shape
    N = width - 1
    n = num.shape[1]
    if derivative:
        pad = np.zeros((P, n, derivative))
        num = np.concatenate([num, pad], axis=2)
        num_abs = np.concatenate([num_abs, pad], axis=2)
    lead = den[:, 0]
    den_scale = np.max(np.abs(den), axis=1)
    suspect = ~(np.abs(lead) > 1e-12 * den_scale) | ~np.all(np.isfinite(den), axis=1) \
        | ~np.all(np.isfinite(num.reshape(P, -1)), axis=1)
    safe_den = np.where(suspect[:, None], _placeholder(N)[None, :], den)
    safe_num = np.where(suspect[:, None, None], 0.0, num)
    roots = polynomial_roots(safe_den)
    radius = np.max(np.abs(roots), axis=1)
    radius = np.where(radius > 0, radius, 1.0)
    labels = _clusters(roots, radius)
    counts = np.sum(labels[:, :, None] == labels[:, None, :], axis=2)
    isolated = counts == 1
    diff = roots[:, :, None] - roots[:, None, :]
    distance = np.abs(diff)
    distance[:, np.arange(N), np.arange(N)] = np.inf
    ordered = np.sort(distance, axis=2)
    gap = ordered[:, :, 0] if N > 1 else np.full((P, N), np.inf)
    second = ordered[:, :, 1] if N > 2 else np.full((P, N), np.inf)
    roots = _polish(safe_den, roots, isolated, gap)
    values = np.zeros((P, n, times.size))
    error = np.zeros((P, n, times.size))
    if coefficient_error is None:
        den_err, num_err = 2 * UNIT * den_abs, 2 * UNIT * num_abs
    else:
        den_err, num_err = coefficient_error
        if derivative:
            num_err = np.concatenate([num_err, np.zeros((P, n, derivative))], axis=2)
    if extended is None:
        den_x, num_x = safe_den, safe_num
    else:
        den_x, num_x = extended
        if derivative:
            num_x = np.concatenate([num_x, np.zeros((P, n, derivative), dtype=num_x.dtype)], axis=2)
    plain = isolated.all(axis=1) & ~suspect
    if plain.any():
        chosen = np.flatnonzero(plain)
        v, e, r = _isolated_terms(roots[chosen], lead[chosen], safe_num[chosen], num_abs[chosen],
                                  den_x[chosen], num_x[chosen], den_abs[chosen], den_err[chosen],
                                  num_err[chosen], times, refine)
        values[chosen], error[chosen], roots[chosen] = v, e, r
    if not plain.all():
        # the older estimates of sets with clusters take bounds on evaluating D and N_i
        # (linear, worst case) plus the coefficients' own rounding, in units of UNIT
        rounded = 0.0 if extended is None else 1.0  # float64 copies of extended ones
        den_abs = (3.3 * N + 1 + rounded) * den_abs + den_err / UNIT
        num_abs = (3.3 * N + 1 + rounded) * num_abs + num_err / UNIT
        rest = np.flatnonzero(~plain)
        v, e = _general_terms(roots[rest], lead[rest], safe_num[rest], num_abs[rest], den_abs[rest],
                              isolated[rest], gap[rest], second[rest], radius[rest], times)
        values[rest], error[rest] = v, e
        _add_clusters(values, error, roots, labels, isolated, suspect, lead, safe_num, num_abs,
                      den_abs, times)
    bad = suspect | ~np.all(np.isfinite(values.reshape(P, -1)), axis=1) \
        | ~np.all(np.isfinite(roots), axis=1)
    error[~np.isfinite(error)] = np.inf
    error[bad] = np.inf
    return Block(values, error, roots, bad)


def _horner_extended(coeffs: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Polynomials (..., K+1) at points (..., R) in ``numpy.longdouble`` arithmetic."""
    point = z.astype(np.clongdouble)
    value = np.broadcast_to(coeffs[..., :1].astype(np.longdouble), z.shape).astype(np.clongdouble)
    for k in range(1, coeffs.shape[-1]):
        value = value * point + coeffs[..., k:k + 1].astype(np.longdouble)
    return value


def _isolated_terms(roots: np.ndarray, lead: np.ndarray, num: np.ndarray, num_abs: np.ndarray,
                    den_x: np.ndarray, num_x: np.ndarray, den_abs: np.ndarray, den_err: np.ndarray,
                    num_err: np.ndarray, times: np.ndarray, refine: bool
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Values and error estimates (B, n, T) of sets whose roots are all isolated, and the
    roots after a last Newton step.

    The last Newton step uses residuals D(r̂_j) evaluated in extended precision
    (``numpy.longdouble``), so a root is left with the error of its final rounding and of
    the coefficients of D themselves, not of evaluating D in float64. Only one root of each
    conjugate pair (and the real roots) is exponentiated. The error estimate is first
    order in the root errors δr_j, times |∂x/∂r_j(t)| with

        ∂x/∂r_j = e^{r_j t} (ρ_j t + N'(r_j)/D'(r_j) + ρ_j Σ_{k≠j} 1/(r_k − r_j))
                  + Σ_{k≠j} ρ_k e^{r_k t}/(r_k − r_j)

    (ρ_j = N(r_j)/D'(r_j)); plus the rounding of N(r_j) (in extended precision) and of
    the coefficients, of D'(r_j), the exponentials and the sum. Without ``refine``
    |∂x/∂r_j| is bounded term by term (cheap: two real products with |e^{r_k t}|, but the
    1/gap terms of a close pair, which cancel, are each counted); with ``refine`` it is
    summed as a complex number first, so they cancel as they do in x itself.
    """
    B, N = roots.shape
    n = num.shape[1]
    T = times.size
    eye = np.arange(N)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        diff = roots[:, :, None] - roots[:, None, :]  # r_j - r_k
        diff[:, eye, eye] = 1.0
        dprime = lead[:, None] * np.prod(diff, axis=2)  # (B, N)
        step = (_horner_extended(den_x, roots) / dprime).astype(complex)
        polished = (roots.astype(np.clongdouble) - step).astype(complex)
        # keep real roots real and conjugate pairs exact conjugates (D'(r_j) as a product
        # of differences is not computed symmetrically)
        partner = np.argmin(np.abs(np.conj(roots)[:, :, None] - roots[:, None, :]), axis=2)
        polished = np.where(roots.imag == 0, polished.real + 0j,
                            np.where(roots.imag > 0, polished,
                                     np.conj(np.take_along_axis(polished, partner, axis=1))))
        step = np.abs(polished - roots)
        near = np.sum(1.0 / np.abs(diff), axis=2) - 1.0  # Σ_{k≠j} 1/|r_j − r_k|
        roots = polished
        diff = roots[:, :, None] - roots[:, None, :]
        diff[:, eye, eye] = 1.0
        dprime = lead[:, None] * np.prod(diff, axis=2)
        inverse = -1.0 / diff  # 1/(r_k - r_j)
        inverse[:, eye, eye] = 0.0
        modulus = np.abs(roots)
        # δr_j: final rounding, the Newton step's own error and evaluating D in extended
        # precision; the rounding of D's coefficients moves the roots by a further
        # |Σ_k δc_k r_j^{N-k}| / |D'(r_j)|
        extended = (3.3 * N + 1) * UNIT_EXTENDED
        delta = UNIT * modulus + step * (3.3 * N * UNIT + step * near) \
            + extended * _horner(den_abs, modulus) / np.abs(dprime)
        at = np.broadcast_to(roots[:, None, :], (B, n, N))
        numer = _horner_extended(num_x, at)
        _, slope = _horner_derivative(num, at)
        if refine:  # ρ_j in extended precision, rounded once
            wide = roots.astype(np.clongdouble)
            gaps = wide[:, :, None] - wide[:, None, :]
            gaps[:, eye, eye] = 1.0
            rho = (numer / (den_x[:, :1].astype(np.longdouble) * np.prod(gaps, axis=2))[:, None, :]
                   ).astype(complex)
            rounding = 4.0 + 3.0 * N  # ρ_j, e^{r_j t} and ρ_j e^{r_j t}, the sum of ≤ 2N terms
        else:
            rho = numer.astype(complex) / dprime[:, None, :]  # (B, n, N)
            rounding = 4.3 * N + 8.0  # also D'(r_j) and the division
        alpha = slope / dprime[:, None, :] + rho * np.sum(inverse, axis=2)[:, None, :]
        beta = rho[:, :, None, :] * inverse[:, None, :, :]  # (B, n, j, k)
        big = np.broadcast_to(modulus[:, None, :], (B, n, N))
        numer_error = extended * _horner(num_abs, big)
        size = np.abs(rho)
        # rounding of N(r_j), of D'(r_j) and ρ_j, of e^{r_j t} and of the sum
        constant = numer_error / np.abs(dprime)[:, None, :] + size * UNIT * rounding
        linear = size * UNIT * modulus[:, None, :]  # the rounding of r_j t
        if not refine:  # Σ_j δr_j |∂x/∂r_j| term by term; conjugates have equal terms
            delta = delta + _horner(den_err, modulus) / np.abs(dprime)
            constant = constant + _horner(num_err, big) / np.abs(dprime)[:, None, :] \
                + delta[:, None, :] * np.abs(alpha) + np.einsum("bj,bijk->bik", delta, np.abs(beta))
            linear = linear + delta[:, None, :] * size
    keep = roots.imag >= 0
    pairs = np.sum(roots.imag > 0, axis=1)
    count = np.sum(keep, axis=1)
    weight = np.where(roots.imag > 0, 2.0, 1.0)
    # kept roots first: one of each complex pair, then the real roots
    rank = np.where(roots.imag > 0, 0, np.where(roots.imag == 0, 1, 2))
    values = np.empty((B, n, T))
    error = np.empty((B, n, T))
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        for code in np.unique(pairs * (N + 1) + count):
            sets = np.flatnonzero(pairs * (N + 1) + count == code)
            S = sets.size
            C, K = divmod(int(code), N + 1)  # C complex pairs, K - C real roots
            columns = np.argsort(rank[sets], axis=1, kind="stable")[:, :K]
            r = np.take_along_axis(roots[sets], columns, axis=1)  # (S, K)
            w = np.take_along_axis(weight[sets], columns, axis=1)
            pick = np.broadcast_to(columns[:, None, :], (S, n, K))
            rho_k = np.take_along_axis(rho[sets], pick, axis=2)  # (S, n, K)
            weighted = w[:, None, :] * rho_k
            # complex roots: e^{rt} and |e^{rt}|; real roots: one real exponential
            exps = np.exp(r[:, :C, None] * times)  # (S, C, T)
            magnitude = np.exp(r.real[:, :, None] * times)  # (S, K, T); e^{rt} of the real roots
            real = magnitude[:, C:]
            values[sets] = np.matmul(np.ascontiguousarray(weighted[..., :C]), exps).real \
                + np.matmul(np.ascontiguousarray(weighted[..., C:].real), real)
            err = np.matmul(w[:, None, :] * np.take_along_axis(constant[sets], pick, axis=2), magnitude) \
                + np.matmul(w[:, None, :] * np.take_along_axis(linear[sets], pick, axis=2), magnitude) * times \
                + _UNDERFLOW * np.sum(np.abs(weighted), axis=2)[:, :, None]
            if not refine:
                error[sets] = err
                continue
            # ∂x_i/∂r_j (t) for the kept roots j: the sum over all roots k, a conjugate
            # root's exponential being the conjugate of its partner's
            all_roots = roots[sets]
            partner = np.where(keep[sets][:, :, None],
                               all_roots[:, :, None] == r[:, None, :],
                               np.conj(all_roots)[:, :, None] == r[:, None, :]).astype(float)
            own = keep[sets][:, :, None] * partner  # (S, N, K): root k is kept root q
            other = partner - own  # root k is the conjugate of kept root q
            er = np.concatenate([exps.real, real], axis=1)
            ei = np.concatenate([exps.imag, np.zeros_like(real)], axis=1)
            b = np.take_along_axis(beta[sets], columns[:, None, :, None], axis=2)  # (S, n, K, N)
            b = b.reshape(S, n * K, N)
            plus = np.matmul(b, own + other)  # (S, nK, K) complex: coefficient of Re e
            minus = np.matmul(b, own - other)  # coefficient of i·Im e
            gr = np.matmul(plus.real, er) - np.matmul(minus.imag, ei)
            gi = np.matmul(plus.imag, er) + np.matmul(minus.real, ei)
            factor = rho_k[..., None] * times + np.take_along_axis(alpha[sets], pick, axis=2)[..., None]
            gr = gr.reshape(S, n, K, T) + er[:, None] * factor.real - ei[:, None] * factor.imag
            gi = gi.reshape(S, n, K, T) + er[:, None] * factor.imag + ei[:, None] * factor.real
            d = w * np.take_along_axis(delta[sets], columns, axis=1)  # (S, K)
            err += np.einsum("sk,sikt->sit", d, np.hypot(gr, gi))
            # the coefficients' rounding δc_k, δn_ik as perturbations of the polynomials:
            # ∂x/∂c_k = −Σ_j ∂x/∂r_j r_j^{N-k}/D'(r_j) and ∂x_i/∂n_ik = Σ_j r_j^p e^{r_j t}/D'(r_j),
            # summed over the roots before the modulus (no 1/gap of a close pair is left)
            width = max(N + 1, num.shape[2])
            powers = r[:, :, None] ** np.arange(width)[::-1][None, None, :]  # (S, K, width)
            scaled = w[:, :, None] * powers / np.take_along_axis(dprime[sets], columns, axis=1)[:, :, None]
            tail = scaled[:, :, width - N - 1:]  # r_j^{N-k}/D'(r_j), k = 0..N
            H = np.einsum("sijt,sjk->sikt", gr, tail.real) - np.einsum("sijt,sjk->sikt", gi, tail.imag)
            err += np.einsum("sk,sikt->sit", den_err[sets], np.abs(H))
            ntail = scaled[:, :, width - num.shape[2]:]
            Y = np.einsum("sjk,sjt->skt", ntail.real, er) - np.einsum("sjk,sjt->skt", ntail.imag, ei)
            err += np.einsum("sik,skt->sit", num_err[sets], np.abs(Y))
            error[sets] = err
    return values, error, roots


def _general_terms(roots: np.ndarray, lead: np.ndarray, safe_num: np.ndarray, num_abs: np.ndarray,
                   den_abs: np.ndarray, isolated: np.ndarray, gap: np.ndarray, second: np.ndarray,
                   radius: np.ndarray, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Isolated roots' terms and error estimates of sets that also have clusters."""
    P, N = roots.shape
    n = safe_num.shape[1]
    # isolated roots
    diff = roots[:, :, None] - roots[:, None, :]
    diff[:, np.arange(N), np.arange(N)] = 1.0
    dprime = lead[:, None] * np.prod(diff, axis=2)
    numer = _horner(safe_num, np.broadcast_to(roots[:, None, :], (P, n, N)))
    numer_abs = _horner(num_abs, np.broadcast_to(np.abs(roots)[:, None, :], (P, n, N)))
    weight = np.where(roots.imag > 0, 2.0, np.where(roots.imag == 0, 1.0, 0.0)) * isolated
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        residues = np.where(weight[:, None, :] > 0, numer / dprime[:, None, :], 0.0) \
            * weight[:, None, :]
        exps = np.exp(roots[:, :, None] * times[None, None, :])  # (P, N, T)
        values = np.matmul(residues, exps).real
        magnitude = np.exp(roots.real[:, :, None] * times[None, None, :])
        den_bound = _horner(den_abs, np.abs(roots))
        shift = np.where(isolated, UNIT * den_bound / np.abs(dprime), 0.0)  # root error
        # ∂x/∂r_j is a confluent divided difference f[r_j, r_j, r_k] (r_k the nearest
        # root), of size |res_j|·gap_j·(t + (N+1)/gap2_j)², gap2 the second-nearest
        # distance: the 1/gap of single residues cancels between the pair.
        # A root far from the others (gap ≥ second/3): |res_j|·(t + N/gap_j).
        paired = (gap < second / 3)[:, None, :]
        reach = (N + 1) / second[:, None, :]
        spread = (shift * np.where(np.isfinite(gap), gap, radius[:, None]))[:, None, :]
        size = np.abs(residues)
        lone = shift[:, None, :] * N / gap[:, None, :]
        constant = size * (UNIT * (N + 2) + np.where(paired, spread * reach**2, lone)) \
            + np.where(weight[:, None, :] > 0, UNIT * numer_abs / np.abs(dprime)[:, None, :], 0.0) \
            * weight[:, None, :]
        slope = size * (UNIT * np.abs(roots)[:, None, :]
                        + np.where(paired, 2 * spread * reach, 0.0) + shift[:, None, :])
        curve = size * np.where(paired, spread, 0.0)
        error = np.matmul(constant, magnitude) + np.matmul(slope, magnitude) * times[None, None, :] \
            + np.matmul(curve, magnitude) * (times**2)[None, None, :] \
            + _UNDERFLOW * np.sum(size, axis=2)[:, :, None]

    return values, error


def _add_clusters(values: np.ndarray, error: np.ndarray, roots: np.ndarray, labels: np.ndarray,
                  isolated: np.ndarray, suspect: np.ndarray, lead: np.ndarray, safe_num: np.ndarray,
                  num_abs: np.ndarray, den_abs: np.ndarray, times: np.ndarray) -> None:
    """Add the clusters' divided-difference terms and error estimates (in place)."""
    N = roots.shape[1]
    if not isolated.all():
        members: dict[int, list[tuple[int, list[int]]]] = {}
        for b in np.flatnonzero(~isolated.all(axis=1)):
            if suspect[b]:
                continue
            for label in np.unique(labels[b][~isolated[b]]):
                group = np.flatnonzero(labels[b] == label).tolist()
                members.setdefault(len(group), []).append((int(b), group))
        for m, items in members.items():
            sets = np.array([b for b, _ in items])
            columns = np.array([g for _, g in items])
            mask = np.ones((len(items), N), dtype=bool)
            mask[np.arange(len(items))[:, None], columns] = False
            z = roots[sets[:, None], columns]
            others = roots[sets[:, None], np.nonzero(mask)[1].reshape(len(items), N - m)]
            value, err = _cluster_terms(z, others, lead[sets], safe_num[sets], num_abs[sets],
                                        den_abs[sets], times, N)
            np.add.at(values, sets, value.real)
            np.add.at(error, sets, err)


def _placeholder(N: int) -> np.ndarray:
    """λ^N − 1: a harmless polynomial for sets that are evaluated another way."""
    out = np.zeros(N + 1)
    out[0], out[-1] = 1.0, -1.0
    return out
