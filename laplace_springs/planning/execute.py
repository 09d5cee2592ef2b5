"""Executing a plan: each engine of the chain evaluates the times still missing the target.

The executor knows nothing of engines but their names and the evaluator a caller builds
for each (``build(name)`` returns ``evaluate(times, order, target) -> (values, bounds)``
or a :class:`~laplace_springs.planning.engines.Refusal` found while building, such as an
eigen-solver failure). For every time it keeps the values whose bound is smallest, and
moves on to the next engine only with the times whose bound misses the target (the
decision for a time looks at that time alone). Engines are called on chunks of times, so
an evaluation holds a bounded amount of memory, shows progress when the plan expects it
to take long, and a Ctrl-C leaves every cache of the solution whole.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..limits import limits
from ..numeric.times import Times
from ..policy import Verdict, column_verdicts, judge_columns
from .engines import Refusal
from .plan import Plan
from .progress import Progress

__all__ = ["EvaluationReport", "Evaluator", "execute", "execute_judged", "relative_bounds", "BUILDERS",
           "DIGIT_HOSTS", "register_engine"]

Evaluator = Callable[[Times, int, float], tuple[np.ndarray, np.ndarray]]

#: engine name -> ``build(solution) -> Evaluator | Refusal``: filled by
#: :mod:`laplace_springs.routes.engines` (the routes sit above this stage).
BUILDERS: dict[str, Callable[[Any], Evaluator | Refusal]] = {}
#: engine name -> ``host(solution) -> Solution | Refusal`` whose ``_digits`` gives ``dps``
#: digits (the arbitrary-precision engines only).
DIGIT_HOSTS: dict[str, Callable[[Any], Any]] = {}


def register_engine(name: str, build: Callable[[Any], Evaluator | Refusal],
                    digits: Callable[[Any], Any] | None = None) -> None:
    """Make engine ``name`` buildable (and, for arbitrary precision, its digits host)."""
    BUILDERS[name] = build
    if digits is not None:
        DIGIT_HOSTS[name] = digits


@dataclass(frozen=True, eq=False)
class EvaluationReport:
    """Which engine produced each time of an evaluation, under which plan.

    Attributes
    ----------
    plan : Plan
    engines : tuple of str
        The engine whose values were kept, per time.
    relative_bounds : numpy.ndarray
        Per time, the largest bound divided by the contract's scale max(‖x(t)‖∞, S₀).
    refusals : tuple of Refusal
        Engines of the chain that could not be built for this scene.
    """

    plan: Plan
    engines: tuple[str, ...]
    relative_bounds: np.ndarray
    refusals: tuple[Refusal, ...] = ()

    def counts(self) -> dict[str, int]:
        """engine -> number of times it produced."""
        return dict(Counter(self.engines))

    def __str__(self) -> str:
        used = ", ".join(f"{name}: {count} time{'s' if count != 1 else ''}"
                         for name, count in self.counts().items())
        worst = float(np.max(self.relative_bounds, initial=0.0))
        return f"{used}; largest bound {worst:.2g} of the scale\n{self.plan}"


def relative_bounds(values: np.ndarray, bounds: np.ndarray, floor: float) -> np.ndarray:
    """Per column, the largest bound over the scale (inf for a non-finite value or bound)."""
    return column_verdicts(values, bounds, floor, 0.0)[1]


def execute(plan: Plan, build: Callable[[str], Evaluator | Refusal], times: Times, n: int,
            order: int, target: float, floor: float,
            progress: bool | None = None) -> tuple[np.ndarray, np.ndarray, EvaluationReport]:
    """Run ``plan`` at ``times``: float64 values, bounds (shape (n, len(times))) and a report.

    :func:`execute_judged` gives the final verdict on the columns as well.

    Parameters
    ----------
    plan : Plan
    build : callable
        ``build(engine) -> evaluator | Refusal``.
    times : Times
    n : int
        Coordinates.
    order : int
        Derivative.
    target : float
        Relative accuracy: a time moves on to the next engine while its bound exceeds
        ``target`` times max(‖x(t)‖∞, floor).
    floor : float
        S₀·ρ^order, the contract's floor of the scale.
    progress : bool, optional
        Show a progress bar on stderr (default: when the plan expects more than
        ``Limits.progress_after_seconds``).
    """
    values, bounds, report, _ = execute_judged(plan, build, times, n, order, target, floor,
                                               progress)
    return values, bounds, report


def execute_judged(plan: Plan, build: Callable[[str], Evaluator | Refusal], times: Times, n: int,
                   order: int, target: float, floor: float, progress: bool | None = None
                   ) -> tuple[np.ndarray, np.ndarray, EvaluationReport, Verdict]:
    """:func:`execute`, and the :class:`~laplace_springs.policy.Verdict` on the values and
    bounds it returns (their largest value and worst relative bound: a caller's range checks
    need no further pass over them)."""
    count = len(times)
    refusals: dict[str, Refusal] = {}
    show = plan.seconds > limits().progress_after_seconds if progress is None else progress
    first = None if show else _primary_at_once(plan, build, times, n, order, target, floor)
    if first is not None and not first.pending.any():
        # the primary took every time within the target: the report, and nothing else
        report = EvaluationReport(plan, (plan.chain[0],) * count, first.relative)
        return first.values, first.bounds, report, first.verdict
    bar = Progress(count * max(len(plan.chain), 1), enabled=bool(show), unit="evaluations")
    run = _Run(plan, build, times, n, order, target, floor, bar, refusals)
    try:
        groups = plan.groups(times.hi, times.span[1]) if count else [(None, plan.chain)]
        if first is not None:  # one group of times: the escalation of the primary's misses
            state = run.chain(plan.chain[1:], None, first)
        elif len(groups) == 1:
            state = run.chain(plan.chain, None, None)
        else:  # the primary for every time, then each band of times its own escalation
            state = run.chain(plan.chain[:1], None, None)
            for mask, chain in groups:
                state = run.chain(chain[1:], mask, state)
    finally:
        bar.close()
    state = state or _Kept.empty(n, count)
    report = EvaluationReport(plan, state.engines(), state.relative, tuple(refusals.values()))
    return state.values, state.bounds, report, state.verdict


def _primary_at_once(plan: Plan, build: Callable[[str], Evaluator | Refusal], times: Times,
                     n: int, order: int, target: float, floor: float) -> _Kept | None:
    """The first step of :func:`execute_judged` where it is one call: the primary engine
    on every time (one group of times, within its horizon and one chunk; no progress bar
    is shown), judged. None where that does not hold or the primary refuses (the plan is
    then run in full)."""
    count = len(times)
    if not (plan.chain and count) or count * n > _chunk_values() \
            or len(plan.groups(times.hi, times.span[1])) > 1:
        return None
    name = plan.chain[0]
    if not plan.request.t_max <= plan.horizons.get(name, np.inf):
        return None
    evaluator = build(name)
    if isinstance(evaluator, Refusal):
        return None
    return _Kept.taking(evaluator(times, order, target), name, floor, target)


@dataclass(eq=False)
class _Run:
    """One execution: the engines of a chain in turn on the times still pending."""

    plan: Plan
    build: Callable[[str], Evaluator | Refusal]
    times: Times
    n: int
    order: int
    target: float
    floor: float
    bar: Progress
    refusals: dict[str, Refusal]

    def chain(self, chain: tuple[str, ...], mask: np.ndarray | None,
              state: _Kept | None) -> _Kept | None:
        """Run ``chain`` on the pending times of ``mask`` (None: every time); the first
        engine to run on a fresh state takes every time in one call when it can."""
        times, count, n = self.times, len(self.times), self.n
        for name in chain:
            horizon = self.plan.horizons.get(name, np.inf)
            if state is None and mask is None and count > 0 \
                    and self.plan.request.t_max <= horizon and count * n <= _chunk_values():
                evaluator = self._evaluator(name)  # every time in one call
                if evaluator is None:
                    continue
                self.bar.update(name, f"{count} times")
                state = _Kept.taking(evaluator(times, self.order, self.target), name,
                                     self.floor, self.target)
                self.bar.advance(count)
            else:
                state = state or _Kept.empty(n, count)
                wanted = state.pending & (times.hi <= horizon)
                columns = np.flatnonzero(wanted if mask is None else wanted & mask)
                if columns.size == 0:
                    continue
                evaluator = self._evaluator(name)
                if evaluator is None:
                    continue
                for chunk in _chunks(columns, n):
                    self.bar.update(name, f"{chunk.size} times")
                    state.keep(evaluator(times.subset(chunk), self.order, self.target), chunk,
                               name)
                    self.bar.advance(chunk.size)
                state.judge(self.floor, self.target)
            if not (state.pending if mask is None else state.pending & mask).any():
                break
        return state

    def _evaluator(self, name: str) -> Evaluator | None:
        """The engine's evaluator, or None when it refuses (kept once per engine)."""
        evaluator = self.build(name)
        if isinstance(evaluator, Refusal):
            self.refusals.setdefault(name, evaluator)
            return None
        return evaluator


@dataclass(eq=False)
class _Kept:
    """The values kept so far, their bounds, the engine of each time, and the verdicts.

    ``source`` is the engine of each time, or one name for every time (the first engine
    took them all)."""

    values: np.ndarray
    bounds: np.ndarray
    source: np.ndarray | str
    verdict: Verdict

    @property
    def pending(self) -> np.ndarray:
        return self.verdict.pending

    @property
    def relative(self) -> np.ndarray:
        return self.verdict.relative

    @classmethod
    def empty(cls, n: int, count: int) -> _Kept:
        return cls(np.full((n, count), np.nan), np.full((n, count), np.inf),
                   np.full(count, "", dtype=object),
                   Verdict(np.ones(count, dtype=bool), np.full(count, np.inf), math.nan,
                           math.inf if count else 0.0))

    @classmethod
    def taking(cls, result: tuple[np.ndarray, np.ndarray], name: str, floor: float,
               target: float) -> _Kept:
        """Every time from one engine's call."""
        values, bounds = (np.array(a, dtype=float) for a in result)   # copies: ours to change
        return cls(values, bounds, name, judge_columns(np.abs(values), bounds, floor, target))

    def engines(self) -> tuple[str, ...]:
        """The engine of each time."""
        if isinstance(self.source, str):
            return (self.source,) * self.values.shape[1]
        return tuple(self.source)

    def judge(self, floor: float, target: float) -> None:
        self.verdict = judge_columns(np.abs(self.values), self.bounds, floor, target)

    def keep(self, result: tuple[np.ndarray, np.ndarray], chunk: np.ndarray, name: str) -> None:
        """Per time, keep the new values where their largest bound is smaller."""
        source = self.source if not isinstance(self.source, str) else \
            np.full(self.values.shape[1], self.source, dtype=object)
        self.source = source
        new, new_bounds = result
        finite = np.isfinite(new)
        with np.errstate(invalid="ignore"):
            old_worst = self.bounds[:, chunk].max(axis=0)
            new_worst = np.where(finite, new_bounds, np.inf).max(axis=0)
            # a value beyond float64 (±inf, no NaN) replaces one that has no bound: the
            # caller then says so (dps= gives it) instead of that no engine bounded it
            beyond = np.isinf(new).any(axis=0) & ~np.isnan(new).any(axis=0) \
                & (old_worst == np.inf)
            take = ~(new_worst >= old_worst) & finite.all(axis=0) \
                | np.isnan(self.values[:, chunk]).any(axis=0) | beyond
        columns = chunk[take]
        self.values[:, columns] = new[:, take]
        self.bounds[:, columns] = new_bounds[:, take]
        source[columns] = name


def _chunk_values() -> int:
    return limits().evaluation_chunk_values


def _chunks(columns: np.ndarray, n: int) -> list[np.ndarray]:
    """Columns in pieces of at most Limits.evaluation_chunk_values values."""
    size = max(1, _chunk_values() // max(n, 1))
    return [columns[i:i + size] for i in range(0, columns.size, size)]
