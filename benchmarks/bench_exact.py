"""Benchmark: the exact route on damped chains of unequal masses (issue 23 item 3).

Run from the repository root (one thread for BLAS)::

    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/bench_exact.py [--sizes 8 12 16]
        [--limit 120] [--no-sympy] [--no-expanded]

A chain of n masses m_k = (k + 2)/2 joined by springs 2, −1 (tridiagonal K), dashpots to
the wall c_k = (k mod 3 + 1)/10, x0 = e_1: Δ(λ) is irreducible of degree 2n. What is
timed, each in a fresh spawned process (imports done before the clock starts, the SymPy
cache empty):

- ours: ``ls.solve(scene, method="exact")``, building ``sol.x`` (the named form:
  ρ_j, α_j, β_j, c_j) and ``sol.evaluate`` at TIMES (the package's lazily loaded
  modules loaded before, by a 3-mass chain; some, such as scipy.sparse for the planner's
  Krylov check, load only for larger scenes); then the same for a second chain of n
  masses (each mass 1/2 heavier: another Δ, nothing cached), every module loaded;
- the previous expanded form: the same with
  ``Limits.exact_expanded_max_degree`` raised above 2n (every coefficient written out
  as a polynomial in re/im of ``CRootOf``; refused above
  ``Limits.max_exact_factor_degree``);
- SymPy's own route: ``sympy.inverse_laplace_transform`` of X_1(λ) = N_1/Δ alone.

Each peer runs under a hard limit (the process is killed when it runs out). The error
of our values is against the 40-digit mpmath matrix exponential of the first-order
system (laplace_springs.bench.reference), relative to max |x|.
"""

from __future__ import annotations

import argparse
import multiprocessing
import platform
import sys
import time
from collections.abc import Callable

import numpy as np
import sympy as sp

import laplace_springs as ls
from laplace_springs.bench.reference import reference_motion
from laplace_springs.limits import limits, using_limits

TIMES = [0.5, 2.0, 10.0, 25.0, 50.0]
STARTUP_LIMIT = 120.0


def chain(n: int, shift: int = 0) -> ls.Scene:
    """The benchmark's chain of n unequal masses (rational entries, Δ irreducible);
    ``shift`` moves every mass by shift/2 (another Δ, for a second timing)."""
    K = sp.zeros(n, n)
    for i in range(n):
        K[i, i] = 2
        if i:
            K[i, i - 1] = K[i - 1, i] = -1
    return ls.Scene.from_matrices(M=sp.diag(*[sp.Rational(k + 2 + shift, 2) for k in range(n)]),
                                  C=sp.diag(*[sp.Rational(k % 3 + 1, 10) for k in range(n)]),
                                  K=K, x0=[1] + [0] * (n - 1), v0=[0] * n)


# ----------------------------------------------------------------------------- child processes


def _exact_worker(n: int, expanded: bool, conn) -> None:
    """Time solve + x + evaluate; send the times, the form's size and the values. The
    package's modules (loaded on first use) are loaded first, by a 3-mass chain."""
    ls.solve(chain(3), method="exact").evaluate(TIMES)
    scene = chain(n)
    conn.send(("ready",))
    with using_limits(exact_expanded_max_degree=10**6 if expanded else limits().exact_expanded_max_degree):
        start = time.perf_counter()
        try:
            solution = ls.solve(scene, method="exact")
        except ls.InversionError as error:
            conn.send(("refused", str(error).split(":")[0]))
            return
        solved = time.perf_counter()
        x = solution.x
        built = time.perf_counter()
        values = solution.evaluate(TIMES)
        done = time.perf_counter()
        again = ls.solve(chain(n, shift=1), method="exact")  # every module now loaded
        _ = again.x
        again.evaluate(TIMES)
        second = time.perf_counter() - done
    conn.send(("time", solved - start, built - solved, done - built, sp.count_ops(x[0]),
               len(str(x[0])), values, second))


def _sympy_worker(n: int, _: bool, conn) -> None:
    """Invert X_1(λ) with SymPy; send the time and whether it stayed unevaluated."""
    X = ls.resolvent(chain(n)).transform()[0]
    conn.send(("ready",))
    start = time.perf_counter()
    result = sp.inverse_laplace_transform(X, ls.lam, ls.t)
    conn.send(("time", time.perf_counter() - start, result.has(sp.InverseLaplaceTransform)))


def _receive(parent, limit: float) -> tuple | None:
    if parent.poll(limit):
        try:
            return parent.recv()
        except EOFError:
            return None
    return None


def run_in_child(target: Callable, n: int, flag: bool, limit: float) -> tuple | None:
    """The child's result message, or None when it runs past ``limit`` seconds (killed)."""
    context = multiprocessing.get_context("spawn")
    parent, child = context.Pipe(duplex=False)
    process = context.Process(target=target, args=(n, flag, child), daemon=True)
    process.start()
    child.close()
    try:
        message = _receive(parent, STARTUP_LIMIT)  # ("ready",): imports are not timed
        return _receive(parent, limit) if message is not None else None
    finally:
        if process.is_alive():
            process.kill()
        process.join()


# ----------------------------------------------------------------------------- output


def _error(values: np.ndarray, n: int) -> float:
    reference = reference_motion(chain(n), TIMES, dps=40)
    exact = np.array([[float(v) for v in row] for row in reference])
    return float(np.abs(values - exact).max() / np.abs(exact).max())


def _peer(message: tuple | None, limit: float, ours: float) -> tuple[str, str]:
    """(peer's cell, ratio cell)."""
    if message is None:
        return f"> {limit:g} s (killed)", f"> {limit / ours:.0f}×"
    if message[0] == "refused":
        return f"refused ({message[1]})", "—"
    seconds = sum(message[1:4]) if len(message) > 4 else message[1]
    note = " (unevaluated)" if len(message) == 3 and message[2] else ""
    return f"{seconds:.2f} s{note}", f"{seconds / ours:.1f}×"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[8, 12, 16])
    parser.add_argument("--limit", type=float, default=120.0, help="seconds per peer run")
    parser.add_argument("--no-sympy", action="store_true")
    parser.add_argument("--no-expanded", action="store_true")
    args = parser.parse_args(argv)
    print(f"# bench_exact: Python {platform.python_version()}, SymPy {sp.__version__}, "
          f"{platform.machine()}; times {TIMES}")
    print("| n | degree of Δ | ours: solve + x + evaluate (s) | ours, second scene (s) | x_1: ops, "
          "chars | error vs 40-digit expm | expanded form (s) | ratio | SymPy ILT of X_1 (s) | ratio |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for n in args.sizes:
        ours = run_in_child(_exact_worker, n, False, STARTUP_LIMIT)
        assert ours is not None and ours[0] == "time", ours
        _, solve, build, evaluate, ops, chars, values, second = ours
        total = solve + build + evaluate
        cells = [str(n), str(2 * n), f"{total:.2f} ({solve:.2f} + {build:.2f} + {evaluate:.2f})",
                 f"{second:.2f}",
                 f"{ops}, {chars}", f"{_error(values, n):.1e}"]
        for skip, target in ((args.no_expanded, _exact_worker), (args.no_sympy, _sympy_worker)):
            if skip:
                cells += ["skipped", "—"]
                continue
            flag = target is _exact_worker
            cells += list(_peer(run_in_child(target, n, flag, args.limit), args.limit, total))
        print("| " + " | ".join(cells) + " |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
