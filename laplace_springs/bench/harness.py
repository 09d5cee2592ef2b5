"""Error against run time: this project's routes and the usual peers on a battery of scenes.

:func:`run_benchmark` solves each case (a scene and its times) with each method of
:mod:`laplace_springs.bench.methods`, measures the error against a certified 60-digit
reference and the run time, decides whether the default route is on the accuracy–time
Pareto front, and writes ``report.md``, ``results.csv`` and one work-precision plot per
case into an output directory. ``laplace-springs bench`` is the command line for it.

Definitions (also printed in the report)
----------------------------------------
error
    max over coordinates and times of |x_method − x_ref|, divided by max |x_ref|.
    The reference is :func:`laplace_springs.bench.reference.reference_motion_arb`: flint's
    ball-arithmetic matrix exponential of the first-order system, certified to 60
    digits, at exactly the float64 times every method is given.
time
    Wall time of the fastest of up to ``max_runs`` runs (repeated while their total is
    under ``min_total`` seconds): other processes only add time. Ours: from the exact
    Scene to values (``solve`` +
    ``evaluate``), with SymPy's and our caches cleared before every run, so no run
    reuses an earlier solve. Peers: from float64 data (the first-order matrix, already
    formed exactly and rounded; X(λ) for the Laplace-domain peers) to values, each run
    after the same clearing (it leaves a peer's results alone and puts the processor's
    caches in the state ours start from, so neither is timed warm).
more accurate
    Errors are floored at ``TIE_FLOOR`` (1e-15: differences there are float64 rounding
    of the output) and a peer is more accurate only if its floored error is below ours
    by more than ``TIE_FACTOR`` (2). The report also gives the strict verdict (raw
    errors, no tie band).
on the Pareto front
    No peer (a method that is not this project's) is both strictly faster and more
    accurate than our default route on that case.
fastest at this accuracy
    No peer at least as accurate as our default route (tie rule) is strictly faster. A
    peer inside the tie band that is faster leaves us on the front but not the fastest;
    the report and the summary give both verdicts and list those cases with the ratio.
"""

from __future__ import annotations

import csv
import fnmatch
import gc
import signal
import sys
import threading
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from types import FrameType
from typing import Any

import mpmath
import numpy as np
from sympy.core.cache import clear_cache

from ..kernels.precision import workdps
from ..model.scene import Scene
from ..numeric import first_order
from ..planning.progress import Progress
from . import report as bench_report
from .battery import battery_cases
from .methods import (
    QUICK_METHODS,
    Method,
    Outcome,
    Problem,
    TimeLimitExceeded,
    Unavailable,
    all_methods,
    missing_modules,
)
from .records import DEFAULT_ROUTE, BenchCase, BenchmarkResult, BenchSettings, Record, Verdict, pareto_verdict
from .reference import reference_motion_arb

__all__ = ["BenchCase", "BenchSettings", "Record", "Verdict", "BenchmarkResult",
           "default_cases", "select_methods", "pareto_verdict", "run_benchmark", "clear_caches"]

# ----------------------------------------------------------------------------- selection


def default_cases(*, large: bool = False) -> list[BenchCase]:
    """The battery of stiff and extreme scenes (:mod:`laplace_springs.bench.battery`).

    Examples
    --------
    >>> cases = default_cases()
    >>> len(cases) >= 5 and all(case.times for case in cases)
    True
    """
    return [BenchCase(c.name, c.kind, c.description, c.scene, c.times)
            for c in battery_cases(large=large)]


def _matches(name: str, patterns: Sequence[str]) -> bool:
    return any(fnmatch.fnmatchcase(name, pattern) for pattern in patterns)


def select_methods(patterns: Sequence[str] | None = None, *, quick: bool = False,
                   sympy_limit: float = 10.0) -> list[Method]:
    """Methods whose names match any of the glob ``patterns`` (all, or the quick set).

    Examples
    --------
    >>> [m.name for m in select_methods(["ours", "ivp-RK45-*"])]
    ['ours', 'ivp-RK45-1e-06', 'ivp-RK45-1e-09', 'ivp-RK45-1e-12']
    """
    methods = list(all_methods(sympy_limit=sympy_limit))
    if quick:
        methods = [m for m in methods if m.name in QUICK_METHODS]
    if patterns:
        unknown = [p for p in patterns if not any(_matches(m.name, [p]) for m in methods)]
        if unknown:
            names = ", ".join(m.name for m in methods)
            raise ValueError(f"no method matches {', '.join(map(repr, unknown))}; "
                             f"methods: {names}")
        methods = [m for m in methods if _matches(m.name, patterns)]
    return methods


def _select_cases(cases: Sequence[BenchCase], patterns: Sequence[str] | None) -> list[BenchCase]:
    if not patterns:
        return list(cases)
    chosen = [case for case in cases if _matches(case.name, patterns)]
    if not chosen:
        names = ", ".join(case.name for case in cases)
        raise ValueError(f"no case matches {', '.join(map(repr, patterns))}; cases: {names}")
    return chosen


# ----------------------------------------------------------------------------- measuring


@contextmanager
def time_limit(seconds: float | None) -> Iterator[None]:
    """Raise :class:`TimeLimitExceeded` in the block after ``seconds`` (SIGALRM).

    Python-level code (integrators' right-hand sides, mpmath, SymPy) is interrupted;
    where SIGALRM is unavailable (Windows, or off the main thread) there is no limit.
    """
    usable = hasattr(signal, "setitimer") and threading.current_thread() is threading.main_thread()
    if seconds is None or not usable:
        yield
        return
    limit: float = seconds

    def _alarm(signum: int, frame: FrameType | None) -> None:
        raise TimeLimitExceeded(f"over {limit:g} s")

    previous = signal.signal(signal.SIGALRM, _alarm)
    signal.setitimer(signal.ITIMER_REAL, limit)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def clear_caches() -> None:
    """Empty SymPy's cache, the functools caches of this package and the tables it keeps
    per scene (``numeric.first_order.scene_cache``: entries, facts, engine data), so every
    timed run of ours starts from the Scene as built, as a first call does."""
    clear_cache()
    first_order._ENTRIES.clear()  # the callbacks pop with a default: safe to empty
    for name, module in list(sys.modules.items()):
        if name.startswith("laplace_springs") and module is not None:
            for value in list(vars(module).values()):
                if callable(getattr(value, "cache_clear", None)):
                    value.cache_clear()


class Reference:
    """The certified reference of a problem and the error measure against it."""

    def __init__(self, problem: Problem, digits: int) -> None:
        self.values = reference_motion_arb(problem.scene, problem.mp_times, digits)
        with workdps(digits + 10):
            self.scale = max(abs(v) for v in self.values.ravel())
            high = np.array([float(v) for v in self.values.ravel()])
            low = np.array([float(v - mpmath.mpf(h)) for v, h in zip(self.values.ravel(), high)])
        self.high = high.reshape(self.values.shape)
        self.low = low.reshape(self.values.shape)

    def error(self, values: np.ndarray) -> float:
        """max |values − reference| / max |reference| (NaN or a wrong shape: inf)."""
        values = np.asarray(values)
        if values.shape != self.values.shape:
            return float("inf")
        if values.dtype == object:
            with workdps(40):
                diff = max(abs(mpmath.mpf(v) - r) for v, r in
                           zip(values.ravel(), self.values.ravel()))
                return float(diff / self.scale) if self.scale else float(diff)
        difference = np.abs((values.astype(float) - self.high) - self.low)
        if not np.all(np.isfinite(difference)):
            return float("inf")
        scale = float(self.scale) or 1.0
        return float(difference.max() / scale)


def _skipped(case: BenchCase, method: Method, status: str, note: str) -> Record:
    return Record(case.name, case.kind, method.name, method.label, method.ours, status,
                  note=note)


def _timed_runs(method: Method, problem: Problem, state: Any, settings: BenchSettings,
                limit: float) -> list[tuple[float, Outcome]]:
    runs: list[tuple[float, Outcome]] = []
    while True:
        # every run starts from the same state: ours from empty caches (a first call), and
        # a peer after the same clearing, which empties the processor's caches as it does
        # before ours (a peer repeated back to back would be timed warm: control's
        # initial_response on the seed's pair 309 µs warm against 403 µs after SymPy work)
        clear_caches()
        gc.collect()  # the garbage of the clearing is not charged to the run that follows
        start = time.perf_counter()
        if method.own_limit:
            outcome = method.run(problem, state)
        else:
            with time_limit(limit):
                outcome = method.run(problem, state)
        elapsed = time.perf_counter() - start
        runs.append((elapsed if outcome.seconds is None else outcome.seconds, outcome))
        total = sum(r[0] for r in runs)
        if method.own_limit or len(runs) >= settings.max_runs or total >= settings.min_total:
            return runs


def _best_run(runs: list[tuple[float, Outcome]]) -> tuple[float, Outcome]:
    """The fastest run: other processes only ever add time (the reasoning of timeit)."""
    return min(runs, key=lambda r: r[0])


def measure(method: Method, case: BenchCase, problem: Problem, reference: Reference,
            settings: BenchSettings, limit: float | None = None) -> Record:
    """Time ``method`` on one case and measure its error (never raises for a peer's failure).

    ``limit`` is the time limit of one run (default: ``settings.ours_limit`` for our
    routes, ``settings.time_limit`` for peers).
    """
    if limit is None:
        limit = settings.ours_limit if method.ours else settings.time_limit
    missing = missing_modules(method)
    if missing:
        return _skipped(case, method, "skipped",
                        f"{', '.join(missing)} not installed (pip install 'laplace_springs[bench]')")
    try:
        with time_limit(limit):
            state = method.prepare(problem) if method.prepare else None
    except Unavailable as exc:
        return _skipped(case, method, "skipped", str(exc))
    except TimeLimitExceeded:
        return _skipped(case, method, "skipped", f"setup (X(λ)) over {limit:g} s")
    try:
        runs = _timed_runs(method, problem, state, settings, limit)
    except TimeLimitExceeded as exc:
        return _skipped(case, method, "timeout", str(exc))
    except Exception as exc:  # a peer (or our route) failing is a result, not a crash
        return _skipped(case, method, "failed", f"{type(exc).__name__}: {exc}"[:160])
    seconds, outcome = _best_run(runs)
    error = reference.error(outcome.values)
    status = "ok" if np.isfinite(error) else "failed"
    note = outcome.note if status == "ok" else f"non-finite values. {outcome.note}"
    return Record(case.name, case.kind, method.name, method.label, method.ours, status,
                  error, seconds, len(runs), dict(outcome.phases), note.strip())


# ----------------------------------------------------------------------------- driver


def _warm_up(methods: Sequence[Method], settings: BenchSettings) -> list[str]:
    """Run each method once on a tiny scene (imports, worker start-up); return notes."""
    scene = Scene.from_matrices(M=[[1]], C=[[1]], K=[[1]], x0=[1], v0=[0])
    case = BenchCase("warm-up", "warm-up", "", scene, ("0", "1", "2"))
    problem = Problem.from_case(case.name, case.kind, scene, case.times)
    reference = Reference(problem, 20)
    notes = []
    for method in methods:
        record = measure(method, case, problem, reference, BenchSettings(max_runs=1), 60.0)
        if record.status != "ok":
            notes.append(f"{method.name}: {record.status} on the warm-up scene ({record.note})")
    return notes


def _measure_case(case: BenchCase, methods: Sequence[Method], settings: BenchSettings,
                  progress: Progress) -> list[Record]:
    progress.update(case.name, "reference")
    try:
        problem = Problem.from_case(case.name, case.kind, case.scene, case.times)
        reference = Reference(problem, settings.digits)
    except (ValueError, ArithmeticError) as exc:  # SceneError is a ValueError
        note = f"no independent reference: {exc}"[:160]
        for _ in methods:
            progress.advance()
        return [_skipped(case, m, "skipped", note) for m in methods]
    records: list[Record] = []
    timed_out: set[str] = set()
    peer_limit = settings.time_limit
    for method in methods:
        progress.update(case.name, method.name)
        if method.family and method.family in timed_out:
            record = _skipped(case, method, "skipped",
                              "an easier tolerance of this solver timed out")
        else:
            record = measure(method, case, problem, reference, settings,
                             None if method.ours else peer_limit)
            if record.status == "timeout" and method.family:
                timed_out.add(method.family)
            if method.name == DEFAULT_ROUTE and record.seconds is not None:
                peer_limit = max(settings.time_limit, 2.0 * record.seconds)
        records.append(record)
        progress.advance()
    return records


def run_benchmark(cases: Sequence[BenchCase] | None = None, *,
                  methods: Sequence[str] | None = None,
                  scenes: Sequence[str] | None = None,
                  out_dir: str | Path = "bench-out",
                  quick: bool = False,
                  large: bool = False,
                  settings: BenchSettings | None = None,
                  progress: bool = True,
                  plots: bool = True) -> BenchmarkResult:
    """Measure error and run time of every method on every case and write the report.

    Parameters
    ----------
    cases : sequence of BenchCase, optional
        The cases (anything with name, kind, description, scene, times); default
        :func:`default_cases`.
    methods : sequence of str, optional
        Glob patterns of method names (``"ours*"``, ``"ivp-Radau-*"``); default all
        (or the quick set).
    scenes : sequence of str, optional
        Glob patterns of case names to keep.
    out_dir : path
        Directory for ``report.md``, ``results.csv`` and ``plots/<case>.png``.
    quick : bool
        A smaller method set (:data:`~laplace_springs.bench.methods.QUICK_METHODS`)
        and no SymPy.
    large : bool
        Ask the battery for its large cases too.
    settings : BenchSettings, optional
        Time limits and repeats.
    progress : bool
        Show a progress bar on stderr.
    plots : bool
        Write the work-precision plots (needs matplotlib).

    Returns
    -------
    BenchmarkResult

    Examples
    --------
    >>> import tempfile
    >>> scene = Scene.from_matrices(M=[[1]], C=[[2]], K=[[1]], x0=[1], v0=[0])
    >>> case = BenchCase("critical", "critical", "(1 + t)e^{-t}", scene, ("0", "1", "10"))
    >>> with tempfile.TemporaryDirectory() as out:
    ...     result = run_benchmark([case], methods=["ours"], out_dir=out,
    ...                            progress=False, plots=False)
    >>> result.records[0].error < 1e-15, result.verdicts[0].on_front
    (True, True)
    """
    settings = settings or BenchSettings()
    started = time.perf_counter()
    chosen_cases = _select_cases(cases if cases is not None else default_cases(large=large),
                                 scenes)
    chosen = select_methods(methods, quick=quick, sympy_limit=settings.sympy_limit)
    try:
        notes = _warm_up(chosen, settings)
        bar = Progress(len(chosen_cases) * len(chosen), enabled=progress)
        records = []
        for case in chosen_cases:
            records += _measure_case(case, chosen, settings, bar)
        bar.close()
    finally:
        for method in chosen:
            method.close()
    verdicts = [pareto_verdict([r for r in records if r.case == case.name])
                for case in chosen_cases]
    result = BenchmarkResult(chosen_cases, chosen, records, verdicts, settings,
                             time.perf_counter() - started, notes=notes)
    result.files = bench_report.write_all(result, Path(out_dir), plots=plots)
    return result


def read_csv(path: str | Path) -> list[dict[str, str]]:
    """The rows of a ``results.csv`` written by :func:`run_benchmark`."""
    with open(path, newline="", encoding="utf-8") as handle:
        return list(csv.DictReader(handle))


def summary_lines(result: BenchmarkResult) -> list[str]:
    """Short per-case lines (our error and time, both verdicts), then the headline:
    both counts and the cases where a peer at least as accurate is faster."""
    lines = []
    for verdict in result.verdicts:
        ours = verdict.ours
        if ours is None or ours.status != "ok":
            lines.append(f"{verdict.case}: our route gave no result "
                         f"({ours.status + ': ' + ours.note if ours else 'not run'})")
            continue
        lines.append(f"{verdict.case}: error {ours.error:.1e}, {ours.seconds:.3g} s — "
                     f"{bench_report.verdict_text(verdict)}; fastest at this accuracy: "
                     f"{bench_report.fastest_text(verdict)}")
    lines += bench_report.headline(result.verdicts)
    lines.append(f"total {result.wall_seconds:.0f} s")
    return lines

