"""PX4 ULog flight logs (``.ulg``), read with pyulog (``pip install 'hrgtc[px4]'``).

A ULog holds many topics, each logged at its own rate; a topic with several instances
(``sensor_gyro`` of three IMUs) has one table per instance. Each topic instance is one
stream, named by the topic (``sensor_combined``) or, for a topic logged with several
instances or with another instance than 0, by the topic and its instance
(``sensor_gyro_0``, ``sensor_gyro_1``). Its ``timestamp`` (µs since boot) is ``time_s``
(seconds); its numeric fields are columns named ``<stream>.<field>``
(``sensor_gyro_0.x``, ``sensor_combined.gyro_rad[2]``), read when the column mapping names
them (text fields are left out). PX4's units are SI: gyro rates in rad/s (pass
``--rate-unit radps``), temperatures in °C::

    hrgtc info flight.ulg --col rate_dph=sensor_gyro_0.z \\
        --col temperature_c=sensor_gyro_0.temperature --rate-unit radps --thermometer sensor

The log's dropouts (lost records, which PX4 logs as such) are counted in
``extra["ulog_dropouts"]``; the gaps they leave are found by the validation as in any file.
"""

from __future__ import annotations

from collections import Counter
from pathlib import Path
from typing import Any

import numpy as np

from hrgtc.recording.formats.base import Format, Source
from hrgtc.recording.formats.logs import (
    Stream,
    check_exists,
    quiet,
    require,
    streams,
    unreadable,
)

#: The ULog file magic: "ULog" and the bytes 0x01 0x12 0x35 (then the version).
MAGIC = b"ULog\x01\x12\x35"
#: µs per s of ULog's timestamps.
TIMESTAMP_UNIT_S = 1e-6
#: The information messages kept in ``extra["ulog"]``.
INFO_KEYS = ("sys_name", "ver_hw", "ver_sw", "ver_sw_release", "sys_uuid", "time_ref_utc")


def stream_names(topics: list[tuple[str, int]]) -> list[str]:
    """The stream name of each ``(topic, instance)``: ``topic``, or ``topic_<instance>`` for a
    topic logged with several instances or with another instance than 0."""
    instances: dict[str, set[int]] = {}
    for topic, instance in topics:
        instances.setdefault(topic, set()).add(instance)
    return [topic if instances[topic] == {0} else f"{topic}_{instance}"
            for topic, instance in topics]


def _columns(data: Any) -> dict[str, np.ndarray]:
    """The numeric fields of one topic instance, ``timestamp`` as ``time_s`` [s]."""
    text = {f.field_name.split("[")[0] for f in data.field_data if f.type_str == "char"}
    columns = {"time_s": np.asarray(data.data["timestamp"], dtype=np.float64) * TIMESTAMP_UNIT_S}
    for name, values in data.data.items():
        if name == "timestamp" or name.split("[")[0] in text or name.startswith("_padding"):
            continue
        array = np.asarray(values)
        if array.ndim == 1 and array.dtype.kind in "fiub":
            columns[name] = array.astype(np.float64) if array.dtype.kind == "b" else array
    return columns


def _metadata(log: Any) -> dict[str, Any]:
    info = {key: log.msg_info_dict[key] for key in INFO_KEYS if key in log.msg_info_dict}
    info = {k: (v if isinstance(v, int | float | str) else str(v)) for k, v in info.items()}
    dropouts = list(getattr(log, "dropouts", []))
    return {"extra": {"ulog": info, "ulog_dropouts": len(dropouts),
                      "ulog_dropouts_ms": int(sum(d.duration for d in dropouts))}}


def read_ulog(path: Path) -> list[Source]:
    """The topic instances of a ULog file, one stream each."""
    check_exists(path)
    pyulog = require("pyulog", "px4", "ULog", path)
    with open(path, "rb") as handle:
        head = handle.read(len(MAGIC))
    if head != MAGIC:
        raise unreadable(path, "ULog", ValueError(f"the file starts with {head!r}, not the "
                                                  "ULog magic"), "is it a PX4 .ulg log?")
    fix = "copy the .ulg from the flight controller's SD card again"
    failure: Exception | None = None
    with quiet() as said:
        try:
            log = pyulog.ULog(str(path))
        except Exception as exc:  # pyulog raises what its parsing meets
            failure = exc
    if failure is None and log.file_corruption:
        failure = ValueError("; ".join(said[:2]) or "pyulog found corrupt records")
    if failure is not None:
        raise unreadable(path, "ULog", failure, fix)
    data = sorted(log.data_list, key=lambda d: (d.name, d.multi_id))
    names = stream_names([(d.name, d.multi_id) for d in data])
    if len(set(names)) != len(names):  # two formats of one topic instance (never seen)
        counts = Counter(names)
        names = [f"{n}#{i}" if counts[n] > 1 else n for i, n in enumerate(names)]
    found = [Stream(name, _columns(d)) for name, d in zip(names, data, strict=True)]
    return streams(path, found, "ulog", ".", _metadata(log))


def sniff(head: bytes) -> bool:
    """True for the ULog magic."""
    return head.startswith(MAGIC)


FORMAT = Format("ulog", (".ulg",), read_ulog, sniff,
                description="PX4 ULog flight log, a stream per topic instance (pyulog)")
