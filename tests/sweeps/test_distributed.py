"""Sweeps on a Dask LocalCluster (2 worker processes, 1 GiB each): the same numbers as the
local run, values streamed to a .npy store written by the workers, progress once per
chunk, and a worker killed in the middle of the run costs nothing but time.

"The same numbers" needs the same code: a worker imports the package when it starts, this
process did at collection, and a file of the package edited in between (a shared working
tree during a long suite: once, sweeps/kernels.py changed set 2098 of the two-mass data
below by 1.6e-15) makes the two differ. Each comparison first checks that no module of the
package this process loaded changed on disk since it started, and skips naming them if one did.
"""

from __future__ import annotations

import os
import signal
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import laplace_springs as ls

distributed = pytest.importorskip("distributed")

N = 12


_IMPORTED = time.time()


def _started() -> float:
    """When this process started (Linux: /proc), else when this module was imported."""
    try:
        with open("/proc/self/stat") as stat:
            ticks = int(stat.read().rsplit(")", 1)[1].split()[19])  # field 22, starttime
        with open("/proc/stat") as stat:
            boot = next(int(line.split()[1]) for line in stat if line.startswith("btime"))
        return boot + ticks / os.sysconf("SC_CLK_TCK")
    except (OSError, StopIteration, ValueError, IndexError):
        return _IMPORTED


def same_code() -> None:
    """Skip unless the workers run the package's code as this process loaded it: no module of
    the package this process has loaded changed on disk since it started (a worker, started
    later, imports the files as they are; a code digest cannot tell, since pytest rewrites
    the asserts of the modules it collects for doctests)."""
    started = _started()
    files = {Path(module.__file__) for name, module in list(sys.modules.items())
             if name.split(".")[0] == "laplace_springs" and getattr(module, "__file__", None)}
    root = Path(ls.__file__).parent.parent
    edited = sorted(str(path.relative_to(root)) for path in files
                    if path.exists() and path.stat().st_mtime > started)
    if edited:
        pytest.skip(f"modules of the package edited after this process loaded them (the workers would "
                    f"run other code): {', '.join(edited)}")


def _chain():
    masses = {f"m{i}": 1 for i in range(N)}
    springs = {"k0": ("wall", "m0", "k"), **{f"k{i}": (f"m{i-1}", f"m{i}", 1) for i in range(1, N)}}
    return ls.Scene.from_components(masses=masses, springs=springs, dashpots={"c": ("wall", "m0", "c")},
                                    x0=[1] + [0] * (N - 1), v0=[0] * N,
                                    parameters={"k": "positive", "c": "nonnegative"})


def _cluster():
    return distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                    memory_limit="1GiB", dashboard_address=None)


@pytest.fixture(scope="module")
def client():
    with _cluster() as cluster, distributed.Client(cluster) as client:
        yield client


@pytest.fixture
def own_client():
    """A cluster of its own, for the test that kills one of its workers."""
    with _cluster() as cluster, distributed.Client(cluster) as client:
        yield client


def test_killed_worker_mid_run_gives_the_complete_identical_result(own_client, tmp_path):
    client = own_client
    scene = _chain()
    rng = np.random.default_rng(2)
    P = 1200
    values = {"k": rng.uniform(0.5, 2, P), "c": rng.uniform(0.01, 1, P)}
    times = np.linspace(0, 20, 21)
    local = ls.sweep(scene, values, times, chunk=60, return_error=True)
    assert local.route == "batched"
    same_code()
    seen: list[int] = []
    killed: list[int] = []
    pids = client.run(os.getpid)  # worker address -> process id (processes this test started)

    def progress(done: int, total: int) -> None:
        seen.append(done)
        if not killed:  # after the first chunk: kill a worker while tasks still run on it
            pid = pids[sorted(pids)[0]]
            os.kill(pid, signal.SIGKILL)
            killed.append(pid)

    store = tmp_path / "x.npy"
    remote = ls.sweep(scene, values, times, chunk=60, return_error=True, client=client,
                      out=store, error_out=tmp_path / "e.npy", progress=progress)
    assert killed and killed[0] not in client.run(os.getpid).values()  # that worker is gone
    assert seen == sorted(seen) and seen[-1] == P and len(seen) == P // 60  # each chunk once
    written = np.load(store)
    assert np.array_equal(written, local.values)  # every row, none lost or duplicated
    assert np.array_equal(np.load(tmp_path / "e.npy"), local.error)
    assert np.array_equal(remote.set_error, local.set_error)
    assert np.array_equal(remote.exact_sets, local.exact_sets)
    same_code()  # the worker started in place of the killed one too


def _pair(count: int) -> tuple[ls.Scene, dict[str, np.ndarray]]:
    """A two-mass scene with parameters k1, k2, c and ``count`` random sets of them."""
    pair = ls.Scene.from_components(masses={"m1": 1, "m2": 1},
                                    springs={"k1": ("wall", "m1", "k1"), "k2": ("m1", "m2", "k2")},
                                    dashpots={"c": ("wall", "m1", "c")}, x0=[1, 0], v0=[0, 1],
                                    parameters=["k1", "k2", "c"])
    rng = np.random.default_rng(11)
    return pair, {"k1": rng.uniform(0.5, 3, count), "k2": rng.uniform(0.5, 3, count),
                  "c": rng.uniform(0.01, 4, count)}


def test_cost_chunks_quantities_and_the_small_path(client):
    """Chunks cut by estimated cost; quantities reduced on the workers; the compiled
    two-mass route gives the local numbers."""
    pair, values = _pair(3000)
    values["c"][5], values["k1"][5], values["k2"][5] = 2.0, 1.0, 1.0
    times = np.linspace(0, 12, 40)
    same_code()
    local = ls.sweep(pair, values, times, chunk=700)
    remote = ls.sweep(pair, values, times, chunk=700, client=client)
    assert np.array_equal(local, remote)
    here = ls.sweep(pair, values, times, quantities={"peak": None, "settling_time": 0.05})
    there = ls.sweep(pair, values, times, quantities={"peak": None, "settling_time": 0.05},
                     client=client)
    for name in ("peak", "settling_time"):
        assert np.array_equal(here.quantities[name], there.quantities[name])
    assert np.allclose(here.quantities["peak"], np.max(np.abs(local), axis=2), rtol=0, atol=0)


def test_the_callers_limits_reach_the_workers(client, set_limits):
    """A sweep under ``using_limits`` runs under them on the workers too: a wider cluster
    gap changes the compiled route's numbers, and the client's run follows the local one."""
    pair, values = _pair(300)
    times = np.linspace(0, 12, 40)
    same_code()
    default = ls.sweep(pair, values, times, chunk=100, return_error=True)
    set_limits(cluster_gap=0.3)
    local = ls.sweep(pair, values, times, chunk=100, return_error=True)
    remote = ls.sweep(pair, values, times, chunk=100, return_error=True, client=client)
    assert not np.array_equal(local.error, default.error)  # the limit matters here
    assert local.exact_sets.size > default.exact_sets.size
    assert np.array_equal(local.values, remote.values) and np.array_equal(local.error, remote.error)
    assert np.array_equal(local.exact_sets, remote.exact_sets)
