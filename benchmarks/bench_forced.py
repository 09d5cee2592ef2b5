"""Formula and periodic forces on chains of 12 to 200 masses: the exo engine against SciPy.

Issue 26 item 2 (any forcing at any size) and the exo engine of ``laplace_springs.routes``.
A chain of n unit masses between a wall spring 2 and unit springs, a dashpot 1/10 at the
wall and 1/5 at the far end (not classically damped), from x0 = (1, 0, ..., 0), driven on
the first mass by ``cos(2t)`` or ``square_wave(1, 2)``; 100 times on [0, 20].

What is timed (a fresh Scene per run, fastest of ``--repeats``):

ours
    ``ls.solve(scene).evaluate(times, return_error=True)`` (the planner picks the exo
    engine from 9 coordinates on).
scipy
    ``scipy.integrate.solve_ivp`` (DOP853, rtol 1e-12, atol 1e-14, dense output off, the
    times as t_eval) on the float64 first-order system with the force as a Python
    function; no bound.

Reference (independent of the exo engine): for the square wave, the same scene with the
force given as held samples 1, 0, 1, 0, ... (``ls.sampled(kind="zoh")``: the sampled route,
double-double segment maps, exact for that history); for cos(2t), solve_ivp at rtol 1e-13
with the Radau method is not accurate enough to grade 1e-13, so the column shows the
difference between ours and the exact route where the exact route serves (n = 12).
Errors are max |x − x_ref| / max |x_ref|.

Run:  python benchmarks/bench_forced.py [--sizes 12,50,200] [--repeats 3]
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np

import laplace_springs as ls

TIMES = np.linspace(0.0, 20.0, 100)


def scene(n: int, force: object) -> ls.Scene:
    masses = {f"m{i}": 1 for i in range(n)}
    springs = {"k0": ("wall", "m0", 2), **{f"k{i}": (f"m{i-1}", f"m{i}", 1) for i in range(1, n)}}
    dashpots = {"c0": ("wall", "m0", "1/10"), "c1": (f"m{n-1}", "wall", "1/5")}
    return ls.Scene.from_components(masses=masses, springs=springs, dashpots=dashpots,
                                    x0=[1] + [0] * (n - 1), v0=[0] * n,
                                    forcing=[force] + ["0"] * (n - 1))


def ours(n: int, force: str) -> tuple[float, np.ndarray, np.ndarray, str]:
    built = scene(n, force)
    start = time.perf_counter()
    sol = ls.solve(built)
    values, bounds = sol.evaluate(TIMES, return_error=True)
    return time.perf_counter() - start, values, bounds, sol.method


def scipy_run(n: int, force: str) -> tuple[float, np.ndarray]:
    from scipy.integrate import solve_ivp

    M = np.eye(n)
    K = np.diag([3.0] + [2.0] * (n - 2) + [1.0]) if n > 1 else np.array([[2.0]])
    K -= np.diag(np.ones(n - 1), 1) + np.diag(np.ones(n - 1), -1)
    C = np.zeros((n, n))
    C[0, 0] += 0.1
    C[n - 1, n - 1] += 0.2
    Z = np.block([[np.zeros((n, n)), np.eye(n)], [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])

    def f(t: float) -> float:
        return float(np.cos(2 * t)) if force == "cos(2*t)" else float((t % 2.0) < 1.0)

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        dy = Z @ y
        dy[n] += f(t)
        return dy

    y0 = np.zeros(2 * n)
    y0[0] = 1.0
    start = time.perf_counter()
    found = solve_ivp(rhs, (0.0, 20.0), y0, method="DOP853", t_eval=TIMES, rtol=1e-12, atol=1e-14)
    return time.perf_counter() - start, found.y[:n]


def reference(n: int, force: str) -> np.ndarray | None:
    if force == "square_wave(1, 2)":
        steps = np.arange(0, 21)
        held = ls.sampled(steps, (steps % 2 == 0).astype(float), kind="zoh")
        return np.asarray(ls.solve(scene(n, held)).evaluate(TIMES))
    if n <= 12:
        return np.asarray(ls.solve(scene(n, force), method="exact").evaluate(TIMES))
    return None


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="12,50,200")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    load = os.getloadavg()[0]
    print(f"laplace_springs {ls.__version__}; fastest of {args.repeats}; load average {load:.1f}")
    print("| force | n | engine | ours (s) | scipy DOP853 (s) | ratio | our bound | our error "
          "| scipy error |")
    print("|---|---|---|---|---|---|---|---|---|")
    for force in ("cos(2*t)", "square_wave(1, 2)"):
        for n in (int(v) for v in args.sizes.split(",")):
            mine = min((ours(n, force) for _ in range(args.repeats)), key=lambda r: r[0])
            peer = min((scipy_run(n, force) for _ in range(args.repeats)), key=lambda r: r[0])
            ref = reference(n, force)
            scale = float(np.max(np.abs(mine[1])))
            bound = float(np.max(mine[2])) / scale
            error = "—" if ref is None else f"{np.max(np.abs(mine[1] - ref)) / scale:.1e}"
            theirs = "—" if ref is None else f"{np.max(np.abs(peer[1] - ref)) / scale:.1e}"
            print(f"| {force} | {n} | {mine[3]} | {mine[0]:.3f} | {peer[0]:.3f} | "
                  f"{mine[0] / peer[0]:.2f} | {bound:.1e} | {error} | {theirs} |")


if __name__ == "__main__":
    main()
