"""Files of the error-against-run-time benchmark: Markdown report, CSV and plots.

:func:`write_all` is called by :func:`laplace_springs.bench.harness.run_benchmark`; the
plots use matplotlib's Agg backend (no display needed).
"""

from __future__ import annotations

import csv
import os
import platform
from collections.abc import Sequence
from datetime import UTC, datetime
from importlib import metadata
from pathlib import Path

from .records import TIE_FACTOR, TIE_FLOOR, BenchmarkResult, Record, Verdict, measured, more_accurate

__all__ = ["write_all", "write_markdown", "write_csv", "plot_case", "verdict_text", "fastest_text",
           "headline"]

PHASES = ("solve", "evaluate", "invert")
CSV_FIELDS = ("case", "kind", "method", "ours", "status", "error", "seconds", "runs",
              *(f"{phase}_seconds" for phase in PHASES), "note")


def _error_text(error: float | None) -> str:
    return "—" if error is None else f"{error:.1e}"


def _seconds_text(seconds: float | None) -> str:
    if seconds is None:
        return "—"
    return f"{seconds:.2g}" if seconds < 0.01 else f"{seconds:.3g}"


def _short(record: Record) -> str:
    return f"{record.method} ({_error_text(record.error)}, {_seconds_text(record.seconds)} s)"


def verdict_text(verdict: Verdict, *, strict: bool = False) -> str:
    """"on the front" or "dominated by ..." for one case.

    Examples
    --------
    >>> from laplace_springs.bench.records import Record, Verdict
    >>> ours = Record("c", "k", "ours", "", True, "ok", 1e-16, 0.01)
    >>> verdict_text(Verdict("c", ours, [], []))
    'on the front'
    """
    if verdict.on_front is None:
        return "no result from our route"
    dominators = verdict.strictly_dominated_by if strict else verdict.dominated_by
    if not dominators:
        return "on the front"
    return "DOMINATED by " + ", ".join(_short(r) for r in dominators)


def _fastest_as_accurate(records: Sequence[Record], error: float) -> tuple[Record, float] | None:
    """The fastest peer whose error is not worse than ``error`` (ours) under the tie rule,
    and its time."""
    peers = [(r, m[1]) for r in records
             if not r.ours and (m := measured(r)) is not None and not more_accurate(error, m[0])]
    return min(peers, key=lambda pair: pair[1], default=None)


def fastest_text(verdict: Verdict, records: Sequence[Record] = ()) -> str:
    """"yes" or "no: <peer> (error, time) N× faster" for "fastest at this accuracy".

    ``records`` (the case's records) only add, when we are the fastest, the next peer at
    least as accurate and how much slower it is.

    Examples
    --------
    >>> from laplace_springs.bench.records import Record, pareto_verdict
    >>> ours = Record("c", "k", "ours", "", True, "ok", 1e-16, 0.01)
    >>> tied = Record("c", "k", "scipy-expm", "", False, "ok", 4e-16, 0.0005)
    >>> fastest_text(pareto_verdict([ours, tied]))
    'no: scipy-expm (4.0e-16, 0.0005 s) 20× faster'
    """
    if verdict.fastest_at_accuracy is None:
        return "no result from our route"
    if verdict.faster_as_accurate:
        rival = verdict.faster_as_accurate[0]
        return f"no: {_short(rival)} {verdict.speedup(rival):.2g}× faster"
    if not records or verdict.ours is None or verdict.ours.error is None:
        return "yes"
    nearest = _fastest_as_accurate(records, verdict.ours.error)
    if nearest is None:
        return "yes (no peer as accurate)"
    return f"yes (next: {_short(nearest[0])}, {1 / verdict.speedup(nearest[0]):.2g}× slower)"


def headline(verdicts: Sequence[Verdict]) -> list[str]:
    """Both counts, then one line per case where a peer at least as accurate is faster.

    Examples
    --------
    >>> from laplace_springs.bench.records import Record, pareto_verdict
    >>> def case(name, peer_error, peer_seconds):
    ...     return pareto_verdict([Record(name, "k", "ours", "", True, "ok", 1e-16, 0.01),
    ...                            Record(name, "k", "peer", "", False, "ok", peer_error, peer_seconds)])
    >>> for line in headline([case("a", 3e-16, 0.002), case("b", 1e-9, 0.001)]):
    ...     print(line)
    no peer both faster and more accurate (on the Pareto front): 2 of 2 cases
    fastest at its accuracy (no peer at least as accurate is faster): 1 of 2 cases
    a peer at least as accurate (tie rule) is faster on 1 case:
    - a: peer (3.0e-16, 0.002 s) 5× faster than ours (1.0e-16, 0.01 s)
    """
    on_front = sum(v.on_front is True for v in verdicts)
    fastest = sum(v.fastest_at_accuracy is True for v in verdicts)
    beaten = [v for v in verdicts if v.fastest_at_accuracy is False]
    lines = [f"no peer both faster and more accurate (on the Pareto front): "
             f"{on_front} of {len(verdicts)} cases",
             f"fastest at its accuracy (no peer at least as accurate is faster): "
             f"{fastest} of {len(verdicts)} cases"]
    if beaten:
        lines.append(f"a peer at least as accurate (tie rule) is faster on {len(beaten)} "
                     f"case{'s' if len(beaten) != 1 else ''}:")
        for v in beaten:
            rival, ours = v.faster_as_accurate[0], v.ours
            mine = f"{_error_text(ours.error)}, {_seconds_text(ours.seconds)} s" if ours else "—"
            lines.append(f"- {v.case}: {_short(rival)} {v.speedup(rival):.2g}× faster than ours ({mine})")
    return lines


def _versions() -> str:
    """Versions of the packages involved, from their metadata (nothing is imported)."""
    parts = [f"Python {platform.python_version()}", f"laplace_springs {_own_version()}"]
    for distribution, label in (("numpy", "NumPy"), ("scipy", "SciPy"),
                                ("control", "python-control"), ("sympy", "SymPy"),
                                ("mpmath", "mpmath"), ("python-flint", "python-flint")):
        try:
            parts.append(f"{label} {metadata.version(distribution)}")
        except metadata.PackageNotFoundError:
            parts.append(f"{label} not installed")
    return ", ".join(parts)


def _own_version() -> str:
    try:
        return metadata.version("laplace_springs")
    except metadata.PackageNotFoundError:
        return "(not installed)"


def _definitions(result: BenchmarkResult) -> list[str]:
    s = result.settings
    return [
        "**Error**: max over coordinates and times of |x − x_ref| / max |x_ref|; x_ref is "
        f"python-flint's certified arb matrix exponential of the first-order system "
        f"({s.digits} digits, `reference_motion_arb`), at the same float64 times.",
        "**Time**: wall time of the fastest of up to "
        f"{s.max_runs} runs (repeated while under {s.min_total:g} s in total; other processes "
        "only add time). "
        "*Ours*: from the exact `Scene` to values, `solve` + `evaluate`, with SymPy's and our "
        "caches cleared before every run (the split is in the CSV). *Peers*: from float64 "
        "data (the first-order matrix Z, formed exactly and rounded; X(λ) for the Laplace-"
        "domain peers, built untimed from our exact resolvent) to values; SymPy is timed in "
        "its worker process (inversion + lambdify + evaluation).",
        f"**Limits** (SIGALRM): {s.time_limit:g} s per peer run, raised to twice our time on "
        f"cases where ours is slower, so a timed-out peer was slower than ours and cannot "
        f"dominate it; {s.ours_limit:g} s per run of ours; SymPy {s.sympy_limit:g} s per case "
        "(worker killed). After a timeout the tighter tolerances of that solver are skipped.",
        f"**More accurate**: errors are floored at {TIE_FLOOR:g} (float64 output rounding) and a "
        f"peer is more accurate only if its floored error is below ours by more than a factor "
        f"{TIE_FACTOR:g}. **Strict**: raw errors, no tie band.",
        "**On the front**: no peer is both faster than our default route (`ours`) and more "
        "accurate on that case.",
        "**Fastest at this accuracy**: no peer at least as accurate as our default route (tie "
        "rule: not less accurate) is faster on that case. A peer whose error is inside the tie "
        "band of ours and that is faster leaves us on the front but not the fastest; the "
        "ratio is our time over the peer's.",
    ]


def _summary_table(result: BenchmarkResult) -> list[str]:
    lines = ["| case | kind | n | ours error | ours time (s) | solve / evaluate (s) "
             "| no peer more accurate and faster | fastest at this accuracy | strict verdict |",
             "|---|---|---|---|---|---|---|---|---|"]
    by_case = {case.name: case for case in result.cases}
    for verdict in result.verdicts:
        case = by_case[verdict.case]
        ours = verdict.ours
        records = [r for r in result.records if r.case == verdict.case]
        mine = measured(ours) if ours is not None else None
        if ours is None or mine is None:
            status = "not run" if ours is None else f"{ours.status}: {ours.note}"
            lines.append(f"| `{case.name}` | {case.kind} | {case.scene.n} | {status} | — | — "
                         f"| no result | no result | no result |")
            continue
        error, seconds = mine
        split = " / ".join(_seconds_text(ours.phases.get(p)) for p in ("solve", "evaluate"))
        lines.append(f"| `{case.name}` | {case.kind} | {case.scene.n} | {_error_text(error)} "
                     f"| {_seconds_text(seconds)} | {split} | {verdict_text(verdict)} "
                     f"| {fastest_text(verdict, records)} | {verdict_text(verdict, strict=True)} |")
    return lines


def _case_section(result: BenchmarkResult, case, plot: Path | None) -> list[str]:
    records = [r for r in result.records if r.case == case.name]
    order = {"ok": 0, "timeout": 1, "failed": 2, "skipped": 3}
    records.sort(key=lambda r: (order.get(r.status, 4), r.seconds or 0.0))
    times = [float(t) for t in case.times]
    lines = ["", f"### `{case.name}` ({case.kind})", "",
             f"{case.description} n = {case.scene.n}, {len(times)} times in "
             f"[{min(times):g}, {max(times):g}].", "",
             "| method | error | time (s) | runs | status | note |", "|---|---|---|---|---|---|"]
    for r in records:
        name = f"**{r.method}**" if r.ours else r.method
        lines.append(f"| {name} | {_error_text(r.error)} | {_seconds_text(r.seconds)} | {r.runs} "
                     f"| {r.status} | {r.note.replace('|', '/')} |")
    if plot is not None:
        lines += ["", f"![{case.name}](plots/{plot.name})"]
    return lines


def write_markdown(result: BenchmarkResult, path: Path, plots: dict[str, Path]) -> None:
    """The report: run details, definitions, the summary with verdicts, one table per case."""
    on_front = sum(v.on_front is True for v in result.verdicts)
    fastest = sum(v.fastest_at_accuracy is True for v in result.verdicts)
    total = len(result.verdicts)
    stamp = datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC")
    lines = ["# laplace_springs: error against run time", "",
             f"{stamp}; {_versions()}; {platform.machine()}, {os.cpu_count()} cores.",
             f"{len(result.cases)} cases × {len(result.methods)} methods in "
             f"{result.wall_seconds:.0f} s. Our default route: no peer both faster and more "
             f"accurate (on the accuracy–time Pareto front) on **{on_front} of {total}** cases; "
             f"**fastest at its accuracy on {fastest} of {total}** cases.", ""]
    beaten = headline(result.verdicts)[2:]
    if beaten:
        lines += [beaten[0][0].upper() + beaten[0][1:], "", *beaten[1:], ""]
    lines += [f"- {text}" for text in _definitions(result)]
    if result.notes:
        lines += ["", "Notes:"] + [f"- {note}" for note in result.notes]
    lines += ["", "## Summary", ""] + _summary_table(result)
    lines += ["", "## Methods", "", "| method | what runs |", "|---|---|"]
    lines += [f"| {m.name} | {m.label} |" for m in result.methods]
    lines += ["", "## Cases"]
    for case in result.cases:
        lines += _case_section(result, case, plots.get(case.name))
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")


def write_csv(records: Sequence[Record], path: Path) -> None:
    """One row per (case, method): status, error, time, runs, phase times, note."""
    with open(path, "w", newline="", encoding="utf-8") as handle:
        writer = csv.DictWriter(handle, fieldnames=CSV_FIELDS)
        writer.writeheader()
        for r in records:
            row = {"case": r.case, "kind": r.kind, "method": r.method, "ours": int(r.ours),
                   "status": r.status, "error": "" if r.error is None else f"{r.error:.3e}",
                   "seconds": "" if r.seconds is None else f"{r.seconds:.6g}", "runs": r.runs,
                   "note": r.note}
            for phase in PHASES:
                value = r.phases.get(phase)
                row[f"{phase}_seconds"] = "" if value is None else f"{value:.6g}"
            writer.writerow(row)


# ----------------------------------------------------------------------------- plots

#: Errors below this are drawn at it (a float64 result can be exact).
PLOT_FLOOR = 1e-18

_STYLE = {"ours": ("tab:red", "*", 16), "ours-modal": ("tab:red", "P", 10),
          "ours-certified": ("tab:red", "h", 10), "ours-mp30": ("tab:red", "D", 8), "scipy-expm": ("tab:blue", "s", 8),
          "control-initial": ("tab:green", "^", 8), "mpmath-talbot": ("tab:purple", "v", 8),
          "mpmath-cohen": ("tab:purple", "<", 8), "sympy-ilt": ("tab:brown", "X", 9)}
_IVP_COLOURS = {"RK45": "tab:orange", "DOP853": "tab:olive", "Radau": "tab:cyan",
                "LSODA": "tab:gray"}


def plot_case(records: Sequence[Record], path: Path, title: str) -> None:
    """Work-precision plot of one case: log error against log time, one marker per method."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, axes = plt.subplots(figsize=(9.0, 5.0))
    families: dict[str, list[tuple[float, float]]] = {}
    for r in records:
        point = measured(r)
        if point is None:
            continue
        error, seconds = point
        if r.method.startswith("ivp-"):
            families.setdefault(r.method.split("-")[1], []).append((seconds, error))
            continue
        colour, marker, size = _STYLE.get(r.method, ("black", "o", 7))
        axes.loglog([seconds], [max(error, PLOT_FLOOR)], marker=marker, color=colour,
                    markersize=size, linestyle="none", label=r.method, zorder=3 if r.ours else 2)
    for solver, members in families.items():
        members.sort()
        axes.loglog([s for s, _ in members], [max(e, PLOT_FLOOR) for _, e in members],
                    marker="o", color=_IVP_COLOURS.get(solver, "black"), label=f"solve_ivp {solver}")
    axes.axhspan(PLOT_FLOOR / 2, TIE_FLOOR, color="0.92", zorder=0, label=f"≤ {TIE_FLOOR:g} (tie)")
    missing = [f"{r.method}: {r.status}" for r in records if r.status in ("timeout", "failed")]
    skipped = sum(r.status == "skipped" for r in records)
    missing = missing[:10] + (["…"] if len(missing) > 10 else [])
    missing += [f"{skipped} skipped (see report)"] if skipped else []
    if missing:
        axes.text(1.02, 0.0, "\n".join(missing), transform=axes.transAxes, ha="left",
                  va="bottom", fontsize=7, color="0.3")
    axes.set_xlabel("run time (s)")
    axes.set_ylabel(f"error relative to max |x| (drawn ≥ {PLOT_FLOOR:g})")
    axes.set_title(title)
    axes.grid(True, which="major", alpha=0.3)
    axes.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)


def _plot_all(result: BenchmarkResult, directory: Path) -> dict[str, Path]:
    directory.mkdir(parents=True, exist_ok=True)
    paths = {}
    for case in result.cases:
        records = [r for r in result.records if r.case == case.name]
        if any(r.status == "ok" for r in records):
            path = directory / f"{case.name}.png"
            plot_case(records, path, f"{case.name} ({case.kind}, n = {case.scene.n})")
            paths[case.name] = path
    return paths


def write_all(result: BenchmarkResult, out_dir: Path, *, plots: bool = True) -> dict[str, Path]:
    """Write results.csv, the plots (if asked and matplotlib is there) and report.md."""
    out_dir.mkdir(parents=True, exist_ok=True)
    files = {"csv": out_dir / "results.csv", "report": out_dir / "report.md"}
    write_csv(result.records, files["csv"])
    plot_paths: dict[str, Path] = {}
    if plots:
        try:
            plot_paths = _plot_all(result, out_dir / "plots")
        except ImportError:
            result.notes.append("plots skipped: matplotlib not installed")
    write_markdown(result, files["report"], plot_paths)
    files.update({f"plot:{name}": path for name, path in plot_paths.items()})
    return files
