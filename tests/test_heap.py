"""engine.keep_heap: the box tests' temporaries (several arrays of half a MiB, freed together at each
call) reuse the heap's memory instead of faulting it in again at every call."""

from __future__ import annotations

import resource
import sys

import numpy as np
import pytest

from fivebar_cli.paving import engine


@pytest.mark.skipif(sys.platform != "linux", reason="glibc's malloc only")
def test_temporaries_of_a_chunk_do_not_fault_again():
    engine.keep_heap()

    def calls(n: int) -> int:
        before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
        for _ in range(n):
            arrays = [np.ones(1 << 16) for _ in range(12)]  # a chunk's temporaries: 12 x 512 KiB
            del arrays
        return resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before

    calls(2)  # the first call grows the heap
    # returned to the system, 12 arrays of 128 pages would fault in again: 1536 faults a call
    assert calls(20) < 20 * 100
