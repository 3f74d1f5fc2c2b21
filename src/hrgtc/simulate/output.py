"""Simulated runs written to files: one file per run, chunk by chunk, atomically.

The recording files follow the recording contract of :mod:`hrgtc.recording`
(Parquet, CSV, HDF5, TDMS, MATLAB v5 or MDF4 by suffix: the formats of the registry with a
writer) with the simulator's ground truth columns and
metadata (:func:`hrgtc.simulate.campaign.run_metadata`). Nothing is
overwritten without ``force``; a campaign checks all its targets first.
"""

from __future__ import annotations

import threading
from collections.abc import Mapping, Sequence
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, fields, replace
from pathlib import Path
from typing import Any

import numpy as np

from hrgtc.core import records
from hrgtc.core.errors import InputError
from hrgtc.core.files import refuse_existing
from hrgtc.core.progress import Progress
from hrgtc.core.summary import Figure, Summary
from hrgtc.recording import RecordingWriter
from hrgtc.recording.formats.registry import formats, output_suffixes
from hrgtc.simulate import units as _units
from hrgtc.simulate.campaign import (
    DEFAULT_CHUNK_ROWS,
    Seed,
    check_rate,
    check_seed,
    iter_run_chunks,
    row_count,
    run_columns,
    run_metadata,
)
from hrgtc.simulate.profiles import Profile
from hrgtc.simulate.units import MultiAxisUnit, Unit

__all__ = ["SimulatedRun", "WrittenFile", "output_paths", "simulate_files",
           "simulate_to_file", "written_summary"]


@dataclass(frozen=True)
class WrittenFile(records.Written):
    """A recording written by the simulator.

    Attributes
    ----------
    path
        File written.
    rows
        Number of samples.
    profile
        The profile's description.
    """

    path: str
    rows: records.Count
    profile: str

    def summary(self) -> Summary:
        """The file, its rows and its profile (its text: one line)."""
        return Summary(self.path, (("written", (Figure("path", "file", self.path),
                                                Figure("rows", "rows", self.rows),
                                                Figure("profile", "profile", self.profile))),),
                       layout=("{path}: {rows} rows ({profile})",))


def simulate_to_file(
    profile: Profile,
    path: str | Path,
    unit: str | Unit | MultiAxisUnit = _units.DEFAULT_UNIT,
    sample_rate_hz: float = 200.0,
    seed: Seed = 0,
    input_rate_dph: float | Mapping[str, float] | None = None,
    chunk_rows: int = DEFAULT_CHUNK_ROWS,
    force: bool = False,
    progress: Progress | None = None,
) -> WrittenFile:
    """Simulate a run straight to a file (format from the suffix), chunk by chunk, atomically.

    Parameters
    ----------
    profile
        The chamber program.
    path
        Output file, ``.parquet``, ``.csv``, ``.h5``, ``.tdms``, ``.mat`` or ``.mf4``; its
        directory must exist.
    unit, sample_rate_hz, seed, input_rate_dph, chunk_rows, progress
        As for :func:`hrgtc.simulate.campaign.iter_run_chunks`.
    force
        Overwrite ``path`` if it exists.

    Returns
    -------
    WrittenFile
        The path and the number of rows written.

    Raises
    ------
    OutputExistsError
        If ``path`` exists and ``force`` is False.
    """
    path = Path(path)
    refuse_existing(path, force)
    metadata = run_metadata(profile, unit, sample_rate_hz, seed, input_rate_dph)
    rows = 0
    chunks = iter_run_chunks(profile, unit, sample_rate_hz, seed, input_rate_dph, chunk_rows,
                             progress)
    # Encode and write chunk k in a worker thread while chunk k+1 is generated
    # (numpy, scipy and pyarrow release the GIL in their loops).
    with (
        RecordingWriter(path, metadata, run_columns(profile, unit), force=force) as writer,
        ThreadPoolExecutor(max_workers=1, thread_name_prefix="hrgtc-writer") as pool,
    ):
        pending: Future[None] | None = None
        for chunk in chunks:
            if pending is not None:
                pending.result()
            pending = pool.submit(writer.write, chunk)
            rows += len(chunk)
        if pending is not None:
            pending.result()
    return WrittenFile(path=str(path), rows=rows, profile=profile.description)


def output_paths(
    profiles: Sequence[Profile], output: str | Path, file_format: str | None = None
) -> list[Path]:
    """Where :func:`simulate_files` writes each profile.

    ``output`` with a recording suffix (``.parquet``, ``.csv``, ``.h5``, ``.tdms`` ...) is the
    file itself (one profile only); otherwise it is a directory and each file
    is named ``<profile.name><suffix>``, the suffix from ``file_format``
    (default Parquet).
    """
    output = Path(output)
    writers = output_suffixes()
    if file_format is not None and file_format not in writers:
        named = [f.name for f in formats() if file_format in (f.name, f.output_name)]
        why = f"the {named[0]} format has no writer" if named else "unknown format"
        raise InputError(f"{why} ({file_format!r}); the formats that write are "
                         f"{', '.join(writers)}")
    suffix = output.suffix.lower()
    by_suffix = {s: fmt.output_name for fmt in formats() for s in fmt.suffixes}
    if suffix in by_suffix:
        if len(profiles) != 1:
            raise InputError(
                f"output {output} is a file but {len(profiles)} runs are to be written; give a "
                "directory, or --single-file for one file holding all set-points"
            )
        if file_format is not None and by_suffix[suffix] != file_format:
            raise InputError(
                f"output {output} has suffix {suffix!r} but the format is {file_format!r}; "
                "make them agree or drop --format"
            )
        return [output]
    chosen = writers[file_format or "parquet"]
    names = [p.name for p in profiles]
    unsafe = [n for n in names if Path(n).name != n or n in ("", ".", "..")]
    if unsafe:
        raise InputError(f"profile name(s) {unsafe} cannot be file names; rename the profile(s)")
    duplicates = sorted({n for n in names if names.count(n) > 1})
    if duplicates:
        raise InputError(
            f"two runs would write the same file(s) {duplicates}; give distinct set-points"
        )
    return [output / f"{name}{chosen}" for name in names]


@dataclass(frozen=True)
class SimulatedRun:
    """How each run of :func:`simulate_files` is simulated (as for :func:`iter_run_chunks`).

    Attributes
    ----------
    unit
        A unit name, a :class:`Unit` or a :class:`MultiAxisUnit`.
    sample_rate_hz
        Sample rate. [Hz]
    seed
        Non-negative integer seed of the campaign (run ``k`` draws from
        ``SeedSequence(seed, spawn_key=(k,))``).
    input_rate_dph
        Known constant input rate, per axis for a multi-axis unit; None: the unit's. [°/h]
    chunk_rows
        Rows per chunk.
    """

    unit: str | Unit | MultiAxisUnit = _units.DEFAULT_UNIT
    sample_rate_hz: float = 200.0
    seed: int = 0
    input_rate_dph: float | Mapping[str, float] | None = None
    chunk_rows: int = DEFAULT_CHUNK_ROWS


def simulate_files(
    profiles: Sequence[Profile],
    output: str | Path,
    file_format: str | None = None,
    run: SimulatedRun | None = None,
    *,
    force: bool = False,
    progress: Progress | None = None,
    workers: int = 2,
    **run_options: Any,
) -> list[WrittenFile]:
    """Simulate one file per profile (a soak campaign, a cool-down, ...).

    Run ``k`` uses the seed ``SeedSequence(seed, spawn_key=(k,))`` (kept in its
    metadata), so the runs are independent and each is reproducible alone.
    Every target is checked before anything is written: with ``force`` False
    an existing file stops the whole campaign. Up to ``workers`` files are
    simulated and written at once (threads; the files do not depend on it).

    Parameters
    ----------
    profiles
        The runs.
    output
        A directory (created if missing), or a file for a single run.
    file_format
        ``"parquet"``, ``"csv"``, ``"h5"``, ``"tdms"``, ``"mat"`` or ``"mf4"`` (a key of
        :func:`~hrgtc.recording.formats.registry.output_suffixes`); None: from ``output``'s
        suffix, else Parquet.
    run
        Unit, sample rate, seed, input rate and chunk rows (:class:`SimulatedRun`);
        None: its defaults.
    force
        Overwrite existing files.
    progress
        Called as ``progress(rows_done, rows_total)`` over all runs (from worker threads).
    workers
        Number of files in flight at once (each holds a few chunks in memory).
    **run_options
        Fields of :class:`SimulatedRun` by keyword (``unit="imu-3", seed=4``), over ``run``'s.

    Returns
    -------
    list of WrittenFile
        Path and row count of each file, in the order of ``profiles``.

    Raises
    ------
    OutputExistsError
        If a target exists and ``force`` is False (nothing is written).
    """
    if not profiles:
        raise InputError("no runs to simulate; give at least one profile")
    settings = _run_settings(run, run_options)
    unit = settings.unit
    unit = unit if isinstance(unit, Unit | MultiAxisUnit) else _units.get(unit)
    fs = check_rate(settings.sample_rate_hz)
    seed = check_seed(settings.seed)
    if not isinstance(seed, int):
        raise InputError(f"a campaign's seed must be a non-negative integer, got {seed!r}")
    paths = output_paths(profiles, output, file_format)
    refuse_existing(paths, force, "nothing was written")
    paths[0].parent.mkdir(parents=True, exist_ok=True)
    shared = _SharedProgress([row_count(p, fs) for p in profiles], progress)
    with ThreadPoolExecutor(max_workers=max(1, min(int(workers), len(profiles)))) as pool:
        futures = [
            pool.submit(simulate_to_file, profile, path, unit, fs,
                        np.random.SeedSequence(seed, spawn_key=(k,)), settings.input_rate_dph,
                        settings.chunk_rows, force, shared.reporter(k))
            for k, (profile, path) in enumerate(zip(profiles, paths, strict=True))
        ]
        try:
            return [future.result() for future in futures]
        except BaseException:
            for future in futures:
                future.cancel()
            raise


def _run_settings(run: SimulatedRun | None, options: Mapping[str, Any]) -> SimulatedRun:
    """``run`` (None: the defaults) with the fields given by keyword replaced."""
    known = {f.name for f in fields(SimulatedRun)}
    unknown = sorted(set(options) - known)
    if unknown:
        raise TypeError(f"simulate_files() got unexpected keyword argument(s) {unknown}; "
                        f"the run's options are {sorted(known)}")
    return replace(run or SimulatedRun(), **options)


class _SharedProgress:
    """One ``progress(rows_done, rows_total)`` over every run, fed from worker threads."""

    def __init__(self, counts: Sequence[int], progress: Progress | None) -> None:
        self.total = float(sum(counts))
        self.done = [0.0] * len(counts)
        self.lock = threading.Lock()
        self.progress = progress

    def reporter(self, k: int) -> Progress:
        """The progress callback of run ``k``."""
        def report(rows: float, _total: float) -> None:
            with self.lock:  # one call at a time, rows_done never decreasing
                self.done[k] = rows
                if self.progress is not None:
                    self.progress(sum(self.done), self.total)

        return report


def written_summary(written: Sequence[WrittenFile], unit: str, sample_rate_hz: float,
                    seed: int) -> Summary:
    """The files ``hrgtc simulate`` wrote, as a table: file, rows, profile."""
    cells: list[Figure] = []
    for k, w in enumerate(written):
        cells += [Figure(f"files[{k}].path", "file", w.path, row=str(k), column="file"),
                  Figure(f"files[{k}].rows", "rows", w.rows, spec=",", row=str(k),
                         column="rows"),
                  Figure(f"files[{k}].profile", "profile", w.profile, row=str(k),
                         column="profile")]
    return Summary("", ((f"simulated {unit}, {sample_rate_hz:g} Hz, seed {seed}",
                         tuple(cells)),))
