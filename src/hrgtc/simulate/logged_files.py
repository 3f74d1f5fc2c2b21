"""A logged run (:mod:`hrgtc.simulate.logger`) written to files, its truth beside it.

For ``run.csv`` (or ``.parquet``, ``.h5``) the files are:

* ``run.csv``: what the logger wrote, in its column names (the reading options of
  hrgtc have to be used: ``--col``, ``--time-unit``, ``--rate-unit``, ...); a CSV is
  written as loggers print (integer ms, rates to a few significant digits, empty cells);
  Parquet and HDF5 hold the same columns as float64, NaN for an empty cell (in HDF5 a
  ``/`` in a column name is written ``_per_``: ``/`` would make it a group);
* ``run.truth.json``: the sidecar (logger, unit, count map, spikes, segments, restarts,
  orientations, handling windows, true df/dt ranges, the hrgtc options that read the file);
* ``run.truth.csv``: the truth of every row (true time, run, segment, flags as
  ``true``/``false``, the simulator's truth columns), row for row with ``run.csv``;
* ``run_reflog.csv``: the hand-written reference log, when the logger has one.

Every file goes through a temporary file and a rename; nothing is overwritten
without ``force``.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from hrgtc.core import records
from hrgtc.core.errors import InputError
from hrgtc.core.files import (
    forget_temporary,
    fsync_file,
    publish,
    refuse_existing,
    temporary_beside,
    write_text_atomic,
)
from hrgtc.core.summary import Figure, Summary
from hrgtc.recording import Metadata, Recording, RecordingWriter
from hrgtc.recording.formats.registry import formats, is_recording, output_suffixes
from hrgtc.simulate.logger import LoggedRun, Logger, log_run
from hrgtc.simulate.output import output_paths
from hrgtc.simulate.profiles import Profile
from hrgtc.simulate.units import MultiAxisUnit, Unit

__all__ = [
    "LoggedFiles",

    "csv_text",
    "logged_summary",
    "sidecar_paths",
    "simulate_logged_files",
    "write_logged",
]


@dataclass(frozen=True)
class LoggedFiles(records.Written):
    """Paths written for a logged run.

    Attributes
    ----------
    path, truth_json, truth_csv
        The recording, its sidecar and its per-row truth.
    reference_log
        The hand-written reference log, or None.
    rows
        Rows of the recording.
    """

    path: str
    truth_json: str
    truth_csv: str
    reference_log: str | None
    rows: records.Count


def sidecar_paths(path: str | Path) -> dict[str, Path]:
    """Where the truth and the reference log of ``path`` go."""
    path = Path(path)
    stem = path.with_suffix("")
    return {
        "truth_json": Path(f"{stem}.truth.json"),
        "truth_csv": Path(f"{stem}.truth.csv"),
        "reference_log": Path(f"{stem}_reflog.csv"),
    }


def _format_column(values: np.ndarray, kind: str) -> list[str]:
    if kind == "str":
        return [str(x) for x in np.asarray(values).tolist()]
    v = np.asarray(values, dtype=np.float64)
    empty = ~np.isfinite(v)
    if kind == "int":
        text = list(map(str, np.where(empty, 0, v).astype(np.int64).tolist()))
    else:
        text = list(map(("{:" + kind.split(":", 1)[1] + "}").format,
                        np.where(empty, 0.0, v).tolist()))
    if empty.any():
        for i in np.flatnonzero(empty).tolist():
            text[i] = ""
    return text


def csv_text(columns: dict[str, np.ndarray], kinds: dict[str, str], newline: str = "\n") -> str:
    """A CSV text of the columns, each formatted as its kind (``int``, ``float:SPEC``)."""
    for name in columns:
        if "," in name or '"' in name or "\n" in name:
            raise InputError(f"column name {name!r} needs quoting; choose another name")
    formatted = [_format_column(v, kinds.get(name, "float:.17g")) for name, v in columns.items()]
    lines = [",".join(columns), *map(",".join, zip(*formatted, strict=True))]
    return newline.join(lines) + newline


def _write_table_csv(path: Path, columns: dict[str, np.ndarray], force: bool) -> Path:
    """The truth table as CSV (pyarrow's writer: fast on 10^5-10^6 rows), atomically."""
    import pyarrow as pa
    import pyarrow.csv as pa_csv

    refuse_existing(path, force)
    temporary = temporary_beside(path)
    try:
        pa_csv.write_csv(pa.table(dict(columns)), temporary)
        fsync_file(temporary)
        publish(temporary, path, force)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        forget_temporary(temporary)
        raise
    return path


def _hdf5_names(run: LoggedRun) -> LoggedRun:
    """The run with ``/`` in column names written ``_per_`` (HDF5 reads ``/`` as a group)."""
    rename = {name: name.replace("/", "_per_") for name in run.columns if "/" in name}
    if not rename:
        return run
    info = json.loads(json.dumps(run.info))
    info["columns"] = {role: rename.get(name, name) for role, name in info["columns"].items()}
    options = []
    for option in info["hrgtc_options"]:
        ours, _, theirs = option.partition("=")
        options.append(f"{ours}={rename[theirs]}" if theirs in rename else option)
    info["hrgtc_options"] = options
    return LoggedRun({rename.get(k, k): v for k, v in run.columns.items()},
                     {rename.get(k, k): v for k, v in run.kinds.items()},
                     run.truth, info, run.reference_log)


def write_logged(run: LoggedRun, path: str | Path, file_format: str | None = None,
                 force: bool = False) -> LoggedFiles:
    """Write a logged run, its truth and its reference log (see the module's docstring).

    Parameters
    ----------
    run
        From :func:`hrgtc.simulate.logger.log_run`.
    path
        The recording; its suffix gives the format unless ``file_format`` does.
    file_format
        ``csv``, ``parquet`` or ``h5``; None: from the suffix.
    force
        Overwrite existing files.

    Raises
    ------
    OutputExistsError
        When a target exists and ``force`` is False (nothing is written).
    """
    path = Path(path)
    suffix = path.suffix.lower()
    writers = output_suffixes()
    by_suffix = {s: f.output_name for f in formats() if f.output_name in writers
                 for s in f.suffixes}
    fmt = file_format or by_suffix.get(suffix)
    if fmt not in writers or (suffix in by_suffix and by_suffix[suffix] != fmt):
        raise InputError(f"output {path}: give a {', '.join(writers.values())} file (format "
                         f"{file_format!r} and suffix {suffix!r} must agree)")
    if fmt != "csv" and "str" in run.kinds.values():
        raise InputError(f"output {path}: wall-clock timestamps are written to CSV only; "
                         "give a .csv file or another time unit")
    if fmt == "h5":
        run = _hdf5_names(run)
    side = sidecar_paths(path)
    targets = [path, side["truth_json"], side["truth_csv"]]
    if run.reference_log is not None:
        targets.append(side["reference_log"])
    refuse_existing(targets, force, "nothing was written")
    path.parent.mkdir(parents=True, exist_ok=True)
    if fmt == "csv":
        write_text_atomic(path, csv_text(run.columns, run.kinds), force=force)
    else:
        logger = run.info["logger"]
        metadata = Metadata(sample_rate_hz=float(logger["sample_rate_hz"]),
                            unit=str(run.info["unit"]), profile=str(run.info["profile"]),
                            extra={"simulated": True, "logger": logger["kind"]})
        with RecordingWriter(path, metadata, list(run.columns), force=force) as writer:
            writer.write(Recording(dict(run.columns), metadata))
    write_text_atomic(side["truth_json"], json.dumps(run.info, indent=1) + "\n", force=force)
    _write_table_csv(side["truth_csv"], run.truth, force)
    reference = None
    if run.reference_log is not None:
        reference = str(write_text_atomic(side["reference_log"], run.reference_log, force=force))
    return LoggedFiles(str(path), str(side["truth_json"]), str(side["truth_csv"]), reference,
                       len(run))


def simulate_logged_files(
    profiles: list[Profile],
    output: str | Path,
    logger: Logger,
    unit: str | Unit | MultiAxisUnit = "paper-unit",
    seed: int = 0,
    file_format: str | None = None,
    input_rate_dph: float | None = None,
    force: bool = False,
) -> list[LoggedFiles]:
    """Simulate each profile as ``logger`` writes it, one recording (and its truth) per run.

    ``output`` is a file for a single run, else a directory of ``<profile name>.csv``
    (or the suffix of ``file_format``). A single run uses ``seed`` itself; run ``k`` of
    several the seed ``SeedSequence(seed, spawn_key=(k,))`` draws.

    Raises
    ------
    OutputExistsError
        When a target exists and ``force`` is False (nothing is written).
    """
    if not profiles:
        raise InputError("no runs to simulate; give at least one profile")
    paths = output_paths(profiles, output, file_format or (
        None if is_recording(output) else "csv"))
    targets = []
    for path in paths:
        side = sidecar_paths(path)
        targets += [path, side["truth_json"], side["truth_csv"]]
        if logger.reference_log is not None:
            targets.append(side["reference_log"])
    refuse_existing(targets, force, "nothing was written")
    seeds = [int(seed)] if len(profiles) == 1 else [
        int(np.random.SeedSequence(int(seed), spawn_key=(k,)).generate_state(1)[0])
        for k in range(len(profiles))
    ]
    return [
        write_logged(log_run(profile, unit, logger, s, input_rate_dph), path, force=force)
        for profile, path, s in zip(profiles, paths, seeds, strict=True)
    ]


def logged_summary(logged: Sequence[LoggedFiles], unit: str, logger: str,
                   sample_rate_hz: float, seed: int) -> Summary:
    """The files ``hrgtc simulate --logger`` wrote, as a table: file, rows, its truth (and
    the reference log, if any)."""
    cells: list[Figure] = []
    for k, w in enumerate(logged):
        truth = w.truth_json + (f", {w.reference_log}" if w.reference_log else "")
        cells += [Figure(f"files[{k}].path", "file", w.path, row=str(k), column="file"),
                  Figure(f"files[{k}].rows", "rows", w.rows, spec=",", row=str(k),
                         column="rows"),
                  Figure(f"files[{k}].truth", "truth", truth, row=str(k), column="truth")]
    return Summary("", ((f"simulated {unit} through a {logger} logger, {sample_rate_hz:g} Hz, "
                         f"seed {seed}", tuple(cells)),))
