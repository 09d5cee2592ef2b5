"""The routes side by side on chains of 1 to 12 damped masses: solve + evaluate, timed.

Issue 10's target: ``solve(scene).evaluate(times)`` (the route "auto" picks) on an 8-mass
damped chain takes at most 3x the time of ``method="numeric"`` (the modal route), both
measured in this run. Every time is the fastest of ``--repeats`` runs with SymPy's cache
cleared first (other processes only add time); every error is against python-flint's
certified ball-arithmetic matrix exponential.

    python benchmarks/bench_routes.py                 # 1, 2, 4, 6, 8, 12 masses
    python benchmarks/bench_routes.py --masses 8 --repeats 7
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from sympy.core.cache import clear_cache

import laplace_springs as ls
from laplace_springs.bench.reference import reference_motion_arb, relative_error

ROUTES = ("auto", "numeric", "certified", "exact")


def chain(n: int) -> ls.Scene:
    """n unit masses between walls, springs 1 and 3/2, dashpots 1/20, the first mass displaced."""
    names = [f"m{i + 1}" for i in range(n)]
    nodes = ["wall", *names, "wall"]
    links = list(zip(nodes, nodes[1:]))
    return ls.Scene.from_components(
        masses=dict.fromkeys(names, 1),
        springs={f"k{i}": (a, b, "1" if i % 2 else "3/2") for i, (a, b) in enumerate(links)},
        dashpots={f"c{i}": (a, b, "1/20") for i, (a, b) in enumerate(links)},
        x0={"m1": 1}, title=f"{n}-mass damped chain")


def timed(scene: ls.Scene, method: str, times: np.ndarray, repeats: int) -> tuple[float, str, np.ndarray]:
    best, route, values = float("inf"), "", np.empty(0)
    for _ in range(repeats):
        clear_cache()
        start = time.perf_counter()
        sol = ls.solve(scene, method=method)
        values = sol.evaluate(times)
        best = min(best, time.perf_counter() - start)
        route = sol.method
    return best, route, values


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--masses", type=int, nargs="*", default=[1, 2, 4, 6, 8, 12])
    parser.add_argument("--times", type=int, default=1000)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    times = np.linspace(0.0, 50.0, args.times)
    print(f"solve + evaluate at {args.times} times, fastest of {args.repeats} runs (exact: 1 run)\n")
    print(f"| masses | {' | '.join(f'{m} (s)' for m in ROUTES)} | auto route | auto / numeric | max error |")
    print("|---" * (len(ROUTES) + 4) + "|")
    for n in args.masses:
        scene = chain(n)
        reference = reference_motion_arb(scene, list(times[::100]), digits=30)
        results = {m: timed(scene, m, times, 1 if m == "exact" else args.repeats) for m in ROUTES}
        error = max(relative_error(values[:, ::100], reference) for _, _, values in results.values())
        cells = " | ".join(f"{results[m][0]:.4f}" for m in ROUTES)
        ratio = results["auto"][0] / results["numeric"][0]
        print(f"| {n} | {cells} | {results['auto'][1]} | {ratio:.2f} | {error:.1e} |")
        if n == 8:
            verdict = "met" if ratio <= 3 else "NOT met"
            print(f"\n8 masses: auto / numeric = {ratio:.2f} (target <= 3: {verdict})\n")


if __name__ == "__main__":
    main()
