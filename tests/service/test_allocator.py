"""The allocator settings: freed memory is reused without the kernel zeroing it again, and handed back
after a job. Each case runs in a process of its own (the settings are process-wide)."""

import subprocess
import sys

import pytest

from monitor.service import allocator

PROBE = """
import resource, sys
import numpy as np
from monitor.service import allocator
if sys.argv[1] == "reuse":
    assert allocator.reuse_freed_memory()
def faults():
    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt
def rss_mb():
    return int(open("/proc/self/statm").read().split()[1]) * 4096 / 1e6
a = np.ones(50_000_000)  # 400 MB written, then freed
del a
f0 = faults()
a = np.ones(50_000_000)
f1 = faults()
del a
before = rss_mb()
allocator.release_freed_memory()
print(f1 - f0, before - rss_mb())
"""


def _probe(mode):
    out = subprocess.run([sys.executable, "-c", PROBE, mode], capture_output=True, text=True, check=True)
    faults, released_mb = out.stdout.split()
    return int(faults), float(released_mb)


@pytest.mark.skipif(allocator._glibc() is None, reason="the settings are glibc's")
def test_freed_memory_is_reused_then_handed_back():
    default_faults, _ = _probe("default")
    reuse_faults, released_mb = _probe("reuse")
    assert default_faults > 150  # 400 MB of fresh pages (2 MB huge pages at the least)
    assert reuse_faults < default_faults / 10  # the freed 400 MB, reused as it is
    assert released_mb > 300  # and given back after the job
