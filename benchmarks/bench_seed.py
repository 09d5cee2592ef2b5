"""Benchmark: exact solves of the bundled seed scenes, against SymPy's inverse_laplace_transform.

Run from the repository root::

    .venv/bin/python benchmarks/bench_seed.py [--repeat 7] [--sympy-limit 30] [--no-sympy]

Prints a Markdown table, one row per bundled scene (see benchmarks/README.md for the
columns). Every measurement that must start from an empty SymPy cache runs in a fresh
spawned process: our cold solve, and SymPy's inversion of the same transforms X_i(λ)
under a hard time limit (the process is killed when it runs out).
"""

from __future__ import annotations

import argparse
import multiprocessing
import platform
import statistics
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass

import flint
import numpy as np
import sympy as sp
from sympy.external.gmpy import GROUND_TYPES

import laplace_springs as ls

#: Warm-time targets (seconds): factorable seed scenes, and scenes whose Δ(λ) has an
#: irreducible factor of degree ≥ 3 (wall-pair-dashpot, three-dashpots).
TARGET_FACTORABLE = 0.1
TARGET_IRREDUCIBLE = 0.5
EVALUATION_TIMES = np.linspace(0.0, 100.0, 1000)
#: Times at which SymPy's result is compared with ours.
CHECK_TIMES = (0.7, 2.9)
STARTUP_LIMIT = 120.0


# ----------------------------------------------------------------------------- child processes


def _exact_x(scene: ls.Scene) -> object:
    """What is timed: the exact route's closed form x(t)."""
    return ls.solve(scene, method="exact").x


def _cold_worker(name: str, conn) -> None:
    """Time one exact solve(scene).x in a fresh interpreter (imports done before timing)."""
    scene = ls.load_scene(name)
    start = time.perf_counter()
    _exact_x(scene)
    conn.send(("cold", time.perf_counter() - start))


def _sympy_worker(name: str, conn) -> None:
    """Invert X_i(λ) with SymPy; send the time, then values at CHECK_TIMES."""
    transforms = list(ls.resolvent(ls.load_scene(name)).transform())
    conn.send(("ready",))
    start = time.perf_counter()
    results = [sp.inverse_laplace_transform(X, ls.lam, ls.t) for X in transforms]
    elapsed = time.perf_counter() - start
    heaviside = any(r.has(sp.Heaviside) for r in results)
    unevaluated = any(r.has(sp.InverseLaplaceTransform) for r in results)
    conn.send(("time", elapsed, heaviside, unevaluated))
    if not unevaluated:
        values = [[complex(sp.N(r.subs(ls.t, sp.Float(tv)), 20)) for tv in CHECK_TIMES]
                  for r in results]
        conn.send(("values", values))


def _receive(parent, limit: float) -> tuple | None:
    """The child's next message, or None if it sends nothing within ``limit`` seconds."""
    if parent.poll(limit):
        try:
            return parent.recv()
        except EOFError:
            return None
    return None


def run_in_child(target: Callable, name: str, limit: float) -> list[tuple]:
    """Run ``target(name, conn)`` in a spawned process; collect its messages.

    The child may first send ``("ready",)`` when its setup is done; from then on each
    further message must arrive within ``limit`` seconds or the child is killed.
    """
    context = multiprocessing.get_context("spawn")
    parent, child = context.Pipe(duplex=False)
    process = context.Process(target=target, args=(name, child), daemon=True)
    process.start()
    child.close()
    messages: list[tuple] = []
    try:
        wait = STARTUP_LIMIT  # spawning and importing SymPy are not part of the limit
        while (message := _receive(parent, wait)) is not None:
            messages.append(message)
            wait = limit
    finally:
        if process.is_alive():
            process.kill()
        process.join()
    return messages


# ----------------------------------------------------------------------------- measurements


@dataclass
class Row:
    name: str
    factors: str
    irreducible: bool
    cold: float | None
    warm: float
    eval_first: float
    eval_warm: float
    sympy: tuple | None = None      # ("time", seconds, heaviside, unevaluated) or None
    sympy_error: float | None = None


def _median_time(function: Callable[[], object], repeat: int) -> float:
    function()  # warm-up
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def _factor_degrees(scene) -> tuple[str, bool]:
    """Degrees of Δ(λ)'s irreducible factors over ℚ, e.g. "2·2", and whether one is ≥ 3."""
    _, factors = sp.factor_list(ls.resolvent(scene).determinant)
    degrees = sorted((f.degree() for f, k in factors for _ in range(k)), reverse=True)
    return "·".join(map(str, degrees)), max(degrees) >= 3


def _evaluation_times(scene) -> tuple[float, float]:
    """First evaluate() on a fresh solution (includes the exact→numeric step), then warm."""
    solution = ls.solve(scene, method="exact")
    start = time.perf_counter()
    solution.evaluate(EVALUATION_TIMES)
    first = time.perf_counter() - start
    return first, _median_time(lambda: solution.evaluate(EVALUATION_TIMES), 7)


def _sympy_error(values, scene) -> float:
    """Largest |SymPy − ours| at CHECK_TIMES, relative to the largest |x|."""
    ours = ls.solve(scene, method="exact").evaluate(list(CHECK_TIMES))
    scale = max(1e-300, float(np.abs(ours).max()))
    return max(abs(complex(v) - ours[i, j]) for i, row in enumerate(values)
               for j, v in enumerate(row)) / scale


def measure(name: str, *, repeat: int, sympy_limit: float | None) -> Row:
    """All measurements of one bundled scene."""
    cold = run_in_child(_cold_worker, name, STARTUP_LIMIT)
    scene = ls.load_scene(name)
    factors, irreducible = _factor_degrees(scene)
    warm = _median_time(lambda: _exact_x(scene), repeat)
    row = Row(name, factors, irreducible, cold[0][1] if cold else None, warm,
              *_evaluation_times(scene))
    if sympy_limit is not None:
        messages = {m[0]: m for m in run_in_child(_sympy_worker, name, sympy_limit)}
        row.sympy = messages.get("time")
        if "values" in messages:
            row.sympy_error = _sympy_error(messages["values"][1], scene)
    return row


# ----------------------------------------------------------------------------- output


def _seconds(value: float | None) -> str:
    return "—" if value is None else f"{value:.4f}"


def _ratio(value: float) -> str:
    return f"{value:.1f}×" if value < 10 else f"{value:.0f}×"


def _sympy_cells(row: Row, limit: float | None) -> list[str]:
    if limit is None:
        return ["skipped", "—", "—", "—"]
    if row.sympy is None:
        ratio = "> " + _ratio(limit / row.cold) if row.cold else "—"
        return [f"> {limit:g} (killed)", ratio, "—", "—"]
    _, seconds, heaviside, unevaluated = row.sympy
    ratio = _ratio(seconds / row.cold) if row.cold else "—"
    if unevaluated:
        return [f"{seconds:.3f} (unevaluated)", ratio, "yes" if heaviside else "no", "—"]
    agreement = "—" if row.sympy_error is None else f"{row.sympy_error:.0e}" if row.sympy_error else "0"
    return [f"{seconds:.3f}", ratio, "yes" if heaviside else "no", agreement]


def _target_cell(row: Row) -> str:
    target = TARGET_IRREDUCIBLE if row.irreducible else TARGET_FACTORABLE
    verdict = "met" if row.warm <= target else "MISSED"
    return f"≤ {target:g} s: {verdict}"


HEADER = ("| scene | Δ(λ) factor degrees | ours cold (s) | ours warm (s) | target (warm) "
          "| eval 1000 t first / warm (ms) | SymPy ILT (s) | SymPy / ours cold "
          "| SymPy has Heaviside | SymPy vs ours |")


def table_lines(rows: list[Row], limit: float | None) -> list[str]:
    lines = [HEADER, "|" + "---|" * HEADER.count(" | ") + "---|"]
    for row in rows:
        cells = [f"`{row.name}`", row.factors, _seconds(row.cold), _seconds(row.warm),
                 _target_cell(row), f"{row.eval_first * 1e3:.2f} / {row.eval_warm * 1e3:.2f}",
                 *_sympy_cells(row, limit)]
        lines.append("| " + " | ".join(cells) + " |")
    return lines


def preamble(repeat: int, limit: float | None) -> list[str]:
    sympy_note = "skipped (--no-sympy)" if limit is None else f"hard limit {limit:g} s per scene"
    return [
        "# laplace_springs: exact solves of the bundled seed scenes",
        "",
        f"Python {platform.python_version()}, SymPy {sp.__version__} (ground types {GROUND_TYPES}), "
        f"python-flint {flint.__version__}, laplace_springs {ls.__version__}, {platform.machine()}.",
        f"Targets: every bundled seed scene ≤ {TARGET_FACTORABLE:g} s warm; scenes whose Δ(λ) has an "
        f"irreducible factor of degree ≥ 3 (wall-pair-dashpot, three-dashpots) ≤ {TARGET_IRREDUCIBLE:g} s.",
        f"ours = `ls.solve(scene, method=\"exact\").x`; cold = first call in a fresh process; warm = median of "
        f"{repeat} calls after one warm-up (solve caches nothing, SymPy caches internally).",
        f"SymPy ILT = `sympy.inverse_laplace_transform(X_i, lam, t)` over all coordinates, "
        f"fresh process, {sympy_note}.",
        "",
    ]


def parse_arguments(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7, help="warm runs per scene (default 7)")
    parser.add_argument("--sympy-limit", type=float, default=30.0, metavar="SECONDS",
                        help="hard time limit for SymPy per scene (default 30)")
    parser.add_argument("--no-sympy", action="store_true", help="skip the SymPy comparison")
    args = parser.parse_args(argv)
    if args.repeat < 1 or args.sympy_limit <= 0:
        parser.error("--repeat and --sympy-limit must be positive")
    return args


def main(argv: list[str] | None = None) -> int:
    args = parse_arguments(argv)
    limit = None if args.no_sympy else args.sympy_limit
    rows = [measure(name, repeat=args.repeat, sympy_limit=limit) for name in ls.bundled_scenes()]
    print("\n".join(preamble(args.repeat, limit) + table_lines(rows, limit)))
    missed = [row.name for row in rows if "MISSED" in _target_cell(row)]
    print(f"\nTargets: {'all met' if not missed else 'MISSED by ' + ', '.join(missed)}.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
