"""The error-against-run-time benchmark: files, plausible numbers, skipped peers, verdicts.

These tests assert what the report contains, never how fast anything is: the
expected errors come from the certified arb reference, and the Pareto logic is
checked on hand-made records.
"""

from __future__ import annotations

import csv
import signal
import sys

import mpmath
import pytest
import sympy

import laplace_springs as ls
from laplace_springs.bench.methods import TimeLimitExceeded
from laplace_springs.bench.harness import (BenchCase, BenchSettings, Record, more_accurate,
                                       pareto_verdict, run_benchmark, time_limit)
from laplace_springs.cli import main
from laplace_springs.model.errors import SceneError
from laplace_springs.bench.reference import first_order_system, reference_motion_arb

FAST = BenchSettings(time_limit=10.0, ours_limit=30.0, max_runs=1, min_total=0.0)


def _cases() -> list[BenchCase]:
    critical = ls.Scene.from_matrices(M=[[1]], C=[[2]], K=[[1]], x0=[1], v0=[0])
    return [BenchCase("critical", "critical", "x'' + 2x' + x = 0", critical,
                      ("0", "0.5", "1", "4", "10")),
            BenchCase("vertical-pair", "bundled", "seed example 1",
                      ls.load_scene("vertical-pair"), ("0", "0.25", "3", "7.5"))]


def _rows(path) -> list[dict[str, str]]:
    with open(path, newline="", encoding="utf-8") as handle:
        return list(csv.DictReader(handle))


def test_report_files_and_plausible_numbers(tmp_path):
    plots = pytest.importorskip("matplotlib") is not None
    result = run_benchmark(_cases(), methods=["ours", "ours-mp30", "mpmath-talbot"],
                           out_dir=tmp_path, settings=FAST, progress=False, plots=plots)
    report = (tmp_path / "report.md").read_text(encoding="utf-8")
    rows = _rows(tmp_path / "results.csv")
    assert len(rows) == 2 * 3
    assert {row["status"] for row in rows} == {"ok"}
    for row in rows:
        assert float(row["seconds"]) > 0
        if row["method"] == "ours":
            assert float(row["error"]) < 1e-12
            assert float(row["solve_seconds"]) > 0 and float(row["evaluate_seconds"]) > 0
        if row["method"] == "ours-mp30":
            assert float(row["error"]) < 1e-25
    assert "## Summary" in report and "`critical`" in report and "`vertical-pair`" in report
    assert "Pareto front" in report
    assert (tmp_path / "plots" / "critical.png").stat().st_size > 1000
    assert all(v.on_front is not None for v in result.verdicts)


def test_missing_peer_is_skipped_with_a_note(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "scipy", None)  # `import scipy` now raises ImportError
    result = run_benchmark(_cases()[:1], methods=["ours", "scipy-expm", "control-initial"],
                           out_dir=tmp_path, settings=FAST, progress=False, plots=False)
    skipped = {r.method: r for r in result.records if r.status == "skipped"}
    assert set(skipped) == {"scipy-expm", "control-initial"}
    assert "scipy" in skipped["scipy-expm"].note and "not installed" in skipped["scipy-expm"].note
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
    assert by_method["ours"].error < 1e-12


def test_pareto_tie_rule():
    ours = Record("c", "k", "ours", "", True, "ok", error=3e-16, seconds=0.010)
    peers = [Record("c", "k", "fast-tied", "", False, "ok", error=1e-16, seconds=0.001),
             Record("c", "k", "fast-better", "", False, "ok", error=1e-16, seconds=0.001),
             Record("c", "k", "slow-better", "", False, "ok", error=0.0, seconds=0.5),
             Record("c", "k", "fast-worse", "", False, "ok", error=1e-9, seconds=0.0001)]
    verdict = pareto_verdict([ours, *peers[:1], *peers[2:]])
    assert verdict.on_front is True                      # 1e-16 vs 3e-16: both below the floor
    assert [r.method for r in verdict.strictly_dominated_by] == ["fast-tied"]
    worse_ours = Record("c", "k", "ours", "", True, "ok", error=1e-12, seconds=0.010)
    verdict = pareto_verdict([worse_ours, *peers[1:]])
    assert [r.method for r in verdict.dominated_by] == ["fast-better"]
    assert more_accurate(1e-13, 1e-12) and not more_accurate(6e-13, 1e-12)


def test_no_result_from_our_route_is_reported():
    ours = Record("c", "k", "ours", "", True, "timeout")
    assert pareto_verdict([ours]).on_front is None


@pytest.mark.skipif(not hasattr(signal, "setitimer"), reason="needs SIGALRM")
def test_time_limit_interrupts_python_code():
    with pytest.raises(TimeLimitExceeded):
        with time_limit(0.05):
            while True:
                pass


def test_cli_bench(tmp_path, capsys):
    status = main(["bench", "--scenes", "critical-unit", "--methods", "ours", "-o",
                   str(tmp_path), "--no-plots", "--no-progress"])
    out = capsys.readouterr().out
    assert status == 0
    assert "critical-unit: error" in out and "on the front" in out
    assert (tmp_path / "report.md").exists() and (tmp_path / "results.csv").exists()


def test_cli_bench_rejects_unknown_method(tmp_path, capsys):
    assert main(["bench", "--methods", "no-such-method", "-o", str(tmp_path)]) == 2
    assert "no method matches" in capsys.readouterr().err


# ----------------------------------------------------------------------------- reference


def test_massless_reference_agrees_with_the_transform_route():
    # A mass on a spring k1 = 3 to the wall, and a Maxwell element (spring k2 = 2 in
    # series with a dashpot c = 1) from the mass to the wall: node 2 is massless.
    scene = ls.Scene.from_matrices(M=[[1, 0], [0, 0]], C=[[0, 0], [0, 1]],
                                   K=[[3, -2], [-2, 2]], x0=[1, 0], v0=[0, 0])
    times = [0.0, 1.0, 2.5]
    reference = reference_motion_arb(scene, times, digits=40)
    transform_route = ls.solve(scene).evaluate(times, dps=35)
    with mpmath.workdps(40):
        assert max(abs(reference[i, j] - transform_route[i, j])
                   for i in range(2) for j in range(3)) < mpmath.mpf(10) ** -30


def test_first_order_system_of_an_ordinary_scene():
    Z, y0, n = first_order_system(ls.Scene.from_matrices(M=[[2]], C=[[1]], K=[[4]],
                                                          x0=[1], v0=[3]))
    assert Z.tolist() == [[0, 1], [-2, sympy.Rational(-1, 2)]]
    assert list(y0) == [1, 3] and n == 1


def test_massless_node_without_dashpot_has_no_reference():
    scene = ls.Scene.from_matrices(M=[[1, 0], [0, 0]], C=[[1, 0], [0, 0]],
                                   K=[[3, -2], [-2, 2]], x0=[1, 0], v0=[0, 0])
    with pytest.raises(SceneError, match="invertible"):
        first_order_system(scene)
