"""Simulated chamber campaigns on disk for calibration tests (reduced sample rate)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from hrgtc.simulate import simulate_files
from hrgtc.simulate import standard_profiles as profiles

SETPOINTS_C = (-20.0, -10.0, 0.0, 10.0, 20.0, 30.0, 40.0)
RATE_HZ = 5.0  # the physics and the 10 s bias stability do not depend on the rate


@dataclass(frozen=True)
class Campaign:
    soaks: list[Path]
    cooldown: Path
    warmup: Path


def make_campaign(folder: Path, unit: str, sample_rate_hz: float = RATE_HZ, hours: float = 5.0,
                  seed: int = 1) -> Campaign:
    """Seven soaks, a cool-down (training) and a warm-up with another seed (validation)."""
    soaks = simulate_files([profiles.soak(sp, hours) for sp in SETPOINTS_C], folder / "soaks",
                           "parquet", unit=unit, sample_rate_hz=sample_rate_hz, seed=seed)
    cool = simulate_files([profiles.cooldown(20.0, -20.0, 5.0)], folder / "cool", "parquet",
                          unit=unit, sample_rate_hz=sample_rate_hz, seed=seed + 1)
    warm = simulate_files([profiles.warmup(-20.0, 20.0, 5.0)], folder / "warm", "parquet",
                          unit=unit, sample_rate_hz=sample_rate_hz, seed=seed + 2)
    return Campaign([Path(w.path) for w in soaks], Path(cool[0].path), Path(warm[0].path))


@dataclass(frozen=True)
class InstrumentCampaign:
    soaks: list[Path]
    cooldown: Path
    warmup: Path
    rate_table: Path
    rate_table_heldout: Path


#: Rate-table plateaus of training and of the held-out run (temperatures between them).
TABLE_PLATEAUS_C = (-15.0, 0.0, 15.0, 30.0)
HELDOUT_PLATEAUS_C = (-5.0, 22.0)


def make_instrument_campaign(folder: Path, unit: str = "imu-3", sample_rate_hz: float = 1.0,
                             seed: int = 11) -> InstrumentCampaign:
    """A three-axis unit: soaks, cool-down, warm-up (held out), rate tables at four
    temperatures (training) and at two others (held out)."""
    def one(profiles_: list, name: str, k: int) -> list[Path]:
        written = simulate_files(profiles_, folder / name, "parquet", unit=unit,
                                 sample_rate_hz=sample_rate_hz, seed=seed + k)
        return [Path(w.path) for w in written]

    axes = ("x", "y", "z")
    soaks = one([profiles.soak(sp, 5.0) for sp in SETPOINTS_C], "soaks", 0)
    cool = one([profiles.cooldown(20.0, -20.0, 5.0)], "cool", 1)
    warm = one([profiles.warmup(-20.0, 20.0, 5.0)], "warm", 2)
    table = one([profiles.rate_table(TABLE_PLATEAUS_C, hold_s=60.0, soak_h=2.0, axes=axes)],
                "table", 3)
    heldout = one([profiles.rate_table(HELDOUT_PLATEAUS_C, hold_s=60.0, soak_h=2.0,
                                       axes=axes)], "table_heldout", 4)
    return InstrumentCampaign(soaks, cool[0], warm[0], table[0], heldout[0])
