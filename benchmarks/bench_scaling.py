"""Scaling benchmark (issue 14, item 3): time, peak memory and error against the number of masses.

Scenes (n = 10, 100, 1,000, 10,000 by default), each with x0 = 1 on the first mass, v0 = 0:

* ``chain-rayleigh``: a fixed-fixed chain of n unit masses and unit springs, with Rayleigh
  damping C = 0.002 K + 0.01 M (a dashpot 1/500 beside every spring and 1/100 from every
  mass to the wall): classical damping;
* ``chain-wall-dashpot``: the same chain and one more dashpot, 1/2, from the middle mass
  (index n // 2) to the wall: non-classical damping;
* ``mesh-rayleigh``: a random connected spring graph (seeded by n): a random tree plus
  random extra springs, 3n springs in all, 1 + n // 50 of them to the wall, stiffness 1, 2
  or 3, masses 1 or 2; Rayleigh damping as above (classical);
* ``mesh-wall-dashpot``: the same mesh and the dashpot 1/2 at the middle mass.

Methods (each (method, scene) runs in a fresh subprocess, so its peak memory is its own):

* ``laplace_springs``: ``ls.solve(scene).evaluate(times, return_error=True)``, timed from
  the exact Scene (built untimed), caches cleared before every run; whatever route
  ``method="auto"`` takes when the benchmark is run;
* ``numpy-eig``: ``numpy.linalg.eig`` of the dense 2n x 2n first-order matrix Z, the
  initial data expanded in its eigenvectors (dense, skipped above n = 2,000);
* ``modal-eigh``: the hand-written symmetric modal route for classical damping:
  ``scipy.linalg.eigh_tridiagonal`` (chains) or dense ``scipy.linalg.eigh(K, M)``
  (meshes, skipped above n = 4,000), modal damping from diag(Φᵀ C Φ), each mode's damped
  motion in closed form;
* ``expm_multiply``: ``scipy.sparse.linalg.expm_multiply`` of the sparse Z with
  start/stop/num (the times are a linspace);
* ``scipy-expm``: dense ``scipy.linalg.expm(Z Δt)`` once, then T - 1 products (the times
  are uniform; one expm per time would cost T times more); skipped above n = 1,000.

Peers get float64 data (M, K, C, Z) built untimed. Times: 1,000 on [0, 50] for n ≤ 1,000,
100 for larger n (``--quick``: 100 everywhere). Time is the fastest of up to 5 runs,
repeated while their total is under 1 s (a single run from n = 10,000 on). Peak memory is
the subprocess's VmHWM during the runs minus its resident size just before them (the peak
is reset through /proc/self/clear_refs once the inputs are built). Error is
max |x − x_ref| / max |x_ref| over coordinates and times, against

* the uniform chain with Rayleigh damping: the analytic modal solution (ω_j = 2 sin(jπ/(2(n+1))),
  shapes sin(ijπ/(n+1)), a_j = ζ_j ω_j = (0.01 + 0.002 ω_j²)/2), in mpmath for n ≤ 30 and
  otherwise in float64 with the phases ω_j t carried in double-double and the sum over
  modes as a type-I discrete sine transform;
* other scenes with n ≤ 30: python-flint's certified arb matrix exponential
  (``laplace_springs.bench.reference.reference_motion_arb``, 20 digits);
* larger non-analytic scenes: Taylor steps of exp(Z h) in double-double arithmetic (about
  32 digits) on the sparse first-order matrix formed from the exact values
  (:class:`DoubleDoubleTaylor`; it agrees with the arb reference to 1e-30 on small scenes,
  and takes up to a few minutes at n = 10,000).

Run (OPENBLAS_NUM_THREADS=1 for one core per method):

    python benchmarks/bench_scaling.py --sizes 10,100 --quick     # a minute
    python benchmarks/bench_scaling.py --write                    # full table into README.md
"""

from __future__ import annotations

import argparse
import gc
import json
import math
import os
import platform
import resource
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import Any

import mpmath
import numpy as np

HERE = Path(__file__).resolve().parent
README = HERE / "README.md"
PLOT = HERE / "scaling.png"
START, END = "<!-- scaling:start -->", "<!-- scaling:end -->"

FAMILIES = ("chain-rayleigh", "chain-wall-dashpot", "mesh-rayleigh", "mesh-wall-dashpot")
CLASSICAL = ("chain-rayleigh", "mesh-rayleigh")
METHODS = ("laplace_springs", "numpy-eig", "modal-eigh", "expm_multiply", "scipy-expm")
#: Dense methods are not run above these sizes (time grows like n³, memory like n²).
DENSE_LIMITS = {"numpy-eig": 2_000, "scipy-expm": 1_000, "modal-eigh-dense": 4_000}
HORIZON = 50.0
ALPHA, BETA = Fraction(1, 100), Fraction(1, 500)      # C = BETA K + ALPHA M
WALL_DASHPOT = Fraction(1, 2)
ARB_MAX_N = 30

Component = tuple[int, int, Fraction]                # (i, j, value); j = -1 is the wall


# ----------------------------------------------------------------------------- scenes


@dataclass
class Spec:
    """A scene as plain data: masses, springs and dashpots with exact values."""

    family: str
    n: int
    masses: list[Fraction]
    springs: list[Component]
    dashpots: list[Component]


def _chain_springs(n: int) -> list[Component]:
    return [(0, -1, Fraction(1))] + [(i, i + 1, Fraction(1)) for i in range(n - 1)] + [
        (n - 1, -1, Fraction(1))]


def _mesh(n: int) -> tuple[list[Fraction], list[Component]]:
    """A random connected spring graph with 3n springs (seeded by n)."""
    rng = np.random.default_rng(1400 + n)
    masses = [Fraction(int(v)) for v in rng.integers(1, 3, n)]
    walls = sorted({0, *(int(i) for i in rng.choice(n, size=n // 50, replace=False))})
    edges: set[tuple[int, int]] = {(int(rng.integers(0, i)), i) for i in range(1, n)}
    wanted = min(3 * n - len(walls), n * (n - 1) // 2)
    while len(edges) < wanted:
        i, j = (int(v) for v in rng.integers(0, n, 2))
        if i != j:
            edges.add((min(i, j), max(i, j)))
    stiffness = rng.integers(1, 4, len(edges) + len(walls))
    springs = [(i, j, Fraction(int(k))) for (i, j), k in zip(sorted(edges), stiffness)]
    springs += [(i, -1, Fraction(int(k))) for i, k in zip(walls, stiffness[len(edges):])]
    return masses, springs


def scene_spec(family: str, n: int) -> Spec:
    """The scene of a family at size n (see the module docstring)."""
    if family.startswith("chain"):
        masses, springs = [Fraction(1)] * n, _chain_springs(n)
    else:
        masses, springs = _mesh(n)
    dashpots = [(i, j, BETA * k) for i, j, k in springs]
    dashpots += [(i, -1, ALPHA * m) for i, m in enumerate(masses)]
    if family.endswith("wall-dashpot"):
        dashpots.append((n // 2, -1, WALL_DASHPOT))
    return Spec(family, n, masses, springs, dashpots)


def build_scene(spec: Spec) -> Any:
    """The exact laplace_springs Scene (``Scene.from_components``)."""
    import laplace_springs as ls

    names = [f"m{i + 1}" for i in range(spec.n)]

    def node(i: int) -> str:
        return "wall" if i < 0 else names[i]

    return ls.Scene.from_components(
        masses={name: str(m) for name, m in zip(names, spec.masses)},
        springs={f"k{e}": (node(i), node(j), str(v)) for e, (i, j, v) in enumerate(spec.springs)},
        dashpots={f"c{e}": (node(i), node(j), str(v)) for e, (i, j, v) in enumerate(spec.dashpots)},
        x0={"m1": 1}, title=f"{spec.family}, n = {spec.n}")


def float_arrays(spec: Spec) -> tuple[np.ndarray, Any, Any]:
    """m (the diagonal of M), K and C as float64 (scipy CSR), from the exact values."""
    import scipy.sparse as sps

    def assemble(components: list[Component]) -> Any:
        rows, cols, values = [], [], []
        for i, j, v in components:
            value = float(v)
            rows.append(i)
            cols.append(i)
            values.append(value)
            if j >= 0:
                rows += [j, i, j]
                cols += [j, j, i]
                values += [value, -value, -value]
        return sps.csr_matrix((values, (rows, cols)), shape=(spec.n, spec.n))

    return np.array([float(m) for m in spec.masses]), assemble(spec.springs), assemble(spec.dashpots)


def first_order(m: np.ndarray, K: Any, C: Any) -> tuple[Any, np.ndarray]:
    """Sparse Z = [[0, I], [-M⁻¹K, -M⁻¹C]] (CSC) and y0 = [x0; v0]."""
    import scipy.sparse as sps

    n = len(m)
    inverse = sps.diags(1.0 / m)
    Z = sps.bmat([[None, sps.identity(n)], [-(inverse @ K), -(inverse @ C)]], format="csc")
    y0 = np.zeros(2 * n)
    y0[0] = 1.0
    return Z, y0


# ----------------------------------------------------------------------------- methods


def run_laplace_springs(scene: Any, times: np.ndarray) -> tuple[np.ndarray, dict[str, Any]]:
    import laplace_springs as ls

    solution = ls.solve(scene)
    values, bounds = solution.evaluate(times, return_error=True)
    scale = float(np.max(np.abs(values))) or 1.0
    return values, {"route": solution.method, "bound": float(np.max(bounds)) / scale}


def run_numpy_eig(Z: Any, y0: np.ndarray, times: np.ndarray) -> np.ndarray:
    n = Z.shape[0] // 2
    w, V = np.linalg.eig(Z.toarray())
    c = np.linalg.solve(V, y0.astype(complex))
    return ((V[:n] * c) @ np.exp(np.outer(w, times))).real


def modal_motion(a: np.ndarray, w2: np.ndarray, q0: np.ndarray, qd0: np.ndarray,
                 times: np.ndarray) -> np.ndarray:
    """q_j(t) of q'' + 2 a_j q' + w2_j q = 0 (float64, one row per mode)."""
    mu = (a * a - w2)[:, None]                    # > 0 overdamped, < 0 underdamped
    t = times[None, :]
    root = np.sqrt(np.abs(mu))
    arg = root * t
    under = mu < 0
    with np.errstate(invalid="ignore", divide="ignore"):
        cos_part = np.where(under, np.cos(arg), np.cosh(arg))
        sin_part = np.where(under, np.sin(arg), np.sinh(arg)) / root
    sin_part = np.where(root == 0, t, sin_part)
    a_ = a[:, None]
    return np.exp(-a_ * t) * (q0[:, None] * cos_part + (qd0 + a * q0)[:, None] * sin_part)


def run_modal_eigh(m: np.ndarray, K: Any, C: Any, times: np.ndarray, chain: bool) -> np.ndarray:
    import scipy.linalg as sla

    if chain:                                      # M = I, K tridiagonal
        w2, Phi = sla.eigh_tridiagonal(K.diagonal(), K.diagonal(1))
    else:
        w2, Phi = sla.eigh(K.toarray(), np.diag(m))   # Φᵀ M Φ = I
    damping = np.einsum("ij,ij->j", Phi, C @ Phi)   # diag(Φᵀ C Φ) = 2 a_j
    x0 = np.zeros(len(m))
    x0[0] = 1.0
    q0 = Phi.T @ (m * x0)
    return Phi @ modal_motion(damping / 2, w2, q0, np.zeros_like(q0), times)


def run_expm_multiply(Z: Any, y0: np.ndarray, times: np.ndarray) -> np.ndarray:
    from scipy.sparse.linalg import expm_multiply

    n = Z.shape[0] // 2
    Y = expm_multiply(Z, y0, start=times[0], stop=times[-1], num=len(times), endpoint=True)
    return np.ascontiguousarray(Y[:, :n].T)


def run_scipy_expm(Z: Any, y0: np.ndarray, times: np.ndarray) -> np.ndarray:
    import scipy.linalg as sla

    n = Z.shape[0] // 2
    E = sla.expm(Z.toarray() * (times[1] - times[0]))
    out = np.empty((n, len(times)))
    y = y0.copy()
    out[:, 0] = y[:n]
    for k in range(1, len(times)):
        y = E @ y
        out[:, k] = y[:n]
    return out


# ----------------------------------------------------------------------------- worker


def _status_kb(key: str) -> int:
    with open("/proc/self/status", encoding="ascii") as handle:
        for line in handle:
            if line.startswith(key + ":"):
                return int(line.split()[1])
    return 0


def _reset_peak() -> bool:
    try:
        with open("/proc/self/clear_refs", "w", encoding="ascii") as handle:
            handle.write("5")
    except OSError:
        return False
    return True


def worker(task: dict[str, Any]) -> dict[str, Any]:
    """Run one method on one scene (in its own process) and report time and memory."""
    if task.get("memory_gb"):
        limit = int(task["memory_gb"] * 2**30)
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    import scipy.linalg
    import scipy.sparse.linalg  # noqa: F401

    import laplace_springs  # noqa: F401
    from laplace_springs.bench.harness import clear_caches

    method, spec = task["method"], scene_spec(task["family"], task["n"])
    times = np.linspace(0.0, HORIZON, task["count"])
    info: dict[str, Any] = {}
    if method == "baseline":
        return {"rss_kb": _status_kb("VmRSS"), "hwm_kb": _status_kb("VmHWM")}
    if method == "laplace_springs":
        scene = build_scene(spec)

        def run() -> np.ndarray:
            clear_caches()
            values, extra = run_laplace_springs(scene, times)
            info.update(extra)
            return values
    else:
        m, K, C = float_arrays(spec)
        Z, y0 = first_order(m, K, C)
        chain = spec.family.startswith("chain")
        run = {"numpy-eig": lambda: run_numpy_eig(Z, y0, times),
               "modal-eigh": lambda: run_modal_eigh(m, K, C, times, chain),
               "expm_multiply": lambda: run_expm_multiply(Z, y0, times),
               "scipy-expm": lambda: run_scipy_expm(Z, y0, times)}[method]
    gc.collect()
    reset = _reset_peak()
    before = _status_kb("VmRSS")
    seconds: list[float] = []
    values = None
    while True:
        values = None
        start = time.perf_counter()
        values = run()
        seconds.append(time.perf_counter() - start)
        if len(seconds) >= task["repeats"] or sum(seconds) >= task["budget"]:
            break
    peak = _status_kb("VmHWM") - (before if reset else task.get("baseline_kb", 0))
    np.save(task["out"], np.asarray(values, dtype=float))
    return {"seconds": min(seconds), "runs": len(seconds), "peak_mb": peak / 1024,
            "peak_reset": reset, **info}


# ----------------------------------------------------------------------------- references


def _two_product(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """a·b = p + e exactly (Dekker), for float64 arrays without overflow."""
    split = 134217729.0                            # 2**27 + 1

    def halves(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        c = split * x
        high = c - (c - x)
        return high, x - high

    p = a * b
    ah, al = halves(a)
    bh, bl = halves(b)
    return p, ((ah * bh - p) + ah * bl + al * bh) + al * bl


def _chain_mode_constants(n: int) -> dict[str, np.ndarray]:
    """Per mode of the uniform chain (mpmath, 40 digits, rounded once): the weight
    (2/(n+1)) sin(jπ/(n+1)) of x0 = e_1, a_j, and the damped frequency or decay root."""
    weight, a, root_hi, root_lo, under = (np.empty(n) for _ in range(5))
    with mpmath.workdps(40):
        for index in range(n):
            j = index + 1
            omega = 2 * mpmath.sin(j * mpmath.pi / (2 * (n + 1)))
            aj = (mpmath.mpf(1) / 100 + omega**2 / 500) / 2
            mu = aj**2 - omega**2
            root = mpmath.sqrt(abs(mu))
            weight[index] = float(2 * mpmath.sin(j * mpmath.pi / (n + 1)) / (n + 1))
            a[index] = float(aj)
            root_hi[index] = float(root)
            root_lo[index] = float(root - mpmath.mpf(root_hi[index]))
            under[index] = mu < 0
    return {"weight": weight, "a": a, "hi": root_hi, "lo": root_lo, "under": under}


def chain_reference_float(n: int, times: np.ndarray) -> np.ndarray:
    """Analytic motion of the Rayleigh-damped unit chain, x0 = e_1, in careful float64."""
    import scipy.fft

    k = _chain_mode_constants(n)
    t = np.broadcast_to(times[None, :], (n, len(times)))
    hi = np.broadcast_to(k["hi"][:, None], t.shape)
    p, e = _two_product(hi, t)
    delta = e + k["lo"][:, None] * t                     # root·t = p + delta, |delta| ≲ 1e-14
    under = k["under"][:, None].astype(bool)
    cos_p, sin_p = np.cos(p), np.sin(p)
    cos_part = np.where(under, cos_p - sin_p * delta, np.cosh(p + delta))
    sine = np.where(under, sin_p + cos_p * delta, np.sinh(p + delta))
    root = np.broadcast_to(k["hi"][:, None], t.shape)
    with np.errstate(invalid="ignore", divide="ignore"):
        sin_part = np.where(root == 0, t, sine / root)
    a = k["a"][:, None]
    q = np.exp(-a * t) * (cos_part + a * sin_part)
    return scipy.fft.dst(k["weight"][:, None] * q, type=1, axis=0) / 2


def chain_reference_mp(n: int, times: np.ndarray, dps: int = 30) -> list[list[Any]]:
    """The same analytic motion in mpmath (for small n): rows of mpf."""
    with mpmath.workdps(dps):
        modes = []
        for j in range(1, n + 1):
            omega = 2 * mpmath.sin(j * mpmath.pi / (2 * (n + 1)))
            aj = (mpmath.mpf(1) / 100 + omega**2 / 500) / 2
            modes.append((aj, aj**2 - omega**2))
        q = []
        for aj, mu in modes:
            row = []
            for tv in times:
                t = mpmath.mpf(float(tv))
                if mu < 0:
                    r = mpmath.sqrt(-mu)
                    c, s = mpmath.cos(r * t), mpmath.sin(r * t) / r
                elif mu > 0:
                    r = mpmath.sqrt(mu)
                    c, s = mpmath.cosh(r * t), mpmath.sinh(r * t) / r
                else:
                    c, s = mpmath.mpf(1), t
                row.append(mpmath.exp(-aj * t) * (c + aj * s))
            q.append(row)
        rows = []
        for i in range(1, n + 1):
            shape = [2 * mpmath.sin(i * j * mpmath.pi / (n + 1)) * mpmath.sin(j * mpmath.pi / (n + 1))
                     / (n + 1) for j in range(1, n + 1)]
            rows.append([mpmath.fsum(shape[j] * q[j][col] for j in range(n))
                         for col in range(len(times))])
        return rows


def _two_sum(a: Any, b: Any) -> tuple[Any, Any]:
    s = a + b
    bb = s - a
    return s, (a - (s - bb)) + (b - bb)


def _fast_two_sum(a: Any, b: Any) -> tuple[Any, Any]:
    s = a + b
    return s, b - (s - a)


def _dd_add(ah: Any, al: Any, bh: Any, bl: Any) -> tuple[Any, Any]:
    s, e = _two_sum(ah, bh)
    t, f = _two_sum(al, bl)
    s, e = _fast_two_sum(s, e + t)
    return _fast_two_sum(s, e + f)


def _dd_mul(ah: Any, al: Any, bh: Any, bl: Any) -> tuple[Any, Any]:
    p, e = _two_product(ah, bh)
    return _fast_two_sum(p, e + (ah * bl + al * bh))


def _dd_div_int(hi: float, lo: float, k: int) -> tuple[float, float]:
    q = hi / k
    p, e = _two_product(np.float64(q), np.float64(k))
    return _fast_two_sum(q, float(((hi - p) - e + lo) / k))


def _dd(value: Fraction) -> tuple[float, float]:
    hi = float(value)
    return hi, float(value - Fraction(hi))


class DoubleDoubleTaylor:
    """x(t) of a scene in double-double arithmetic (about 32 digits), by Taylor steps of
    exp(Z h) on the sparse first-order matrix.

    Independent of every timed method: Z is formed from the exact (Fraction) values, the
    state is u = (s x, v) with s a power of two near sqrt(‖M⁻¹K‖∞) (so ‖Z‖∞ is about
    2 sqrt(‖M⁻¹K‖∞) and every scaling is exact), each step from one output time to the
    next (their difference is exact in double-double) is cut into pieces with ‖Z h‖∞ ≤ 2,
    and each piece sums its Taylor series until the terms fall below 1e-32 of the state.
    """

    STEP_NORM = 2.0

    def __init__(self, spec: Spec) -> None:
        n = spec.n
        K: dict[tuple[int, int], Fraction] = {}
        C: dict[tuple[int, int], Fraction] = {}
        for matrix, components in ((K, spec.springs), (C, spec.dashpots)):
            for i, j, v in components:
                matrix[i, i] = matrix.get((i, i), Fraction(0)) + v
                if j >= 0:
                    matrix[j, j] = matrix.get((j, j), Fraction(0)) + v
                    matrix[i, j] = matrix.get((i, j), Fraction(0)) - v
                    matrix[j, i] = matrix.get((j, i), Fraction(0)) - v
        rows: list[list[tuple[int, Fraction]]] = [[] for _ in range(2 * n)]
        sums = [Fraction(0)] * n
        for (i, _), v in K.items():
            sums[i] += abs(v)
        stiff = max(s / m for s, m in zip(sums, spec.masses))     # ‖M⁻¹K‖∞
        self.scale = 2.0 ** round(math.log2(math.sqrt(float(stiff))))
        s = Fraction(self.scale)
        for r in range(n):
            rows[r].append((n + r, s))
        for (i, j), v in K.items():
            rows[n + i].append((j, -v / (spec.masses[i] * s)))
        for (i, j), v in C.items():
            rows[n + i].append((n + j, -v / spec.masses[i]))
        # entries in slots: slot k holds the k-th entry of every row that has one, so a
        # product is one vectorised double-double multiply and a few slot-wise additions
        entries = [(k, r, c, v) for r, row in enumerate(rows) for k, (c, v) in enumerate(row)]
        entries.sort(key=lambda e: (e[0], e[1]))
        slot = np.array([e[0] for e in entries])
        self.rows = np.array([e[1] for e in entries], dtype=np.intp)
        self.cols = np.array([e[2] for e in entries], dtype=np.intp)
        parts = [_dd(e[3]) for e in entries]
        self.hi = np.array([p[0] for p in parts])
        self.lo = np.array([p[1] for p in parts])
        bounds = np.searchsorted(slot, np.arange(slot.max() + 2))
        self.slots = [(int(a), int(b)) for a, b in zip(bounds, bounds[1:]) if b > a]
        row_sums = np.zeros(2 * n)
        np.add.at(row_sums, self.rows, np.abs(self.hi))
        self.norm = float(row_sums.max())
        self.n = n

    def _matvec(self, vh: np.ndarray, vl: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        ph, pl = _dd_mul(self.hi, self.lo, vh[self.cols], vl[self.cols])
        yh = np.zeros_like(vh)
        yl = np.zeros_like(vl)
        for a, b in self.slots:                      # rows within one slot are distinct
            rows = self.rows[a:b]
            yh[rows], yl[rows] = _dd_add(yh[rows], yl[rows], ph[a:b], pl[a:b])
        return yh, yl

    def _step(self, uh: np.ndarray, ul: np.ndarray, hh: float, hl: float) -> tuple[np.ndarray, np.ndarray]:
        acc_h, acc_l = uh.copy(), ul.copy()
        th, tl = uh, ul
        x = self.norm * abs(hh)
        for k in range(1, 400):
            th, tl = self._matvec(th, tl)
            sh, sl = _dd_div_int(hh, hl, k)
            th, tl = _dd_mul(th, tl, sh, sl)
            acc_h, acc_l = _dd_add(acc_h, acc_l, th, tl)
            if k > 2 * x and np.max(np.abs(th)) <= 1e-32 * np.max(np.abs(acc_h)):
                return acc_h, acc_l
        raise ArithmeticError("Taylor series did not converge")

    def motion(self, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """x at the (float64, increasing) times, as high and low float64 parts."""
        n = self.n
        uh, ul = np.zeros(2 * n), np.zeros(2 * n)
        uh[0] = self.scale                           # u = (s x0, v0), x0 = e_1
        high, low = np.empty((n, len(times))), np.empty((n, len(times)))
        now = 0.0
        for index, t in enumerate(times):
            dh, dl = _two_sum(float(t), -now)
            pieces = max(1, math.ceil(abs(dh) * self.norm / self.STEP_NORM)) if dh else 0
            if pieces:
                hh, hl = _dd_div_int(dh, dl, pieces)
                for _ in range(pieces):
                    uh, ul = self._step(uh, ul, hh, hl)
            now = float(t)
            high[:, index], low[:, index] = _fast_two_sum(uh[:n] / self.scale, ul[:n] / self.scale)
        return high, low


def _split(rows: Any) -> tuple[np.ndarray, np.ndarray]:
    """mpf values as float64 high and low parts."""
    high = np.array([[float(v) for v in row] for row in rows])
    with mpmath.workdps(40):
        low = np.array([[float(v - mpmath.mpf(h)) for v, h in zip(row, hrow)]
                        for row, hrow in zip(rows, high)])
    return high, low


@dataclass
class Reference:
    kind: str
    high: np.ndarray
    low: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def error(self, values: np.ndarray) -> float:
        if values.shape != self.high.shape:
            return math.inf
        low = self.low if self.low.size else 0.0
        difference = np.abs((values - self.high) - low)
        if not np.all(np.isfinite(difference)):
            return math.inf
        return float(difference.max() / np.max(np.abs(self.high)))


def reference_for(spec: Spec, times: np.ndarray) -> Reference:
    """The independent reference of a scene (see the module docstring)."""
    if spec.family == "chain-rayleigh":
        if spec.n <= ARB_MAX_N:
            high, low = _split(chain_reference_mp(spec.n, times))
            return Reference("analytic modal solution (mpmath, 30 digits)", high, low)
        return Reference("analytic modal solution (float64, double-double phases, DST-I)",
                         chain_reference_float(spec.n, times))
    if spec.n <= ARB_MAX_N:
        from laplace_springs.bench.reference import reference_motion_arb

        rows = reference_motion_arb(build_scene(spec), list(times), digits=20)
        high, low = _split(rows)
        return Reference("python-flint arb matrix exponential (20 digits)", high, low)
    high, low = DoubleDoubleTaylor(spec).motion(times)
    return Reference("double-double Taylor steps on the exact sparse Z (about 30 digits)", high, low)


# ----------------------------------------------------------------------------- driver


@dataclass
class Cell:
    status: str                                     # ok, infeasible, timeout, failed, n/a
    seconds: float | None = None
    runs: int = 0
    peak_mb: float | None = None
    error: float | None = None
    note: str = ""
    info: dict[str, Any] = field(default_factory=dict)
    projected: float | None = None                  # seconds, for an infeasible dense method


def applicable(method: str, family: str) -> bool:
    return method != "modal-eigh" or family in CLASSICAL


def dense_limit(method: str, family: str) -> int | None:
    if method == "modal-eigh":
        return None if family.startswith("chain") else DENSE_LIMITS["modal-eigh-dense"]
    return DENSE_LIMITS.get(method)


def run_cell(task: dict[str, Any], limit: float) -> tuple[Cell, np.ndarray | None]:
    command = [sys.executable, str(Path(__file__).resolve()), "--worker", json.dumps(task)]
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=limit, check=False)
    except subprocess.TimeoutExpired:
        return Cell("timeout", note=f"> {limit:g} s (killed)"), None
    if done.returncode != 0:
        lines = [line for line in done.stderr.strip().splitlines() if line.strip()]
        return Cell("failed", note=(lines[-1] if lines else f"exit {done.returncode}")[:200]), None
    result = json.loads(done.stdout.strip().splitlines()[-1])
    values = np.load(task["out"])
    info = {k: v for k, v in result.items() if k in ("route", "bound", "peak_reset")}
    return Cell("ok", result["seconds"], result["runs"], result["peak_mb"], info=info), values


def run_all(sizes: list[int], families: list[str], quick: bool, limit: float, memory_gb: float,
            log: Any) -> dict[str, Any]:
    results: dict[tuple[str, int, str], Cell] = {}
    references: dict[tuple[str, int], str] = {}
    with tempfile.TemporaryDirectory() as tmp:
        baseline_task = {"method": "baseline", "family": families[0], "n": 1, "count": 2,
                         "repeats": 1, "budget": 0.0, "out": ""}
        done = subprocess.run([sys.executable, str(Path(__file__).resolve()), "--worker",
                               json.dumps(baseline_task)], capture_output=True, text=True, check=True)
        baseline = json.loads(done.stdout.strip().splitlines()[-1])
        for family in families:
            for n in sizes:
                count = 100 if quick or n > 1000 else 1000
                times = np.linspace(0.0, HORIZON, count)
                values: dict[str, np.ndarray] = {}
                for method in METHODS:
                    key = (family, n, method)
                    if not applicable(method, family):
                        continue
                    cap = dense_limit(method, family)
                    if cap is not None and n > cap:
                        results[key] = _infeasible(results, family, n, method, sizes)
                        log(f"{family} n={n} {method}: {results[key].note}")
                        continue
                    task = {"method": method, "family": family, "n": n, "count": count,
                            "repeats": (2 if quick else 5) if n < 1000 else (1 if n > 1000 else 3),
                            "budget": 1.0, "memory_gb": memory_gb,
                            "baseline_kb": baseline["hwm_kb"],
                            "out": os.path.join(tmp, f"{family}-{n}-{method}.npy")}
                    cell, array = run_cell(task, limit)
                    results[key] = cell
                    if array is not None:
                        values[method] = array
                    log(f"{family} n={n} {method}: {cell.status} "
                        f"{'' if cell.seconds is None else f'{cell.seconds:.4g} s'} {cell.note}")
                started = time.perf_counter()
                reference = reference_for(scene_spec(family, n), times)
                references[(family, n)] = reference.kind
                log(f"{family} n={n} reference: {reference.kind}, "
                    f"{time.perf_counter() - started:.1f} s")
                for method, array in values.items():
                    results[(family, n, method)].error = reference.error(array)
    return {"cells": results, "references": references, "baseline_mb": baseline["hwm_kb"] / 1024,
            "sizes": sizes, "families": families, "quick": quick, "limit": limit}


def _infeasible(results: dict[tuple[str, int, str], Cell], family: str, n: int, method: str,
                sizes: list[int]) -> Cell:
    """A skipped dense method, with its time projected like n³ from its largest run."""
    measured = [(m, results[(family, m, method)].seconds) for m in sizes
                if m < n and (family, m, method) in results and results[(family, m, method)].seconds]
    words = f"dense, not run above n = {dense_limit(method, family):,}"
    if not measured:
        return Cell("infeasible", note=words)
    m, seconds = measured[-1]
    projected = seconds * (n / m) ** 3
    words += f"; projected {_duration(projected)} (n³ from n = {m:,})"
    return Cell("infeasible", note=words, projected=projected)


def _duration(seconds: float) -> str:
    if seconds < 120:
        return f"{seconds:.3g} s"
    if seconds < 7200:
        return f"{seconds / 60:.3g} min"
    if seconds < 2 * 86400:
        return f"{seconds / 3600:.3g} h"
    return f"{seconds / 86400:.3g} days"


def growth_exponent(points: list[tuple[int, float]]) -> float | None:
    """Least-squares slope of log t against log n (None below two sizes).

    >>> round(growth_exponent([(10, 1.0), (100, 100.0), (1000, 10000.0)]), 6)
    2.0
    """
    if len(points) < 2:
        return None
    x = np.log([p[0] for p in points])
    y = np.log([p[1] for p in points])
    return float(np.polyfit(x, y, 1)[0])


# ----------------------------------------------------------------------------- output


def _seconds(value: float) -> str:
    return f"{value:.2g}" if value < 0.01 else f"{value:.3g}"


def _cell_text(cell: Cell | None, ours: Cell | None) -> str:
    if cell is None:
        return "—"
    if cell.status == "infeasible":
        return f"infeasible ({cell.note})"
    if cell.status != "ok" or cell.seconds is None:
        return f"{cell.status}: {cell.note}".replace("|", "/")
    parts = [f"{_seconds(cell.seconds)} s"]
    if ours is not None and ours.status == "ok" and ours.seconds:
        parts.append(f"{cell.seconds / ours.seconds:.2g}×")
    parts.append(f"{max(cell.peak_mb or 0.0, 0.0):.3g} MB")
    if cell.error is not None:
        parts.append(f"err {cell.error:.1e}")
    return " · ".join(parts)


def markdown(run: dict[str, Any]) -> str:
    cells: dict[tuple[str, int, str], Cell] = run["cells"]
    sizes = run["sizes"]
    threads = os.environ.get("OPENBLAS_NUM_THREADS", "unset")
    lines = [f"Run {time.strftime('%Y-%m-%d %H:%M')}: {platform.machine()}, {os.cpu_count()} cores, "
             f"OPENBLAS_NUM_THREADS={threads}, NumPy {np.__version__}, SciPy {_scipy_version()}, "
             f"load average {os.getloadavg()[0]:.1f} at the end; sizes {', '.join(f'{n:,}' for n in sizes)}"
             f"{'; --quick (100 times, at most 2 runs)' if run['quick'] else ''}; "
             f"a subprocess that only imports peaks at {run['baseline_mb']:.0f} MB. "
             "Each cell: time (fastest run) · ratio to laplace_springs · peak MB over the inputs · "
             "max error relative to max |x|.", ""]
    for family in run["families"]:
        lines += [f"**{family}** ({'classical' if family in CLASSICAL else 'non-classical'} damping)", ""]
        header = "| method | " + " | ".join(f"n = {n:,}" for n in sizes) + " | growth exponent |"
        lines += [header, "|---|" + "---|" * (len(sizes) + 1)]
        for method in METHODS:
            if not applicable(method, family):
                continue
            row = [_cell_text(cells.get((family, n, method)), cells.get((family, n, "laplace_springs")))
                   for n in sizes]
            points = [(n, c.seconds) for n in sizes
                      if (c := cells.get((family, n, method))) is not None and c.status == "ok" and c.seconds]
            exponent = growth_exponent(points)
            lines.append(f"| {method} | " + " | ".join(row)
                         + f" | {'—' if exponent is None else f'{exponent:.2f}'} |")
        routes = []
        for n in sizes:
            c = cells.get((family, n, "laplace_springs"))
            if c is not None and c.status == "ok":
                routes.append(f"n = {n:,}: {c.info.get('route')} (bound {c.info.get('bound', math.nan):.1e})")
        refs = "; ".join(f"n = {n:,}: {run['references'].get((family, n), '—')}" for n in sizes)
        lines += ["", f"laplace_springs route (its own error bound relative to max |x|): "
                  f"{'; '.join(routes) or 'no result'}. Reference: {refs}.", ""]
    return "\n".join(lines)


def _scipy_version() -> str:
    try:
        import scipy
    except ImportError:
        return "not installed"
    return scipy.__version__


def plot(run: dict[str, Any], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cells: dict[tuple[str, int, str], Cell] = run["cells"]
    styles = {"laplace_springs": ("tab:red", "*"), "numpy-eig": ("tab:blue", "s"),
              "modal-eigh": ("tab:green", "^"), "expm_multiply": ("tab:purple", "o"),
              "scipy-expm": ("tab:orange", "D")}
    families = run["families"]
    columns = 2 if len(families) > 1 else 1
    rows = math.ceil(len(families) / columns)
    figure, axes = plt.subplots(rows, columns, figsize=(5.5 * columns, 4.0 * rows), squeeze=False)
    for ax, family in zip(axes.ravel(), families):
        for method in METHODS:
            points = [(n, c.seconds) for n in run["sizes"]
                      if (c := cells.get((family, n, method))) is not None and c.status == "ok" and c.seconds]
            if not points:
                continue
            colour, marker = styles[method]
            ax.loglog(*zip(*points), marker=marker, color=colour, label=method)
            projected = [(n, c.projected) for n in run["sizes"]
                         if (c := cells.get((family, n, method))) is not None and c.projected]
            if projected:
                ax.loglog(*zip(points[-1], *projected), linestyle=":", marker=marker, color=colour,
                          markerfacecolor="none")
        ax.set_title(f"{family} (dotted, hollow: projected)" if any(
            c.projected for (f, _, _), c in cells.items() if f == family) else family)
        ax.set_xlabel("masses n")
        ax.set_ylabel("time (s)")
        ax.grid(True, which="major", alpha=0.3)
        ax.legend(fontsize=7)
    for ax in axes.ravel()[len(families):]:
        ax.set_visible(False)
    figure.tight_layout()
    figure.savefig(path, dpi=100)
    plt.close(figure)


def write_readme(table: str, path: Path = README) -> None:
    text = path.read_text(encoding="utf-8")
    if START not in text or END not in text:
        raise SystemExit(f"{path}: markers {START} / {END} not found")
    head, rest = text.split(START, 1)
    _, tail = rest.split(END, 1)
    path.write_text(f"{head}{START}\n{table}\n{END}{tail}", encoding="utf-8")


def main() -> None:
    if len(sys.argv) == 3 and sys.argv[1] == "--worker":
        print(json.dumps(worker(json.loads(sys.argv[2]))))
        return
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="10,100,1000,10000",
                        help="comma-separated numbers of masses (default 10,100,1000,10000)")
    parser.add_argument("--families", default=",".join(FAMILIES), help="comma-separated scene families")
    parser.add_argument("--quick", action="store_true", help="100 times and at most 2 runs per cell")
    parser.add_argument("--limit", type=float, default=1800.0,
                        help="seconds allowed per (method, scene) subprocess (default 1800)")
    parser.add_argument("--memory-gb", type=float, default=16.0,
                        help="address-space limit of each subprocess in GB (default 16; 0: none)")
    parser.add_argument("--write", action="store_true",
                        help=f"write the table into {README.name} between {START} and {END}")
    parser.add_argument("--plot", default=str(PLOT), help=f"log-log plot file (default {PLOT.name})")
    args = parser.parse_args()
    sizes = sorted({int(s) for s in args.sizes.split(",") if s.strip()})
    families = [f.strip() for f in args.families.split(",") if f.strip()]
    unknown = [f for f in families if f not in FAMILIES]
    if unknown or not sizes or min(sizes) < 2:
        parser.error(f"families must be among {', '.join(FAMILIES)}; sizes at least 2")

    def log(text: str) -> None:
        print(text, file=sys.stderr, flush=True)

    started = time.perf_counter()
    run = run_all(sizes, families, args.quick, args.limit, args.memory_gb, log)
    table = markdown(run)
    print(table)
    print(f"\ntotal {time.perf_counter() - started:.0f} s")
    if args.plot:
        try:
            plot(run, Path(args.plot))
            print(f"wrote {args.plot}")
        except ImportError:
            print("no plot: matplotlib not installed")
    if args.write:
        write_readme(table)
        print(f"wrote the table into {README}")


if __name__ == "__main__":
    main()
