"""The corpus of real recordings no one here wrote, and the figures a newcomer's run must reach.

Each file of ``tests/data/`` (and the AGPL one kept apart in ``tests/data-agpl/``) is
described once here: where it is, the column mapping and units a newcomer passes (nothing
else), the periods its README calls at rest, and how numpy alone reads it. The checks of
issue 27 item 1 (``tests/test_real_corpus.py``) run the documented path on each --
``info``, ``calibrate`` on the first 60 % of the time, ``compensate`` and ``evaluate`` on
the rest -- and compare the compensated rate with a numpy line ``a + b·T`` fitted on the
still training samples, computed here without hrgtc:

* the held-out still samples' 60 s means (a mean of at least half a minute of samples),
* minus their mean per still period (a constant offset per orientation or restart is a
  nuisance parameter: the unit's g-sensitivity, the Earth rate's projection, and unknown
  for a new orientation to both methods alike),
* their RMS, hrgtc's over the line's.

docs/real-loggers/corpus.md tabulates the figures; the test checks the table.
"""

from __future__ import annotations

import gzip
import math
import shutil
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

DATA = Path(__file__).resolve().parent / "data"
AGPL = Path(__file__).resolve().parent / "data-agpl"
#: °/h per rad/s.
DPH_PER_RADPS = 180.0 / math.pi * 3600.0
#: Share of the time trained on; the rest is held out.
TRAINED = 0.6
#: Length of the held-out means compared. [s]
MEAN_S = 60.0
#: Fewest samples a 60 s mean needs (half a minute at 1 Hz).
MIN_MEAN_SAMPLES = 30
#: hrgtc's held-out RMS may be at most this many times the line's.
LINE_RATIO = 1.05


@dataclass(frozen=True)
class Reading:
    """A file as numpy reads it: seconds since the first sample, °C, °/h per axis, and the
    first sample's time in seconds as the file counts it."""

    time_s: np.ndarray
    temperature_c: np.ndarray
    rates_dph: dict[str, np.ndarray]
    origin_s: float = 0.0


@dataclass(frozen=True)
class RealFile:
    """One recording of the corpus.

    Attributes
    ----------
    name
        Its folder under the tests' data.
    source
        The data file, as committed (hrgtc reads a ``.csv.gz`` as it is; numpy's reading
        unpacks it first).
    args
        The column mapping and units: all a newcomer passes.
    still
        The periods at rest, seconds since the first sample (from its README).
    read
        numpy's reading of the file (independent of hrgtc).
    """

    name: str
    source: Path
    args: tuple[str, ...]
    still: tuple[tuple[float, float], ...]
    read: Callable[[Path], Reading]

    def unpacked(self, directory: Path) -> Path:
        """The data file, unpacked into ``directory`` when it is a ``.gz``."""
        if self.source.suffix != ".gz":
            return self.source
        target = directory / self.source.stem
        if not target.exists():
            with gzip.open(self.source, "rb") as packed, open(target, "wb") as out:
                shutil.copyfileobj(packed, out)
        return target


def _columns(path: Path, delimiter: str = ",") -> dict[str, np.ndarray]:
    table = np.genfromtxt(path, delimiter=delimiter, names=True, deletechars="",
                          encoding="utf-8")
    return {name: np.asarray(table[name], dtype=np.float64) for name in table.dtype.names}


def _cats(path: Path) -> Reading:
    c = _columns(path)
    return Reading(c["time_s"] - c["time_s"][0], c["temp_C"],
                   {a: c[f"gyro_{a}_mrad_s"] * 1e-3 * DPH_PER_RADPS for a in "xyz"},
                   c["time_s"][0])


def _tofupilot(path: Path) -> Reading:
    c = _columns(path, "\t")
    return Reading((c["timestamp"] - c["timestamp"][0]) * 1e-6, c["imu.temperature"],
                   {a: c[f"imu.gyro.{a}"] * DPH_PER_RADPS for a in "xyz"},
                   c["timestamp"][0] * 1e-6)


def _vn100(path: Path) -> Reading:
    c = _columns(path)
    return Reading((c["millis"] - c["millis"][0]) * 1e-3, c["Temp"],
                   {a: c[f"Gyro{a.upper()}"] * DPH_PER_RADPS for a in "xyz"},
                   c["millis"][0] * 1e-3)


CORPUS = (
    RealFile(
        "cats-imu-fridge", AGPL / "cats-imu-fridge" / "cats_temperature_calib.csv.gz",
        ("--col", "rate_dph_x=gyro_x_mrad_s", "--col", "rate_dph_y=gyro_y_mrad_s",
         "--col", "rate_dph_z=gyro_z_mrad_s", "--col", "temperature_c=temp_C",
         "--rate-unit", "mradps", "--thermometer", "sensor"),
        # the README's still periods; still 0 from 325 s, where the data is at rest (the
        # README says 480 s), less the touch inside still 1
        ((325.0, 92460.0), (92880.0, 138257.0), (138306.0, 183780.0), (184920.0, 268020.0)),
        _cats),
    RealFile(
        "tofupilot-imu-chamber", DATA / "tofupilot-imu-chamber" / "imu_raw_data.csv",
        ("--col", "time_s=timestamp", "--col", "rate_dph_x=imu.gyro.x",
         "--col", "rate_dph_y=imu.gyro.y", "--col", "rate_dph_z=imu.gyro.z",
         "--col", "temperature_c=imu.temperature", "--time-unit", "us",
         "--rate-unit", "radps", "--thermometer", "sensor"),
        ((0.1, 1e9),),  # at rest throughout; row 0 is an outlier
        _tofupilot),
    RealFile(
        "vn100-waves-in-ice", DATA / "vn100-waves-in-ice" / "vn100_F00379-F00383.csv",
        ("--col", "time_s=millis", "--col", "rate_dph_x=GyroX", "--col", "rate_dph_y=GyroY",
         "--col", "rate_dph_z=GyroZ", "--col", "temperature_c=Temp", "--time-unit", "ms",
         "--rate-unit", "radps", "--thermometer", "sensor"),
        # the README's (seconds of millis / 1000) less the first sample's 7.985 s
        ((40.0, 1074.0), (1107.0, 1286.0), (1821.0, 3279.0), (3432.0, 4493.0)),
        _vn100),
)


def split_s(reading: Reading) -> float:
    """Start of the held-out part: 60 % of the recorded time. [s since the first sample]"""
    t = reading.time_s
    period = float(np.median(np.diff(t)))
    return TRAINED * (t[-1] - t[0] + period)


def still_mask(time_s: np.ndarray, periods) -> np.ndarray:
    """True for the samples inside one of the still periods."""
    mask = np.zeros(time_s.size, dtype=bool)
    for a, b in periods:
        mask |= (time_s >= a) & (time_s < b)
    return mask


def centred_means(time_s: np.ndarray, values: np.ndarray, periods) -> np.ndarray:
    """The 60 s means of each still period, less their mean in that period."""
    out = []
    for a, b in periods:
        inside = (time_s >= a) & (time_s < b) & np.isfinite(values)
        if not inside.any():
            continue
        k = np.floor((time_s[inside] - time_s[inside][0]) / MEAN_S).astype(np.int64)
        count = np.bincount(k)
        total = np.bincount(k, values[inside])
        full = count >= MIN_MEAN_SAMPLES
        if full.sum() < 2:
            continue
        means = total[full] / count[full]
        out.append(means - means.mean())
    return np.concatenate(out) if out else np.empty(0)


def line_figures(reading: Reading, periods, compensated_time_s: np.ndarray,
                 compensated: dict[str, np.ndarray]) -> dict[str, dict[str, float]]:
    """Per axis: the held-out RMS of raw, of the numpy line, of hrgtc, and hrgtc/line."""
    cut = split_s(reading)
    t, temperature = reading.time_s, reading.temperature_c
    still = still_mask(t, periods)
    train, held = still & (t < cut), still & (t >= cut)
    held_periods = [(max(a, cut), b) for a, b in periods if b > cut]
    out = {}
    for axis, rate in reading.rates_dph.items():
        slope, intercept = np.polyfit(temperature[train], rate[train], 1)
        line = np.where(held, rate - (intercept + slope * temperature), np.nan)
        rms = {
            "raw": np.where(held, rate, np.nan),
            "line": line,
        }
        figures = {k: float(np.sqrt(np.mean(centred_means(t, v, held_periods) ** 2)))
                   for k, v in rms.items()}
        mine = compensated[axis]
        figures["hrgtc"] = float(np.sqrt(np.mean(centred_means(
            compensated_time_s, mine, held_periods) ** 2)))
        figures["ratio"] = figures["hrgtc"] / figures["line"]
        figures["n_means"] = int(centred_means(t, line, held_periods).size)
        figures["periods"] = sum(1 for a, b in held_periods
                                 if np.count_nonzero(held & (t >= a) & (t < b)))
        figures["slope_dph_per_c"] = float(slope)
        out[axis] = figures
    return out


def ratio_bound(figures: dict[str, float], level: float = 0.95) -> float:
    """Upper end of the two-sided ``level`` interval of an RMS ratio that chance alone gives
    a model as good as the line (bench/bench_corpus_terms.py prints it): χ² with the
    held-out means' degrees of freedom (their number less one per still period, whose mean
    was taken off)."""
    from scipy.stats import chi2

    dof = max(figures["n_means"] - figures["periods"], 1)
    return math.sqrt(dof / chi2.ppf((1.0 - level) / 2.0, dof))


def at_rest_extremes(reading: Reading, periods, trained: bool = True) -> tuple[float, float]:
    """Lowest and highest temperature of the still samples of the trained (or held-out)
    part. [°C]"""
    cut = split_s(reading)
    t = reading.time_s
    part = (t < cut) if trained else (t >= cut)
    values = reading.temperature_c[still_mask(t, periods) & part]
    return float(values.min()), float(values.max())
