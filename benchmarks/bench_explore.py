"""The explorer's time per slider move on the seed's scenes, against re-solving per move.

For each bundled scene: build ``ls.explore(scene)`` (the scene with its knobs as
parameters, compiled once), then make 60 moves as a hand on the sliders would (one knob
at a time, random values in its range, seeded): each move evaluates the compiled scene at
400 times and redraws the curves, the diagram (SVG) and the closed form. The peer, timed
in the same run on 5 of the same moves: what a notebook would do without the explorer,
``ls.solve(scene.subs(values)).evaluate(times)`` (the evaluation alone, no drawing).

The target is 50 ms per move. Prints median, 90th percentile and slowest move, the build
time, and the ratio of the peer's median to the explorer's.

    python benchmarks/bench_explore.py [moves]
"""

from __future__ import annotations

import sys
import time

import numpy as np

import laplace_springs as ls

TARGET_MS = 50.0


def moves(explorer: ls.Explorer, count: int, seed: int = 27) -> list[dict[str, float]]:
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(count):
        knob = explorer.knobs[rng.integers(len(explorer.knobs))]
        if knob.log:
            value = float(np.exp(rng.uniform(np.log(knob.low), np.log(knob.high))))
        else:
            value = float(rng.uniform(knob.low, knob.high))
        out.append({knob.name: value})
    return out


def peer_seconds(explorer: ls.Explorer, steps: list[dict[str, float]]) -> list[float]:
    values = explorer.values
    out = []
    for step in steps:
        values.update(step)
        start = time.perf_counter()
        numbers = explorer.compiled.scene.subs(values)
        ls.solve(numbers).evaluate(explorer.times)
        out.append(time.perf_counter() - start)
    return out


def main(count: int = 60) -> None:
    print(f"{'scene':<22}{'knobs':>6}{'build s':>9}{'median ms':>11}{'p90 ms':>8}{'max ms':>8}"
          f"{'peer ms':>9}{'ratio':>7}  target {TARGET_MS:g} ms")
    worst = 0.0
    for name in sorted(ls.bundled_scenes()):
        start = time.perf_counter()
        explorer = ls.explore(ls.load_scene(name))
        build = time.perf_counter() - start
        steps = moves(explorer, count)
        seconds = []
        for step in steps:
            explorer.set(**step)
            seconds.append(explorer.last_update_seconds)
        explorer.reset()
        peer = peer_seconds(explorer, steps[:5])
        ms = np.array(seconds) * 1e3
        worst = max(worst, float(np.percentile(ms, 90)))
        print(f"{name:<22}{len(explorer.knobs):>6}{build:>9.2f}{np.median(ms):>11.1f}"
              f"{np.percentile(ms, 90):>8.1f}{ms.max():>8.1f}{np.median(peer) * 1e3:>9.0f}"
              f"{np.median(peer) * 1e3 / np.median(ms):>7.0f}")
    verdict = "meets" if worst <= TARGET_MS else "misses"
    print(f"90th percentile of the slowest scene: {worst:.1f} ms: {verdict} the {TARGET_MS:g} ms target")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 60)
