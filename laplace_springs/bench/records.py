"""What the error-against-run-time benchmark records: cases, settings, records, verdicts.

Shared by :mod:`laplace_springs.bench.harness` (which measures) and
:mod:`laplace_springs.bench.report` (which writes), so neither imports the other's internals.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

from ..model.scene import Scene
from .methods import Method

__all__ = ["BenchCase", "BenchSettings", "Record", "Verdict", "BenchmarkResult", "TIE_FLOOR",
           "TIE_FACTOR", "DEFAULT_ROUTE", "measured", "more_accurate", "pareto_verdict"]

#: Errors at or below this count as equal (float64 rounding of the output).
TIE_FLOOR = 1e-15
#: A peer is more accurate only if its (floored) error is smaller by more than this factor.
TIE_FACTOR = 2.0
#: Name of our default route among the methods.
DEFAULT_ROUTE = "ours"


@dataclass(frozen=True)
class BenchCase:
    """A scene and the times to evaluate it at (same fields as ``battery.BatteryCase``)."""

    name: str
    kind: str
    description: str
    scene: Scene
    times: tuple[str, ...]


@dataclass(frozen=True)
class BenchSettings:
    """Limits of a run.

    Attributes
    ----------
    time_limit : float
        Seconds allowed for one run of a peer on one case (and for its setup); raised
        to twice our route's time on cases where ours is slower, so a limit never
        hides a peer that could have been faster than ours.
    ours_limit : float
        Seconds allowed for one run of one of our routes.
    sympy_limit : float
        Seconds allowed for SymPy's inversion of one case (in its worker process).
    max_runs : int
        At most this many timed runs per method and case.
    min_total : float
        Runs are repeated (up to ``max_runs``) while their total time is below this.
    digits : int
        Certified digits of the reference.
    """

    time_limit: float = 2.0
    ours_limit: float = 60.0
    sympy_limit: float = 10.0
    max_runs: int = 5
    min_total: float = 0.3
    digits: int = 60


@dataclass
class Record:
    """One method on one case."""

    case: str
    kind: str
    method: str
    label: str
    ours: bool
    status: str                    # "ok", "timeout", "skipped" or "failed"
    error: float | None = None
    seconds: float | None = None
    runs: int = 0
    phases: dict[str, float] = field(default_factory=dict)
    note: str = ""


@dataclass
class Verdict:
    """Two verdicts on our default route for one case.

    *On the front* (:attr:`on_front`): no peer is both strictly faster and more accurate
    (tie rule). *Fastest at this accuracy* (:attr:`fastest_at_accuracy`): no peer that is
    at least as accurate (tie rule: not less accurate) is strictly faster. The second is
    the stricter: a peer whose error is inside the tie band of ours and that is faster
    leaves us on the front but not the fastest.
    """

    case: str
    ours: Record | None
    dominated_by: list[Record]          # tie band applied (TIE_FLOOR, TIE_FACTOR)
    strictly_dominated_by: list[Record]  # raw errors
    #: Peers strictly faster than ours and at least as accurate (tie rule), fastest first.
    faster_as_accurate: list[Record] = field(default_factory=list)

    @property
    def on_front(self) -> bool | None:
        """True/False, or None when our route produced no result on this case."""
        if self.ours is None or self.ours.status != "ok":
            return None
        return not self.dominated_by

    @property
    def fastest_at_accuracy(self) -> bool | None:
        """True when no peer at least as accurate is faster; None without our result."""
        if self.on_front is None:
            return None
        return not self.faster_as_accurate

    def speedup(self, record: Record) -> float:
        """Our time over ``record``'s time (> 1: the peer is that many times faster)."""
        if self.ours is None or self.ours.seconds is None or not record.seconds:
            return float("nan")
        return self.ours.seconds / record.seconds


@dataclass
class BenchmarkResult:
    """All records, the verdicts, the files written and the wall time of the run."""

    cases: list[BenchCase]
    methods: list[Method]
    records: list[Record]
    verdicts: list[Verdict]
    settings: BenchSettings
    wall_seconds: float
    files: dict[str, Path] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)


def measured(record: Record) -> tuple[float, float] | None:
    """(error, seconds) of a record that finished ("ok" with both numbers), else None.

    Examples
    --------
    >>> measured(Record("c", "k", "m", "", False, "ok", error=1e-9, seconds=0.5))
    (1e-09, 0.5)
    >>> measured(Record("c", "k", "m", "", False, "timeout")) is None
    True
    """
    if record.status != "ok" or record.error is None or record.seconds is None:
        return None
    return record.error, record.seconds


def _floored(error: float) -> float:
    return max(error, TIE_FLOOR)


def more_accurate(error: float, than: float, *, strict: bool = False) -> bool:
    """Whether ``error`` is more accurate than ``than`` under the report's tie rule.

    Examples
    --------
    >>> more_accurate(1e-16, 8e-16), more_accurate(1e-16, 8e-16, strict=True)
    (False, True)
    >>> more_accurate(1e-12, 1e-9)
    True
    """
    if strict:
        return error < than
    return _floored(error) * TIE_FACTOR < _floored(than)


def pareto_verdict(records: Sequence[Record], route: str = DEFAULT_ROUTE) -> Verdict:
    """Which peers are strictly faster than our ``route`` on one case and how accurate.

    ``dominated_by``: faster and more accurate (tie rule); ``strictly_dominated_by``:
    faster and more accurate in raw errors; ``faster_as_accurate``: faster and not less
    accurate (tie rule), fastest first. Only peers (records with ``ours`` false) that
    finished count; our other routes never dominate the default one.

    Examples
    --------
    >>> ours = Record("c", "k", "ours", "", True, "ok", error=1e-12, seconds=0.01)
    >>> peer = Record("c", "k", "peer", "", False, "ok", error=1e-14, seconds=0.001)
    >>> [r.method for r in pareto_verdict([ours, peer]).dominated_by]
    ['peer']

    A peer inside the tie band (3e-16 against 1e-16: both below the floor) and ten times
    faster leaves us on the front, but not the fastest at this accuracy:

    >>> ours = Record("c", "k", "ours", "", True, "ok", error=1e-16, seconds=0.01)
    >>> tied = Record("c", "k", "tied", "", False, "ok", error=3e-16, seconds=0.001)
    >>> verdict = pareto_verdict([ours, tied])
    >>> verdict.on_front, verdict.fastest_at_accuracy, round(verdict.speedup(tied), 6)
    (True, False, 10.0)
    """
    ours = next((r for r in records if r.method == route), None)
    case = records[0].case if records else ""
    mine = measured(ours) if ours is not None else None
    if mine is None:
        return Verdict(case, ours, [], [])
    error, seconds = mine
    peers = [(r, m[0]) for r in records
             if not r.ours and (m := measured(r)) is not None and m[1] < seconds]
    as_accurate = [r for r, e in peers if not more_accurate(error, e)]
    as_accurate.sort(key=lambda r: r.seconds or 0.0)
    return Verdict(case, ours,
                   [r for r, e in peers if more_accurate(e, error)],
                   [r for r, e in peers if more_accurate(e, error, strict=True)],
                   as_accurate)
