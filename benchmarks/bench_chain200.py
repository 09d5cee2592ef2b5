"""A 200-mass damped chain: the modal route against a certified reference (and scipy).

Target (issue 3): solve and evaluate at 1,000 times in under 1 s with error <= 1e-10,
relative to max |x| over the times.

The scene: 200 unit masses in a line between two walls, unit springs; a dashpot beside
every spring with c cycling through 0.01, 0.02, ..., 0.10, and a dashpot c = 0.01 to the
ground at every tenth mass (non-proportional damping); m1 displaced by 1, m100 by -1/2,
m150 given velocity 1/3. Times t_j = j/8, j = 0..999 (exact binary fractions, t <= 124.9).

The reference is python-flint's ball arithmetic at 128 bits: E = exp(Z/8) of the exact
first-order matrix, its squares E^(2^k), and x(t_j) = E^j y0 by binary powers of j (a few
matrix-vector products per time). The balls' radii bound its error; they are printed.
scipy.linalg.expm (one 400x400 exponential per time) is timed on 20 of the times and its
cost extrapolated to 1,000. BLAS threads: OPENBLAS_NUM_THREADS=1 unless set (on two busy
cores threading only adds contention); the setting is printed.

Run:  .venv/bin/python benchmarks/bench_chain200.py [--masses 200] [--repeats 3]
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import flint
import numpy as np

import laplace_springs as ls
from laplace_springs import Scene
from laplace_springs.numeric.first_order import first_order_system, scene_arrays


def damped_chain(n: int) -> Scene:
    masses = {f"m{i + 1}": 1 for i in range(n)}
    nodes = ["wall", *masses, "wall"]
    springs = {f"k{i}": (a, b, 1) for i, (a, b) in enumerate(zip(nodes, nodes[1:]))}
    dashpots = {f"c{i}": (a, b, f"{i % 10 + 1}/100") for i, (a, b) in enumerate(zip(nodes, nodes[1:]))}
    dashpots.update({f"g{i}": ("ground", f"m{i}", "1/100") for i in range(10, n + 1, 10)})
    return Scene.from_components(masses=masses, springs=springs, dashpots=dashpots,
                                 x0={"m1": 1, f"m{n // 2}": "-1/2"}, v0={f"m{3 * n // 4}": "1/3"},
                                 title=f"{n}-mass damped chain")


def exact_first_order(scene: Scene) -> flint.fmpq_mat:
    """Z = [[0, I], [-M⁻¹K, -M⁻¹C]] over the rationals."""
    Z = first_order_system(scene)[0]
    return flint.fmpq_mat(Z.rows, Z.cols, [flint.fmpq(int(e.p), int(e.q)) for e in Z])


def certified_reference(scene: Scene, steps: int, h: flint.fmpq, bits: int = 128):
    """x(j·h), j < steps, as float64 midpoints and the largest ball radius."""
    n = scene.n
    with flint.ctx.workprec(bits):
        Z = flint.arb_mat(exact_first_order(scene))
        powers = [(Z * flint.arb(h)).exp()]
        while 2 ** len(powers) < steps:
            powers.append(powers[-1] * powers[-1])
        y0 = flint.arb_mat(2 * n, 1, [flint.fmpq(int(e.p), int(e.q)) for e in [*scene.x0, *scene.v0]])
        mids, radius = np.empty((n, steps)), 0.0
        for j in range(steps):
            y = y0
            for k, power in enumerate(powers):
                if j >> k & 1:
                    y = power * y
            mids[:, j] = [float(y[i, 0].mid()) for i in range(n)]
            radius = max(radius, *(float(y[i, 0].rad()) for i in range(n)))
    return mids, radius


def relative(values: np.ndarray, reference: np.ndarray) -> float:
    return float(np.max(np.abs(values - reference)) / np.max(np.abs(reference)))


def scipy_expm(scene: Scene, times: np.ndarray):
    try:
        from scipy.linalg import expm
    except ImportError:
        return None
    M, C, K, x0, v0 = scene_arrays(scene)
    n = scene.n
    Z = np.block([[np.zeros((n, n)), np.eye(n)], [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    y0 = np.concatenate([x0, v0])
    start = time.perf_counter()
    values = np.array([(expm(Z * t) @ y0)[:n] for t in times]).T
    return values, time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--masses", type=int, default=200)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--times", type=int, default=1000)
    args = parser.parse_args()

    scene = damped_chain(args.masses)
    times = np.arange(args.times) / 8.0
    print(f"{scene.title}: {2 * scene.n} poles, {len(times)} times in [0, {times[-1]}]; "
          f"OPENBLAS_NUM_THREADS={os.environ['OPENBLAS_NUM_THREADS']}")

    start = time.perf_counter()
    reference, radius = certified_reference(scene, len(times), flint.fmpq(1, 8))
    reference_time = time.perf_counter() - start
    scale = np.max(np.abs(reference))

    runs = []
    for _ in range(args.repeats):
        t0 = time.perf_counter()
        sol = ls.solve(scene, method="modal")
        t1 = time.perf_counter()
        values, bound = sol.evaluate(times, return_error=True)
        t2 = time.perf_counter()
        runs.append((t1 - t0, t2 - t1))
    solve_time, evaluate_time = min(runs, key=sum)
    error = relative(values, reference)

    rows = [("modal route: solve + evaluate", solve_time + evaluate_time, f"{error:.2e}"),
            ("  solve (eigen-decomposition)", solve_time, ""),
            ("  evaluate at all times (with error bound)", evaluate_time,
             f"bound {np.max(bound) / scale:.1e}")]
    peer = scipy_expm(scene, times[:: max(1, len(times) // 20)])
    if peer is None:
        rows.append(("scipy.linalg.expm per time", float("nan"), "scipy not installed"))
    else:
        peer_values, peer_time = peer
        sampled = reference[:, :: max(1, len(times) // 20)]
        rows.append((f"scipy.linalg.expm per time (x{len(times) / sampled.shape[1]:.0f} of "
                     f"{sampled.shape[1]} times)", peer_time * len(times) / sampled.shape[1],
                     f"{relative(peer_values, sampled):.2e}"))
    rows.append(("reference: flint arb exp(Z/8) and binary powers, 128 bits", reference_time,
                 f"radius {radius / scale:.1e}"))

    print()
    print(f"| {'method':<62} | {'time (s)':>9} | {'rel. error':>18} |")
    print(f"|{'-' * 64}|{'-' * 11}|{'-' * 20}|")
    for name, seconds, note in rows:
        print(f"| {name:<62} | {seconds:9.3f} | {note:>18} |")
    verdict = "met" if solve_time + evaluate_time < 1 and error <= 1e-10 else "NOT met"
    print(f"\ntarget (< 1 s, error <= 1e-10): {verdict}; {sol!r}")


if __name__ == "__main__":
    main()
