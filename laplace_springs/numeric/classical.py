"""Classically damped and undamped scenes: modes from a symmetric eigenproblem of size n.

When M, C and K are symmetric and C M⁻¹ K = K M⁻¹ C (checked exactly,
:func:`classical_damping`), one M-orthonormal set of shapes Φ diagonalises K and C
together: Φᵀ K Φ = diag(θ), Φᵀ C Φ = diag(c), Φᵀ M Φ = I. Each modal coordinate moves
alone, q_j'' + c_j q_j' + θ_j q_j = 0, and x = Φ q. The shapes come from the symmetric
generalized eigenproblem K φ = θ M φ: for a diagonal M and a tridiagonal or banded K from
``scipy.linalg.eigh_tridiagonal`` / ``eig_banded`` on M^{-1/2} K M^{-1/2}, else from
``scipy.linalg.eigh(K, M)``. Each scalar equation is solved in closed form,

    q(t) = e^{−ht}[q(0)·C(t) + (q'(0) + h q(0))·S(t)],   h = c/2, δ = θ − h²,

with C = cos(√δ t), S = sin(√δ t)/√δ for δ > 0, and for δ ≤ 0 (overdamped, critical)
the stable forms e^{−ht}C = (e^{−s t} + e^{−f t})/2, e^{−ht}S = e^{−s t}·(1 − e^{−2gt})/(2g)
with g = √(−δ), f = h + g and the slow rate s = θ/(h + g) (no cancellation): the critical
case is their limit g → 0 (S = t e^{−ht}).

The error bound (:meth:`ClassicalMotion.bound`)
------------------------------------------------
The computed motion x̂ = Φ̂ q̂ satisfies M x̂'' + C x̂' + K x̂ = r(t) exactly, with
r = R_K q̂ + R_C q̂', R_K = KΦ̂ − MΦ̂Θ̂, R_C = CΦ̂ − MΦ̂ diag(ĉ) (both computed, with the
rounding of computing them bounded). The error e = x̂ − x therefore moves as
M e'' + C e' + K e = r, e(0) = Φ̂q̂(0) − x0, e'(0) = Φ̂q̂'(0) − v0 (computed too), and
its energy E = e'ᵀMe' + eᵀKe obeys d√E/dt ≤ δ_C √E + ‖M^{-1/2} r‖ where δ_C ≥ 0
bounds how far C is from positive semidefinite (zero up to rounding for dashpots).
Hence √E(t) ≤ e^{δ_C t}(√E(0) + t·max‖M^{-1/2}r‖), with ‖q̂(s)‖, ‖q̂'(s)‖ bounded by the
modal energies (non-increasing when ĉ ≥ 0), and ‖e‖₂ ≤ √E/√(θ_low μ), ‖e'‖₂ ≤ √E/√μ,
μ the least eigenvalue of M and θ_low a lower bound on the least θ (Weyl's theorem with
the residual and the measured loss of M-orthogonality G = Φ̂ᵀMΦ̂ − I). The rounding of
the scalar closed forms (phases (|√δ| + h)t) and of the product Φ̂q̂ is added. The bound
is the same for every coordinate; it is pessimistic (often by 10³ or more at long
times: it assumes the residual feeds the slowest mode) but it holds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np
import sympy as sp
from flint import fmpq, fmpq_mat

from ..kernels.batch import columns_product
from ..limits import limits
from ..model.errors import FloatRangeError, SceneError
from ..model.scene import Scene
from ..model.symbols import TIME
from .first_order import rational_entries, scene_arrays, scene_cache, scene_entries
from .krylov_entries import entries_of

__all__ = ["NOT_CLASSICAL", "classical_damping", "float_matrices", "mode_poles", "float_eigenpairs", "classical_motion", "decompose_classical", "ClassicalMotion", "ModalForm", "ModalTerm", "SymmetricScene",
           "symmetric_scene"]

_EPS = float(np.finfo(float).eps)


def _scipy() -> Any:
    try:
        import scipy.linalg
        import scipy.sparse
    except ImportError:  # pragma: no cover - scipy is installed with the package's test extra
        raise ImportError("the symmetric (classically damped) route needs scipy: "
                          "pip install scipy") from None
    return scipy


# ----------------------------------------------------------------------------- exact check


def _symmetric(entries: dict[tuple[int, int], Any]) -> bool:
    return all(entries.get((j, i)) == value for (i, j), value in entries.items())


def float_matrices(scene: Scene) -> tuple[Any, Any, Any] | None:
    """M, C, K of a rational scene as float64 CSR matrices (each entry its exact value
    correctly rounded), from the entry arrays kept with the scene; None when an entry is
    not rational.

    >>> M, C, K = float_matrices(Scene.from_matrices(M=[[2]], C=[["1/3"]], K=[[8]],
    ...                                              x0=[1], v0=[0]))
    >>> float(C[0, 0]) == 1 / 3
    True
    """
    table = scene_cache(scene)
    if "float matrices" not in table:
        sparse = _scipy().sparse
        n = scene.n
        read = [entries_of(scene, name) for name in ("M", "C", "K")]
        table["float matrices"] = None if any(e is None for e in read) else tuple(
            sparse.csr_matrix((e.value, (e.rows, e.cols)), shape=(n, n)) for e in read if e)
    found: tuple[Any, Any, Any] | None = table["float matrices"]
    return found


def _clearly_not_classical(scene: Scene) -> bool:
    """A float64 screen for a diagonal M: C M⁻¹K v and Kᵀ M⁻¹Cᵀ v (the product and its
    transpose applied to one fixed positive vector v) differ in an entry by more than 1e-9
    of |C| M⁻¹|K| v, far above their rounding (about 1e-15 of it), so C M⁻¹K is not
    symmetric and the exact check need not run (a 4,000-mass mesh: four sparse products
    instead of 0.2 s of fmpq products). A scene it does not reject goes to the exact check."""
    found = float_matrices(scene)
    if found is None:
        return False
    Mf, Cf, Kf = found
    with np.errstate(divide="ignore"):
        inverse = np.where(Mf.diagonal() != 0, 1 / Mf.diagonal(), 0.0)
    v = _probe_vector(scene.n)
    forward = Cf @ (inverse * (Kf @ v))
    backward = Kf.T @ (inverse * (Cf.T @ v))
    size = abs(Cf) @ (inverse * (abs(Kf) @ v)) + abs(Kf.T) @ (inverse * (abs(Cf.T) @ v))
    return bool(np.any(np.abs(forward - backward) > 1e-9 * size))


def _probe_vector(n: int) -> np.ndarray:
    """A fixed vector of entries in [1, 2) with no pattern a spring network shares."""
    return 1 + (np.arange(n) * 0.6180339887498949) % 1


#: Why an engine of the symmetric eigenproblem declines a scene :func:`classical_damping` refuses
#: (a nonsymmetric K is not a matter of damping, so the damping alone is not blamed).
NOT_CLASSICAL = ("the scene is not classical (needs symmetric M, C, K, no massless node and "
                 "C M⁻¹K = K M⁻¹C)")


def classical_damping(scene: Scene) -> bool:
    """Whether the scene is undamped or classically damped, exactly: rational symmetric
    M, C, K with M diagonal (any size) or small (≤ 64 coordinates), and C M⁻¹ K = K M⁻¹ C.

    With M diagonal the products are taken entry by entry over the nonzero entries
    (time proportional to them for banded matrices). An unforced scene is assumed;
    massless nodes (a zero row of M) make it non-classical here.

    Examples
    --------
    Rayleigh damping C = K/10 + M/5 is classical; a dashpot on one mass only is not:

    >>> K = [[2, -1], [-1, 2]]
    >>> classical_damping(Scene.from_matrices(M=[[1, 0], [0, 1]], C=[["2/5", "-1/10"],
    ...     ["-1/10", "2/5"]], K=K, x0=[1, 0], v0=[0, 0]))
    True
    >>> classical_damping(Scene.from_matrices(M=[[1, 0], [0, 1]], C=[[1, 0], [0, 0]], K=K,
    ...                                       x0=[1, 0], v0=[0, 0]))
    False
    """
    M, C, K = (rational_entries(scene, name) for name in ("M", "C", "K"))
    if M is None or C is None or K is None:
        return False
    n = scene.n
    diagonal = all(i == j for i, j in M)
    if diagonal and len(M) < n:
        return False  # massless nodes
    # the float64 screen first: on a large non-classical scene it decides in milliseconds
    # what the exact symmetry checks below take a Python pass over every entry to find
    if diagonal and len(C) > 64 and _clearly_not_classical(scene):
        return False
    if not (_symmetric(M) and _symmetric(C) and _symmetric(K)):
        return False
    if not C:
        return True
    if diagonal:
        needed = {k for _, k in C}   # rows of M⁻¹K that C M⁻¹K uses (one dashpot: one row)
        inverse = {i: 1 / value for (i, _), value in M.items() if i in needed}
        rows: dict[int, list[tuple[int, Any]]] = {}
        for (k, j), value in K.items():
            if k in needed:
                rows.setdefault(k, []).append((j, value * inverse[k]))
        product: dict[tuple[int, int], Any] = {}
        for (i, k), value in C.items():
            for j, scaled in rows.get(k, ()):
                product[i, j] = product.get((i, j), 0) + value * scaled
        return all(product.get((j, i), 0) == value for (i, j), value in product.items())
    if n > limits().dense_check_max_coordinates:
        return False
    dense = [fmpq_mat(n, n) for _ in range(3)]
    for matrix, entries in zip(dense, (M, C, K)):
        for (i, j), value in entries.items():
            matrix[i, j] = value
    Mq, Cq, Kq = dense
    if Mq.det() == 0:
        return False
    P = Cq * Mq.solve(Kq)
    return bool(P.transpose() == P)


# ----------------------------------------------------------------------------- float data


@dataclass(frozen=True, eq=False)
class SymmetricScene:
    """The float64 data of a classically damped scene.

    ``mass`` is the diagonal of M (a vector) or a dense matrix; ``C`` and ``K`` are
    scipy CSR matrices; ``bandwidth`` is K's half-bandwidth. ``rounding`` holds the
    largest relative rounding of an entry of M, C, K (0 for exactly representable data).
    """

    mass: np.ndarray
    C: Any
    K: Any
    x0: np.ndarray
    v0: np.ndarray
    bandwidth: int
    damped: bool

    @property
    def n(self) -> int:
        return len(self.x0)

    @property
    def diagonal(self) -> bool:
        return self.mass.ndim == 1


def _float(entry: Any) -> float:
    """float(entry), correctly rounded; fast for rationals (int / int rounds correctly)."""
    if isinstance(entry, fmpq) or entry.is_Rational:
        try:
            return int(entry.p) / int(entry.q)
        except OverflowError:
            return math.inf if entry > 0 else -math.inf
    return float(entry)


def _csr(n: int, entries: dict[tuple[int, int], Any], name: str) -> Any:
    scipy = _scipy()
    keys = np.array(list(entries), dtype=np.int64).reshape(-1, 2)
    values = np.array([_float(entry) for entry in entries.values()], dtype=float)
    bad = np.flatnonzero(~np.isfinite(values))
    if bad.size:
        i, j = (int(v) for v in keys[bad[0]])
        raise FloatRangeError(f"{name}[{i},{j}] = {entries[i, j]} is beyond the float64 range")
    return scipy.sparse.csr_matrix((values, (keys[:, 0], keys[:, 1])), shape=(n, n))


def _entries(scene: Scene, name: str) -> dict[tuple[int, int], Any]:
    """The nonzero entries: flint fmpq where all are rational (fast), else SymPy numbers."""
    exact = rational_entries(scene, name)
    return scene_entries(scene, name) if exact is None else exact


def symmetric_scene(scene: Scene, damping: Any = None) -> SymmetricScene:
    """The float64 data of a scene :func:`classical_damping` accepts (time ∝ nonzero entries
    for a diagonal M). ``damping = (a, b)`` builds C = aK + bM from the float K and M
    instead of reading C (Rayleigh damping, known exactly; a diagonal M).

    Examples
    --------
    >>> data = symmetric_scene(Scene.from_matrices(M=[[2]], K=[[8]], x0=[1], v0=[0]))
    >>> data.mass, data.bandwidth
    (array([2.]), 0)
    """
    n = scene.n
    Md, Cd, Kd = (_entries(scene, name) for name in ("M", "C", "K"))
    if all(i == j for i, j in Md):
        mass = np.zeros(n)
        for (i, _), entry in Md.items():
            mass[i] = _float(entry)
    else:
        mass = np.zeros((n, n))
        for (i, j), entry in Md.items():
            mass[i, j] = _float(entry)
    if not np.all(np.isfinite(mass)):
        raise FloatRangeError("M has an entry beyond the float64 range")
    bandwidth = max((abs(i - j) for i, j in Kd), default=0)
    x0, v0 = np.zeros(n), np.zeros(n)
    for vector, name in ((x0, "x0"), (v0, "v0")):
        for (i, _), entry in _entries(scene, name).items():
            vector[i] = _float(entry)
        if not np.all(np.isfinite(vector)):
            raise FloatRangeError(f"{name} has an entry beyond the float64 range")
    K = _csr(n, Kd, "K")
    if damping is None:
        C = _csr(n, Cd, "C")
    else:
        a, b = (float(v) for v in damping)
        C = (a * K + _scipy().sparse.diags(b * mass)).tocsr() if mass.ndim == 1 else _csr(n, Cd, "C")
    return SymmetricScene(mass, C, K, x0, v0, bandwidth, bool(Cd))


# ----------------------------------------------------------------------------- modal form


@dataclass(frozen=True)
class ModalTerm:
    """One term t^power e^{rate.real t}(cos_vector cos(rate.imag t) + sin_vector sin(rate.imag t))."""

    power: int
    rate: complex
    cos_vector: np.ndarray
    sin_vector: np.ndarray

    def __repr__(self) -> str:
        growth = f"t^{self.power} " if self.power else ""
        return (f"<ModalTerm {growth}e^({self.rate.real:.6g} t), frequency {self.rate.imag:.6g}, "
                f"largest coefficient {max(np.max(np.abs(self.cos_vector), initial=0.0), np.max(np.abs(self.sin_vector), initial=0.0)):.3g}>")


class ModalForm:
    """x(t) = Σ_j t^{p_j} e^{α_j t} (a_j cos β_j t + b_j sin β_j t): a sum over modes with
    coefficient vectors a_j = shapes[:, j]·cos[j], b_j = sin_shapes[:, j]·sin[j].

    The compact closed form of a large scene's motion (float64 coefficients): row ``i``
    (``form[i]``) is a SymPy expression, :meth:`as_matrix` builds the whole column, and
    calling the form evaluates it numerically at times (no ``subs``).

    Examples
    --------
    >>> form = ModalForm([0], [-0.5], [2.0], np.array([[1.0], [0.5]]), [1.0], [0.0])
    >>> form
    <ModalForm: 2 coordinates, 1 terms t^p e^(αt)(a cos βt + b sin βt); α in [-0.5, -0.5], β in [2, 2]>
    >>> form[1]
    0.5*exp(-0.5*t)*cos(2.0*t)
    >>> form(np.array([0.0]))
    array([[1. ],
           [0.5]])
    """

    def __init__(self, powers: Any, alphas: Any, betas: Any, shapes: np.ndarray, cos: Any,
                 sin: Any, sin_shapes: np.ndarray | None = None) -> None:
        self.powers = np.asarray(powers, dtype=int)
        self.alphas = np.asarray(alphas, dtype=float)
        self.betas = np.asarray(betas, dtype=float)
        self.shapes = np.asarray(shapes, dtype=float)
        self.cos = np.asarray(cos, dtype=float)
        self.sin = np.asarray(sin, dtype=float)
        self.sin_shapes = self.shapes if sin_shapes is None else np.asarray(sin_shapes, dtype=float)

    @property
    def n(self) -> int:
        return int(self.shapes.shape[0])

    @property
    def shape(self) -> tuple[int, int]:
        return (self.n, 1)

    def __len__(self) -> int:
        return self.n

    @property
    def modes(self) -> tuple[ModalTerm, ...]:
        """The terms, one per mode (and power of t), with their coefficient vectors."""
        return tuple(ModalTerm(int(p), complex(a, b), self.shapes[:, j] * self.cos[j],
                               self.sin_shapes[:, j] * self.sin[j])
                     for j, (p, a, b) in enumerate(zip(self.powers, self.alphas, self.betas)))

    def __repr__(self) -> str:
        def span(v: np.ndarray) -> str:
            return f"[{v.min():.3g}, {v.max():.3g}]" if v.size else "[]"

        return (f"<ModalForm: {self.n} coordinates, {len(self.powers)} terms t^p e^(αt)"
                f"(a cos βt + b sin βt); α in {span(self.alphas)}, β in {span(self.betas)}>")

    def __call__(self, times: Any) -> np.ndarray:
        """x(t) at the times (float64, shape (n, len(times)))."""
        t = np.atleast_1d(np.asarray(times, dtype=float))
        with np.errstate(over="ignore", invalid="ignore"):
            growth = np.exp(np.outer(self.alphas, t)) * t[None, :] ** self.powers[:, None]
            phase = np.outer(self.betas, t)
            return (columns_product(self.shapes, self.cos[:, None] * growth * np.cos(phase))
                    + columns_product(self.sin_shapes, self.sin[:, None] * growth * np.sin(phase)))

    def _row(self, i: int, relative: float = 1e-13) -> sp.Expr:
        a = self.shapes[i] * self.cos
        b = self.sin_shapes[i] * self.sin
        largest = max(np.max(np.abs(a), initial=0.0), np.max(np.abs(b), initial=0.0))
        t = TIME
        out: list[sp.Expr] = []
        for j in range(len(self.powers)):
            ca = float(a[j]) if abs(a[j]) > relative * largest else 0.0
            cb = float(b[j]) if abs(b[j]) > relative * largest and self.betas[j] else 0.0
            if not (ca or cb):
                continue
            growth = t ** int(self.powers[j]) * (sp.exp(sp.Float(self.alphas[j], 15) * t)
                                                 if self.alphas[j] else 1)
            beta = sp.Float(self.betas[j], 15)
            wave = ((sp.Float(ca, 15) * (sp.cos(beta * t) if self.betas[j] else 1) if ca else 0)
                    + (sp.Float(cb, 15) * sp.sin(beta * t) if cb else 0))
            out.append(growth * wave)
        return sp.Add(*out)

    def __getitem__(self, index: Any) -> sp.Expr:
        if isinstance(index, tuple):
            index, column = index
            if column not in (0, -1):
                raise IndexError(f"x has one column, got column {column}")
        if not isinstance(index, (int, np.integer)) or not -self.n <= index < self.n:
            raise IndexError(f"row index must be an integer in [0, {self.n}), got {index!r}")
        return self._row(int(index) % self.n)

    def as_matrix(self) -> sp.ImmutableMatrix:
        """x(t) as a SymPy column matrix with Float coefficients (n rows of up to m terms)."""
        return sp.ImmutableMatrix([self._row(i) for i in range(self.n)])


# ----------------------------------------------------------------------------- decomposition


@dataclass(frozen=True, eq=False)
class _Decomposition:
    theta: np.ndarray       # θ_j
    phi: np.ndarray         # n x n, M-orthonormal shapes
    c: np.ndarray           # c_j
    q0: np.ndarray          # Φᵀ M x0
    dq0: np.ndarray         # Φᵀ M v0
    colmax: np.ndarray      # max_i |Φ_ij|
    constants: dict         # bound constants


def _eigen(data: SymmetricScene) -> tuple[np.ndarray, np.ndarray]:
    """θ (ascending) and M-orthonormal Φ of K φ = θ M φ."""
    scipy = _scipy()
    la = scipy.linalg
    n = data.n
    if data.diagonal:
        scale = 1 / np.sqrt(data.mass)
        if data.bandwidth == 0:
            theta = data.K.diagonal() * scale**2
            _check_finite(theta, "M⁻¹K")
            order = np.argsort(theta)
            phi = np.zeros((n, n))
            phi[order, np.arange(n)] = scale[order]
            return theta[order], phi
        A = data.K.multiply(scale[:, None]).multiply(scale[None, :]).tocsr() if n else data.K
        _check_finite(A.data, "M^(-1/2) K M^(-1/2)")
        if data.bandwidth == 1:
            theta, V = la.eigh_tridiagonal(A.diagonal(), A.diagonal(1))
        elif data.bandwidth <= limits().banded_max_bandwidth:
            b = data.bandwidth
            bands = np.zeros((b + 1, n))
            for k in range(b + 1):
                bands[k, : n - k] = A.diagonal(-k)
            theta, V = la.eig_banded(bands, lower=True)
        else:
            theta, V = la.eigh(A.toarray())
        return theta, scale[:, None] * V
    return la.eigh(data.K.toarray(), data.mass)


def _check_finite(values: np.ndarray, name: str) -> None:
    """A FloatRangeError when an entry of ``name`` (formed in float64) overflowed: a mass
    of 1e-300 on a spring of 1e300 gives 1e600 (the eigen solvers raise on inf)."""
    if not np.all(np.isfinite(values)):
        raise FloatRangeError(f"an entry of {name} is beyond the float64 range (about "
                              f"{float(np.max(np.abs(values))):.3g} in float64): the classical "
                              "route cannot hold this scene; the certified and exact routes can")


def _mass_times(data: SymmetricScene, X: np.ndarray) -> np.ndarray:
    return data.mass[:, None] * X if data.diagonal else data.mass @ X


def _norm_inf(A: Any) -> float:
    """max row sum of |A| (≥ ‖A‖₂ for symmetric A)."""
    if isinstance(A, np.ndarray):
        return float(np.max(np.sum(np.abs(A), axis=-1), initial=0.0)) if A.ndim == 2 else \
            float(np.max(np.abs(A), initial=0.0))
    return float(np.max(np.asarray(abs(A).sum(axis=1)).ravel(), initial=0.0))


def decompose_classical(data: SymmetricScene) -> _Decomposition:
    """Modes, modal initial data and the constants of the error bound (module notes)."""
    scipy = _scipy()
    n = data.n
    theta, phi = _eigen(data)
    Mphi = _mass_times(data, phi)
    Kphi = data.K @ phi
    Cphi = data.C @ phi if data.damped else np.zeros_like(phi)
    c = np.einsum("ij,ij->j", phi, Cphi) if data.damped else np.zeros(n)
    q0, dq0 = Mphi.T @ data.x0, Mphi.T @ data.v0
    # residuals and their rounding (γ_w with w nonzeros per row; dense M: n)
    w = max(int(np.max(np.diff(data.K.indptr), initial=0)), int(np.max(np.diff(data.C.indptr), initial=0)),
            1 if data.diagonal else n) + 2
    gamma = 1.01 * w * _EPS
    colnorm = np.linalg.norm(phi, axis=0)
    abs_norms = (_norm_inf(data.K), _norm_inf(data.C), _norm_inf(data.mass))
    RK = float(np.linalg.norm(Kphi - Mphi * theta)) + gamma * math.sqrt(n) * float(np.linalg.norm(
        colnorm * (abs_norms[0] + abs_norms[2] * np.abs(theta))))
    RC = float(np.linalg.norm(Cphi - Mphi * c)) + gamma * math.sqrt(n) * float(np.linalg.norm(
        colnorm * (abs_norms[1] + abs_norms[2] * np.abs(c)))) if data.damped else 0.0
    if data.diagonal:  # G = VᵀV − I with V = M^{1/2}Φ: a symmetric rank-n update, half the work
        V = np.sqrt(data.mass)[:, None] * phi
        G = scipy.linalg.blas.dsyrk(1.0, V, trans=1, lower=0)
        G = np.triu(G) + np.triu(G, 1).T
    else:
        G = phi.T @ Mphi
    G[np.diag_indices(n)] -= 1
    g = float(np.linalg.norm(G)) + gamma * n * float(np.max(colnorm) ** 2 * abs_norms[2])
    mu = float(np.min(data.mass)) if data.diagonal else float(np.linalg.eigvalsh(data.mass)[0])
    mu -= (n * _EPS * abs_norms[2]) if not data.diagonal else 0.0
    colmax = np.max(np.abs(phi), axis=0)
    # initial mismatch, computed (with the rounding of the products)
    e0 = phi @ q0 - data.x0
    e1 = phi @ dq0 - data.v0
    round0 = gamma * (np.abs(phi) @ np.abs(q0) + np.abs(data.x0))
    round1 = gamma * (np.abs(phi) @ np.abs(dq0) + np.abs(data.v0))
    e0n = float(np.linalg.norm(np.abs(e0) + round0))
    e1n = float(np.linalg.norm(np.abs(e1) + round1))
    constants: dict[str, float] = {"RK": RK, "RC": RC, "g": g, "mu": mu, "e0": e0n, "e1": e1n,
                                   "normK": abs_norms[0], "normC": abs_norms[1],
                                   "normM": abs_norms[2]}
    return _Decomposition(theta, phi, c, q0, dq0, colmax, constants)


def _scalar_parts(theta: np.ndarray, c: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, ...]:
    """e^{−ht}C(t), e^{−ht}S(t) (modes x times), their envelopes, and h, per mode."""
    h = c / 2
    omega = np.sqrt(np.maximum(theta, 0.0))
    delta = np.where(theta >= 0, (omega - h) * (omega + h), theta - h * h)  # θ < 0: overdamped
    under = delta > 0
    Cf = np.empty((len(theta), len(t)))
    Sf = np.empty_like(Cf)
    envC = np.empty_like(Cf)
    envS = np.empty_like(Cf)
    speed = np.empty(len(theta))  # |√δ| + h: the phase's size per unit time
    tt = t[None, :]
    with np.errstate(over="ignore", invalid="ignore", divide="ignore", under="ignore"):
        if under.any():
            d = np.sqrt(delta[under])[:, None]
            decay = np.exp(-h[under][:, None] * tt)
            phase = d * tt
            Cf[under] = decay * np.cos(phase)
            Sf[under] = decay * np.sin(phase) / d
            envC[under] = decay
            envS[under] = decay * np.minimum(tt, 1 / d)
            speed[under] = d[:, 0] + h[under]
        over = ~under
        if over.any():
            g = np.sqrt(-delta[over])[:, None]
            hh = h[over][:, None]
            slow = np.where(hh + g > 0, theta[over][:, None] / (hh + g), 0.0)
            P, Q = np.exp(-slow * tt), np.exp(-(hh + g) * tt)
            factor = np.where(g > 0, -np.expm1(-2 * g * tt) / (2 * np.where(g > 0, g, 1.0)), tt)
            Cf[over] = (P + Q) / 2
            Sf[over] = P * factor
            envC[over] = Cf[over]
            envS[over] = Sf[over]
            speed[over] = g[:, 0] + h[over]
    return Cf, Sf, envC, envS, h, speed


def _coefficients(theta: np.ndarray, c: np.ndarray, q0: np.ndarray, dq0: np.ndarray,
                  order: int) -> tuple[np.ndarray, np.ndarray]:
    """(u_k, u_{k+1} + h u_k) for the order-th derivative: q^(k) = u_k e^{−ht}C + w_k e^{−ht}S."""
    u = [q0, dq0]
    for _ in range(order):
        u.append(-c * u[-1] - theta * u[-2])
    h = c / 2
    return u[order], u[order + 1] + h * u[order]


def mode_poles(theta: np.ndarray, c: np.ndarray) -> np.ndarray:
    """The roots of λ² + c_j λ + θ_j (two per mode), sorted: −h ± i√δ (underdamped),
    −θ/(h + g) and −(h + g) (overdamped, no cancellation), h = c/2, δ = θ − h² = −g².

    >>> mode_poles(np.array([4.0, 1.0]), np.array([0.0, 3.0])).round(6)
    array([-2.618034+0.j, -0.381966+0.j, -0.      -2.j,  0.      +2.j])
    """
    h = c / 2
    omega = np.sqrt(np.maximum(theta, 0.0))
    delta = (omega - h) * (omega + h)
    root = np.sqrt(np.abs(delta))
    with np.errstate(divide="ignore", invalid="ignore"):
        slow = np.where(h + root > 0, theta / (h + root), 0.0)
    upper = np.where(delta > 0, -h + 1j * root, -slow)
    lower = np.where(delta > 0, -h - 1j * root, -(h + root))
    values = np.concatenate([upper, lower]).astype(complex)
    return values[np.lexsort((values.imag, values.real))]


class ClassicalMotion:
    """x(t) of a classically damped (or undamped) scene from its real modes (see module notes).

    The decomposition is computed on first use. Built by :func:`classical_motion`.
    """

    def __init__(self, data: SymmetricScene) -> None:
        self.data = data
        self._last: tuple[Any, tuple[np.ndarray, np.ndarray]] | None = None

    @cached_property
    def decomposition(self) -> _Decomposition:
        return decompose_classical(self.data)

    @property
    def n(self) -> int:
        return self.data.n

    @property
    def has_zero_frequency(self) -> bool:
        """Whether some θ is zero to working precision (rigid-body motion: the general
        route splits it off exactly; here its bound would be infinite)."""
        theta = self.decomposition.theta
        largest = float(np.max(np.abs(theta), initial=0.0))
        return bool(theta.size) and float(np.min(theta)) <= 64 * _EPS * self.n * largest

    @property
    def modes(self) -> Any:
        """(θ, c, Φ): stiffness and damping of each mode and the M-orthonormal shapes."""
        d = self.decomposition
        return _ModeData(d.theta, d.c, d.phi)

    def poles(self) -> np.ndarray:
        """λ = −h ± i√δ (underdamped), −s and −f (overdamped), for every mode."""
        d = self.decomposition
        return mode_poles(d.theta, d.c)

    def _modal(self, t: np.ndarray, order: int) -> tuple[np.ndarray, np.ndarray]:
        """q̂^(order) at the times (modes x times) and the rounding of each entry; the last
        call is kept, since :meth:`values` and :meth:`bound` are asked for the same times."""
        key = (t.tobytes(), order)
        if self._last is not None and self._last[0] == key:
            return self._last[1]
        d = self.decomposition
        Cf, Sf, envC, envS, h, speed = _scalar_parts(d.theta, d.c, t)
        u, w = _coefficients(d.theta, d.c, d.q0, d.dq0, order)
        with np.errstate(over="ignore", invalid="ignore"):
            q = u[:, None] * Cf
            q += w[:, None] * Sf
            envC *= np.abs(u)[:, None]
            envC += np.abs(w)[:, None] * envS
            envC *= (10 + 4 * speed[:, None] * np.abs(t)[None, :]) * _EPS
            envC += (1.01 * (self.n + 2) * _EPS) * np.abs(q)
        self._last = (key, (q, envC))
        return q, envC

    def values(self, times: np.ndarray, order: int = 0) -> np.ndarray:
        """d^order x/dt^order at the times, float64, shape (n, len(times))."""
        q, _ = self._modal(np.asarray(times, dtype=float), order)
        return columns_product(self.decomposition.phi, q)   # a time's column alone

    def bound(self, times: np.ndarray, order: int = 0) -> np.ndarray:
        """A bound on the error of :meth:`values`, the same for every coordinate."""
        d = self.decomposition
        t = np.asarray(times, dtype=float)
        _, scalar = self._modal(t, order)
        with np.errstate(over="ignore", invalid="ignore"):
            total = columns_product(d.colmax[None, :], scalar)[0] \
                + self._energy_bound(np.abs(t), order, d.constants)
        return np.broadcast_to(np.where(np.isfinite(total), total, np.inf), (self.n, len(t))).copy()

    @cached_property
    def _energy_constants(self) -> tuple[float, float, float, float]:
        """(θ_low, δ_C, max‖q̂‖, max‖q̂'‖ up to the growth e^{δ_q t})."""
        d = self.decomposition
        k = d.constants
        g = k["g"]
        if not g < 0.5 or k["mu"] <= 0:
            return (0.0, np.inf, np.inf, np.inf)
        scale = 1 / (1 - g)
        theta_norm = float(np.max(np.abs(d.theta), initial=0.0))
        spread_K = (k["RK"] / math.sqrt(k["mu"]) + 2 * g * theta_norm) * scale
        c_norm = float(np.max(np.abs(d.c), initial=0.0))
        spread_C = (k["RC"] / math.sqrt(k["mu"]) + 2 * g * c_norm) * scale
        theta_low = float(np.min(d.theta, initial=np.inf)) - spread_K
        negative = max(0.0, -float(np.min(d.c, initial=0.0)))
        delta_C = negative + spread_C
        energy = d.dq0**2 + d.theta * d.q0**2
        with np.errstate(divide="ignore", invalid="ignore"):
            Q0 = math.sqrt(float(np.sum(energy / d.theta))) if np.all(d.theta > 0) else np.inf
        Q1 = math.sqrt(float(np.sum(energy)))
        return theta_low, delta_C, Q0, Q1

    def _energy_bound(self, t: np.ndarray, order: int, k: dict) -> np.ndarray:
        theta_low, delta_C, Q0, Q1 = self._energy_constants
        if not theta_low > 0:
            return np.full(len(t), np.inf)
        d = self.decomposition
        growth_q = np.exp(max(0.0, -float(np.min(d.c, initial=0.0))) / 2 * t)
        residual = (k["RK"] * Q0 + k["RC"] * Q1) * growth_q  # max ‖r(s)‖, s ≤ t
        mu = k["mu"]
        start = math.sqrt(k["normK"] * k["e0"] ** 2 + k["normM"] * k["e1"] ** 2)
        root_E = np.exp(delta_C * t) * (start + t * residual / math.sqrt(mu))
        x_err = root_E / math.sqrt(theta_low * mu)
        v_err = root_E / math.sqrt(mu)
        if order == 0:
            return x_err
        if order == 1:
            return v_err
        return (residual + k["normC"] * v_err + k["normK"] * x_err) / mu

    def modal_form(self) -> ModalForm:
        """x(t) as a :class:`ModalForm` (one or two terms per mode)."""
        d = self.decomposition
        return _modal_form(d.theta, d.c, d.phi, d.q0, d.dq0)

    def closed_form(self) -> sp.ImmutableMatrix:
        """x(t) as a SymPy column with Float coefficients."""
        return self.modal_form().as_matrix()


@dataclass(frozen=True)
class _ModeData:
    theta: np.ndarray
    c: np.ndarray
    shapes: np.ndarray
    warnings: tuple[str, ...] = ()


def _modal_form(theta: np.ndarray, c: np.ndarray, phi: np.ndarray, q0: np.ndarray,
                dq0: np.ndarray) -> ModalForm:
    h = c / 2
    omega = np.sqrt(np.maximum(theta, 0.0))
    delta = (omega - h) * (omega + h)
    w0 = dq0 + h * q0
    powers, alphas, betas, columns, cos, sin = [], [], [], [], [], []
    for j in range(len(theta)):
        if delta[j] > 0:
            d = math.sqrt(delta[j])
            entries = [(0, -h[j], d, q0[j], w0[j] / d)]
        else:
            g = math.sqrt(-delta[j])
            if g <= 1e-9 * max(h[j], 1e-300):  # critical: e^{−ht}(q0 + w0 t)
                entries = [(0, -h[j], 0.0, q0[j], 0.0), (1, -h[j], 0.0, w0[j], 0.0)]
            else:
                slow = theta[j] / (h[j] + g)
                entries = [(0, -slow, 0.0, q0[j] / 2 + w0[j] / (2 * g), 0.0),
                           (0, -(h[j] + g), 0.0, q0[j] / 2 - w0[j] / (2 * g), 0.0)]
        for p, a, b, ca, cb in entries:
            powers.append(p)
            alphas.append(a)
            betas.append(b)
            columns.append(j)
            cos.append(ca)
            sin.append(cb)
    return ModalForm(powers, alphas, betas, phi[:, columns], cos, sin)


def classical_motion(scene: Scene) -> ClassicalMotion:
    """The motion of a scene :func:`classical_damping` accepts (decomposed on first use).

    Examples
    --------
    One mass, x'' + x' + x = 0 ... and an overdamped one, x'' + 3x' + x = 0, x(0) = 1:

    >>> motion = classical_motion(Scene.from_matrices(M=[[1]], C=[[3]], K=[[1]], x0=[1], v0=[0]))
    >>> float(motion.values(np.array([1.0]))[0, 0])  # doctest: +ELLIPSIS
    0.7...
    """
    return ClassicalMotion(symmetric_scene(scene))



def float_eigenpairs(scene: Scene, general_max: int = 1000) -> list[tuple[complex, np.ndarray]]:
    """The eigenvalues λ of λ²M + λC + K (Im λ ≥ 0 of each pair) with a shape, in float64.

    Undamped and classically damped scenes: the symmetric eigenproblem of size n (real
    shapes; an overdamped mode gives two real λ). Others: the eigenvalues of the 2n x 2n
    first-order matrix (up to ``general_max`` coordinates). Shapes are scaled so that
    their largest entry is 1.

    Examples
    --------
    >>> pairs = float_eigenpairs(Scene.from_matrices(M=[[1]], C=[["2/5"]], K=[[4]], x0=[1], v0=[0]))
    >>> [(complex(round(lam.real, 6), round(lam.imag, 6)), v) for lam, v in pairs]
    [((-0.2+1.989975j), array([1.+0.j]))]
    """
    if classical_damping(scene):
        d = decompose_classical(symmetric_scene(scene))
        h = d.c / 2
        omega = np.sqrt(np.maximum(d.theta, 0.0))
        delta = (omega - h) * (omega + h)
        out = []
        for j in range(len(d.theta)):
            shape = d.phi[:, j].astype(complex)
            shape = shape / shape[np.argmax(np.abs(shape))]
            if delta[j] > 0:
                out.append((complex(-h[j], math.sqrt(delta[j])), shape))
            else:
                g = math.sqrt(-delta[j])
                slow = d.theta[j] / (h[j] + g) if h[j] + g > 0 else 0.0
                out.extend([(complex(-slow, 0.0), shape), (complex(-(h[j] + g), 0.0), shape)])
        return out
    if scene.n > general_max:
        raise SceneError(f"the modes of a scene whose damping is not classical come from its "
                         f"2n x 2n first-order matrix, held densely: n = {scene.n:,} is more than "
                         f"{general_max:,}")
    scipy = _scipy()
    M, C, K, _, _ = scene_arrays(scene)
    n = scene.n
    try:
        Minv = np.linalg.inv(M)
    except np.linalg.LinAlgError:
        raise SceneError("the float64 modes need an invertible mass matrix") from None
    # time in units of 1/γ, γ = √‖M⁻¹K‖ (else ‖M⁻¹C‖): Z = [[0, I], [−A/γ², −B/γ]] has
    # entries of order 1, where LAPACK's eig of the unscaled Z with entries of 1 and 1e300
    # (masses of 1e-300 on springs of 1) gave eigenvalues of 1e-12 for 1e150
    A, B = Minv @ K, Minv @ C
    gamma = math.sqrt(float(np.linalg.norm(A, 1))) or float(np.linalg.norm(B, 1)) or 1.0
    Z = np.zeros((2 * n, 2 * n))
    Z[:n, n:] = np.eye(n)
    Z[n:, :n] = -(A / gamma) / gamma
    Z[n:, n:] = -B / gamma
    values, vectors = scipy.linalg.eig(Z)
    values = values * gamma
    tiny = 1e-12 * max(float(np.max(np.abs(values), initial=0.0)), 1e-300)
    out = []
    for k, lam in enumerate(values):
        if lam.imag < -tiny:
            continue
        shape = vectors[:n, k]
        shape = shape / shape[np.argmax(np.abs(shape))]
        out.append((complex(lam.real, lam.imag if abs(lam.imag) > tiny else 0.0), shape))
    return out
