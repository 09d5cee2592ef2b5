"""Sweeps on a Dask LocalCluster (2 worker processes, 1 GiB each): the same numbers as the
local run, values streamed to a .npy store written by the workers, progress once per
chunk, and a worker killed in the middle of the run costs nothing but time.

"The same numbers" needs the same code: a worker imports the package when it starts, this
process did at collection, and a file of the package edited in between (a shared working
tree during a long suite: once, sweeps/kernels.py changed set 2098 of the two-mass data
below by 1.6e-15) makes the two differ. Each comparison first checks that the workers run
the code this process runs, and skips with the modules that differ if they do not.
"""

from __future__ import annotations

import hashlib
import importlib
import os
import signal
import sys
import types

import numpy as np
import pytest

import laplace_springs as ls

distributed = pytest.importorskip("distributed")
cloudpickle = pytest.importorskip("cloudpickle")

N = 12


def _digest(code: types.CodeType, out) -> None:
    """Feed a code object (bytecode, names, constants, nested code) to ``out``."""
    out.update(code.co_code)
    out.update(repr(code.co_names).encode())
    for const in code.co_consts:
        if isinstance(const, types.CodeType):
            _digest(const, out)
        else:  # frozenset order follows string hashing, which differs between processes
            out.update(repr(sorted(map(repr, const)) if isinstance(const, frozenset) else const).encode())


def _code_digests(names: list[str]) -> dict[str, str]:
    """A digest of the functions and methods of each module ``names`` as this process
    runs them (imported if needed)."""
    digests = {}
    for name in names:
        module = importlib.import_module(name)
        out = hashlib.sha256()
        for _, value in sorted(vars(module).items()):
            if getattr(value, "__module__", None) != name:
                continue
            members = sorted(vars(value).items()) if isinstance(value, type) else [("", value)]
            for _, member in members:
                for function in (getattr(member, "__func__", member), getattr(member, "fget", None)):
                    if isinstance(function, types.FunctionType):
                        _digest(function.__code__, out)
        digests[name] = out.hexdigest()
    return digests


cloudpickle.register_pickle_by_value(sys.modules[__name__])  # the workers cannot import tests/


def same_code(client) -> None:
    """Skip unless every worker runs the package's code as this process loaded it."""
    names = sorted(name for name in sys.modules if name.split(".")[0] == "laplace_springs")
    here = _code_digests(names)
    for worker, there in client.run(_code_digests, names).items():
        differ = [name for name in names if here[name] != there[name]]
        if differ:
            pytest.skip(f"worker {worker} runs other code than this process (files edited after "
                        f"it imported them): {', '.join(differ)}")


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
    same_code(client)
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
    same_code(client)  # the worker started in place of the killed one too


def test_cost_chunks_quantities_and_the_small_path(client):
    """Chunks cut by estimated cost; quantities reduced on the workers; the compiled
    two-mass route gives the local numbers."""
    pair = ls.Scene.from_components(masses={"m1": 1, "m2": 1},
                                    springs={"k1": ("wall", "m1", "k1"), "k2": ("m1", "m2", "k2")},
                                    dashpots={"c": ("wall", "m1", "c")}, x0=[1, 0], v0=[0, 1],
                                    parameters=["k1", "k2", "c"])
    rng = np.random.default_rng(11)
    values = {"k1": rng.uniform(0.5, 3, 3000), "k2": rng.uniform(0.5, 3, 3000),
              "c": rng.uniform(0.01, 4, 3000)}
    values["c"][5], values["k1"][5], values["k2"][5] = 2.0, 1.0, 1.0
    times = np.linspace(0, 12, 40)
    same_code(client)
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
    pair = ls.Scene.from_components(masses={"m1": 1, "m2": 1},
                                    springs={"k1": ("wall", "m1", "k1"), "k2": ("m1", "m2", "k2")},
                                    dashpots={"c": ("wall", "m1", "c")}, x0=[1, 0], v0=[0, 1],
                                    parameters=["k1", "k2", "c"])
    rng = np.random.default_rng(11)
    values = {"k1": rng.uniform(0.5, 3, 300), "k2": rng.uniform(0.5, 3, 300),
              "c": rng.uniform(0.01, 4, 300)}
    times = np.linspace(0, 12, 40)
    same_code(client)
    default = ls.sweep(pair, values, times, chunk=100, return_error=True)
    set_limits(cluster_gap=0.3)
    local = ls.sweep(pair, values, times, chunk=100, return_error=True)
    remote = ls.sweep(pair, values, times, chunk=100, return_error=True, client=client)
    assert not np.array_equal(local.error, default.error)  # the limit matters here
    assert local.exact_sets.size > default.exact_sets.size
    assert np.array_equal(local.values, remote.values) and np.array_equal(local.error, remote.error)
    assert np.array_equal(local.exact_sets, remote.exact_sets)
