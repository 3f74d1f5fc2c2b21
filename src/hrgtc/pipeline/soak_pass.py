"""Each soak's one pass in a calibration: its plateaus and the drift fit's at-rest pass.

:func:`hrgtc.pipeline.axis_calibration.fit_soaks` reads each soak once for its plateau and,
on the same chunks, the at-rest detector the drift fit will need (:class:`SoakRests`); the
soaks are independent until their plateaus are combined, so each soak's pass
(:class:`SoakPass`) is a piece of work a worker process can run
(:mod:`hrgtc.core.forked`: the soaks on every core).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from hrgtc.core.errors import CalibrationError, InputError
from hrgtc.drift.fit_stages import TrainingReading, rest_key
from hrgtc.drift.rest import RestPass
from hrgtc.pipeline.narrow_reading import PassPrints
from hrgtc.recording import ReadOptions, Recording
from hrgtc.recording.schema import concatenate
from hrgtc.settings.calibration import CalibrationSettings
from hrgtc.thermometry.plateaus import Plateau, plateaus_from_recordings

PathLike = str | os.PathLike[str]

#: Columns plateau detection needs from a soak.
SOAK_COLUMNS = ("time_s", "freq_hz", "chamber_c")


class SoakRests:
    """The drift fit's at-rest passes over the soaks, run on the soak plateaus' reading of
    each file (each soak read once fewer): the detector's columns gathered from the same
    chunks (:class:`~hrgtc.drift.rest.RestPass`), one result per likely warm-up."""

    def __init__(self, motion: str, warmups_s: Sequence[float]) -> None:
        self.motion, self.warmups_s = motion, tuple(warmups_s)
        self.found: dict[str, dict[float, Any]] = {}
        self.prints = PassPrints()  # the drift fit's window pass reads fewer columns

    def read(self, options: ReadOptions, path: PathLike) -> Any:
        """The soak's :data:`SOAK_COLUMNS` (as ``options.read(path, keep=SOAK_COLUMNS)``),
        its at-rest passes kept."""
        if type(options).read is not ReadOptions.read or not self.warmups_s:
            return options.read(path, keep=SOAK_COLUMNS)  # a reading held in memory
        rest = RestPass(self.motion)
        first, others = None, []  # the first chunk; the columns the detector does not take
        for chunk in self.prints.whole(path, options.chunks(path)):
            rest.partial_fit(chunk)
            first = chunk if first is None else first
            others.append({k: chunk[k] for k in SOAK_COLUMNS
                           if k in chunk and k not in RestPass.WANTED})
        if first is None:
            return concatenate([])  # refused as the plain reading refuses it
        gathered = rest.columns  # the detector's buffers hold time_s and freq_hz whole
        try:
            found = rest.finish_each(self.warmups_s)
        except (InputError, CalibrationError):  # said by the fit's own pass, if it joins
            found = []
        self.found[str(path)] = dict(zip(self.warmups_s, found, strict=False))
        return Recording({k: gathered[k] if k in RestPass.WANTED else
                          np.concatenate([part[k] for part in others])
                          for k in SOAK_COLUMNS if k in first}, first.metadata, first.source)

    def taken(self, path: PathLike) -> tuple[Any, Any]:
        """What reading ``path`` left here (its at-rest passes, its fingerprints)."""
        return self.found.get(str(path)), self.prints.files.get(str(path))

    def keep(self, path: PathLike, taken: tuple[Any, Any]) -> None:
        """Keep :meth:`taken` of ``path`` (from a worker process's reading of it)."""
        found, prints = taken
        if found is not None:
            self.found[str(path)] = found
        if prints is not None:
            self.prints.files[str(path)] = prints

    def cache(self, training: Sequence[PathLike], first: int,
              options: ReadOptions) -> dict[Any, Any]:
        """A rest cache for the drift fit on ``training``, whose runs from ``first`` on are
        the soaks (keyed as :func:`~hrgtc.drift.fit_stages.rest_key`)."""
        reading = TrainingReading(motion=options.motion, gaps=options.gaps)
        return {rest_key(number, reading, warmup): rest
                for number, path in enumerate(training) if number >= first
                for warmup, rest in self.found.get(str(path), {}).items()}


@dataclass(frozen=True)
class SoakPass:
    """One soak's pass of :func:`~hrgtc.pipeline.axis_calibration.fit_soaks` (its sample
    rate, its plateaus and what its at-rest pass left in ``rests``), a piece of work a
    worker process can run."""

    options: ReadOptions
    settings: CalibrationSettings
    rests: SoakRests | None

    @staticmethod
    def prepare() -> None:
        """Load what every soak's pass loads on first use (before worker processes fork)."""
        import scipy.optimize  # noqa: F401  (the settling transients' fits)

        import hrgtc.thermometry._plateau_kernel  # noqa: F401  (the plateaus' block sums)

    def __call__(self, path: PathLike) -> tuple[float, list[Plateau], Any]:
        rests = self.rests
        soak = (self.options.read(path, keep=SOAK_COLUMNS) if rests is None
                else rests.read(self.options, path))
        found = plateaus_from_recordings([soak], self.settings.plateaus)
        return (soak.metadata.sample_rate_hz, found,
                None if rests is None else rests.taken(path))
