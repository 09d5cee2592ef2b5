"""The precision sections (kernels/precision.py): each thread's section keeps its own
working precision while other threads enter theirs (mpmath and python-flint keep one
process-wide precision)."""

from __future__ import annotations

import sys
import threading
import time

import flint
import mpmath
import numpy as np

import laplace_springs as ls
from laplace_springs.kernels.precision import flint_workdps, flint_workprec, workdps, workprec


def _hammer(section, read, values, seconds=0.3):
    """Threads that each hold a section at their own precision and read it back while the
    others switch: the precisions seen that were not the thread's own."""
    wrong: list[tuple[int, int]] = []
    stop = time.perf_counter() + seconds

    def work(value: int) -> None:
        while time.perf_counter() < stop:
            with section(value):
                for _ in range(200):
                    seen = read()
                    if seen != value:
                        wrong.append((value, seen))
                    mpmath.mpf(1) / 3  # let the interpreter switch threads
    threads = [threading.Thread(target=work, args=(v,)) for v in values]
    old = sys.getswitchinterval()
    sys.setswitchinterval(1e-5)
    try:
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
    finally:
        sys.setswitchinterval(old)
    return wrong


def test_mpmath_sections_keep_their_precision_across_threads():
    assert _hammer(workdps, lambda: mpmath.mp.dps, [20, 40, 60]) == []
    assert _hammer(workprec, lambda: mpmath.mp.prec, [80, 160]) == []
    assert mpmath.mp.dps == 15


def test_flint_sections_keep_their_precision_across_threads():
    assert _hammer(flint_workprec, lambda: flint.ctx.prec, [100, 300, 500]) == []
    assert _hammer(flint_workdps, lambda: flint.ctx.dps, [30, 90]) == []
    assert flint.ctx.prec == 53


def test_the_unlocked_libraries_do_interfere():
    """The check above can fail: mpmath's own sections, unlocked, see each other."""
    assert _hammer(mpmath.workdps, lambda: mpmath.mp.dps, [20, 40, 60]) != []
    mpmath.mp.dps = 15


def test_digits_evaluated_on_threads_match_the_serial_ones():
    """dps evaluations of the seed's damped pair on four threads at once, each at its own
    digits, against the same calls made one after another."""
    sol = ls.solve(ls.load_scene("vertical-pair-damped"))
    times = ["1/3", "2", "7"]
    digits = [20, 35, 50, 65]
    serial = {d: sol.evaluate(times, dps=d) for d in digits}
    found: dict[int, np.ndarray] = {}

    def work(d: int) -> None:
        for _ in range(3):
            found[d] = sol.evaluate(times, dps=d)
            if not np.array_equal(found[d], serial[d]):
                return
    threads = [threading.Thread(target=work, args=(d,)) for d in digits]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    for d in digits:
        assert np.array_equal(found[d], serial[d]), d
