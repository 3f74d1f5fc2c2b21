"""The accelerometer's columns found under their common names.

A logger writes its accelerometer as ``acc_x``, ``accel_x``, ``ax``, ``a_x``, ``AccX``,
``imu.acc.x`` or ``acc_x [m/s^2]``. The motion detector and the per-orientation offsets
use the contract's ``accel_x/y/z`` (:mod:`hrgtc.recording.motion`): found by name, the
three columns are used without a ``--col`` mapping, and ``hrgtc info`` says so.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping

#: Prefixes of an accelerometer's columns in loggers' files (compared case-insensitively):
#: ``acc_x``, ``accel_x``, ``ax``, ``a_x``, ``AccX``, ``accelerometer.x``, ``imu_acc_x``,
#: with or without a unit after the axis (``acc_x [m/s^2]``, ``acc_x_m_s2``, ``accX(g)``).
_ACCEL_NAME = re.compile(
    r"^(?:imu[ _.\-]?)?(?:acc|accel|accl|acceleration|accelerometer|a)[ _.\-]?([xyz])"
    r"(?:$|[ _.\-\[(].*$)", re.IGNORECASE)


def find_accelerometer(names: Iterable[str], taken: Iterable[str],
                       kinds: Mapping[str, str] | None = None) -> dict[str, str]:
    """The file's accelerometer columns under their common names, as a column mapping
    ``{"accel_x": theirs, ...}``: all three axes, exactly one numeric column each, and none
    mapped or named ``accel_*`` already; else ``{}`` (the motion detector then uses the gyro).

    Examples
    --------
    >>> find_accelerometer(["time_s", "acc_x [m/s^2]", "acc_y [m/s^2]", "acc_z [m/s^2]"], [])
    {'accel_x': 'acc_x [m/s^2]', 'accel_y': 'acc_y [m/s^2]', 'accel_z': 'acc_z [m/s^2]'}
    >>> find_accelerometer(["ax", "ay", "az", "a_x", "a_y", "a_z"], [])  # which? none
    {}
    """
    names = list(names)
    taken = set(taken)
    if any(n.startswith("accel_") for n in (*names, *taken)):
        return {}
    found: dict[str, list[str]] = {}
    for name in names:
        match = _ACCEL_NAME.match(name.strip())
        if match and name not in taken and (kinds is None or kinds.get(name) == "numeric"):
            found.setdefault(match.group(1).lower(), []).append(name)
    if sorted(found) != ["x", "y", "z"] or any(len(v) != 1 for v in found.values()):
        return {}
    return {f"accel_{axis}": found[axis][0] for axis in "xyz"}
