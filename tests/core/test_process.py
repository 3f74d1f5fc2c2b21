"""The command's allocator settings: a chunk's freed buffers are reused, not faulted in again."""

from __future__ import annotations

import subprocess
import sys

#: Chunks of a few arrays of 8-24 MB, each chunk's freed before the next (as a command's
#: reading, filtering and writing do), written to so that every new page is faulted in;
#: prints the minor page faults of the loop.
_CHUNKS = """
import resource, sys
import numpy as np
from hrgtc.core.process import keep_freed_memory
if sys.argv[1] == "keep":
    assert keep_freed_memory()
def chunk(k):
    arrays = [np.empty((1 + (k + i) % 3) << 20) for i in range(4)]
    for a in arrays:
        a.fill(k)
    return sum(float(a[-1]) for a in arrays)
chunk(0)
before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
for k in range(1, 40):
    chunk(k)
print(resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before)
"""


def _faults(mode: str) -> int:
    done = subprocess.run([sys.executable, "-c", _CHUNKS, mode], capture_output=True,
                          text=True, check=True)
    return int(done.stdout.strip())


def test_freed_chunk_buffers_are_reused_without_new_page_faults():
    # by default glibc returns each large block to the kernel (39 chunks of 64-96 MB:
    # hundreds of thousands of faults); kept, the loop reuses the first chunk's pages
    default, kept = _faults("default"), _faults("keep")
    assert default > 20 * 39
    assert kept * 10 < default


_POOL = """
import sys
from hrgtc.core.process import keep_freed_memory
keep_freed_memory()
import pyarrow as pa
print(pa.default_memory_pool().backend_name)
"""


def _pool(environment: dict[str, str]) -> str:
    import os

    env = {k: v for k, v in os.environ.items() if k != "ARROW_DEFAULT_MEMORY_POOL"}
    done = subprocess.run([sys.executable, "-c", _POOL], capture_output=True, text=True,
                          check=True, env={**env, **environment})
    return done.stdout.strip()


def test_arrow_takes_its_buffers_from_the_same_heap_unless_the_user_chose_a_pool():
    assert _pool({}) == "system"
    assert _pool({"ARROW_DEFAULT_MEMORY_POOL": "mimalloc"}) == "mimalloc"
