"""ls.sweep against a batched numpy.linalg.eig modal baseline, measured in the same run.

10^5 parameter sets of a two-mass scene (masses 1, springs k1 wall-m1 and k2 m1-m2, a
dashpot c wall-m1) at 100 times. The baseline stacks the first-order matrices
[[0, I], [-K, -C]], takes eig once for all sets, solves V a = z0 and sums the modes;
it is accurate where the modes are well separated, so the agreement is measured on the
sets whose eigenvector matrix is well conditioned (cond(V) < 1e3).

The two are timed interleaved, best of two runs each (the CPU may be shared).

    python benchmarks/bench_sweep.py [sets] [repeat]
"""

from __future__ import annotations

import sys
import time

import numpy as np

import laplace_springs as ls
from laplace_springs.sweeps import sweep


def baseline(k1: np.ndarray, k2: np.ndarray, c: np.ndarray, times: np.ndarray,
             x0: np.ndarray, v0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """x(t) (P, 2, T) by batched eig of the stacked first-order matrices, and cond(V)."""
    P = k1.size
    A = np.zeros((P, 4, 4))
    A[:, 0, 2] = A[:, 1, 3] = 1.0
    A[:, 2, 0], A[:, 2, 1], A[:, 2, 2] = -(k1 + k2), k2, -c
    A[:, 3, 0], A[:, 3, 1] = k2, -k2
    lam, V = np.linalg.eig(A)
    z0 = np.broadcast_to(np.concatenate([x0, v0]), (P, 4))
    a = np.linalg.solve(V, z0[..., None])[..., 0]
    modes = V[:, :2, :] * a[:, None, :]
    x = np.matmul(modes, np.exp(lam[:, :, None] * times[None, None, :])).real
    return x, np.linalg.cond(V)


def main(P: int = 100_000, repeat: int = 2) -> None:
    scene = ls.Scene.from_components(
        masses={"m1": 1, "m2": 1},
        springs={"k1": ("wall", "m1", "k1"), "k2": ("m1", "m2", "k2")},
        dashpots={"c": ("wall", "m1", "c")},
        x0=[1, 0], v0=[0, 1], parameters=["k1", "k2", "c"])
    rng = np.random.default_rng(0)
    values = {"k1": rng.uniform(0.5, 3, P), "k2": rng.uniform(0.5, 3, P), "c": rng.uniform(0.01, 4, P)}
    times = np.linspace(0, 20, 100)
    t_base = t_sweep = np.inf
    for _ in range(repeat):  # interleaved, best of `repeat`: the CPU may be shared
        start = time.perf_counter()
        ref, cond = baseline(values["k1"], values["k2"], values["c"], times, np.array([1.0, 0.0]),
                             np.array([0.0, 1.0]))
        t_base = min(t_base, time.perf_counter() - start)
        start = time.perf_counter()
        result = sweep(scene, values, times, return_error=True)
        t_sweep = min(t_sweep, time.perf_counter() - start)
    good = cond < 1e3
    scale = np.maximum(np.max(np.abs(result.values), axis=1, keepdims=True), 1.0)
    agree = np.max(np.abs(result.values - ref)[good] / scale[good])
    print(f"{P:,} sets x {times.size} times, two-mass scene (k1, k2, c); best of {repeat}")
    print(f"{'route':<34}{'time [s]':>10}")
    print(f"{'batched numpy.linalg.eig (modal)':<34}{t_base:>10.2f}")
    print(f"{'ls.sweep (exact, vectorised)':<34}{t_sweep:>10.2f}")
    print(f"ratio sweep / eig baseline: {t_sweep / t_base:.2f}")
    print(f"sets sent to the exact solver: {result.exact_sets.size} "
          f"({100 * result.exact_sets.size / P:.2f} %); largest error estimate "
          f"{np.max(result.set_error):.1e} of max(|x|, S0)")
    print(f"agreement with the baseline where cond(V) < 1e3 ({good.mean():.1%} of sets): {agree:.1e}")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 100_000,
         int(sys.argv[2]) if len(sys.argv) > 2 else 2)
