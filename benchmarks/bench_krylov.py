"""Krylov engine against ``scipy.sparse.linalg.expm_multiply`` (issue 23 item 2).

Scenes (``bench_scaling.scene_spec``): ``chain-wall-dashpot`` (a fixed-fixed chain of n
unit masses and springs, Rayleigh damping C = K/500 + M/100 and one more dashpot, 1/2,
from the middle mass to the wall: damping not classical) and ``mesh-wall-dashpot`` (a
random connected spring graph with 3n springs, the same damping and extra dashpot);
x0 = 1 on the first mass. 100 times on [0, 50].

In one process, interleaved, fastest of ``--repeats`` runs of each:

* ours: ``ls.solve(scene).evaluate(times, return_error=True)`` on a Scene built untimed
  (a fresh Scene each run, so the scene's facts and the engine's data are built inside the
  timing; imports warmed by a 30-mass scene first);
* engine alone: ``krylov_refusal`` + ``krylov_motion(scene).evaluate(times)`` on a fresh
  Scene whose exact entries were read before the clock (the part of the call that is the
  krylov engine's own; the rest is the scene facts and the planner);
* peer: ``expm_multiply(Z, z0, start=0, stop=50, num=100, endpoint=True)`` on the sparse
  float64 first-order matrix Z = [[0, I], [-M⁻¹K, -M⁻¹C]] (CSC, built untimed).

Errors, relative to max |x_ref|, against the benchmark's own double-double Taylor march
on the exact sparse Z (``bench_scaling.DoubleDoubleTaylor``, about 30 digits, no code of
the package); ``--check-small`` first checks that reference and our values against
python-flint's certified arb matrix exponential on 30-mass scenes. "holds" says whether
every |value − reference| is within its bound.

Run (one core per method):

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_krylov.py                 # 1,000 and 4,000
    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_krylov.py --sizes 10000 --families mesh-wall-dashpot
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import bench_scaling as bench  # noqa: E402

TIMES = np.linspace(0.0, 50.0, 100)


def ours(spec: bench.Spec, method: str = "auto") -> tuple[float, np.ndarray, np.ndarray, str]:
    import laplace_springs as ls

    scene = bench.build_scene(spec)
    started = time.perf_counter()
    solution = ls.solve(scene, method=method)
    values, bounds = solution.evaluate(TIMES, return_error=True)
    return time.perf_counter() - started, values, bounds, solution.method


def engine(spec: bench.Spec) -> float:
    """The krylov engine alone: krylov_refusal + its data + the march and values, on a fresh
    Scene whose exact entries were read before the clock (the scene facts read them)."""
    from laplace_springs.numeric.first_order import rational_entries
    from laplace_springs.numeric.krylov import krylov_motion, krylov_refusal

    scene = bench.build_scene(spec)
    for name in ("M", "C", "K", "x0", "v0"):
        rational_entries(scene, name)
    started = time.perf_counter()
    assert krylov_refusal(scene, t_max=float(TIMES[-1]), count=len(TIMES)) is None
    krylov_motion(scene).evaluate(TIMES)
    return time.perf_counter() - started


def peer(Z: object, z0: np.ndarray) -> tuple[float, np.ndarray]:
    from scipy.sparse.linalg import expm_multiply

    started = time.perf_counter()
    Y = expm_multiply(Z, z0, start=0.0, stop=50.0, num=len(TIMES), endpoint=True)
    return time.perf_counter() - started, np.asarray(Y)[:, : len(z0) // 2].T


def check_small() -> None:
    from laplace_springs.bench.reference import reference_motion_arb

    for family in ("chain-wall-dashpot", "mesh-wall-dashpot"):
        spec = bench.scene_spec(family, 30)
        arb = np.array(reference_motion_arb(bench.build_scene(spec), list(TIMES), digits=25),
                       dtype=float)
        high, low = bench.DoubleDoubleTaylor(spec).motion(TIMES)
        _, values, bounds, method = ours(spec, "krylov")
        scale = float(np.max(np.abs(arb)))
        print(f"{family} n=30 ({method}): dd-Taylor vs arb {np.max(np.abs(high - arb)) / scale:.1e}, "
              f"ours vs arb {np.max(np.abs(values - arb)) / scale:.1e}, bound {np.max(bounds) / scale:.1e}, "
              f"holds {bool(np.all(np.abs(values - arb) <= bounds + 2 ** -60 * scale))}")


def run(family: str, n: int, repeats: int) -> dict[str, object]:
    spec = bench.scene_spec(family, n)
    m, K, C = bench.float_arrays(spec)
    Z, z0 = bench.first_order(m, K, C)
    mine, theirs, alone = [], [], []
    for _ in range(repeats):
        seconds, values, bounds, method = ours(spec)
        mine.append(seconds)
        alone.append(engine(spec))
        seconds, peer_values = peer(Z, z0)
        theirs.append(seconds)
    started = time.perf_counter()
    high, low = bench.DoubleDoubleTaylor(spec).motion(TIMES)
    reference_seconds = time.perf_counter() - started
    scale = float(np.max(np.abs(high)))
    error = np.abs((values - high) - low)
    return {"family": family, "n": n, "method": method, "ours": min(mine), "peer": min(theirs),
            "ratio": min(mine) / min(theirs), "engine": min(alone),
            "engine_ratio": min(alone) / min(theirs), "bound": float(np.max(bounds)) / scale,
            "error": float(np.max(error)) / scale, "holds": bool(np.all(error <= bounds)),
            "peer_error": float(np.max(np.abs((peer_values - high) - low))) / scale,
            "all_ours": mine, "all_peer": theirs, "reference_seconds": reference_seconds}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="1000,4000")
    parser.add_argument("--families", default="chain-wall-dashpot,mesh-wall-dashpot")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--check-small", action="store_true")
    args = parser.parse_args()
    import scipy

    import laplace_springs as ls

    print(f"Python {platform.python_version()}, NumPy {np.__version__}, SciPy {scipy.__version__}, "
          f"OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS', 'unset')}, "
          f"{os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}")
    ours(bench.scene_spec("chain-wall-dashpot", 30))          # imports and first-use costs
    ls.solve(bench.build_scene(bench.scene_spec("mesh-wall-dashpot", 30)))
    if args.check_small:
        check_small()
    print("| scene | n | ours (s) | expm_multiply (s) | ratio | engine alone (s) | ratio | our bound | "
          "our error | holds | expm_multiply error |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for family in args.families.split(","):
        for n in (int(v) for v in args.sizes.split(",")):
            r = run(family, n, args.repeats)
            print(f"| {family} | {n:,} | {r['ours']:.3f} | {r['peer']:.3f} | {r['ratio']:.2f} | "
                  f"{r['engine']:.3f} | {r['engine_ratio']:.2f} | {r['bound']:.1e} | {r['error']:.1e} | {r['holds']} | {r['peer_error']:.1e} |",
                  flush=True)
            print(f"<!-- runs: ours {[round(v, 3) for v in r['all_ours']]}, expm_multiply "
                  f"{[round(v, 3) for v in r['all_peer']]}, method {r['method']}, reference "
                  f"{r['reference_seconds']:.0f} s -->", flush=True)


if __name__ == "__main__":
    main()
