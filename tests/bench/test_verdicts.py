"""Both verdicts of the battery benchmark on hand-made records with known answers (issue 14, item 4).

"On the front": no peer both strictly faster and more accurate (tie rule). "Fastest at
this accuracy": no peer at least as accurate (tie rule) strictly faster. The records
below are built so that each answer, each count and each ratio is known by hand; the
report, the summary lines and the headline are checked against those numbers.
"""

from __future__ import annotations

import pytest

import laplace_springs as ls
from laplace_springs.bench.harness import summary_lines
from laplace_springs.bench.records import (
    TIE_FACTOR,
    TIE_FLOOR,
    BenchCase,
    BenchmarkResult,
    BenchSettings,
    Record,
    pareto_verdict,
)
from laplace_springs.bench.report import fastest_text, headline, write_markdown


def _r(case: str, method: str, error: float | None, seconds: float | None, *, ours: bool = False,
       status: str = "ok") -> Record:
    return Record(case, "k", method, "", ours, status, error=error, seconds=seconds)


def _battery() -> dict[str, list[Record]]:
    """Five cases whose verdicts are known by hand (the comments give them)."""
    return {
        # the example: a peer inside the tie band (both errors below the floor
        # 1e-15) is 0.0125 / 0.00057 = 21.9× faster: on the front, not the fastest
        "tied": [_r("tied", "ours", 5.2e-18, 0.0125, ours=True),
                 _r("tied", "scipy-expm", 3.8e-16, 0.00057),
                 _r("tied", "slow-exact", 1e-20, 0.9)],
        # faster peers are less accurate, the more accurate one is slower; our own
        # faster route does not count; a peer taking the same time is not faster
        "clean": [_r("clean", "ours", 1e-13, 0.01, ours=True),
                  _r("clean", "ours-certified", 1e-16, 0.001, ours=True),
                  _r("clean", "rk45", 1e-9, 0.001),
                  _r("clean", "same-time", 1e-13, 0.01),
                  _r("clean", "mpmath", 1e-20, 0.5),
                  _r("clean", "timed-out", None, None, status="timeout")],
        # a peer 100 times more accurate and twice as fast: dominated, and not the fastest
        "dominated": [_r("dominated", "ours", 1e-12, 0.01, ours=True),
                      _r("dominated", "better", 1e-14, 0.005)],
        # no result from our route: neither verdict
        "no-result": [_r("no-result", "ours", None, None, ours=True, status="timeout"),
                      _r("no-result", "peer", 1e-16, 0.001)],
        # the edge of the tie band: ours 1e-16 floors to 1e-15, so a peer's error of
        # TIE_FACTOR·TIE_FLOOR = 2e-15 is still "as accurate"; 2.1e-15 is not
        "band-edge": [_r("band-edge", "ours", 1e-16, 0.01, ours=True),
                      _r("band-edge", "edge", TIE_FACTOR * TIE_FLOOR, 0.001),
                      _r("band-edge", "outside", 2.1e-15, 0.0001)],
    }


def test_the_two_verdicts_on_known_cases():
    verdicts = {name: pareto_verdict(records) for name, records in _battery().items()}
    expected = {"tied": (True, False, ["scipy-expm"]),
                "clean": (True, True, []),
                "dominated": (False, False, ["better"]),
                "no-result": (None, None, []),
                "band-edge": (True, False, ["edge"])}
    for name, (front, fastest, rivals) in expected.items():
        v = verdicts[name]
        assert (v.on_front, v.fastest_at_accuracy) == (front, fastest), name
        assert [r.method for r in v.faster_as_accurate] == rivals, name
    assert verdicts["tied"].speedup(verdicts["tied"].faster_as_accurate[0]) == pytest.approx(
        0.0125 / 0.00057)
    assert verdicts["dominated"].speedup(verdicts["dominated"].faster_as_accurate[0]) == pytest.approx(2.0)
    assert verdicts["tied"].dominated_by == [] and verdicts["tied"].strictly_dominated_by == []


def test_faster_as_accurate_is_sorted_fastest_first():
    records = [_r("c", "ours", 1e-16, 0.01, ours=True), _r("c", "second", 5e-16, 0.004),
               _r("c", "first", 9e-16, 0.002), _r("c", "slower", 1e-16, 0.02)]
    verdict = pareto_verdict(records)
    assert [r.method for r in verdict.faster_as_accurate] == ["first", "second"]
    assert fastest_text(verdict) == "no: first (9.0e-16, 0.002 s) 5× faster"


def test_fastest_text_names_the_next_peer_when_we_are_fastest():
    records = _battery()["clean"]
    assert fastest_text(pareto_verdict(records), records) == "yes (next: same-time (1.0e-13, 0.01 s), 1× slower)"
    alone = [_r("c", "ours", 1e-13, 0.01, ours=True), _r("c", "rough", 1e-6, 0.001)]
    assert fastest_text(pareto_verdict(alone), alone) == "yes (no peer as accurate)"


def test_headline_gives_both_counts_and_the_list():
    verdicts = [pareto_verdict(records) for records in _battery().values()]
    assert headline(verdicts) == [
        "no peer both faster and more accurate (on the Pareto front): 3 of 5 cases",
        "fastest at its accuracy (no peer at least as accurate is faster): 1 of 5 cases",
        "a peer at least as accurate (tie rule) is faster on 3 cases:",
        "- tied: scipy-expm (3.8e-16, 0.00057 s) 22× faster than ours (5.2e-18, 0.0125 s)",
        "- dominated: better (1.0e-14, 0.005 s) 2× faster than ours (1.0e-12, 0.01 s)",
        "- band-edge: edge (2.0e-15, 0.001 s) 10× faster than ours (1.0e-16, 0.01 s)",
    ]


def _result() -> BenchmarkResult:
    scene = ls.Scene.from_matrices(M=[[1]], C=[[2]], K=[[1]], x0=[1], v0=[0])
    battery = _battery()
    cases = [BenchCase(name, "k", "hand-made", scene, ("0", "1")) for name in battery]
    records = [r for rows in battery.values() for r in rows]
    verdicts = [pareto_verdict(rows) for rows in battery.values()]
    return BenchmarkResult(cases, [], records, verdicts, BenchSettings(), 1.0)


def test_report_headline_and_rows(tmp_path):
    path = tmp_path / "report.md"
    write_markdown(_result(), path, {})
    text = path.read_text(encoding="utf-8")
    assert "on **3 of 5** cases; **fastest at its accuracy on 1 of 5** cases" in text
    assert "A peer at least as accurate (tie rule) is faster on 3 cases:" in text
    assert "- tied: scipy-expm (3.8e-16, 0.00057 s) 22× faster than ours" in text
    rows = {line.split("|")[1].strip(): [cell.strip() for cell in line.split("|")[7:10]]
            for line in text.splitlines() if line.startswith("| `")}
    assert rows["`tied`"] == ["on the front", "no: scipy-expm (3.8e-16, 0.00057 s) 22× faster",
                              "on the front"]
    assert rows["`clean`"][:2] == ["on the front", "yes (next: same-time (1.0e-13, 0.01 s), 1× slower)"]
    assert rows["`dominated`"][0].startswith("DOMINATED by better")
    assert rows["`dominated`"][1] == "no: better (1.0e-14, 0.005 s) 2× faster"
    assert rows["`band-edge`"][1] == "no: edge (2.0e-15, 0.001 s) 10× faster"
    assert "| `no-result` |" in text and "no result | no result | no result |" in text


def test_summary_lines_give_both_verdicts_per_case():
    lines = summary_lines(_result())
    assert lines[0] == ("tied: error 5.2e-18, 0.0125 s — on the front; fastest at this accuracy: "
                        "no: scipy-expm (3.8e-16, 0.00057 s) 22× faster")
    assert lines[1].endswith("on the front; fastest at this accuracy: yes")
    assert lines[3].startswith("no-result: our route gave no result (timeout")
    assert lines[5:8] == headline(_result().verdicts)[:3]
    assert lines[-1] == "total 1 s"
