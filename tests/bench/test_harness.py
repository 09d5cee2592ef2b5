"""The error-against-run-time benchmark: recorded errors, statuses, verdicts and files.

These tests assert what the benchmark records, never how fast anything is. Recorded
errors are checked against errors computed here from an independent reference (mpmath's
matrix exponential, while the harness uses flint's arb exponential) or against errors
built into hand-made methods; statuses are checked on methods made to raise or to run
past their limit; the Pareto logic is checked on hand-made records.
"""

from __future__ import annotations

import csv
import math
import re
import signal
import sys

import mpmath
import numpy as np
import pytest
import sympy

import laplace_springs as ls
from laplace_springs.bench.harness import Reference, measure, run_benchmark, time_limit
from laplace_springs.bench.methods import (
    Method,
    Outcome,
    Problem,
    TimeLimitExceeded,
    Unavailable,
)
from laplace_springs.bench.records import (
    BenchCase,
    BenchSettings,
    Record,
    more_accurate,
    pareto_verdict,
)
from laplace_springs.bench.reference import reference_motion, reference_motion_arb, relative_error
from laplace_springs.cli import main
from laplace_springs.model.errors import SceneError
from laplace_springs.numeric.first_order import first_order_system

FAST = BenchSettings(time_limit=10.0, ours_limit=30.0, max_runs=1, min_total=0.0)
needs_alarm = pytest.mark.skipif(not hasattr(signal, "setitimer"), reason="needs SIGALRM")

CRITICAL = ls.Scene.from_matrices(M=[[1]], C=[[2]], K=[[1]], x0=[1], v0=[0])
CRITICAL_CASE = BenchCase("critical", "critical", "x'' + 2x' + x = 0", CRITICAL,
                          ("0", "0.5", "1", "4", "10"))


def _cases() -> list[BenchCase]:
    return [CRITICAL_CASE,
            BenchCase("vertical-pair", "bundled", "seed example 1",
                      ls.load_scene("vertical-pair"), ("0", "0.25", "3", "7.5"))]


def _rows(path) -> list[dict[str, str]]:
    with open(path, newline="", encoding="utf-8") as handle:
        return list(csv.DictReader(handle))


def _critical_x(t: float) -> float:
    """Textbook solution of x'' + 2x' + x = 0, x(0) = 1, x'(0) = 0."""
    return (1.0 + t) * math.exp(-t)


def _independent_error(case: BenchCase, method: str) -> float:
    """Our route's error on a case, against mpmath's 40-digit expm (not the harness's arb)."""
    times = [float(v) for v in case.times]   # every test time is exactly a binary64 number
    reference = reference_motion(case.scene, times, dps=40)
    if method == "ours-mp30":
        values = ls.solve(case.scene).evaluate([mpmath.mpf(v) for v in times], dps=30)
    else:
        route = {"ours": "auto", "ours-modal": "modal", "ours-certified": "certified"}[method]
        values = ls.solve(case.scene, method=route).evaluate(np.array(times))
    return relative_error(values, reference)


# ----------------------------------------------------------------------------- a whole run


OUR_METHODS = ("ours", "ours-modal", "ours-certified", "ours-mp30")


def test_recorded_errors_agree_with_an_independent_reference(tmp_path):
    pytest.importorskip("matplotlib")
    cases = _cases()
    result = run_benchmark(cases, methods=[*OUR_METHODS, "mpmath-talbot"], out_dir=tmp_path,
                           settings=FAST, progress=False, plots=True)
    rows = _rows(tmp_path / "results.csv")
    assert sorted((row["case"], row["method"]) for row in rows) == sorted(
        (case.name, method) for case in cases for method in (*OUR_METHODS, "mpmath-talbot"))
    assert {row["status"] for row in rows} == {"ok"}
    by_case = {case.name: case for case in cases}
    for row in rows:
        if row["method"] not in OUR_METHODS:
            continue
        recorded = float(row["error"])                       # written with 4 digits
        independent = _independent_error(by_case[row["case"]], row["method"])
        assert recorded == pytest.approx(independent, rel=2e-3, abs=1e-300), row
        assert independent < (1e-25 if row["method"] == "ours-mp30" else 1e-14), row
        # the solve/evaluate split belongs to the timed run: its parts fit inside it
        parts = float(row["solve_seconds"]) + float(row["evaluate_seconds"])
        assert 0 < parts <= float(row["seconds"]) * (1 + 1e-5), row
    notes = {(row["case"], row["method"]): row["note"] for row in rows}
    for case in cases:
        assert notes[case.name, "ours-modal"] in ("route: classical", "route: chebyshev", "route: modal")
        assert notes[case.name, "ours-certified"] == "route: certified"
        assert re.fullmatch(r"route: \w+", notes[case.name, "ours"])
    # the verdicts are about our default route, and the report counts them as they are
    assert [v.ours.method if v.ours else None for v in result.verdicts] == ["ours", "ours"]
    on_front = sum(v.on_front is True for v in result.verdicts)
    fastest = sum(v.fastest_at_accuracy is True for v in result.verdicts)
    report = (tmp_path / "report.md").read_text(encoding="utf-8")
    assert f"Pareto front) on **{on_front} of 2** cases" in report
    assert f"**fastest at its accuracy on {fastest} of 2** cases" in report
    assert "`critical`" in report and "`vertical-pair`" in report
    assert (tmp_path / "plots" / "critical.png").stat().st_size > 1000


def test_missing_peer_is_skipped_with_a_note(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "scipy", None)  # `import scipy` now raises ImportError
    result = run_benchmark(_cases()[:1], methods=["ours", "scipy-expm", "control-initial"],
                           out_dir=tmp_path, settings=FAST, progress=False, plots=False)
    skipped = {r.method: r for r in result.records if r.status == "skipped"}
    assert set(skipped) == {"scipy-expm", "control-initial"}
    assert "scipy" in skipped["scipy-expm"].note and "not installed" in skipped["scipy-expm"].note
    assert all(r.error is None and r.seconds is None for r in skipped.values())
    report = (tmp_path / "report.md").read_text(encoding="utf-8")
    assert "skipped" in report and "not installed" in report
    assert result.verdicts[0].on_front is True  # ours ran; no peer to dominate it


def test_scipy_peers_and_timeouts(tmp_path):
    pytest.importorskip("scipy")
    stiff = ls.Scene.from_matrices(M=[[1]], C=[[10**6]], K=[[1]], x0=[1], v0=[0])
    case = BenchCase("stiff", "heavy-damping", "c = 1e6", stiff, ("0", "1", "1000000"))
    settings = BenchSettings(time_limit=0.5, ours_limit=30.0, max_runs=1, min_total=0.0)
    result = run_benchmark([case], methods=["ours", "scipy-expm", "ivp-RK45-*"],
                           out_dir=tmp_path, settings=settings, progress=False, plots=False)
    by_method = {r.method: r for r in result.records}
    assert by_method["ivp-RK45-1e-06"].status == "timeout"   # explicit RK on a stiff scene
    assert by_method["ivp-RK45-1e-09"].status == "skipped"   # tighter tolerance not tried
    assert by_method["scipy-expm"].status == "ok"
    assert by_method["ours"].error == pytest.approx(_independent_error(case, "ours"), rel=1e-6)
    assert by_method["ours"].error < 1e-12


# ----------------------------------------------------------------------------- one measurement


def _peer(name: str, run, **options) -> Method:
    return Method(name, f"hand-made {name}", False, run, **options)


def _measure(method: Method, limit: float | None = None) -> Record:
    problem = Problem.from_case(CRITICAL_CASE.name, CRITICAL_CASE.kind, CRITICAL, CRITICAL_CASE.times)
    return measure(method, CRITICAL_CASE, problem, Reference(problem, 40), FAST, limit)


def _textbook(problem: Problem) -> np.ndarray:
    return np.array([[_critical_x(float(t)) for t in problem.times]])


def test_error_of_a_hand_made_method_is_its_built_in_error():
    exact = _measure(_peer("textbook", lambda p, s: Outcome(_textbook(p))))
    assert exact.status == "ok" and exact.error < 1e-15   # float64 rounding of (1 + t)e^{-t}
    # max |x| = x(0) = 1, so an offset of 1e-6 at one time is a relative error of 1e-6
    def off(problem, state):
        values = _textbook(problem)
        values[0, 2] += 1e-6
        return Outcome(values)
    offset = _measure(_peer("offset", off))
    assert offset.status == "ok" and offset.error == pytest.approx(1e-6, rel=1e-9)
    doubled = _measure(_peer("doubled", lambda p, s: Outcome(2 * _textbook(p))))
    assert doubled.error == pytest.approx(1.0, rel=1e-12)      # |2x - x| / max |x| at t = 0


def test_non_finite_or_misshapen_values_are_failures():
    def nan(problem, state):
        values = _textbook(problem)
        values[0, -1] = np.nan
        return Outcome(values)
    record = _measure(_peer("nan", nan))
    assert record.status == "failed" and "non-finite" in record.note
    misshapen = _measure(_peer("transposed", lambda p, s: Outcome(_textbook(p).T)))
    assert misshapen.status == "failed"


def test_a_method_that_raises_is_recorded_as_failed():
    def broken(problem, state):
        raise RuntimeError("matrix is singular")
    record = _measure(_peer("broken", broken))
    assert record.status == "failed" and record.error is None and record.seconds is None
    assert record.note == "RuntimeError: matrix is singular"


def test_a_method_that_cannot_run_is_skipped():
    def unavailable(problem):
        raise Unavailable("no transform for this scene")
    record = _measure(_peer("unavailable", lambda p, s: Outcome(_textbook(p)),
                            prepare=unavailable))
    assert (record.status, record.note) == ("skipped", "no transform for this scene")


@needs_alarm
def test_a_peer_past_its_limit_is_recorded_as_timeout():
    def forever(problem, state):
        while True:
            pass
    record = _measure(_peer("forever", forever), limit=0.05)
    assert record.status == "timeout" and record.error is None


def test_a_worker_that_reports_its_own_timeout_is_recorded_as_timeout():
    def killed(problem, state):
        raise TimeLimitExceeded("killed after 1 s")
    record = _measure(_peer("worker", killed, own_limit=True))
    assert (record.status, record.note) == ("timeout", "killed after 1 s")


@needs_alarm
def test_time_limit_interrupts_python_code():
    with pytest.raises(TimeLimitExceeded), time_limit(0.05):
        while True:
            pass


# ----------------------------------------------------------------------------- verdicts


def _record(method: str, error: float | None, seconds: float | None, *, ours: bool = False,
            status: str = "ok") -> Record:
    return Record("c", "k", method, "", ours, status, error=error, seconds=seconds)


def test_pareto_tie_rule():
    ours = _record("ours", 3e-16, 0.010, ours=True)
    fast_tied = _record("fast-tied", 1e-16, 0.001)
    fast_better = _record("fast-better", 1e-16, 0.001)
    slow_better = _record("slow-better", 0.0, 0.5)
    fast_worse = _record("fast-worse", 1e-9, 0.0001)
    verdict = pareto_verdict([ours, fast_tied, slow_better, fast_worse])
    assert verdict.on_front is True                      # 1e-16 vs 3e-16: both below the floor
    assert verdict.dominated_by == []
    assert [r.method for r in verdict.strictly_dominated_by] == ["fast-tied"]
    worse_ours = _record("ours", 1e-12, 0.010, ours=True)
    verdict = pareto_verdict([worse_ours, fast_better, slow_better, fast_worse])
    assert verdict.on_front is False
    assert [r.method for r in verdict.dominated_by] == ["fast-better"]
    assert more_accurate(1e-13, 1e-12) and not more_accurate(6e-13, 1e-12)
    assert not more_accurate(1e-16, 8e-16) and more_accurate(1e-16, 8e-16, strict=True)


def test_pareto_counts_only_finished_strictly_faster_peers():
    ours = _record("ours", 1e-10, 0.010, ours=True)
    others = [_record("ours-modal", 1e-16, 0.001, ours=True),     # our own route: never a rival
              _record("same-time", 1e-16, 0.010),                 # not strictly faster
              _record("timed-out", None, None, status="timeout"),
              _record("failed", None, None, status="failed"),
              _record("skipped", None, None, status="skipped")]
    verdict = pareto_verdict([ours, *others])
    assert verdict.on_front is True and verdict.strictly_dominated_by == []
    verdict = pareto_verdict([*others, ours, _record("rival", 1e-12, 0.009)])
    assert verdict.ours is ours and [r.method for r in verdict.dominated_by] == ["rival"]


def test_no_result_from_our_route_is_reported():
    assert pareto_verdict([_record("ours", None, None, ours=True, status="timeout")]).on_front is None
    assert pareto_verdict([_record("peer", 1e-16, 0.001)]).on_front is None   # ours not run


# ----------------------------------------------------------------------------- command line


def test_cli_bench(tmp_path, capsys):
    status = main(["bench", "--scenes", "critical-unit", "--methods", "ours", "-o",
                   str(tmp_path), "--no-plots", "--no-progress"])
    out = capsys.readouterr().out
    assert status == 0
    (row,) = _rows(tmp_path / "results.csv")
    assert (row["case"], row["method"], row["status"]) == ("critical-unit", "ours", "ok")
    printed = re.search(r"critical-unit: error (\S+), .* on the front", out)
    assert printed is not None, out
    assert float(printed.group(1)) == pytest.approx(float(row["error"]), rel=0.06)  # 2 digits
    assert float(row["error"]) < 1e-14
    assert (tmp_path / "report.md").exists()


def test_cli_bench_rejects_unknown_method(tmp_path, capsys):
    assert main(["bench", "--methods", "no-such-method", "-o", str(tmp_path)]) == 2
    assert "no method matches" in capsys.readouterr().err


# ----------------------------------------------------------------------------- reference


def test_references_agree_with_the_textbook_solution():
    times = [0.0, 0.5, 3.0, 25.0]
    arb_values = reference_motion_arb(CRITICAL, times, digits=40)
    expm_values = reference_motion(CRITICAL, times, dps=45)
    with mpmath.workdps(50):
        for col, tv in enumerate(times):
            t = mpmath.mpf(tv)
            expected = (1 + t) * mpmath.exp(-t)
            assert abs(arb_values[0, col] - expected) < mpmath.mpf(10) ** -39
            assert abs(expm_values[0, col] - expected) < mpmath.mpf(10) ** -39


def test_reference_with_an_irrational_stiffness():
    # x'' + √3 x = 0, x(0) = 1: x = cos(3^(1/4) t); K enters the balls as a widened decimal
    scene = ls.Scene.from_matrices(M=[[1]], K=[[sympy.sqrt(3)]], x0=[1], v0=[0])
    values = reference_motion_arb(scene, [1.0, 10.0], digits=40)
    with mpmath.workdps(50):
        omega = mpmath.root(3, 4)
        for col, t in enumerate([1, 10]):
            assert abs(values[0, col] - mpmath.cos(omega * t)) < mpmath.mpf(10) ** -39


def test_float_times_are_read_as_their_binary_value():
    # 0.1 as a float is 0.1000000000000000055511151231257827...: x differs from x(1/10)
    # by about x'(0.1)·5.6e-18 = -5e-19, far above the 30 certified digits
    with mpmath.workdps(40):
        binary = mpmath.mpf(0.1)
        expected = (1 + binary) * mpmath.exp(-binary)
        decimal = (1 + mpmath.mpf("0.1")) * mpmath.exp(-mpmath.mpf("0.1"))
        assert abs(expected - decimal) > mpmath.mpf(10) ** -20
        for values in (reference_motion_arb(CRITICAL, [0.1], digits=30),
                       reference_motion(CRITICAL, [0.1], dps=35)):
            assert abs(values[0, 0] - expected) < mpmath.mpf(10) ** -29


def test_massless_reference_agrees_with_the_transform_route():
    # A mass on a spring k1 = 3 to the wall, and a Maxwell element (spring k2 = 2 in
    # series with a dashpot c = 1) from the mass to the wall: node 2 is massless.
    scene = ls.Scene.from_matrices(M=[[1, 0], [0, 0]], C=[[0, 0], [0, 1]],
                                   K=[[3, -2], [-2, 2]], x0=[1, 0], v0=[0, 0])
    times = [0.0, 1.0, 2.5]
    reference = reference_motion_arb(scene, times, digits=40)
    transform_route = ls.solve(scene, method="exact").evaluate(times, dps=35)
    with mpmath.workdps(40):
        assert max(abs(reference[i, j] - transform_route[i, j])
                   for i in range(2) for j in range(3)) < mpmath.mpf(10) ** -30


def test_first_order_system_of_an_ordinary_scene():
    Z, y0, massive = first_order_system(ls.Scene.from_matrices(M=[[2]], C=[[1]], K=[[4]],
                                                               x0=[1], v0=[3]))
    assert Z.tolist() == [[0, 1], [-2, sympy.Rational(-1, 2)]]
    assert list(y0) == [1, 3] and massive == [0]


def test_massless_node_without_dashpot_has_no_reference():
    scene = ls.Scene.from_matrices(M=[[1, 0], [0, 0]], C=[[1, 0], [0, 0]],
                                   K=[[3, -2], [-2, 2]], x0=[1, 0], v0=[0, 0])
    with pytest.raises(SceneError, match="invertible"):
        first_order_system(scene)
