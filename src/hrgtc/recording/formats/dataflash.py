"""ArduPilot DataFlash logs (``.bin``), read with pymavlink's DFReader
(``pip install 'hrgtc[ardupilot]'``).

A DataFlash log is a sequence of messages, each type declared by an ``FMT`` message and
logged at its own rate. Each message type is one stream (``IMU``, ``IMU2``, ``GYR``,
``BARO``), a type with an instance field (``IMU`` of ArduPilot 4.x, whose ``I`` field
says which IMU) one stream per instance, named as ArduPilot's tools name them
(``IMU[0]``, ``IMU[1]``). Its ``TimeUS`` (µs since boot) is ``time_s`` (seconds); its
numeric fields are columns named ``<stream>.<field>`` (``IMU.GyrX``, ``IMU[1].T``), read
when the column mapping names them (text fields and messages without ``TimeUS`` are left
out). DFReader applies the log's multipliers, so values are in the units of the log's
``UNIT`` messages: the ``IMU`` gyro rates ``GyrX/GyrY/GyrZ`` in rad/s (``--rate-unit
radps``), its temperature ``T`` in °C::

    hrgtc info flight.bin --col rate_dph=IMU.GyrZ --col temperature_c=IMU.T \\
        --rate-unit radps --thermometer sensor
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any

import numpy as np

from hrgtc.core.errors import HrgtcWarning
from hrgtc.recording.formats.base import Format, Source
from hrgtc.recording.formats.logs import (
    Stream,
    check_exists,
    quiet,
    require,
    streams,
    unreadable,
)

#: The head of every DataFlash message: 0xA3 0x95, then the message id (128: FMT first).
HEAD = b"\xa3\x95"
#: µs per s of ``TimeUS``.
TIMESTAMP_UNIT_S = 1e-6


def stream_name(message: Any) -> str:
    """``IMU``, or ``IMU[1]`` for a message type with an instance field."""
    name = message.get_type()
    field = getattr(message.fmt, "instance_field", None)
    return name if field is None else f"{name}[{getattr(message, field)}]"


def _collect(reader: Any) -> tuple[dict[str, dict[str, list[Any]]], list[str]]:
    """Every message with ``TimeUS``, by stream: field -> values; and the ``MSG`` texts."""
    tables: dict[str, dict[str, list[Any]]] = {}
    texts: list[str] = []
    while True:
        message = reader.recv_msg()
        if message is None:
            return tables, texts
        kind = message.get_type()
        if kind == "MSG":
            texts.append(str(getattr(message, "Message", "")))
        fields = message.get_fieldnames()
        if "TimeUS" not in fields or kind == "BAD_DATA":
            continue
        table = tables.setdefault(stream_name(message), {name: [] for name in fields})
        if len(table) != len(fields):  # a type redefined mid-log: keep the first layout
            continue
        for name in fields:
            table[name].append(getattr(message, name, None))


def _columns(table: dict[str, list[Any]]) -> dict[str, np.ndarray]:
    columns = {"time_s": np.asarray(table["TimeUS"], dtype=np.float64) * TIMESTAMP_UNIT_S}
    for name, values in table.items():
        if name == "TimeUS" or not all(isinstance(v, int | float) for v in values):
            continue
        columns[name] = np.asarray(values, dtype=np.float64)
    return columns


def read_dataflash(path: Path) -> list[Source]:
    """The message types of a DataFlash log, one stream each (one per instance)."""
    check_exists(path)
    DFReader = require("pymavlink.DFReader", "ardupilot", "DataFlash", path)
    with open(path, "rb") as handle:
        head = handle.read(3)
    if not sniff(head):
        raise unreadable(path, "DataFlash", ValueError(
            f"the file starts with {head!r}, not a DataFlash message (0xA3 0x95 0x80)"),
            "is it an ArduPilot .bin log (a .tlog is a MAVLink telemetry log)?")
    failure: Exception | None = None
    with quiet() as said:
        try:
            reader = DFReader.DFReader_binary(str(path), zero_time_base=False)
            tables, texts = _collect(reader)
        except Exception as exc:  # DFReader raises what its parsing meets
            failure = exc
    bad = [line for line in said if "bad" in line.lower() or "unknown msg" in line.lower()]
    if failure is None and bad:
        failure = ValueError(f"{bad[-1]} ({len(bad)} such report(s))")
    if failure is not None:
        raise unreadable(path, "DataFlash", failure, "download the log from the flight "
                         "controller again")
    firmware = next((t for t in texts if t.startswith(("Ardu", "APM"))), None)
    # a log whose logger stopped inside a message (power off) ends with a part of one:
    # read up to the last whole message, as mavlogdump does, and say how many bytes were left
    left = int(reader.data_len - reader.offset)
    extra: dict[str, Any] = {"dataflash_messages": texts[:20],
                             "dataflash_trailing_bytes": left}
    if left:
        warnings.warn(f"{path}: the log ends inside a message ({left} byte(s) after the last "
                      "whole one: the logger stopped while writing); read up to the last whole "
                      "message", HrgtcWarning, stacklevel=2)
    if firmware:
        extra["firmware"] = firmware
    found = [Stream(name, _columns(table)) for name, table in sorted(tables.items())]
    return streams(path, found, "dataflash", ".", {"extra": extra})


def sniff(head: bytes) -> bool:
    """True for a file that starts with a DataFlash ``FMT`` message."""
    return head[:3] == HEAD + b"\x80"


FORMAT = Format("dataflash", (".bin",), read_dataflash, sniff,
                description="ArduPilot DataFlash log, a stream per message type (pymavlink)")
