"""Plausible-looking corruptions of recordings and model files, each with its expected outcome.

Issue 21, Deliver 7: the fuzzing of issue 11 (``tests/fuzzing.py``) damages bytes and
values in ways a reader sees at once (NaN, 1e300, a cut line). The damage users make
keeps every value plausible: a rate logged in °/s declared °/h (×3600), rad/s (×57.3),
m°/h (×1000); time in ms; an axis column dropped, or stored as an (N, 3) matrix; two
headers swapped; a model of another unit, another rate unit or another axis set; a
compensated file given back as training input; bursts and gaps. This module is the
GENERATOR of such a corpus (the corpus itself is not committed): :func:`recording_cases`
and :func:`model_cases` list :class:`Case` objects, each of which writes its files into
a folder and says, per command, what must happen:

* ``Expect("error", names)``: exit 2 and one ``error:`` line naming the file and every
  string of ``names`` (the column, the row, the option of the fix);
* ``Expect("correct")``: exit 0 and the same result as the undamaged file (a layout
  that reads the same: CRLF, a byte-order mark, a trailing delimiter, ...); its
  ``names``, if any, must appear in the output (a spike dropped and counted).

``owner`` names who fixes a class the main branch gets wrong (``relread`` this work;
``relmodel`` unit plausibility, absurd coefficients, model/recording axis mismatch;
``time`` ms/µs time diagnosis). ``detectable=False`` marks the cases the docs name as
impossible to tell from a valid file (a larger rate unit in ``calibrate --thermometer
sensor``). :mod:`audit` (``bench/audit.py``) runs them all and counts the outcomes.
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from hrgtc.model import Model, save_model
from hrgtc.recording import Recording, write

from fuzzing import make_model
from synthetic import ramp_run

RECORDING_COMMANDS = ("info", "compensate", "evaluate", "calibrate")
MODEL_COMMANDS = ("compensate", "evaluate", "export-c", "export-params", "report")
FORMATS = (".csv", ".parquet", ".h5")


@dataclass(frozen=True)
class Expect:
    """What a command must do with a case: ``"error"`` naming ``names``, or ``"correct"``."""

    outcome: str
    names: tuple[str, ...] = ()
    code: int = 2
    detectable: bool = True
    compare: bool = True  # "correct": the result equals the undamaged file's


@dataclass(frozen=True)
class Case:
    """One corrupted input: ``make(material, folder)`` writes it and returns its path."""

    name: str
    family: str
    target: str  # "recording" or "model"
    make: Callable[[Material, Path], Path]
    expect: dict[str, Expect]
    owner: str = "main"
    axes: str = "1"  # the recording the case is run with ("1" or "3" axes)

    def expected(self, command: str) -> Expect | None:
        return self.expect.get(command, self.expect.get("*"))


def error(*names: str, detectable: bool = True) -> Expect:
    return Expect("error", tuple(names), detectable=detectable)


CORRECT = Expect("correct")


# -- the undamaged material -----------------------------------------------------------------
def base_run(axes: str = "1") -> Recording:
    """A 15-min cool-down at 10 Hz (2.4 °C) inside the model's ranges, with a sensor temperature."""
    run = ramp_run(seed=3, start_c=10.0, end_c=0.0, hours=0.25, ramp_hours=0.5, tau_s=600.0)
    columns = {"time_s": run["time_s"]}
    if axes == "1":
        columns |= {"freq_hz": run["freq_hz"], "rate_dph": run["rate_dph"]}
    else:
        rng = np.random.default_rng(7)
        for axis in "xyz":
            columns[f"freq_hz_{axis}"] = run["freq_hz"]
            columns[f"rate_dph_{axis}"] = run["rate_dph"] + rng.normal(0.0, 0.5, len(run))
    columns |= {"chamber_c": run["chamber_c"], "temperature_c": run["resonator_c"] + 0.3}
    return Recording(columns, run.metadata)


class Material:
    """The valid files every case starts from, written once into ``folder``."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        folder.mkdir(parents=True, exist_ok=True)
        self.model = make_model()
        self.model_path = save_model(self.model, folder / "model.json", force=True)
        instrument = Model({a: self.model.axis for a in "xyz"}, unit="FZ-3")
        self.model3_path = save_model(instrument, folder / "model3.json", force=True)
        self.runs = {axes: base_run(axes) for axes in ("1", "3")}
        self.paths = {(axes, fmt): write(run, folder / f"run{axes}{fmt}", force=True)
                      for axes, run in self.runs.items() for fmt in FORMATS}

    def run_path(self, axes: str) -> Path:
        return self.paths[(axes, ".parquet")]

    def model_for(self, axes: str) -> Path:
        return self.model_path if axes == "1" else self.model3_path


# -- writing damaged recordings --------------------------------------------------------------
def _write(columns: dict[str, np.ndarray], run: Recording, path: Path) -> Path:
    return write(Recording(columns, run.metadata), path, force=True)


def _columns(run: Recording) -> dict[str, np.ndarray]:
    return {k: np.array(run[k]) for k in run.names}


def _per_axis(name: str, axes: str) -> list[str]:
    return [name] if axes == "1" else [f"{name}_{a}" for a in "xyz"]


def scaled(column: str, factor: float, fmt: str, axes: str) -> Callable:
    """Every ``column`` (per axis) multiplied by ``factor``: a wrong unit, values plausible."""
    def make(material: Material, folder: Path) -> Path:
        run = material.runs[axes]
        columns = _columns(run)
        for name in _per_axis(column, axes) if column != "time_s" else ["time_s"]:
            columns[name] = columns[name] * factor
        return _write(columns, run, folder / f"case{fmt}")
    return make


def edited(change: Callable[[dict[str, np.ndarray]], dict[str, np.ndarray]], fmt: str,
           axes: str, metadata: dict | None = None) -> Callable:
    """The columns changed by ``change`` (drop, rename, insert a gap, ...)."""
    def make(material: Material, folder: Path) -> Path:
        run = material.runs[axes]
        meta = dataclasses.replace(run.metadata, **(metadata or {}))
        return write(Recording(change(_columns(run)), meta), folder / f"case{fmt}", force=True)
    return make


def renamed(pairs: dict[str, str]) -> Callable:
    def change(columns: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        return {pairs.get(k, k): v for k, v in columns.items()}
    return change


def dropped(*names: str) -> Callable:
    return lambda columns: {k: v for k, v in columns.items() if k not in names}


def rows_removed(start: int, stop: int) -> Callable:
    return lambda columns: {k: np.delete(v, np.s_[start:stop]) for k, v in columns.items()}


def bursts(on_s: float, every_s: float) -> Callable:
    def change(columns: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        keep = (columns["time_s"] % every_s) < on_s
        return {k: v[keep] for k, v in columns.items()}
    return change


def value_at(name: str, row: int, value: float) -> Callable:
    def change(columns: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        columns[name][row] = value
        return columns
    return change


def time_at(row: int, how: str) -> Callable:
    def change(columns: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        t = columns["time_s"]
        t[row] = t[row - 1] if how == "duplicate" else t[row - 1] - 0.05
        return columns
    return change


def csv_text(change: Callable[[str], str | bytes], axes: str) -> Callable:
    """The CSV file's text changed by ``change`` (line ends, delimiters, header)."""
    def make(material: Material, folder: Path) -> Path:
        text = material.paths[(axes, ".csv")].read_text()
        out = change(text)
        path = folder / "case.csv"
        (path.write_bytes if isinstance(out, bytes) else path.write_text)(out)
        return path
    return make


def _header_index(lines: list[str]) -> int:
    return next(i for i, line in enumerate(lines) if not line.startswith("#"))


def on_lines(change: Callable[[list[str], int], list[str]]) -> Callable[[str], str]:
    def apply(text: str) -> str:
        lines = text.split("\n")
        return "\n".join(change(lines, _header_index(lines)))
    return apply


def swap_header(a: str, b: str) -> Callable[[str], str]:
    def change(lines: list[str], h: int) -> list[str]:
        names = lines[h].split(",")
        i, j = names.index(a), names.index(b)
        names[i], names[j] = names[j], names[i]
        return [*lines[:h], ",".join(names), *lines[h + 1:]]
    return on_lines(change)


def hdf5_dataset(name: str, shape: str, axes: str) -> Callable:
    """An HDF5 recording whose ``name`` is a matrix, a column vector, a scalar or a table."""
    def make(material: Material, folder: Path) -> Path:
        path = write(material.runs[axes], folder / "case.h5", force=True)
        with h5py.File(path, "a") as handle:
            group = handle["recording"]
            if shape == "compound":
                names = list(group)
                table = np.zeros(len(group[names[0]]), dtype=[(n, "f8") for n in names])
                for n in names:
                    table[n] = group[n][:]
                del handle["recording"]
                handle["recording"] = table
                return path
            values = group[name][:]
            del group[name]
            group[name] = {"n3": np.stack([values] * 3, axis=1), "n1": values[:, None],
                           "scalar": np.float64(values[0])}[shape]
        return path
    return make


def parquet_list_column(name: str, axes: str) -> Callable:
    def make(material: Material, folder: Path) -> Path:
        run = material.runs[axes]
        arrays = {k: pa.array(run[k]) for k in run.names}
        values = run[name]
        arrays[name] = pa.FixedSizeListArray.from_arrays(pa.array(np.repeat(values, 3)), 3)
        table = pa.table(arrays, metadata={b"hrgtc": json.dumps(run.metadata.to_dict()).encode()})
        pq.write_table(table, folder / "case.parquet")
        return folder / "case.parquet"
    return make


def compensated(fmt: str, axes: str) -> Callable:
    """The compensation of the run (by the library), as a file a user could train on."""
    def make(material: Material, folder: Path) -> Path:
        from hrgtc.compensate import compensate_file
        from hrgtc.model import load_model

        path = folder / f"case{fmt}"
        path.unlink(missing_ok=True)
        compensate_file(material.paths[(axes, fmt)], path,
                        load_model(material.model_for(axes)), force=True)
        return path
    return make


# -- the recording cases ---------------------------------------------------------------------
EITHER = Expect("either")  # info describes what it reads: exit 0, or a clear error
ROWS = (0, 1234, 4321, 8999)


def _first(name: str, axes: str) -> str:
    return name if axes == "1" else f"{name}_x"


def _values_cases(axes: str, fmt: str) -> list[Case]:
    """A non-finite or absurd value in one row of one column: the column and row named."""
    cases = []
    tag = f"{axes}-axis {fmt}"
    names = [_first("freq_hz", axes), _first("rate_dph", axes), "time_s", "temperature_c",
             "chamber_c"]
    for name in names:
        for row in ROWS:
            for value, label in ((np.nan, "NaN"), (np.inf, "inf"), (1e300, "1e300")):
                if name == "time_s" and label != "NaN" and row != ROWS[-1]:
                    continue  # a huge time inside the file is a step back, checked below
                expect = {"*": error(name, f"row {row}"), "info": EITHER}
                if name.startswith("freq_hz"):  # calibrate --thermometer sensor reads no freq
                    expect["calibrate"] = EITHER
                cases.append(Case(f"{label} in {name} row {row} / {tag}", "values", "recording",
                                  edited(value_at(name, row, value), fmt, axes), expect,
                                  axes=axes))
    for row in (1, 4500, 8999):
        for how in ("duplicate", "back"):
            cases.append(Case(f"time {how} at row {row} / {tag}", "time order", "recording",
                              edited(time_at(row, how), fmt, axes),
                              {"*": error("time_s", f"row {row}"), "info": EITHER}, axes=axes))
    return cases


def recording_cases() -> list[Case]:
    """Every recording case (≥ 600), in a fixed order."""
    cases: list[Case] = []
    for axes in ("1", "3"):
        rate, freq = _first("rate_dph", axes), _first("freq_hz", axes)
        for fmt in FORMATS:
            tag = f"{axes}-axis {fmt}"

            def add(name: str, family: str, make: Callable, expect: dict[str, Expect],
                    owner: str = "main", tag: str = tag, axes: str = axes,
                    cases: list[Case] = cases) -> None:
                cases.append(Case(f"{name} / {tag}", family, "recording", make, expect, owner,
                                  axes))

            for factor, unit in ((3600.0, "°/s"), (180 / np.pi, "rad/s"), (1000.0, "m°/h")):
                # calibrate --thermometer sensor too: the file logs freq_hz, an HRG's
                # rate has no MEMS noise (issue 27)
                add(f"rate x{factor:.4g} (logged in {unit})", "unit up",
                    scaled("rate_dph", factor, fmt, axes),
                    {"*": error(rate), "info": EITHER,
                     "calibrate": error(rate, "freq_hz")}, owner="relmodel")
            if axes == "3":  # one channel of the three misconfigured
                for factor in (3600.0, 180 / np.pi, 1000.0):
                    add(f"rate_dph_y x{factor:.4g} only", "unit up",
                        edited(lambda c, f=factor: c | {"rate_dph_y": c["rate_dph_y"] * f},
                               fmt, axes),
                        {"*": error("rate_dph_y"), "info": EITHER,
                         "calibrate": error("rate_dph_y", "freq_hz_y")}, owner="relmodel")
            add("rate x1/3600 (logged in °/h, declared °/s)", "unit down",
                scaled("rate_dph", 1 / 3600.0, fmt, axes),
                {"*": error(rate, "--rate-unit"), "info": EITHER})
            # 0.17 °/h of bias and 0.03 °/h of noise: a good HRG's figures; only the model's
            # training noise can tell (the noise ratio of issue 21's Deliver 2)
            add("rate in rad/h (x1/57.3)", "unit down",
                scaled("rate_dph", np.pi / 180, fmt, axes),
                {"*": error(rate), "info": EITHER,
                 "calibrate": error(rate, detectable=False)}, owner="relmodel")
            add("freq in kHz", "freq unit", scaled("freq_hz", 1e-3, fmt, axes),
                {"*": error(freq, "--freq-unit kHz"), "info": EITHER, "calibrate": EITHER})
            add("freq x1000", "freq unit", scaled("freq_hz", 1e3, fmt, axes),
                {"*": error(freq), "info": EITHER, "calibrate": EITHER})
            add("freq +300 Hz (another unit)", "another unit",
                scaled("freq_hz", 1.0 + 300.0 / 4428.0, fmt, axes),
                {"*": error(freq), "info": EITHER, "calibrate": EITHER})
            for factor, unit in ((1e3, "ms"), (1e6, "us")):
                add(f"time in {unit}", "time unit", scaled("time_s", factor, fmt, axes),
                    {"*": error("time_s", f"--time-unit {unit}"), "info": EITHER},
                    owner="time")
            for factor in (10.0, 0.1):
                add(f"sample_rate_hz x{factor:g} in the metadata", "rate metadata",
                    edited(lambda c: c, fmt, axes, {"sample_rate_hz": 10.0 * factor}),
                    {"*": error("time_s"), "info": EITHER}, owner="time")
            for start, stop, row in ((100, 150, 100), (7000, 7600, 7000)):
                add(f"rows {start}-{stop} missing (a gap)", "gaps",
                    edited(rows_removed(start, stop), fmt, axes),
                    {"*": error("time_s", f"row {row}", "--gaps split"), "info": EITHER})
            # 0.4 s: a dropout (issue 27): bridged, counted and said, never refused
            add("rows 4000-4003 missing (a dropout)", "gaps",
                edited(rows_removed(4000, 4003), fmt, axes),
                {"*": Expect("correct", ("dropout",), compare=False)})
            for row in (3000, 6000):  # a new run (issue 20), named at its row
                add(f"time restarts at 0 at row {row} (logger restart)", "time order",
                    edited(lambda c, r=row: c | {"time_s": np.concatenate(
                        [c["time_s"][:r], c["time_s"][r:] - c["time_s"][r]])}, fmt, axes),
                    {"*": Expect("correct", ("time_s", f"row {row}", "restarts"),
                                 compare=False), "info": EITHER}, owner="time")
            add("rows 3000-3100 written twice", "time order",
                edited(lambda c: {k: np.concatenate([v[:3100], v[3000:]]) for k, v in c.items()},
                       fmt, axes), {"*": CORRECT, "info": EITHER})  # dropped and counted
            add("the run joined to itself", "time order",
                edited(lambda c: {k: np.concatenate([v, v]) for k, v in c.items()}, fmt, axes),
                # time back to its start: a restart read as a new segment (issue 20), or
                # a step back named at its row (evaluate and calibrate on Parquet/HDF5 today)
                {"*": Expect("error_or_same", ("time_s", "row 9000"), compare=False),
                 "info": EITHER}, owner="time")
            add("temperature_c a raw count (x100 + 2000)", "temperature unit",
                edited(lambda c: c | {"temperature_c": c["temperature_c"] * 100 + 2000}, fmt,
                       axes), {"*": error("temperature_c", "--temp-scale"), "info": EITHER})
            # one sample 6 % off both neighbours: a spike (not a step), which evaluate's
            # default --spike-filter drop removes and must count (docs/reliability-reading.md)
            add("freq glitch of 6 % at row 2500", "values",
                edited(value_at(freq, 2500, 4428.0 * 1.06), fmt, axes),
                {"*": error(freq, "row 2500"), "info": EITHER, "calibrate": EITHER,
                 "evaluate": Expect("correct", ('"spikes": 1',), compare=False)})
            add("rate offset 4 °/s (a MEMS gyro's bias)", "level", edited(
                lambda c: c | {k: v + 4 * 3600.0 for k, v in c.items() if k.startswith("rate")},
                fmt, axes), {"*": Expect("correct", compare=False)}, owner="relmodel")
            add("rate table at 100 °/s (input_rate_dph in the metadata)", "level", edited(
                lambda c: c | {k: v + 360000.0 for k, v in c.items() if k.startswith("rate")},
                fmt, axes, {"input_rate_dph": 10.0 + 360000.0}),
                {"*": Expect("correct", compare=False)}, owner="relmodel")
            add("one row missing (2 periods: not a gap)", "gaps",
                edited(rows_removed(5000, 5001), fmt, axes),
                {"*": Expect("correct", compare=False)})
            # a duty-cycled logger's file: its gaps are bridged by default (a GapWarning
            # says so; no row is left out) (issue 27: the cold test needed --gaps bridge)
            add("bursts of 5 s every 30 s", "gaps", edited(bursts(5.0, 30.0), fmt, axes),
                {"*": Expect("correct", compare=False),
                 "info": Expect("either", compare=False)})
            add("compensated file", "compensated", compensated(fmt, axes),
                {"*": error("already compensated"), "info": Expect("either", compare=False)},
                owner="relread")
            swaps = {"freq_hz/rate_dph": ((freq, rate), (freq, rate), "relread"),
                     "time_s/rate_dph": (("time_s", rate), ("time_s",), "main"),
                     "rate_dph/temperature_c": ((rate, "temperature_c"), (rate,), "relmodel")}
            for label, ((a, b), names, owner) in swaps.items():
                # calibrate --thermometer sensor too: the file's own freq_hz is checked
                # against the rate (issue 27)
                expect = {"*": error(*names), "info": EITHER}
                add(f"headers {label} swapped", "swapped headers",
                    edited(renamed({a: b, b: a}), fmt, axes), expect, owner=owner)
            add("headers chamber_c/temperature_c swapped", "swapped headers",
                edited(renamed({"chamber_c": "temperature_c", "temperature_c": "chamber_c"}),
                       fmt, axes),
                # calibrate --thermometer sensor: the set-point is a noise-free ramp (issue 27)
                {"*": CORRECT, "calibrate": error("temperature_c", "chamber_c", "swapped")})
            if fmt == ".h5":
                for name, shape in ((rate, "n3"), (rate, "n1"), (freq, "scalar"),
                                    ("time_s", "n1"), (rate, "compound")):
                    shown = "recording" if shape == "compound" else name
                    add(f"{name} stored {shape}", "axis reshaped",
                        hdf5_dataset(name, shape, axes), {"*": error(shown)}, owner="relread")
            if fmt == ".parquet":
                add(f"{rate} a list column", "axis reshaped", parquet_list_column(rate, axes),
                    {"*": error(rate)})
            cases += _values_cases(axes, fmt)
            if axes == "3":
                for gone, named in (("rate_dph_z", "freq_hz_z"), ("rate_dph_y", "freq_hz_y"),
                                    ("freq_hz_y", "freq_hz_y")):
                    rate_gone = gone.startswith("rate")
                    add(f"{gone} dropped", "axis dropped", edited(dropped(gone), fmt, axes),
                        {"*": error(named), "info": error(named) if rate_gone else EITHER,
                         # the sensor thermometer reads no frequency column
                         "calibrate": error(named) if rate_gone else EITHER},
                        owner="relread" if rate_gone else "main")
                add("rate_dph_z renamed rate_z", "axis dropped",
                    edited(renamed({"rate_dph_z": "rate_z"}), fmt, axes),
                    {"*": error("freq_hz_z")}, owner="relread")
                add("axis z dropped whole (a 2-axis file, 3-axis model)", "axis dropped",
                    edited(dropped("rate_dph_z", "freq_hz_z"), fmt, axes),
                    {"*": error("z"), "info": Expect("correct", compare=False),
                     "calibrate": Expect("correct", compare=False)}, owner="relmodel")
        cases += _csv_layout_cases(axes)
    return cases + _second_audit_cases()


def hdf5_byte_strings(name: str, axes: str) -> Callable:
    """An HDF5 recording whose ``name`` holds its numbers as fixed-length byte strings,
    space-padded as MATLAB and Fortran write them (b'4428.27...   ')."""
    def make(material: Material, folder: Path) -> Path:
        path = write(material.runs[axes], folder / "case.h5", force=True)
        with h5py.File(path, "a") as handle:
            group = handle["recording"]
            values = group[name][:]
            del group[name]
            group[name] = np.array([repr(float(v)).ljust(32).encode() for v in values],
                                   dtype="S32")
        return path
    return make


def first_rows(count: int) -> Callable:
    return lambda columns: {k: v[:count] for k, v in columns.items()}


def on_data_line(row: int, change: Callable[[str], str]) -> Callable[[str], str]:
    """The CSV text with data row ``row`` (0 = the first after the header) changed."""
    return on_lines(lambda ls, h: [change(line) if i == h + 1 + row else line
                                   for i, line in enumerate(ls)])


def _second_audit_cases() -> list[Case]:
    """The cases of issue 27's independent audit (item 7) that the corpus lacked."""
    cases: list[Case] = []

    def add(name: str, family: str, make: Callable, expect: dict[str, Expect], axes: str,
            fmt: str) -> None:
        cases.append(Case(f"{name} / {axes}-axis {fmt}", family, "recording", make, expect,
                          "audit27", axes))

    for fmt in FORMATS:
        # a single-axis file with a stray per-axis rate: one axis x, or the plain rate?
        add("stray rate_dph_x beside rate_dph", "axis set", edited(
            lambda c: c | {"rate_dph_x": c["rate_dph"].copy()}, fmt, "1"),
            {"*": error("rate_dph", "rate_dph_x")}, "1", fmt)
        # a 3-axis file with a plain freq_hz beside freq_hz_x/y/z: whose is it?
        add("extra plain freq_hz", "axis set", edited(
            lambda c: c | {"freq_hz": c["freq_hz_x"].copy()}, fmt, "3"),
            {"*": error("freq_hz")}, "3", fmt)
        for count in (2, 5, 10):
            for axes in ("1", "3"):
                # compensate: the rows are compensated, whatever their number
                add(f"only {count} rows", "too short", edited(first_rows(count), fmt, axes),
                    {"*": error("too short"), "calibrate": error(f"{count} rows", "too short"),
                     "info": Expect("either", compare=False),
                     "compensate": Expect("correct", compare=False)}, axes, fmt)
    for axes in ("1", "3"):
        freq = _first("freq_hz", axes)
        add(f"{freq} as byte strings", "axis reshaped", hdf5_byte_strings(freq, axes),
            {"*": CORRECT}, axes, ".h5")
        add("upper-case header", "csv layout", csv_text(on_lines(lambda ls, h: [
            *ls[:h], ls[h].upper(), *ls[h + 1:]]), axes), {"*": CORRECT}, axes, ".csv")
        add("stray CR inside row 500", "csv layout", csv_text(on_data_line(
            500, lambda line: line.replace(",", ",\r", 1)), axes),
            {"*": error("row 500")}, axes, ".csv")
        add("stray quote in row 500", "csv layout", csv_text(on_data_line(
            500, lambda line: line.replace(",", ',"', 1)), axes),
            {"*": error("row 500")}, axes, ".csv")
    return cases


def _csv_layout_cases(axes: str) -> list[Case]:
    rate = _first("rate_dph", axes)
    tag = f"{axes}-axis .csv"
    layouts: list[tuple[str, Callable[[str], str | bytes], Expect, str]] = [
        ("CR-only line ends", lambda t: t.replace("\n", "\r"), error("carriage return"),
         "relread"),
        ("CRLF line ends", lambda t: t.replace("\n", "\r\n"), CORRECT, "main"),
        ("byte-order mark", lambda t: "\ufeff" + t, CORRECT, "main"),
        ("trailing delimiter", on_lines(lambda ls, h: [
            line + "," if i >= h and line else line for i, line in enumerate(ls)]), CORRECT,
         "relread"),
        ("semicolons", on_lines(lambda ls, h: [
            line.replace(",", ";") if i >= h else line for i, line in enumerate(ls)]), CORRECT,
         "main"),
        ("tabs", on_lines(lambda ls, h: [
            line.replace(",", "\t") if i >= h else line for i, line in enumerate(ls)]), CORRECT,
         "main"),
        ("spaces", on_lines(lambda ls, h: [
            line.replace(",", " ") if i >= h else line for i, line in enumerate(ls)]),
         error("separated by spaces"), "relread"),
        ("duplicated header name", on_lines(lambda ls, h: [
            *ls[:h], ls[h].replace("chamber_c", rate), *ls[h + 1:]]), error(rate), "relread"),
        ("header name missing", on_lines(lambda ls, h: [
            *ls[:h], ls[h].replace("chamber_c", ""), *ls[h + 1:]]), error("has no name"),
         "relread"),
        ("no header line", on_lines(lambda ls, h: [*ls[:h], *ls[h + 1:]]),
         error("column_1", "--col"), "main"),
        ("quoted header", on_lines(lambda ls, h: [
            *ls[:h], ",".join(f'"{n}"' for n in ls[h].split(",")), *ls[h + 1:]]), CORRECT,
         "main"),
        ("blank lines between rows", on_lines(lambda ls, h: [
            x for i, line in enumerate(ls) for x in ((line, "") if i > h + 500 and i % 997 == 0
                                                     else (line,))]), CORRECT, "main"),
    ]
    return [Case(f"{label} / {tag}", "csv layout", "recording", csv_text(change, axes),
                 {"*": expect}, owner, axes) for label, change, expect, owner in layouts]
