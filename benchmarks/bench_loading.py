"""Loading large scene files: time against size, and the growth exponent (issue 11).

Targets: a TOML file with 30,000 springs in <= 3 s and a 10,000-mass chain in <= 10 s
(``ls.load_scene(path)``), time linear in the file's size, and files beyond the limits
of :mod:`laplace_springs.model.scene_files` refused in well under a second.

Files (written to a temporary folder, timed from ``load_scene`` of the path):

* springs: 1,000 unit masses on a ring, one tied to a wall, and N springs m_i - m_{i+d}
  (d = 1, 2, ...) of stiffness 1, 2 or 3: N = 1,000, 10,000, 30,000;
* masses: a fixed-fixed chain of N unit masses with a spring "2" and a dashpot "1/10" on
  every link (N masses, 2N + 2 components): N = 1,000, 10,000 (and 100,000 with --large);
* refusals: Limits.max_coordinates + 1 masses, Limits.max_components + 1 springs, a [matrices] M of
  Limits.max_matrix_input_size + 1 columns, a file of Limits.max_file_bytes + 1 bytes.

The exponent between two sizes is log(t2/t1)/log(N2/N1): 1 is linear, 2 quadratic.

Run:  .venv/bin/python benchmarks/bench_loading.py [--repeat 3] [--large]
"""

from __future__ import annotations

import argparse
import math
import tempfile
import time
from pathlib import Path

import laplace_springs as ls
from laplace_springs.limits import limits
from laplace_springs.model.errors import SceneError


def chain_toml(n: int) -> str:
    nodes = ["wall", *(f"m{i}" for i in range(1, n + 1)), "wall"]
    links = list(zip(nodes, nodes[1:]))
    lines = [f'title = "{n}-mass chain"', "[masses]", *(f'm{i} = "1"' for i in range(1, n + 1))]
    lines += ["[springs]", *(f'k{i} = ["{a}", "{b}", "2"]' for i, (a, b) in enumerate(links, 1))]
    lines += ["[dashpots]", *(f'c{i} = ["{a}", "{b}", "1/10"]' for i, (a, b) in enumerate(links, 1))]
    lines += ["[initial]", 'x0 = {m1 = "1"}']
    return "\n".join(lines) + "\n"


def springs_toml(springs: int, masses: int = 1000) -> str:
    lines = ['title = "mesh"', "[masses]", *(f"m{i} = 1" for i in range(masses))]
    lines += ["[springs]", 'w = ["wall", "m0", "1"]']
    label, offset = 0, 1
    while label < springs:
        for i in range(min(masses, springs - label)):
            lines.append(f'k{label} = ["m{i}", "m{(i + offset) % masses}", {1 + label % 3}]')
            label += 1
        offset += 1
    lines += ["[initial]", 'x0 = {m0 = "1"}']
    return "\n".join(lines) + "\n"


def timed_load(path: Path, repeat: int) -> float:
    best = math.inf
    for _ in range(repeat):
        start = time.perf_counter()
        ls.load_scene(path)
        best = min(best, time.perf_counter() - start)
    return best


def timed_refusal(path: Path) -> tuple[float, str]:
    start = time.perf_counter()
    try:
        ls.load_scene(path)
    except SceneError as exc:
        return time.perf_counter() - start, str(exc)
    raise AssertionError(f"{path} was not refused")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=1, help="runs per file; the fastest is kept")
    parser.add_argument("--large", action="store_true", help="also a 100,000-mass chain")
    args = parser.parse_args()
    folder = Path(tempfile.mkdtemp(prefix="bench-loading-"))
    series = {
        "springs (1,000 masses)": [(n, springs_toml(n)) for n in (1_000, 10_000, 30_000)],
        "chain masses (2N+2 components)": [(n, chain_toml(n)) for n in
                                           (1_000, 10_000, *((100_000,) if args.large else ()))],
    }
    print("| file | N | size (MB) | load (s) | exponent vs previous |\n|---|---|---|---|---|")
    results = {}
    for name, files in series.items():
        previous = None
        for n, text in files:
            path = folder / f"{name.split()[0]}-{n}.toml"
            path.write_text(text, encoding="utf-8")
            seconds = timed_load(path, args.repeat)
            results[(name, n)] = seconds
            exponent = (f"{math.log(seconds / previous[1]) / math.log(n / previous[0]):.2f}"
                        if previous else "")
            print(f"| {name} | {n:,} | {path.stat().st_size / 1e6:.2f} | {seconds:.2f} | {exponent} |")
            previous = (n, seconds)
    print()
    refusals = {
        f"{limits().max_coordinates + 1:,} masses": "[masses]\n" + "".join(
            f"m{i} = 1\n" for i in range(limits().max_coordinates + 1)),
        f"{limits().max_components + 1:,} springs": "[masses]\nm = 1\n[springs]\n" + "".join(
            f'k{i} = ["m", "wall", 1]\n' for i in range(limits().max_components + 1)),
        f"[matrices] M of {limits().max_matrix_input_size + 1:,} columns": "[matrices]\nM = [" + ",\n".join(
            ["[" + ", ".join(["0"] * (limits().max_matrix_input_size + 1)) + "]"] * (limits().max_matrix_input_size + 1)) + "]\n",
        f"{limits().max_file_bytes + 1:,} bytes": "#" * (limits().max_file_bytes + 1),
    }
    print("| refused file | size (MB) | time (s) | message |\n|---|---|---|---|")
    for label, text in refusals.items():
        path = folder / "refused.toml"
        path.write_text(text, encoding="utf-8")
        seconds, message = timed_refusal(path)
        message = message.removeprefix(f"{path}: ").replace(str(path), "<file>")
        print(f"| {label} | {path.stat().st_size / 1e6:.2f} | {seconds:.3f} | {message[:110]} |")
    print()
    springs, chain = results[("springs (1,000 masses)", 30_000)], results[("chain masses (2N+2 components)", 10_000)]
    print(f"30,000 springs: {springs:.2f} s (target <= 3 s: {'met' if springs <= 3 else 'MISSED'}); "
          f"10,000-mass chain: {chain:.2f} s (target <= 10 s: {'met' if chain <= 10 else 'MISSED'})")


if __name__ == "__main__":
    main()
