"""glibc's thresholds during a sweep task: a process started as a Dask nanny starts its
workers (MALLOC_TRIM_THRESHOLD_=65536) serves every NumPy temporary above 128 KiB with a
fresh mapping, one page fault per 4 KiB page; inside roomy_allocator the heap reuses them,
and the thresholds the environment asked for are back afterwards. Counted in page faults
(getrusage), not in time."""

from __future__ import annotations

import json
import os
import platform
import subprocess
import sys

import pytest

from laplace_springs.sweeps.allocator import fixed_thresholds

glibc = pytest.mark.skipif(platform.system() != "Linux" or platform.libc_ver()[0] != "glibc",
                           reason="glibc's malloc only")

# Faults of 200 allocations of 2 MiB, each written through, in a worker thread (as a Dask
# task runs): before, inside and after roomy_allocator, and through run_chunk's own use.
CHILD = r"""
import json, resource, threading
import numpy as np
from laplace_springs.sweeps.allocator import roomy_allocator

def faults(block):
    out = []
    def work():
        before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
        with block():
            for _ in range(200):
                a = np.empty(2 ** 18)
                a[:] = 1.0
                del a
        out.append(resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before)
    thread = threading.Thread(target=work)
    thread.start()
    thread.join()
    return out[0]

class plain:
    def __enter__(self): pass
    def __exit__(self, *args): pass

print(json.dumps([faults(plain), faults(roomy_allocator), faults(plain)]))
"""


def _faults(**environ: str) -> list[int]:
    env = {k: v for k, v in os.environ.items() if not k.startswith("MALLOC_") and k != "GLIBC_TUNABLES"}
    output = subprocess.run([sys.executable, "-c", CHILD], env={**env, **environ}, check=True,
                            capture_output=True, text=True).stdout
    return json.loads(output.strip().splitlines()[-1])


@glibc
def test_a_fixed_trim_threshold_costs_faults_that_roomy_allocator_saves():
    pages = 200 * (2 ** 21 // 4096)  # every page of every array, if each one is a new mapping
    before, inside, after = _faults(MALLOC_TRIM_THRESHOLD_="65536")
    assert before > pages // 2  # the worker's setting: a new mapping for each array
    assert inside < pages // 20  # reused from the heap
    assert after > pages // 2  # the environment's thresholds are back after the block


@glibc
def test_roomy_allocator_leaves_a_plain_process_alone():
    pages = 200 * (2 ** 21 // 4096)
    assert all(count < pages // 20 for count in _faults())  # glibc adjusts by itself


def test_the_thresholds_a_process_runs_under():
    default = 128 * 1024  # glibc's start value of M_TRIM_THRESHOLD and M_MMAP_THRESHOLD
    assert fixed_thresholds({}) is None
    assert fixed_thresholds({"MALLOC_TRIM_THRESHOLD_": "65536"}) == (65536, default)
    assert fixed_thresholds({"MALLOC_MMAP_THRESHOLD_": "0x100000"}) == (default, 1 << 20)
    assert fixed_thresholds({"MALLOC_TOP_PAD_": "0"}) == (default, default)
    assert fixed_thresholds({"GLIBC_TUNABLES": "glibc.malloc.trim_threshold=4096:glibc.malloc.tcache_count=0"}
                            ) == (4096, default)
    assert fixed_thresholds({"GLIBC_TUNABLES": "glibc.malloc.tcache_count=0"}) is None
    assert fixed_thresholds({"MALLOC_TRIM_THRESHOLD_": "lots"}) == (default, default)
