"""ls.sweep against batched NumPy eigen-decompositions and a loop of ls.solve, measured in
the same run.

Part 1 (the compiled route): 10^5 parameter sets of a two-mass scene (masses 1, springs
k1 wall-m1 and k2 m1-m2, a dashpot c wall-m1) at 100 times. The baseline stacks the
first-order matrices [[0, I], [-K, -C]], takes eig once for all sets, solves V a = z0 and
sums the modes; it is accurate where the modes are well separated, so the agreement is
measured on the sets whose eigenvector matrix is well conditioned (cond(V) < 1e3). Timed
interleaved, best of two (the CPU may be shared).

Part 2 (the batched route): 10^4 sets of a 50-mass chain (unit masses and springs, the
first spring k and a dashpot c at the wall, x0 = e1) at 20 times on [0, 20]:

* ls.sweep on one worker (this process), with a bound on every value;
* the best hand-written batched NumPy code: stacked first-order matrices, numpy.linalg.eig,
  numpy.linalg.solve for the coefficients, one matmul for the modal sum, in chunks of 500
  sets (no error estimate);
* a loop of ls.solve(scene.subs(set)).evaluate(times) over the first 100 sets
  (extrapolated to 10^4: it would take hours);
* ls.sweep and the hand-written code on a Dask LocalCluster of 2 worker processes (one
  thread each), ls.sweep streaming its values to a .npy store written by the workers;
* ls.sweep on the same cluster with glibc's thresholds left where the nanny fixes them
  (MALLOC_TRIM_THRESHOLD_=65536, which turns glibc's adaptive mmap threshold off): the
  package's tasks raise them while they run (sweeps/allocator.py); this row switches that
  off in the workers to show what it is worth. The Dask rows also report the workers' minor
  page faults.

Each measurement runs in its own process (the 1-minute load average at its start is
printed: the machine may be shared), which reports its wall time, its CPU time (on the
cluster, the workers': what a task costs there, whatever else runs), and its peak
resident memory (VmHWM: ru_maxrss would carry the parent's peak across fork and exec);
on the cluster, the client's and each worker's peak.

    python benchmarks/bench_sweep.py [sets of part 1] [sets of part 2]
    python benchmarks/bench_sweep.py --scale 400 3   # the 2-worker speed-up, in quiet gaps
"""

from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
import tempfile
import time

import numpy as np

import laplace_springs as ls
from laplace_springs.sweeps import allocator, sweep

N_CHAIN = 50
TIMES_CHAIN = np.linspace(0, 20, 20)


# ----------------------------------------------------------------------------- part 1


def baseline(k1: np.ndarray, k2: np.ndarray, c: np.ndarray, times: np.ndarray,
             x0: np.ndarray, v0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """x(t) (P, 2, T) by batched eig of the stacked first-order matrices, and cond(V)."""
    P = k1.size
    A = np.zeros((P, 4, 4))
    A[:, 0, 2] = A[:, 1, 3] = 1.0
    A[:, 2, 0], A[:, 2, 1], A[:, 2, 2] = -(k1 + k2), k2, -c
    A[:, 3, 0], A[:, 3, 1] = k2, -k2
    lam, V = np.linalg.eig(A)
    z0 = np.broadcast_to(np.concatenate([x0, v0]), (P, 4))
    a = np.linalg.solve(V, z0[..., None])[..., 0]
    modes = V[:, :2, :] * a[:, None, :]
    x = np.matmul(modes, np.exp(lam[:, :, None] * times[None, None, :])).real
    return x, np.linalg.cond(V)


def part_one(P: int, repeat: int = 2) -> None:
    scene = ls.Scene.from_components(
        masses={"m1": 1, "m2": 1},
        springs={"k1": ("wall", "m1", "k1"), "k2": ("m1", "m2", "k2")},
        dashpots={"c": ("wall", "m1", "c")},
        x0=[1, 0], v0=[0, 1], parameters=["k1", "k2", "c"])
    rng = np.random.default_rng(0)
    values = {"k1": rng.uniform(0.5, 3, P), "k2": rng.uniform(0.5, 3, P), "c": rng.uniform(0.01, 4, P)}
    times = np.linspace(0, 20, 100)
    t_base = t_sweep = np.inf
    for _ in range(repeat):  # interleaved, best of `repeat`: the CPU may be shared
        start = time.perf_counter()
        ref, cond = baseline(values["k1"], values["k2"], values["c"], times, np.array([1.0, 0.0]),
                             np.array([0.0, 1.0]))
        t_base = min(t_base, time.perf_counter() - start)
        start = time.perf_counter()
        result = sweep(scene, values, times, return_error=True)
        t_sweep = min(t_sweep, time.perf_counter() - start)
    good = cond < 1e3
    scale = np.maximum(np.max(np.abs(result.values), axis=1, keepdims=True), 1.0)
    agree = np.max(np.abs(result.values - ref)[good] / scale[good])
    print(f"Part 1: {P:,} sets x {times.size} times, two-mass scene (k1, k2, c); best of {repeat}")
    print(f"  {'route':<36}{'time [s]':>10}")
    print(f"  {'batched numpy.linalg.eig (modal)':<36}{t_base:>10.2f}")
    print(f"  {'ls.sweep (compiled, vectorised)':<36}{t_sweep:>10.2f}")
    print(f"  ratio sweep / eig baseline: {t_sweep / t_base:.2f}")
    print(f"  sets solved alone: {result.exact_sets.size} ({100 * result.exact_sets.size / P:.2f} %); "
          f"largest bound {np.max(result.set_error):.1e} of max(|x|, S0)")
    print(f"  agreement with the baseline where cond(V) < 1e3 ({good.mean():.1%} of sets): {agree:.1e}")


# ----------------------------------------------------------------------------- part 2


def chain() -> ls.Scene:
    n = N_CHAIN
    masses = {f"m{i}": 1 for i in range(n)}
    springs = {"k0": ("wall", "m0", "k"), **{f"k{i}": (f"m{i-1}", f"m{i}", 1) for i in range(1, n)}}
    return ls.Scene.from_components(masses=masses, springs=springs, dashpots={"c": ("wall", "m0", "c")},
                                    x0=[1] + [0] * (n - 1), v0=[0] * n,
                                    parameters={"k": "positive", "c": "nonnegative"})


def chain_values(P: int) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(1)
    return {"k": rng.uniform(0.5, 2, P), "c": rng.uniform(0.05, 1, P)}


def handwritten(k: np.ndarray, c: np.ndarray, times: np.ndarray) -> np.ndarray:
    """The chain's x(t) (P, n, T) by batched eig, in chunks of 500 sets (no error estimate)."""
    n = N_CHAIN
    P = k.size
    K0 = np.diag(np.full(n, 2.0)) - np.diag(np.ones(n - 1), 1) - np.diag(np.ones(n - 1), -1)
    K0[-1, -1] = 1.0
    out = np.empty((P, n, times.size))
    z0 = np.zeros(2 * n)
    z0[0] = 1.0
    for start in range(0, P, 500):
        kk, cc = k[start:start + 500], c[start:start + 500]
        B = kk.size
        A = np.zeros((B, 2 * n, 2 * n))
        A[:, np.arange(n), n + np.arange(n)] = 1.0
        A[:, n:, :n] = -K0
        A[:, n, 0] -= kk - 1.0  # K[0,0] = k + 1 (the wall spring k and the first unit spring)
        A[:, n, n] = -cc
        lam, V = np.linalg.eig(A)
        a = np.linalg.solve(V, np.broadcast_to(z0, (B, 2 * n))[..., None])[..., 0]
        out[start:start + B] = np.matmul(V[:, :n, :] * a[:, None, :],
                                         np.exp(lam[:, :, None] * times)).real
    return out


def _leave_thresholds() -> None:
    """In a worker: leave glibc's thresholds as the nanny fixed them during tasks."""
    allocator._LIBC = None


def _peak_mb() -> float:
    """This process's peak resident memory since it started (VmHWM, reset by exec)."""
    try:
        with open("/proc/self/status") as status:
            for line in status:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def _faults() -> int:
    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt


def _cpu() -> float:
    return time.process_time()


def _measure(kind: str, P: int, folder: str) -> dict:
    start = time.perf_counter()
    extra: dict = {}
    values = chain_values(P)
    faults, cpu = _faults(), _cpu()
    if kind == "sweep":
        result = sweep(chain(), values, TIMES_CHAIN, return_error=True)
        np.save(os.path.join(folder, "sweep.npy"), result.values)
        extra = {"alone": int(result.exact_sets.size), "bound": float(np.max(result.set_error)),
                 "route": result.route, "faults": _faults() - faults}
    elif kind == "handwritten":
        np.save(os.path.join(folder, "handwritten.npy"), handwritten(values["k"], values["c"], TIMES_CHAIN))
    elif kind == "loop":
        scene = chain()
        count = min(P, 100)
        out = np.empty((count, N_CHAIN, TIMES_CHAIN.size))
        for b in range(count):
            out[b] = ls.solve(scene.subs({"k": values["k"][b], "c": values["c"][b]})).evaluate(TIMES_CHAIN)
        np.save(os.path.join(folder, "loop.npy"), out)
        extra = {"sets": count}
    else:  # the two Dask runs
        import distributed

        with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                      dashboard_address=None) as cluster, distributed.Client(cluster) as client:
            if kind == "dask-sweep-nanny":
                client.run(_leave_thresholds)
            before, cpu = client.run(_faults), client.run(_cpu)
            start = time.perf_counter()
            if kind in ("dask-sweep", "dask-sweep-nanny"):
                store = os.path.join(folder, f"{kind}.npy")
                result = sweep(chain(), values, TIMES_CHAIN, return_error=True, client=client, out=store)
                extra = {"alone": int(result.exact_sets.size)}
            else:
                chunks = [(s, min(s + 500, P)) for s in range(0, P, 500)]
                futures = client.map(lambda b: handwritten(values["k"][b[0]:b[1]], values["c"][b[0]:b[1]],
                                                           TIMES_CHAIN), chunks)
                out = np.empty((P, N_CHAIN, TIMES_CHAIN.size))
                for (s, e), part in zip(chunks, client.gather(futures)):
                    out[s:e] = part
            seconds = time.perf_counter() - start
            after, used = client.run(_faults), client.run(_cpu)
            extra["worker_faults"] = sum(after[w] - before[w] for w in after)
            extra["cpu"] = sum(used[w] - cpu[w] for w in used)  # the workers' (the client's is small)
            workers = client.run(_peak_mb)
            extra["worker_peak_mb"] = round(max(workers.values()), 1)
            return {"seconds": seconds, "peak_mb": _peak_mb(),
                    **extra}
    return {"seconds": time.perf_counter() - start, "cpu": _cpu() - cpu,
            "peak_mb": _peak_mb(), **extra}


def _run(kind: str, P: int, folder: str) -> dict:
    load = os.getloadavg()[0]
    output = subprocess.run([sys.executable, __file__, "--measure", kind, str(P), folder],
                            capture_output=True, text=True, check=True).stdout
    return {**json.loads(output.strip().splitlines()[-1]), "load": load}


def part_two(P: int) -> None:
    folder = tempfile.mkdtemp(prefix="bench_sweep_")
    runs = {kind: _run(kind, P, folder) for kind in ("sweep", "handwritten", "loop", "dask-sweep",
                                                     "dask-sweep-nanny", "dask-handwritten")}
    ours = np.load(os.path.join(folder, "sweep.npy"))
    hand = np.load(os.path.join(folder, "handwritten.npy"))
    loop = np.load(os.path.join(folder, "loop.npy"))
    dask = np.load(os.path.join(folder, "dask-sweep.npy"))
    nanny = np.load(os.path.join(folder, "dask-sweep-nanny.npy"))
    count = loop.shape[0]
    loop_total = runs["loop"]["seconds"] * P / count
    print(f"Part 2: {P:,} sets x {TIMES_CHAIN.size} times, {N_CHAIN}-mass chain (k, c at the wall); "
          f"route {runs['sweep']['route']}")
    print(f"  {'':<44}{'time [s]':>10}{'cpu [s]':>9}  {'peak memory [MB]':<26}{'page faults':>12}{'load':>6}")
    rows = [("ls.sweep, one worker (bounds on every value)", runs["sweep"]),
            ("hand-written batched numpy.linalg.eig", runs["handwritten"]),
            (f"loop of ls.solve ({count} sets, x {P // count})", {"seconds": loop_total,
                                                                 "peak_mb": runs["loop"]["peak_mb"],
                                                                 "load": runs["loop"]["load"]}),
            ("ls.sweep, 2 Dask workers (.npy store)", runs["dask-sweep"]),
            ("  same, glibc thresholds as the nanny fixes", runs["dask-sweep-nanny"]),
            ("hand-written, 2 Dask workers", runs["dask-handwritten"])]
    for name, run in rows:
        memory = f"{run['peak_mb']:.0f}"
        if "worker_peak_mb" in run:
            memory += f" (workers {run['worker_peak_mb']:.0f})"
        faults = run.get("faults", run.get("worker_faults"))
        cpu = f"{run['cpu']:.1f}" if "cpu" in run else ""
        print(f"  {name:<44}{run['seconds']:>10.1f}{cpu:>9}  {memory:<26}{'' if faults is None else f'{faults:,}':>12}"
              f"{run['load']:>6.2f}")
    print(f"  ls.sweep speed-up on 2 workers: {runs['sweep']['seconds'] / runs['dask-sweep']['seconds']:.2f} "
          f"({runs['sweep']['seconds'] / runs['dask-sweep-nanny']['seconds']:.2f} with the nanny's thresholds); "
          f"hand-written: {runs['handwritten']['seconds'] / runs['dask-handwritten']['seconds']:.2f}")
    print(f"  ratio ls.sweep / hand-written: one worker {runs['sweep']['seconds'] / runs['handwritten']['seconds']:.2f}, "
          f"2 workers {runs['dask-sweep']['seconds'] / runs['dask-handwritten']['seconds']:.2f}; "
          f"loop of ls.solve / ls.sweep: {loop_total / runs['sweep']['seconds']:.0f}")
    print(f"  sets solved alone: {runs['sweep']['alone']}; largest bound {runs['sweep']['bound']:.1e} "
          f"of max(|x|, S0)")
    print(f"  |ls.sweep - hand-written| {np.max(np.abs(ours - hand)):.1e}; |ls.sweep - ls.solve| "
          f"{np.max(np.abs(ours[:count] - loop)):.1e} (first {count} sets); Dask runs identical: "
          f"{bool(np.array_equal(ours, dask) and np.array_equal(ours, nanny))}")


# ----------------------------------------------------------------------------- scale-out


def _others_busy(skip: set[int]) -> bool:
    """Whether a process not in ``skip`` (this one, the workers) uses more than 30 % CPU."""
    rows = subprocess.run(["ps", "-eo", "pcpu=,pid="], check=True, capture_output=True, text=True).stdout.split()
    return any(float(cpu) > 30 and int(pid) not in skip for cpu, pid in zip(rows[::2], rows[1::2]))


def _idle() -> tuple[int, int]:
    with open("/proc/stat") as stat:
        jiffies = [int(v) for v in stat.readline().split()[1:]]
    return sum(jiffies), jiffies[3] + jiffies[4]


def scale_out(P: int, rounds: int) -> None:
    """ls.sweep and the hand-written code on one process and on 2 Dask workers (one
    cluster started once), interleaved, each round only while no other process is busy;
    prints the idle share of the cores during the Dask sweep (0: both cores worked)."""
    import distributed

    scene, values = chain(), chain_values(P)
    chunks = [(s, min(s + 100, P)) for s in range(0, P, 100)]
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        sweep(scene, {k: v[:64] for k, v in values.items()}, TIMES_CHAIN, client=client)  # warm
        skip = {os.getpid(), *client.run(os.getpid).values()}
        done = 0
        while done < rounds:
            time.sleep(3)
            if _others_busy(skip) or os.getloadavg()[0] > 1.3:
                continue
            load = os.getloadavg()[0]
            start = time.perf_counter()
            local = sweep(scene, values, TIMES_CHAIN)
            t_local = time.perf_counter() - start
            before, start = _idle(), time.perf_counter()
            remote = sweep(scene, values, TIMES_CHAIN, client=client)
            t_dask, after = time.perf_counter() - start, _idle()
            idle = 2 * (after[1] - before[1]) / max(after[0] - before[0], 1)
            start = time.perf_counter()
            handwritten(values["k"], values["c"], TIMES_CHAIN)
            t_hand = time.perf_counter() - start
            start = time.perf_counter()
            client.gather(client.map(lambda b: handwritten(values["k"][b[0]:b[1]], values["c"][b[0]:b[1]],
                                                           TIMES_CHAIN), chunks))
            t_hdask = time.perf_counter() - start
            print(f"load {load:.2f}: ls.sweep {t_local:.2f} s, 2 workers {t_dask:.2f} s ({t_local / t_dask:.2f}x, "
                  f"idle cores {idle:.2f}); hand-written {t_hand:.2f} s, 2 workers {t_hdask:.2f} s "
                  f"({t_hand / t_hdask:.2f}x); identical {bool(np.array_equal(local, remote))}", flush=True)
            done += 1


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--measure":
        print(json.dumps(_measure(sys.argv[2], int(sys.argv[3]), sys.argv[4])))
    elif len(sys.argv) > 1 and sys.argv[1] == "--scale":
        scale_out(int(sys.argv[2]), int(sys.argv[3]))
    else:
        part_one(int(sys.argv[1]) if len(sys.argv) > 1 else 100_000)
        part_two(int(sys.argv[2]) if len(sys.argv) > 2 else 10_000)
