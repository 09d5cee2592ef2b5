"""The krylov engine's march: steps from checkpoints, the error bound carried from step to
step and the values inside a step (:class:`KrylovMotion`, the Taylor steps of
:mod:`.krylov_steps`; the module notes of :mod:`.krylov` give the bound).
"""

from __future__ import annotations

import bisect
import math
from typing import Any

import numpy as np

from ..kernels.dd import U
from ..limits import limits
from .krylov_data import KrylovData
from .krylov_steps import Stepper, StepTerms
from .times import Times

__all__ = ["KrylovMotion"]

_TINY = 1e-300


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
        d = self.data
        _, _, E, X = state
        zh, zl, sum_energy, sum_x = self.stepper.advance(terms)
        root = math.sqrt(d.m_min)
        local = terms.truncation + terms.rounding + sum_energy
        local_x = terms.truncation_x + d.H * terms.rounding_x / root + sum_x
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

        >>> from laplace_springs import Scene
        >>> from laplace_springs.numeric.krylov import krylov_motion
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
        d = self.data
        _, _, E, X = state
        root = math.sqrt(d.m_min)
        if order == 0:
            carried = np.minimum(X + s * (E / root), d.compliance * E)
            fixed = terms.truncation_x + d.H * terms.rounding_x / root
            clock = U * s * (d.energy / root)
        else:
            carried = np.full(s.shape, E / root)
            fixed = (terms.truncation + terms.rounding) / root
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
