"""Facts about the running process that benchmarks and fleet reports give, and how a
command's process keeps its freed memory."""

from __future__ import annotations

import os
import resource

__all__ = ["keep_freed_memory", "peak_rss_mb"]

#: ``mallopt`` parameters of glibc's ``malloc.h``.
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3
#: Blocks up to this size come from the heap, and are reused once freed (glibc's largest
#: mmap threshold on a 64-bit system). [bytes]
MMAP_THRESHOLD_BYTES = 32 << 20
#: Freed memory at the heap's top kept for the next chunk, up to this much. [bytes]
TRIM_THRESHOLD_BYTES = 256 << 20
#: Arrow's choice of memory pool, read when pyarrow first allocates.
ARROW_POOL_VARIABLE = "ARROW_DEFAULT_MEMORY_POOL"


def keep_freed_memory() -> bool:
    """Let glibc's ``malloc`` keep and reuse the buffers of one chunk for the next.

    A command reads, filters and writes a recording chunk by chunk: arrays of a few
    megabytes, each freed before the next chunk asks for the same again. By default glibc
    serves such blocks with their own ``mmap`` and returns them to the kernel on ``free``,
    so every chunk's arrays are new pages that the kernel zeroes on first touch (about a
    fifth of ``compensate``'s CPU on a 10 M-row file: ``docs/benchmarks.md``). With a fixed
    mmap threshold of 32 MiB and a trim threshold of 256 MiB they come from the heap and are
    reused. Arrow's decoded columns are taken from the same heap (its ``system`` pool, set
    through ``ARROW_DEFAULT_MEMORY_POOL`` unless the environment names a pool): its default
    pool, mimalloc, gives freed segments back and faults them in again as huge pages, each
    zeroed. Called by the ``hrgtc`` command only, before pyarrow is imported (a library
    leaves its host's allocator alone); no effect but on glibc. Returns whether both
    ``mallopt`` settings were taken.
    """
    try:
        glibc = os.confstr("CS_GNU_LIBC_VERSION") or ""
    except (ValueError, OSError):  # not a glibc system
        return False
    if not glibc.startswith("glibc"):
        return False
    import ctypes

    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return False
    mallopt.argtypes, mallopt.restype = [ctypes.c_int, ctypes.c_int], ctypes.c_int
    kept = bool(mallopt(_M_MMAP_THRESHOLD, MMAP_THRESHOLD_BYTES)
                and mallopt(_M_TRIM_THRESHOLD, TRIM_THRESHOLD_BYTES))
    if kept:  # Arrow's decoded buffers from the same heap (unless the user chose a pool)
        os.environ.setdefault(ARROW_POOL_VARIABLE, "system")
    return kept


def peak_rss_mb() -> float:
    """This process's peak resident set size. [MB]

    ``VmHWM`` of /proc/self/status belongs to the current address space, so it
    starts afresh in a spawned child; ``ru_maxrss`` survives fork + exec on
    Linux and would report the parent's peak (it is the fallback elsewhere).
    """
    try:
        with open("/proc/self/status", encoding="ascii") as status:
            for line in status:
                if line.startswith("VmHWM:"):
                    return round(int(line.split()[1]) / 1024.0, 1)
    except OSError:
        pass
    return round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0, 1)
