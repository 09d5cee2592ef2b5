"""Large sparse scenes with non-classical damping: Taylor steps of the first-order system,
bounded through the energy (the ``krylov`` engine).

The state z = (x, v) obeys z' = A z, A = [[0, I], [−M⁻¹K, −M⁻¹C]], held sparse. Time is cut
into steps of length H (θ = H·ν ≤ Limits.krylov_step_norm, ν below); each step sums m
terms of the Taylor series of exp(HA), one sparse product each, the large ones formed to
about 2^-70 and the rest in float64 (:mod:`.krylov_steps`, :mod:`.krylov_data`). The cost
is about 12 sparse products per unit of t·ν at θ = 5 (a double-double term counting 2.5),
independent of the number of output times, which each cost one float64 sum of the step's
terms.

The error bound (:meth:`KrylovMotion.evaluate`)
-----------------------------------------------
It rests on the energy seminorm N(z)² = vᵀMv + xᵀKx, which the exact motion never
increases when M is diagonal positive, K symmetric positive semidefinite and C + Cᵀ
positive semidefinite (dN²/dt = −vᵀ(C + Cᵀ)v). :func:`krylov_refusal` checks this
exactly (symmetric, diagonally dominant matrices with a non-negative diagonal: every
spring and dashpot network). In energy coordinates A is [[0, P], [−Pᵀ, −D]] with
‖P‖₂² = λ_max(M⁻¹K) and D = M^{−1/2}CM^{−1/2}, so N(Az) ≤ ν N(z) with
ν = √(p² + d²/4) + d/2 for p ≥ ‖P‖₂, d ≥ ‖D‖₂ bounded by Collatz–Wielandt or Gershgorin
sums (:func:`.krylov_entries.spectral_bound`). A step from the computed state ẑ_j commits a local error δ_j
(truncation after m terms, at most tail(θ, m)·N(ẑ_j); the terms' rounding; the rounding of
their sum), and the error e_j = ẑ_j − z(jH) obeys e_{j+1} = exp(HA)e_j + δ_j, so

* E_{j+1} = E_j + N(δ_j) bounds N(e_{j+1}): errors add, never grow;
* the x part, X_{j+1} = min(X_j + H·E_j/√m_min, √R·E_j) + ‖(δ_j)_x‖∞: x(t) = x(b) + ∫v
  with |v_i| ≤ N/√m_i (rigid-body motion allowed), or |x_i| ≤ √R·√(xᵀKx) with R the
  compliance bound of :mod:`.krylov_data` where every part of the scene is held;
* a value at b + s inside step j adds the propagated error (the same min at s), the
  truncation and rounding of the terms, the float64 rounding of its own sum
  (Σ_k (3k + 4)u·|ω_k|·‖U_{k−1}‖∞) and u·s of the time's own rounding times the speed bound.

The bound is the same for every coordinate; x'' comes from the equation M x'' = −Kx − Cx'
with the rounding of that product added.
"""

from __future__ import annotations

import bisect
import math
from typing import Any

import numpy as np

from ..kernels.dd import U
from ..limits import limits
from ..model.scene import Scene
from .first_order import rational_entries
from .krylov_data import KrylovData, krylov_data, scene_refusal, spectral_bound, step_length
from .krylov_steps import Stepper, StepTerms
from .times import Times

__all__ = ["KrylovData", "KrylovMotion", "krylov_refusal", "krylov_cost", "krylov_data",
           "krylov_motion"]

_TINY = 1e-300


# ----------------------------------------------------------------------------- planning


def _steps(scene: Scene, t_max: float) -> float:
    return math.floor(max(t_max, 0.0) / step_length(spectral_bound(scene))) + 1


def krylov_refusal(scene: Scene, *, t_max: float = 0.0, count: int = 0,
                   order: int = 0) -> str | None:
    """None when the engine can serve this request, else why not (one sentence).

    It needs rational entries, no forcing, a diagonal positive M, a symmetric K and K, C
    whose symmetric parts are diagonally dominant with a non-negative diagonal (K ⪰ 0,
    C + Cᵀ ⪰ 0, proved exactly): the energy then never grows. A last time beyond
    Limits.krylov_max_steps steps is refused (``count`` does not matter: the cost per time
    is one float64 sum).

    Examples
    --------
    >>> ok = Scene.from_matrices(M=[[1, 0], [0, 2]], C=[[1, 0], [0, 0]], K=[[2, -1], [-1, 1]],
    ...                          x0=[1, 0], v0=[0, 0])
    >>> krylov_refusal(ok) is None
    True
    >>> krylov_refusal(ok, t_max=1e9).endswith("Taylor steps > Limits.krylov_max_steps = 200,000")
    True
    >>> krylov_refusal(Scene.from_matrices(M=[[1]], C=[[-1]], K=[[1]], x0=[1], v0=[0]))
    'C + Cᵀ is not diagonally dominant with a non-negative diagonal (C + Cᵀ ⪰ 0 is not proved)'
    """
    why = scene_refusal(scene)
    if why is not None:
        return why
    if order > 2:
        return f"derivative order {order} > 2"
    steps = _steps(scene, t_max)
    if steps > limits().krylov_max_steps:
        return (f"t = {t_max:g} needs {steps:,.0f} Taylor steps > Limits.krylov_max_steps = "
                f"{limits().krylov_max_steps:,}")
    return None


#: Cost constants (seconds, one core of the development machine; see krylov_cost).
_BUILD = (1e-3, 5e-6)              # fixed, per nonzero of M, C, K (reading and checks)
_STEP = (3e-4, 2.5e-9, 2e-8)       # per step: fixed, per term·nonzero, per term·coordinate
_TIME = (2e-5, 2.5e-9)             # per time: fixed, per term·coordinate


def krylov_cost(scene: Scene, *, t_max: float = 100.0, count: int = 100, order: int = 0) -> float:
    """Estimated seconds of building the engine and evaluating ``count`` times up to
    ``t_max`` (cheap: reads the entries once).

    The model (the planner's, :mod:`laplace_springs.planning.engines`), measured on chains
    and meshes of 1,000 to 10,000 masses (one core): building 1 ms + 5 µs per nonzero of
    M, C, K; then t_max/H + 1 steps of about 60 sparse-product equivalents each (m ≈ 37
    terms at θ = 5, a third of them double-double at 2.5 products), a step costing
    0.3 ms + 60·(2.5 ns·nnz + 20 ns·n); and per time 20 µs + 2.5 ns·m·n (a third more
    per derivative order).

    >>> scene = Scene.from_matrices(M=[[1]], C=[[1]], K=[[4]], x0=[1], v0=[0])
    >>> 0 < krylov_cost(scene, t_max=10.0, count=100) < 0.1
    True
    """
    n = scene.n
    nnz = sum(len(rational_entries(scene, name) or {}) for name in ("M", "C", "K"))
    products, terms = 60.0, 37.0
    step = _STEP[0] + products * (_STEP[1] * nnz + _STEP[2] * n)
    per_time = (_TIME[0] + _TIME[1] * terms * n) * (1 + order / 3)
    return _BUILD[0] + _BUILD[1] * nnz + _steps(scene, t_max) * step + count * per_time


# ----------------------------------------------------------------------------- the motion


class KrylovMotion:
    """x(t), x'(t), x''(t) of a scene from Taylor steps (see the module notes).

    The march keeps the state at the start of its steps (checkpoints, at most
    Limits.krylov_checkpoint_floats numbers), so a later call starts from the nearest one;
    a step is computed the same way whatever the call, so a value does not depend on the
    other times asked.
    """

    def __init__(self, data: KrylovData) -> None:
        self.data = data
        self.stepper = Stepper(data)
        self.H = data.H
        self.m = self.stepper.m
        zh, zl = data.z0
        n = data.n
        start_energy = 3 * U * U * (math.sqrt(data.m_max) * float(np.linalg.norm(zh[n:]))
                                    + math.sqrt(data.norm_K) * float(np.linalg.norm(zh[:n])))
        start_x = 3 * U * U * float(np.max(np.abs(zh[:n]), initial=0.0))
        self._checkpoints: dict[int, tuple[np.ndarray, np.ndarray, float, float]] = {
            0: (zh.copy(), zl.copy(), start_energy, start_x)}
        self._keys = [0]
        self._stride = 1

    @property
    def n(self) -> int:
        return self.data.n

    # -- the march ---------------------------------------------------------------------
    def _store(self, j: int, state: tuple[np.ndarray, np.ndarray, float, float]) -> None:
        if j % self._stride or j in self._checkpoints:
            return
        self._checkpoints[j] = state
        bisect.insort(self._keys, j)
        if len(self._keys) * 4 * max(self.n, 1) > limits().krylov_checkpoint_floats and len(self._keys) > 2:
            self._stride *= 2
            self._keys = [k for k in self._keys if k % self._stride == 0]
            self._checkpoints = {k: self._checkpoints[k] for k in self._keys}

    def _next(self, j: int, state: tuple[np.ndarray, np.ndarray, float, float],
              terms: StepTerms) -> tuple[np.ndarray, np.ndarray, float, float]:
        """The state at step j + 1 from step j's terms, with its error bounds."""
        d, stepper = self.data, self.stepper
        _, _, E, X = state
        zh, zl, sum_energy, sum_x = stepper.advance(terms)
        root = math.sqrt(d.m_min)
        scale = d.energy + E
        local = stepper.tail * scale + terms.rounding + sum_energy
        local_x = (stepper.tail / d.nu * scale + d.H * terms.rounding_x) / root + sum_x
        carried = min(X + d.H * E / root, d.compliance * E)
        following = (zh, zl, (E + local) * (1 + 1e-12), (carried + local_x) * (1 + 1e-12))
        self._store(j + 1, following)
        return following

    def _walk(self, steps: np.ndarray) -> Any:
        """Yield (j, state, terms) for each step j of the sorted array ``steps``."""
        base = self._keys[bisect.bisect_right(self._keys, int(steps[0])) - 1]
        j, state = base, self._checkpoints[base]
        for wanted in steps:
            while j < wanted:
                state = self._next(j, state, self.stepper.terms(state[0], state[1]))
                j += 1
            terms = self.stepper.terms(state[0], state[1])
            yield j, state, terms
            state = self._next(j, state, terms)
            j += 1

    # -- evaluation --------------------------------------------------------------------
    def evaluate(self, times: Times | np.ndarray, order: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """d^order x/dt^order at the times (t ≥ 0) and a bound on each entry's error, both
        shape (n, len(times)); a time beyond Limits.krylov_max_steps steps gets NaN and an
        infinite bound.

        Examples
        --------
        x'' + x' + 4x = 0, x(0) = 1 against its closed form:

        >>> motion = krylov_motion(Scene.from_matrices(M=[[1]], C=[[1]], K=[[4]], x0=[1], v0=[0]))
        >>> values, bounds = motion.evaluate(np.array([0.0, 2.0]))
        >>> w = np.sqrt(15) / 2
        >>> exact = np.exp(-1.0) * (np.cos(2 * w) + np.sin(2 * w) / (2 * w))
        >>> bool(abs(values[0, 1] - exact) <= bounds[0, 1] < 1e-14)
        True
        """
        if isinstance(times, Times):
            hi, lo = times.hi, times.lo
        else:
            hi = np.asarray(times, dtype=float).ravel()
            lo = np.zeros_like(hi)
        if order not in (0, 1, 2):
            raise ValueError(f"derivative order must be 0, 1 or 2, got {order!r}")
        n, T = self.n, hi.size
        values = np.full((n, T), np.nan)
        bounds = np.full((n, T), np.inf)
        if T == 0:
            return values, bounds
        step = self._step_index(hi)
        served = step < limits().krylov_max_steps
        if served.any():
            wanted = np.unique(step[served])
            if order < 2:
                self._fill(hi, step, wanted, order, values, bounds)
            else:
                self._fill_acceleration(hi, step, wanted, values, bounds)
        if lo.any():  # a decimal time: evaluated at hi, off by lo·x^(order+1)
            bounds = bounds + 2 * np.abs(lo)[None, :] * self.slope_bound(order)
        return values, bounds

    def _step_index(self, hi: np.ndarray) -> np.ndarray:
        H = self.H
        with np.errstate(over="ignore", invalid="ignore"):
            j = np.floor(np.minimum(hi / H, 2.0**62)).astype(np.int64)
        j = np.where(hi - j * H < 0, j - 1, j)
        return np.where(hi - (j + 1) * H >= 0, j + 1, j)

    def _fill(self, hi: np.ndarray, step: np.ndarray, wanted: np.ndarray, order: int,
              values: np.ndarray, bounds: np.ndarray) -> None:
        for j, state, terms in self._walk(wanted):
            columns = np.flatnonzero(step == j)
            s = hi[columns] - j * self.H          # exact (Sterbenz, or j = 0)
            found, rounding = self.stepper.values(terms, s / self.H, order)
            values[:, columns] = found.T
            bounds[:, columns] = self._bound(state, terms, s, rounding, order)[None, :]

    def _bound(self, state: tuple[np.ndarray, np.ndarray, float, float], terms: StepTerms,
               s: np.ndarray, rounding: np.ndarray, order: int) -> np.ndarray:
        """The bound of a value at b + s of a step from ``state`` (module notes)."""
        d, stepper = self.data, self.stepper
        _, _, E, X = state
        root = math.sqrt(d.m_min)
        scale = d.energy + E
        if order == 0:
            carried = np.minimum(X + s * (E / root), d.compliance * E)
            fixed = (stepper.tail / d.nu * scale + d.H * terms.rounding_x) / root
            clock = U * s * (d.energy / root)
        else:
            carried = np.full(s.shape, E / root)
            fixed = (stepper.tail * scale + terms.rounding) / root
            clock = U * s * (d.nu * d.energy / root)
        return (carried + fixed + rounding + clock) * (1 + 1e-12) + _TINY

    def _fill_acceleration(self, hi: np.ndarray, step: np.ndarray, wanted: np.ndarray,
                           values: np.ndarray, bounds: np.ndarray) -> None:
        """x'' = −B·(x, x') from the step's x and x' (module notes)."""
        d = self.data
        for j, state, terms in self._walk(wanted):
            columns = np.flatnonzero(step == j)
            s = hi[columns] - j * self.H
            r = s / self.H
            x, round_x = self.stepper.values(terms, r, 0)
            v, round_v = self.stepper.values(terms, r, 1)
            bx = self._bound(state, terms, s, round_x, 0)
            bv = self._bound(state, terms, s, round_v, 1)
            states = np.concatenate([x, v], axis=1).T          # (2n, T_j)
            values[:, columns] = -(d.matrix @ states)
            size = abs(d.matrix) @ np.abs(states)
            gamma = (d.width + 3) * U / (1 - (d.width + 3) * U)
            bounds[:, columns] = ((d.row_K[:, None] * bx[None, :] + d.row_C[:, None] * bv[None, :])
                                  * (1 + 1e-12) + gamma * size + _TINY)

    def slope_bound(self, order: int) -> float:
        """A bound on |x^(order+1)_i(t)| for every i and t ≥ 0 (for decimal times)."""
        d = self.data
        return d.nu ** order * d.energy / math.sqrt(d.m_min) * 1.01

    def poles(self, count: int = 6) -> np.ndarray:
        """Some poles: all of them (dense) up to Limits.dense_poles_max_coordinates, else the
        ``count`` of largest modulus and the ``count`` nearest 0 (ARPACK; empty where it
        fails)."""
        import scipy.linalg as sla
        import scipy.sparse as sps
        import scipy.sparse.linalg as spla

        d = self.data
        n = d.n
        A = sps.bmat([[None, sps.identity(n)], [-d.matrix[:, :n], -d.matrix[:, n:]]], format="csc")
        if n <= limits().dense_poles_max_coordinates:
            return np.sort_complex(sla.eigvals(A.toarray()))
        found = []
        for kw in ({"which": "LM"}, {"sigma": 0.0, "which": "LM"}):
            try:
                found.append(spla.eigs(A, k=count, return_eigenvectors=False, tol=1e-10, **kw))
            except (RuntimeError, ValueError, spla.ArpackError):
                continue
        return np.sort_complex(np.unique(np.concatenate(found))) if found else np.zeros(0, complex)


def krylov_motion(scene: Scene) -> KrylovMotion:
    """The Taylor-step motion of a scene :func:`krylov_refusal` accepts (SceneError if not).

    >>> krylov_motion(Scene.from_matrices(M=[[1]], C=[[1]], K=[[4]], x0=[1], v0=[0])).m > 4
    True
    """
    return KrylovMotion(krylov_data(scene))
