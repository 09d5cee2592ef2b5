"""Sampled force histories: our exact per-segment response against scipy.signal.lsim.

10^5 samples over 100 s of a force on the first mass of the seed's Example 5 (2 masses,
damped) and of an undamped 2-mass scene, evaluated at the 10^5 sample times (lsim's grid)
and at 10^5 other times. Both are timed in the same run (best of 3); agreement is measured
against lsim on its grid, and our own bound against the contract's target (Limits.target of
max(|x(t)|, S₀) at each time; "escalated" counts the times whose bound misses it).

    python benchmarks/bench_sampled.py [samples]
"""

from __future__ import annotations

import sys
import time

import numpy as np
from scipy import signal

from laplace_springs.limits import limits
from laplace_springs.model.sampled import sampled
from laplace_springs.model.scene import Scene
from laplace_springs.policy import column_scales, escalate_columns
from laplace_springs.routes.sampled import solve_sampled


def best(run, repeat=3):
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        out = run()
        times.append(time.perf_counter() - start)
    return min(times), out


SCENES = {
    "2-mass damped (Example 5)": ([[1, 0], [0, "4/5"]], [["19/10", "-7/5"], ["-7/5", "23/10"]],
                                  [[779, -379], [-379, 479]]),
    "2-mass undamped": ([[1, 0], [0, 2]], [[0, 0], [0, 0]], [[3, -1], [-1, 1]]),
}


def run(label, M, C, K, samples):
    T = np.linspace(0, 100, samples)
    U = np.sin(T) * np.cos(3 * np.sqrt(T)) + 0.1 * np.sin(37 * T)
    scene = Scene.from_matrices(M=M, C=C, K=K, x0=[0, 0], v0=[0, 0], forcing=[sampled(T, U), 0])
    A, B = (np.array(m, dtype=float) for m in scene.state_space()[:2])
    system = signal.StateSpace(A, B[:, [0]], np.hstack([np.eye(2), np.zeros((2, 2))]), np.zeros((2, 1)))
    lsim_time, (_, y, _) = best(lambda: signal.lsim(system, U, T))

    def ours_on(times):
        sol = solve_sampled(scene)
        return sol, *sol.evaluate(times, return_error=True)

    our_time, (sol, values, bounds) = best(lambda: ours_on(T))
    other = np.sort(np.random.default_rng(0).uniform(0, 100, samples))
    other_time, (_, other_values, other_bounds) = best(lambda: ours_on(other))
    scale = np.max(np.abs(y))
    floor = sol._floor(0)
    worst = max(np.max(b / column_scales(v, floor)) for v, b in ((values, bounds),
                                                                 (other_values, other_bounds)))
    missed = sum(int(np.sum(escalate_columns(v, b, floor, limits().target)))
                 for v, b in ((values, bounds), (other_values, other_bounds)))
    print(f"{label}: {samples:,} samples over 100 s, {samples:,} output times")
    print(f"{'':28s}{'time (s)':>10s}{'ratio to lsim':>15s}")
    print(f"{'scipy.signal.lsim':28s}{lsim_time:10.3f}{1.0:15.2f}")
    print(f"{'ours, at the sample times':28s}{our_time:10.3f}{our_time / lsim_time:15.2f}")
    print(f"{'ours, at other times':28s}{other_time:10.3f}{other_time / lsim_time:15.2f}")
    print(f"max |ours - lsim| / max|x|: {np.max(np.abs(values - y.T)) / scale:.2e}; "
          f"our largest bound / max|x|: {np.max(bounds) / scale:.2e}")
    print(f"worst bound / column scale: {worst:.2e} (target {limits().target:g}); escalated times: {missed}\n")


def main(samples: int = 100_000) -> None:
    for label, (M, C, K) in SCENES.items():
        run(label, M, C, K, samples)


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 100_000)
