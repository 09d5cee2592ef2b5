"""Start-up: ``import laplace_springs`` against ``import sympy``, and the command line.

Issue 23 item 4: ``import laplace_springs`` within 1.2x of ``import sympy``, and
``laplace-springs solve vertical-pair-damped`` in under 1.5 s wall.

Every figure is a fresh Python process started from here (``subprocess.run``), timed by
the wall clock around it and by the CPU seconds the operating system charges to it
(``resource.getrusage(RUSAGE_CHILDREN)``); the commands run in turn (A B A B ...) so that
the ratios, taken pair by pair, share the machine's drift. The medians are the figures to
quote; min and max show the spread (a wide one says the machine was busy).

Bytecode: Python compiles each module it imports unless a cached ``.pyc`` is found. An
installed package has its bytecode cached after the first import; a checkout run with
``PYTHONDONTWRITEBYTECODE=1`` compiles every module on every start. ``--bytecode-cache DIR``
runs the children with bytecode cached under DIR (``PYTHONPYCACHEPREFIX``), as an
installed package would; without it they run with the environment as it is (printed).

Run:  python benchmarks/bench_import.py [--runs 7] [--bytecode-cache /tmp/pycache]
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import time

COMMANDS = {
    "python (nothing)": [sys.executable, "-c", "pass"],
    "import sympy": [sys.executable, "-c", "import sympy"],
    "import laplace_springs": [sys.executable, "-c", "import laplace_springs"],
    "import laplace_springs; first use": [
        sys.executable, "-c", "import laplace_springs as ls; ls.Scene"],
    "laplace-springs solve vertical-pair-damped": [
        sys.executable, "-m", "laplace_springs", "solve", "vertical-pair-damped"],
}


def _run(command: list[str], env: dict[str, str]) -> tuple[float, float]:
    """(wall, cpu) seconds of one fresh process running ``command``."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run(command, env=env, check=True, stdout=subprocess.DEVNULL)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def measure(runs: int, env: dict[str, str]) -> dict[str, list[tuple[float, float]]]:
    for command in COMMANDS.values():  # warm the file system cache
        _run(command, env)
    out: dict[str, list[tuple[float, float]]] = {name: [] for name in COMMANDS}
    for _ in range(runs):
        for name, command in COMMANDS.items():
            out[name].append(_run(command, env))
    return out


def _spread(values: list[float]) -> str:
    return f"{statistics.median(values):.3f} ({min(values):.3f}–{max(values):.3f})"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=7, help="runs of each command (interleaved)")
    parser.add_argument("--bytecode-cache", metavar="DIR",
                        help="cache bytecode under DIR for the children (PYTHONPYCACHEPREFIX)")
    args = parser.parse_args()
    env = dict(os.environ)
    if args.bytecode_cache:
        env.pop("PYTHONDONTWRITEBYTECODE", None)
        env["PYTHONPYCACHEPREFIX"] = args.bytecode_cache
    print(f"Python {sys.version.split()[0]}; PYTHONDONTWRITEBYTECODE="
          f"{env.get('PYTHONDONTWRITEBYTECODE', '(unset)')}; PYTHONPYCACHEPREFIX="
          f"{env.get('PYTHONPYCACHEPREFIX', '(unset)')}; {args.runs} interleaved runs; "
          f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    results = measure(args.runs, env)
    print("| command | wall s, median (min–max) | cpu s, median (min–max) |")
    print("|---|---|---|")
    for name, rows in results.items():
        print(f"| {name} | {_spread([w for w, _ in rows])} | {_spread([c for _, c in rows])} |")
    ours, peer = results["import laplace_springs"], results["import sympy"]
    wall = [a[0] / b[0] for a, b in zip(ours, peer)]
    cpu = [a[1] / b[1] for a, b in zip(ours, peer)]
    print(f"\nimport laplace_springs / import sympy (pairwise): wall {_spread(wall)}, "
          f"cpu {_spread(cpu)}")
    cli = results["laplace-springs solve vertical-pair-damped"]
    print(f"laplace-springs solve vertical-pair-damped: wall median "
          f"{statistics.median(w for w, _ in cli):.3f} s, cpu median "
          f"{statistics.median(c for _, c in cli):.3f} s (target: under 1.5 s wall); "
          f"over import sympy (pairwise, cpu): "
          f"{_spread([a[1] / b[1] for a, b in zip(cli, peer)])}")


if __name__ == "__main__":
    main()
