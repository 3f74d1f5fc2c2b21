"""Random corruptions of valid inputs and the judge of what the CLI did with them (issue 11).

A case is one corruption of a small valid recording (CSV or Parquet) or of a valid
model file, given to ``hrgtc compensate`` in-process. The outcome is one of:

* ``"error"``: exit 2, one line on standard error that names the file and says what
  is wrong (a column and row for data, a place for a model file), no traceback and
  no "internal error";
* ``"correct"``: exit 0, and the output equals the compensation of the file's
  content read by an independent parser (Python's ``csv`` module, pyarrow without
  hrgtc; repeated rows dropped, as reading does) with the numpy engine; for a model
  file, the output equals the one of the uncorrupted model (the corruption touched a
  statistic);
* anything else is a failure, described by a string.

Used by ``tests/cli/test_fuzz.py`` (bounded, derandomized) and ``bench/fuzz_report.py``
(more cases, counts for the record).
"""

from __future__ import annotations

import csv
import io
import json
import math
import traceback
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
from hypothesis import strategies as st
from typer.testing import CliRunner

from hrgtc import drift
from hrgtc.cli import app
from hrgtc.compensate import Compensator
from hrgtc.model import AxisModel, Model, save_model
from hrgtc.recording import Metadata, Recording, write

from synthetic import THERMOMETER, ramp_run

COLUMNS = ("time_s", "freq_hz", "rate_dph", "chamber_c")
REQUIRED = COLUMNS[:3]
runner = CliRunner()


def make_model() -> Model:
    """A model of the synthetic unit at 10 Hz (cool-down 20 -> -20 °C), with the statistics
    of its training data as ``calibrate`` writes them (the noise-ratio unit checks use them)."""
    from hrgtc.drift.training import TrainingStatistics

    run = ramp_run(seed=11, hours=3.0)
    return Model.single(
        AxisModel(thermometer=THERMOMETER, drift=drift.fit([run], THERMOMETER),
            training=TrainingStatistics.from_runs([run])), unit="FZ-1")


def make_run(rows: int = 1200) -> Recording:
    """A short run inside the model's ranges (2 min at 10 Hz, one column each)."""
    run = ramp_run(seed=3, start_c=10.0, end_c=5.0, hours=rows / 36000.0)
    return Recording({k: run[k] for k in COLUMNS}, run.metadata)


class Fixture:
    """The valid files of the fuzz test, written once into ``folder``."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        self.model = make_model()
        self.run = make_run()
        self.model_path = save_model(self.model, folder / "model.json", force=True)
        self.model_text = self.model_path.read_text()
        self.csv_path = write(self.run, folder / "run.csv", force=True)
        self.csv_text = self.csv_path.read_text()
        self.parquet_path = write(self.run, folder / "run.parquet", force=True)
        self.parquet_bytes = self.parquet_path.read_bytes()
        self.expected = Compensator(self.model, engine="numpy").transform(self.run)


# -- corruptions ---------------------------------------------------------------------------
NASTY_VALUES = ("", "nan", "NaN", "inf", "-inf", "1e300", "-1e300", "0", "-1", "abc", "4.4e6",
                "1e-300", "0x10", "1,5", "  ", "+", "1e", "--1", "\u00e9", "1e308", "5e-324")


@st.composite
def csv_corruption(draw: Any, text: str) -> tuple[str | bytes, str]:
    """A corrupted copy of a CSV recording's text and the name of the corruption."""
    lines = text.split("\n")
    header = next(i for i, line in enumerate(lines) if not line.startswith("#"))
    data_rows = [i for i in range(header + 1, len(lines)) if lines[i]]
    kind = draw(st.sampled_from([
        "field", "field", "field", "scale", "delete_line", "duplicate_line", "swap_lines",
        "truncate", "cut_last_number", "flip_byte", "bad_utf8", "drop_column", "header",
        "metadata", "extra_field"]))
    if kind in ("field", "scale", "extra_field"):
        row = draw(st.sampled_from(data_rows))
        fields = lines[row].split(",")
        column = draw(st.integers(0, len(fields) - 1))
        if kind == "field":
            fields[column] = draw(st.sampled_from(NASTY_VALUES))
        elif kind == "scale":
            factor = draw(st.sampled_from([1000.0, 0.001, -1.0, 3600.0, 1 / 3600.0, 2.0]))
            fields[column] = repr(float(fields[column]) * factor)
        else:
            fields.insert(column, "1")
        lines[row] = ",".join(fields)
        return "\n".join(lines), f"{kind} {COLUMNS[min(column, 3)]} row {row - header - 1}"
    if kind == "delete_line":
        del lines[draw(st.sampled_from(data_rows))]
    elif kind == "duplicate_line":
        row = draw(st.sampled_from(data_rows))
        lines.insert(row, lines[row])
    elif kind == "swap_lines":
        a = draw(st.sampled_from(data_rows[:-1]))
        lines[a], lines[a + 1] = lines[a + 1], lines[a]
    elif kind == "truncate":
        return text[: draw(st.integers(0, len(text) - 1))], kind
    elif kind == "cut_last_number":
        body = text.rstrip("\n")
        return body[: -draw(st.integers(1, 6))], kind
    elif kind == "flip_byte":
        data = bytearray(text.encode())
        at = draw(st.integers(0, len(data) - 1))
        data[at] ^= 1 << draw(st.integers(0, 7))
        return bytes(data), kind
    elif kind == "bad_utf8":
        data = bytearray(text.encode())
        at = draw(st.integers(0, len(data) - 1))
        data[at:at] = b"\xff\xfe"
        return bytes(data), kind
    elif kind == "drop_column":
        column = draw(st.integers(0, 3))
        lines = [",".join(f for j, f in enumerate(line.split(",")) if j != column)
                 if not line.startswith("#") and line else line for line in lines]
    elif kind == "header":
        names = lines[header].split(",")
        names[draw(st.integers(0, len(names) - 1))] = draw(st.sampled_from(
            ["rate_comp_dph", "bias_model_dph", "", "time_s", "x"]))
        lines[header] = ",".join(names)
    elif kind == "metadata":
        row = draw(st.integers(0, header - 1))
        key = lines[row].split(":")[0]
        lines[row] = f"{key}: {draw(st.sampled_from(NASTY_VALUES))}"
    return "\n".join(lines), kind


@st.composite
def parquet_corruption(draw: Any, fixture: Fixture) -> tuple[bytes, str]:
    """A corrupted Parquet recording: flipped or cut bytes, or a nasty value in a column."""
    kind = draw(st.sampled_from(["value", "value", "value", "flip_bit", "flip_bit", "truncate",
                                 "scale_tail", "nan_run"]))
    data = fixture.parquet_bytes
    if kind == "flip_bit":
        raw = bytearray(data)
        at = draw(st.integers(0, len(raw) - 1))
        raw[at] ^= 1 << draw(st.integers(0, 7))
        return bytes(raw), f"flip_bit at byte {at}"
    if kind == "truncate":
        return data[: draw(st.integers(0, len(data) - 1))], kind
    columns = {k: np.array(fixture.run[k]) for k in COLUMNS}
    name = draw(st.sampled_from(COLUMNS))
    row = draw(st.integers(0, len(fixture.run) - 1))
    if kind == "value":
        columns[name][row] = draw(st.sampled_from(
            [math.nan, math.inf, -math.inf, 1e300, -1e300, 0.0, -1.0, 4.4e6,
             columns[name][row] * 1000.0, columns[name][row] / 1000.0,
             columns[name][row] + 1e-9, 5e-324]))
    elif kind == "scale_tail":
        factor = draw(st.sampled_from([1000.0, 1 / 3600.0, 0.5, 2.0]))
        columns[name][row:] = columns[name][row:] * factor
    else:
        columns[name][row: row + draw(st.integers(1, 50))] = math.nan
    table = pa.table(columns, metadata={b"hrgtc": json.dumps(
        fixture.run.metadata.to_dict()).encode()})
    sink = io.BytesIO()
    pq.write_table(table, sink, write_page_checksum=True)
    return sink.getvalue(), f"{kind} {name} row {row}"


def _leaves(value: Any, path: tuple = ()) -> list[tuple]:
    if isinstance(value, dict):
        return [p for k, v in value.items() for p in _leaves(v, (*path, k))] + [path]
    if isinstance(value, list):
        return [p for i, v in enumerate(value) for p in _leaves(v, (*path, i))] + [path]
    return [path]


@st.composite
def model_corruption(draw: Any, text: str) -> tuple[str | bytes, str]:
    """A corrupted model file: a leaf set to a nasty value or removed, or bytes cut/flipped."""
    kind = draw(st.sampled_from(["leaf", "leaf", "leaf", "leaf", "delete", "truncate",
                                 "flip_byte", "version"]))
    if kind == "truncate":
        return text[: draw(st.integers(0, len(text) - 1))], kind
    if kind == "flip_byte":
        raw = bytearray(text.encode())
        at = draw(st.integers(0, len(raw) - 1))
        raw[at] ^= 1 << draw(st.integers(0, 7))
        return bytes(raw), kind
    data = json.loads(text)
    if kind == "version":
        data["schema_version"] = draw(st.sampled_from([0, 1, 3, "2", None, 2.5]))
        return json.dumps(data), f"version {data['schema_version']!r}"
    paths = [p for p in _leaves(data) if p and p[0] not in ("provenance", "plateaus")]
    path = draw(st.sampled_from(paths))
    parent = data
    for key in path[:-1]:
        parent = parent[key]
    if kind == "delete":
        if isinstance(parent, list):
            parent.pop(path[-1])
        else:
            del parent[path[-1]]
    else:
        old = parent[path[-1]]
        parent[path[-1]] = draw(st.sampled_from(
            [math.nan, math.inf, -math.inf, 0.0, -1.0, 1e300, "x", None, [], {}, True,
             (-old if isinstance(old, float) else 7), (old * 1.5 if isinstance(old, float)
                                                       else "f^9")]))
    return json.dumps(data, allow_nan=True), f"{kind} {'.'.join(map(str, path))}"


# -- judging ------------------------------------------------------------------------------
def _independent_csv(path: Path) -> dict[str, np.ndarray]:
    with open(path, encoding="utf-8") as handle:
        rows = [line for line in handle if not line.startswith("#") and line.strip()]
    table = list(csv.reader(rows))
    header, body = table[0], table[1:]
    return {name: np.array([float(r[header.index(name)]) for r in body])
            for name in COLUMNS if name in header or name in REQUIRED}


def _independent_parquet(path: Path) -> dict[str, np.ndarray]:
    table = pq.read_table(path)
    return {name: table.column(name).to_numpy() for name in COLUMNS
            if name in table.column_names or name in REQUIRED}


def clear_error(message: str, path: Path) -> str | None:
    """None if ``message`` is a clear one-line error about ``path``, else what is wrong."""
    if "Traceback" in message or "internal error" in message:
        return "traceback or internal error"
    if not message.startswith("error:"):
        return "no 'error:' line"
    if path.name not in message and str(path) not in message:
        return "the file is not named"
    return None


def run_compensate(run: Path, model: Path, output: Path) -> Any:
    if output.exists():
        output.unlink()
    return runner.invoke(app, ["compensate", str(run), "-m", str(model), "-o", str(output),
                               "--json"])


def judge_data(fixture: Fixture, run: Path) -> str:
    """Outcome of compensating a corrupted recording ``run`` with the valid model."""
    output = run.with_name("out.parquet")
    try:
        result = run_compensate(run, fixture.model_path, output)
    except BaseException:  # the runner catches everything; this is a last resort
        return "other: runner raised " + traceback.format_exc(limit=1)
    if result.exit_code == 2:
        problem = clear_error(result.stderr.strip(), run)
        return "error" if problem is None else f"other: {problem}: {result.stderr[:300]!r}"
    if result.exit_code != 0:
        return f"other: exit {result.exit_code}: {result.exception!r} {result.stderr[:300]!r}"
    try:
        columns = (_independent_csv(run) if run.suffix == ".csv" else _independent_parquet(run))
    except (ValueError, KeyError, IndexError, UnicodeDecodeError, OSError, pa.ArrowException) \
            as exc:
        return f"other: exit 0 but an independent parser fails: {str(exc)[:200]}"
    # a repeated row (same time, same values) is dropped on reading (hrgtc.core.time_steps)
    stacked = np.column_stack(list(columns.values()))
    repeated = np.r_[False, np.all(stacked[1:] == stacked[:-1], axis=1)]
    columns = {name: values[~repeated] for name, values in columns.items()}
    truth = Compensator(fixture.model, engine="numpy").transform(
        Recording(columns, Metadata(**{**fixture.run.metadata.to_dict()})))
    out = pq.read_table(output)
    for name in ("rate_comp_dph", "bias_model_dph", "in_range"):
        got = out.column(name).to_numpy()
        if got.shape != truth[name].shape or not np.allclose(got, truth[name], rtol=1e-9,
                                                             atol=1e-9):
            return f"other: exit 0 with wrong {name}"
    return "correct"


def judge_model(fixture: Fixture, model: Path) -> str:
    """Outcome of compensating the valid run with a corrupted model file ``model``."""
    output = model.with_name("out.parquet")
    result = run_compensate(fixture.parquet_path, model, output)
    if result.exit_code == 2:
        problem = clear_error(result.stderr.strip(), model)
        if problem is not None and "model" not in result.stderr:
            return f"other: {problem}: {result.stderr[:300]!r}"
        return "error"
    if result.exit_code != 0:
        return f"other: exit {result.exit_code}: {result.exception!r} {result.stderr[:300]!r}"
    out = pq.read_table(output)
    for name in ("rate_comp_dph", "bias_model_dph", "in_range", "resonator_c_est"):
        got = out.column(name).to_numpy()
        want = fixture.expected[name]
        if not np.allclose(got, want, rtol=1e-12, atol=1e-12, equal_nan=True):
            return f"other: exit 0 with a different {name}"
    return "correct"


def write_case(folder: Path, name: str, content: str | bytes) -> Path:
    path = folder / name
    if isinstance(content, str):
        path.write_text(content, encoding="utf-8")
    else:
        path.write_bytes(content)
    return path
