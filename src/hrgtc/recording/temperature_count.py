"""A temperature logged as a raw count: a signed count stored unsigned, and what a count
map gives.

A sensor's signed 16- or 32-bit count is often logged unsigned (65236 for -300):
:func:`wrapped_count_bits` tells it, :func:`unwrap_count` signs it again. A count map
(``--temp-scale``/``--temp-offset``, or a model's map) that gives temperatures no
thermometer reads is named by :func:`map_problem`, with the option that fixes it, before
any impossible-value check judges the mapped values (issue 27).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from hrgtc.recording.checks import TEMPERATURE_RANGE_C

__all__ = ["map_problem", "unwrap_count", "wrapped_count_bits"]

#: A signed count stored unsigned: widths tried and how close under 2^bits it must sit.
_WRAP_WIDTHS = ((16, 2.0**12), (32, 2.0**24))


def wrapped_count_bits(values: np.ndarray) -> int | None:
    """16 or 32 when a raw count looks like a signed count stored unsigned, else None.

    That is: whole numbers in [0, 2^bits) with the median within 2^12 (2^24 for 32
    bits) under 2^bits, i.e. small negative numbers read as unsigned ones.
    """
    finite = values[np.isfinite(values)]
    if finite.size == 0 or np.any(finite != np.round(finite)) or finite.min() < 0:
        return None
    middle = float(np.median(finite))
    for bits, near in _WRAP_WIDTHS:
        top = 2.0**bits
        if finite.max() < top and top - near <= middle < top:
            return bits
    return None


def unwrap_count(values: np.ndarray, bits: int) -> np.ndarray:
    """A signed ``bits``-bit count stored unsigned, signed again (65236 -> -300 for 16 bits)."""
    half, full = 2.0 ** (bits - 1), 2.0**bits
    return np.where(values >= half, values - full, values)


def map_problem(plan: Any, raw: np.ndarray, mapped: np.ndarray, theirs: str,
                row_offset: int) -> str | None:
    """What a count map (``--temp-scale``/``--temp-offset``, or a model's map) gave when
    the median of its first chunk is a temperature no thermometer reads, and the option
    that fixes it (None when the map gives possible temperatures).

    A map written for the unsigned count of a sensor whose count was unwrapped (65236 ->
    −300) gives −362 °C instead of 22 °C; ``--temp-unwrap off`` reads the count as it is
    (and ``--temp-unwrap 16`` the other way round). A single impossible value is a spike,
    left to ``--spikes``; a whole column of them is the map's.
    """
    low, high = TEMPERATURE_RANGE_C
    finite = np.isfinite(mapped)
    median = float(np.median(mapped[finite]))
    if low <= median <= high:
        return None
    i = int(np.argmax(finite))
    scale, offset = plan.temp_scale, plan.temp_offset_c

    def plausible(counts: np.ndarray) -> float | None:
        value = float(np.median(counts[np.isfinite(counts)])) * scale + offset
        return value if low <= value <= high else None

    if plan.wrap_bits is not None:
        as_is = plausible(raw)
        fix = (f"the count was read as a signed {plan.wrap_bits}-bit number stored unsigned "
               f"({raw[i]:.0f} -> {unwrap_count(raw[i:i + 1], plan.wrap_bits)[0]:.0f}); "
               + (f"read as it is, the map gives {as_is:.4g} °C: if the scale and offset are "
                  "for the unsigned count, pass --temp-unwrap off" if as_is is not None else
                  "check --temp-scale/--temp-offset (temperature_c = count × K + C), or pass "
                  "--temp-unwrap off if they are for the unsigned count"))
    else:
        bits = next((b for b, _ in _WRAP_WIDTHS
                     if np.all(raw[np.isfinite(raw)] < 2.0**b)
                     and plausible(unwrap_count(raw, b)) is not None), None)
        fix = (f"read as a signed {bits}-bit count stored unsigned, the map gives "
               f"{plausible(unwrap_count(raw, bits)):.4g} °C: pass --temp-unwrap {bits}"
               if bits is not None else
               "check --temp-scale/--temp-offset (temperature_c = count × K + C; calibrate "
               "--temp-ref LOG fits them to a reference log)")
    return (f"{plan.source.path}: column {theirs!r} (temperature_c): the count map "
            f"temperature_c = count × {scale:.6g} {'-' if offset < 0 else '+'} {abs(offset):.6g} "
            f"gives {median:.4g} °C "
            f"(median; row {row_offset + i}: {raw[i]:.6g} -> {mapped[i]:.4g} °C), outside "
            f"the {low:g} to {high:g} °C a thermometer reads; {fix}")
