"""Facts about the running process that benchmarks and fleet reports give."""

from __future__ import annotations

import resource

__all__ = ["peak_rss_mb"]


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
