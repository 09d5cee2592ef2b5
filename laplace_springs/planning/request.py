"""What a caller asks of a solution: :class:`Request` (how many times, how far, how
accurately, which derivative, with bounds or digits)."""

from __future__ import annotations

from dataclasses import dataclass

from ..limits import limits
from ..numeric.times import Times

__all__ = ["Request", "request_for", "DEFAULT_REQUEST"]


@dataclass(frozen=True)
class Request:
    """An evaluation request, as the planner sees it.

    Attributes
    ----------
    count : int
        Number of times.
    t_max : float
        The largest time.
    target : float
        Relative accuracy asked (see the contract in :mod:`laplace_springs.policy`).
    dps : int or None
        Decimal digits asked (None: float64).
    order : int
        Derivative: 0, 1 or 2.
    formula : bool
        A closed form is wanted (``x``, LaTeX), not only values.
    """

    count: int = 100
    t_max: float = 100.0
    target: float = 1e-13
    dps: int | None = None
    order: int = 0
    formula: bool = False

    def __str__(self) -> str:
        digits = f"{self.dps} digits" if self.dps else f"target {self.target:g}"
        return (f"{self.count:,} time{'s' if self.count != 1 else ''} up to t = {self.t_max:g}, "
                f"{digits}" + (f", derivative {self.order}" if self.order else ""))


#: What ``solve`` plans for before any time is known: 100 times on [0, 100].
DEFAULT_REQUEST = Request()


def request_for(times: Times, *, target: float | None = None, dps: int | None = None,
                order: int = 0) -> Request:
    """The request of an evaluation at ``times``.

    >>> from laplace_springs.numeric.times import as_times
    >>> request_for(as_times([0, 1e6]), order=1)
    Request(count=2, t_max=1000000.0, target=1e-13, dps=None, order=1, formula=False)
    """
    return Request(count=len(times), t_max=times.span[1],
                   target=limits().target if target is None else float(target), dps=dps,
                   order=order)
