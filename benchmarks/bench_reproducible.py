"""The cost of reproducible values (issue 21 item 3): fixed-shape products against plain @.

A time's value must be the same float64 bits alone or in any batch. The engines form their
products over the time axis with :func:`laplace_springs.kernels.batch.columns_product` and
``rows_product`` (every gemm of one shape) instead of ``A @ B`` (whose kernels, and so
roundings, change with the number of columns). This script times, in the same run:

1. the products alone: ``columns_product(A, B)`` against ``A @ B`` for the shapes the
   engines use (modes x modes, coordinates x modes, real and complex, 1 to 2,000 times);
2. whole evaluations (``sol.evaluate(times, return_error=True)``) on the routes that use
   them, with the products as they are against the same engines with the products
   replaced by plain ``@`` (what the engines did before; such values depend on the batch).

Each figure is the best of several repeats. BLAS threads: OPENBLAS_NUM_THREADS=1 unless set
(two busy cores); the setting is printed.

Run:  .venv/bin/python benchmarks/bench_reproducible.py [--repeats 7]
"""

from __future__ import annotations

import argparse
import os
import time
from contextlib import contextmanager

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np

import laplace_springs as ls
from laplace_springs.kernels import batch
from laplace_springs.model.sampled import sampled
from laplace_springs.numeric import chebyshev, classical, dd_matrix, modal, pole_sum
from laplace_springs.numeric import sampled as sampled_engine

MODULES = (chebyshev, classical, dd_matrix, modal, pole_sum, sampled_engine)


def best(call, repeats: int) -> float:
    call()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    return min(times)


@contextmanager
def plain_products():
    """The engines with ``A @ B`` in place of the fixed-shape products."""
    saved = [(m, name, getattr(m, name)) for m in MODULES
             for name in ("columns_product", "rows_product") if hasattr(m, name)]
    for m, name, _ in saved:
        setattr(m, name, (lambda A, B: A @ B))
    try:
        yield
    finally:
        for m, name, value in saved:
            setattr(m, name, value)


def chain(n: int, damping: str) -> ls.Scene:
    names = [f"m{i + 1}" for i in range(n)]
    nodes = ["wall", *names, "wall"]
    links = list(zip(nodes, nodes[1:]))
    if damping == "rayleigh":  # C = K/500 + M/100: classical
        dashpots = {f"c{i}": (p, q, "1/500") for i, (p, q) in enumerate(links)}
        dashpots.update({f"g{i}": ("ground", m, "1/100") for i, m in enumerate(names)})
    else:  # one dashpot: non-classical
        dashpots = {"c": ("ground", "m1", "3/10")}
    return ls.Scene.from_components(masses=dict.fromkeys(names, 1),
                                    springs={f"k{i}": (p, q, 1) for i, (p, q) in enumerate(links)},
                                    dashpots=dashpots, x0={"m1": 1})


def scenes() -> dict[str, tuple[ls.Scene, str]]:
    T = np.sort(np.concatenate([[0.0, 5.0], np.random.default_rng(2).uniform(0, 5, 60)]))
    return {
        "classical, 12 masses": (chain(12, "rayleigh"), "classical"),
        "classical, 1,000 masses": (chain(1000, "rayleigh"), "classical"),
        "modal, 12 masses": (chain(12, "one"), "modal"),
        "modal, 60 masses": (chain(60, "one"), "modal"),
        "chebyshev, 200 masses": (chain(200, "rayleigh"), "chebyshev"),
        "exact, 2 masses": (ls.Scene.from_matrices(
            M=[[1, 0], [0, 2]], C=[["1/10", 0], [0, 0]], K=[[3, -1], [-1, 1]],
            x0=[1, 0], v0=[0, "1/3"]), "exact"),
        "sampled, 2 masses": (ls.Scene.from_matrices(
            M=[[1, 0], [0, 1]], C=[["1/10", 0], [0, 0]], K=[[2, -1], [-1, 2]], x0=[1, 0],
            v0=[0, 0], forcing=[sampled(T, np.sin(3 * T)), 0]), "auto"),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args()
    print(f"OPENBLAS_NUM_THREADS={os.environ['OPENBLAS_NUM_THREADS']}")
    rng = np.random.default_rng(0)
    print("\n1. products: columns_product(A, B) against A @ B")
    print(f"{'A':>16} {'times':>6} {'ours':>10} {'A @ B':>10} {'ratio':>6}")
    for p, k, complex_ in [(12, 12, True), (12, 24, False), (60, 120, True), (200, 200, False),
                           (1000, 1000, False)]:
        A = rng.standard_normal((p, k)) + (1j * rng.standard_normal((p, k)) if complex_ else 0)
        for count in (1, 50, 2000):
            B = rng.standard_normal((k, count)) + (1j * rng.standard_normal((k, count))
                                                   if complex_ else 0)
            ours = best(lambda A=A, B=B: batch.columns_product(A, B), args.repeats)
            peer = best(lambda A=A, B=B: A @ B, args.repeats)
            label = f"{p}x{k}{' complex' if complex_ else ''}"
            print(f"{label:>16} {count:>6} {ours * 1e6:>8.1f}us {peer * 1e6:>8.1f}us "
                  f"{ours / peer:>6.2f}")
    print("\n2. evaluate(times, return_error=True): fixed-shape products against plain @")
    print(f"{'scene':>24} {'times':>6} {'ours':>10} {'plain @':>10} {'ratio':>6}")
    for name, (scene, method) in scenes().items():
        sol = ls.solve(scene, method=method)
        for count in (1, 50, 2000):
            if count == 2000 and "1,000" in name:
                continue  # seconds per call (the refined engine): the products do not show
            times = np.linspace(0.01, 50, count) if count > 1 else np.array([3.3])
            ours = best(lambda sol=sol, times=times: sol.evaluate(times, return_error=True),
                        args.repeats)
            with plain_products():
                peer = best(lambda sol=sol, times=times: sol.evaluate(times, return_error=True),
                            args.repeats)
            print(f"{name:>24} {count:>6} {ours * 1e3:>8.2f}ms {peer * 1e3:>8.2f}ms "
                  f"{ours / peer:>6.2f}")


if __name__ == "__main__":
    main()
